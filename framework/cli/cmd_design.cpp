// SPDX-License-Identifier: MIT
// `binocle design`: which baseline and which lens for a target range (or band)?
// Ranks every (B, f) of the available hardware by the form factor (Eq. 7) and the
// sensor-aware figures; with --simulate, by the stereo efficiency η3D measured on the
// simulated rig.
#include "cli/command.hpp"
#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/json.hpp"
#include "experiment/experiment.hpp"
#include "method/design.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <sstream>

namespace fs = std::filesystem;

namespace binocle::cli {
namespace {

std::vector<double> numberList(const std::string &option, const std::string &text) {
    std::vector<double> out;
    std::stringstream ss(text);
    for (std::string item; std::getline(ss, item, ',');) {
        try {
            size_t used = 0;
            out.push_back(std::stod(item, &used));
            if (used != item.size()) throw std::invalid_argument(item);
        } catch (const std::logic_error &) {
            throw Error(option + " " + text + ": '" + item + "' is not a number (expected e.g. 2.8,4,8)");
        }
    }
    return out;
}

// "100:200:10" (min:max:step) or a list "100,150,190".
std::vector<double> baselines(const std::string &text) {
    if (text.find(':') == std::string::npos) return numberList("--baselines", text);
    std::vector<double> p;
    std::stringstream ss(text);
    for (std::string item; std::getline(ss, item, ':');) p.push_back(numberList("--baselines", item).at(0));
    if (p.size() != 3 || !(p[2] > 0) || p[1] < p[0]) throw Error("--baselines " + text + ": expected MIN:MAX:STEP in mm, e.g. 100:200:10");
    std::vector<double> out;
    for (double b = p[0]; b <= p[1] + 1e-9; b += p[2]) out.push_back(b);
    return out;
}

struct Candidate {
    double baseline_mm, focal_length_mm;
    std::vector<method::DesignFigures> at; // one per range of the band
    double worst_ff_distance = 0;          // distance of the worst range's FF from the best band
    bool panel_fits = true, in_search = true;
    double eta_3d = NAN;                   // --simulate
};

// How far FF lies from the paper's best band 1.2-2.0 (0 inside), in log terms so that
// 0.6 and 4.0 (both a factor 2 off) weigh alike.
double ffDistance(double ff) {
    if (ff >= 1.2 && ff <= 2.0) return 0;
    return ff < 1.2 ? std::log(1.2 / ff) : std::log(ff / 2.0);
}

int run(const Args &args) {
    std::vector<double> ranges;
    if (args.has("--range")) ranges = numberList("--range", args.get("--range"));
    if (args.has("--band")) {
        auto b = numberList("--band", args.get("--band"));
        if (b.size() != 2 || !(b[0] > 0) || b[1] <= b[0]) throw Error("--band " + args.get("--band") + ": expected MIN,MAX in mm, e.g. 5000,12000");
        for (int i = 0; i <= 4; ++i) ranges.push_back(b[0] + (b[1] - b[0]) * i / 4.0);
    }
    if (ranges.empty()) throw Error("give a target: --range 6000 (mm) or --band 5000,12000 (see --help)");
    for (double r : ranges)
        if (!(r > 0)) throw Error("--range: " + std::to_string(r) + " mm: expected a positive range");
    const std::vector<double> lenses = numberList("--lenses", args.get("--lenses", "2.8,4,8,12,16"));
    const std::vector<double> bases = baselines(args.get("--baselines", "100:200:10"));
    method::StereoDesign head;
    head.pixel_pitch_um = args.real("--pixel-pitch-um", 20.8);
    head.image_width_px = static_cast<int>(args.integer("--image-width", 320));
    head.image_height_px = static_cast<int>(args.integer("--image-height", 240));
    head.num_disparities = static_cast<int>(args.integer("--num-disparities", 64));
    head.camera_height_mm = args.real("--camera-height-mm", 1500);
    head.inclination_deg = args.real("--inclination-deg", 0);
    method::PanelPlacement panel;
    panel.width_mm = args.real("--panel-width-mm", 2500);
    panel.height_mm = args.real("--panel-height-mm", 2000);
    for (double v : lenses)
        if (!(v > 0)) throw Error("--lenses: focal lengths must be positive mm");
    for (double v : bases)
        if (!(v > 0)) throw Error("--baselines: baselines must be positive mm");
    if (!(head.pixel_pitch_um > 0)) throw Error("--pixel-pitch-um must be positive");

    std::vector<Candidate> cands;
    for (double b : bases)
        for (double f : lenses) {
            Candidate c{b, f, {}, 0, true, true, NAN};
            head.baseline_mm = b;
            head.focal_length_mm = f;
            for (double r : ranges) {
                c.at.push_back(method::designFigures(head, r, 0.25, &panel));
                const auto &x = c.at.back();
                c.worst_ff_distance = std::max(c.worst_ff_distance, ffDistance(x.form_factor));
                c.panel_fits = c.panel_fits && x.panel_fits_width;
                c.in_search = c.in_search && (!std::isfinite(x.min_range_mm) || x.min_range_mm <= r);
            }
            cands.push_back(c);
        }
    // Rank: configurations that see the whole panel and whose search reaches the range
    // first, then FF closest to the best band, then the finer depth resolution.
    auto byFigures = [](const Candidate &a, const Candidate &b) {
        if (a.panel_fits != b.panel_fits) return a.panel_fits;
        if (a.in_search != b.in_search) return a.in_search;
        if (std::fabs(a.worst_ff_distance - b.worst_ff_distance) > 1e-9) return a.worst_ff_distance < b.worst_ff_distance;
        return a.at.back().depth_resolution_mm < b.at.back().depth_resolution_mm;
    };
    std::stable_sort(cands.begin(), cands.end(), byFigures);

    const size_t top = static_cast<size_t>(std::max<long long>(1, args.integer("--top", 10)));
    if (args.has("--simulate")) {
        // Measure η3D on the simulated rig for the best `--simulate-count` by figures.
        const size_t n = std::min(cands.size(), static_cast<size_t>(std::max<long long>(1, args.integer("--simulate-count", 12))));
        PluginHost host;
        // No scan: the rig opens only the plugins it names.
        const std::string rig = args.get("--rig", dataFile("configs/rigs/sim-e1.yaml"));
        std::vector<TestGeometry> tests;
        std::vector<size_t> which;
        for (size_t i = 0; i < n; ++i)
            for (double r : ranges) {
                tests.push_back({cands[i].baseline_mm, cands[i].focal_length_mm, r, head.camera_height_mm, head.inclination_deg});
                which.push_back(i);
            }
        Experiment e = makeExperiment("design", rig, tests, host);
        ExperimentOptions opt;
        opt.out_dir = args.get("--out", "out/design") + "/simulated";
        opt.progress = !args.has("--quiet");
        runExperiment(e, host, opt);
        // Read η3D back from the table the experiment wrote.
        const std::string csv = readTextFile(opt.out_dir + "/results.csv");
        std::stringstream lines(csv);
        std::string header;
        std::getline(lines, header);
        std::vector<std::string> cols;
        std::stringstream hs(header);
        for (std::string c; std::getline(hs, c, ',');) cols.push_back(c);
        const auto col = std::find(cols.begin(), cols.end(), "eta_3d_percent") - cols.begin();
        std::vector<double> sum(n, 0), cnt(n, 0);
        size_t t = 0;
        for (std::string line; std::getline(lines, line) && t < which.size(); ++t) {
            std::vector<std::string> cells;
            std::stringstream ls(line);
            for (std::string c; std::getline(ls, c, ',');) cells.push_back(c);
            if (static_cast<size_t>(col) < cells.size() && !cells[col].empty()) {
                // Averaged over the band: a configuration is as good as it is across it.
                sum[which[t]] += std::stod(cells[col]);
                cnt[which[t]] += 1;
            }
        }
        for (size_t i = 0; i < n; ++i) cands[i].eta_3d = cnt[i] ? sum[i] / cnt[i] : 0.0;
        std::stable_sort(cands.begin(), cands.begin() + static_cast<long>(n),
                         [](const Candidate &a, const Candidate &b) { return a.eta_3d > b.eta_3d; });
    }

    // Table on stdout, JSON and CSV in --out.
    const bool sim = args.has("--simulate");
    std::printf("%-4s %8s %7s %7s %9s %10s %9s %7s %s\n", "rank", "B (mm)", "f (mm)", "FF", "d (px)", "dR (mm)", "Rmin (m)",
                "panel", sim ? "η3D (%)" : "reading");
    Json list = Json::array();
    std::string csv = "rank,baseline_mm,focal_length_mm,range_mm,form_factor,disparity_px,depth_resolution_mm,min_range_mm,"
                      "stereo_field_width_mm,panel_fits,eta_3d_percent\n";
    for (size_t i = 0; i < cands.size(); ++i) {
        const Candidate &c = cands[i];
        const auto &x = c.at[c.at.size() / 2]; // the middle of the band (or the range)
        if (i < top)
            std::printf("%-4zu %8.0f %7.1f %7.2f %9.2f %10.1f %9.2f %7s %s\n", i + 1, c.baseline_mm, c.focal_length_mm,
                        x.form_factor, x.disparity_px, x.depth_resolution_mm, x.min_range_mm / 1000,
                        c.panel_fits ? "fits" : "cut", sim ? (std::isfinite(c.eta_3d) ? std::to_string(c.eta_3d).substr(0, 5).c_str() : "-")
                                                           : method::formFactorReading(x.form_factor));
        Json j = Json::object();
        j.set("rank", static_cast<int64_t>(i + 1)).set("baseline_mm", c.baseline_mm).set("focal_length_mm", c.focal_length_mm);
        j.set("panel_fits", c.panel_fits).set("search_reaches_range", c.in_search);
        if (std::isfinite(c.eta_3d)) j.set("eta_3d_percent", c.eta_3d);
        Json per = Json::array();
        for (const auto &f : c.at) {
            per.push(Json::object()
                         .set("range_mm", f.range_mm)
                         .set("form_factor", f.form_factor)
                         .set("reading", method::formFactorReading(f.form_factor))
                         .set("disparity_px", f.disparity_px)
                         .set("depth_resolution_mm", f.depth_resolution_mm)
                         .set("min_range_mm", f.min_range_mm)
                         .set("horizontal_fov_deg", f.horizontal_fov_deg)
                         .set("stereo_field_width_mm", f.stereo_field_width_mm));
            char row[256];
            std::snprintf(row, sizeof row, "%zu,%g,%g,%g,%.4f,%.4f,%.2f,%.1f,%.1f,%d,%s\n", i + 1, c.baseline_mm,
                          c.focal_length_mm, f.range_mm, f.form_factor, f.disparity_px, f.depth_resolution_mm, f.min_range_mm,
                          f.stereo_field_width_mm, c.panel_fits ? 1 : 0,
                          std::isfinite(c.eta_3d) ? std::to_string(c.eta_3d).c_str() : "");
            csv += row;
        }
        j.set("ranges", std::move(per));
        list.push(std::move(j));
    }
    if (args.has("--out")) {
        std::error_code ec;
        fs::create_directories(args.get("--out"), ec);
        writeFileAtomic(args.get("--out") + "/design.json", Json::object().set("candidates", std::move(list)).dump());
        writeFileAtomic(args.get("--out") + "/design.csv", csv);
        std::cerr << "design: " << cands.size() << " configurations ranked; design.json and design.csv in " << args.get("--out") << "\n";
    }
    return 0;
}

Register reg({"design", "rank baselines and lenses for a target range or band by FF (Eq. 7), or by simulated η3D",
              "usage: binocle design (--range MM[,MM...] | --band MIN,MAX) [options]\n\n"
              "Ranks every combination of the available baselines and lenses for the target\n"
              "range(s): configurations that see the whole test panel and whose disparity search\n"
              "reaches the range first, then by how close the form factor FF = 10·B·f/R (Eq. 7)\n"
              "lies to the paper's best band 1.2-2.0 (worst range of the band counts), then by\n"
              "depth resolution. Beside FF it reports the expected disparity d = B·f/(R·p), the\n"
              "depth resolution dR = R²·p·Δd/(B·f) for Δd = 0.25 px, the minimum range of the\n"
              "disparity search and whether the panel fits the stereo field.\n\n"
              "  --range 6000,12000        target range(s) in mm\n"
              "  --band 5000,12000         a range band in mm (5 ranges across it)\n"
              "  --lenses 2.8,4,8,12,16    focal lengths available, mm (default: the Videre set)\n"
              "  --baselines 100:200:10    baselines, mm: MIN:MAX:STEP or a list (default 100:200:10)\n"
              "  --pixel-pitch-um 20.8     effective pixel pitch (default: Videre head decimated by 4)\n"
              "  --image-width 320 --image-height 240   image size in pixels\n"
              "  --num-disparities 64      the matcher's disparity search\n"
              "  --camera-height-mm 1500 --inclination-deg 0\n"
              "  --panel-width-mm 2500 --panel-height-mm 2000   the object that must fit\n"
              "  --top 10                  rows printed\n"
              "  --simulate                measure η3D on the simulated rig for the best candidates\n"
              "  --simulate-count 12       how many candidates to simulate\n"
              "  --rig FILE                base rig for --simulate (default configs/rigs/sim-e1.yaml)\n"
              "  --out DIR                 write design.json and design.csv (and simulated/ runs)\n"
              "  --quiet                   no progress bar\n",
              {"--simulate", "--quiet"},
              run});

} // namespace
} // namespace binocle::cli
