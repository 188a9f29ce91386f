// SPDX-License-Identifier: MIT
// `binocle design`: which baseline and which lens for a target range (or band)?
// Ranks every (B, f) of the available hardware by the form factor (Eq. 7) and the
// sensor-aware figures; with --simulate, by the stereo efficiency η3D measured on the
// simulated rig.
#include "cli/command.hpp"
#include "core/error.hpp"
#include "core/json.hpp"
#include "core/output_folder.hpp"
#include "experiment/experiment.hpp"
#include "experiment/predictor_choice.hpp"
#include "files/atomic_file.hpp"
#include "method/design.hpp"
#include "method/predictors.hpp"

#include <binocle/numbers.hpp>
#include <binocle/text.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <spdlog/spdlog.h>
#include <sstream>

namespace fs = std::filesystem;

namespace binocle::cli {
namespace {

struct DesignArgs {
    std::string range, band, lenses = method::kVidereLensesMm, baselines = "100:200:10";
    // The head's sensor and matcher, and its pose (method's one head description);
    // each candidate configures its baseline and lens.
    method::StereoDesign head = method::videreHead();
    double panel_width_mm = 2500, panel_height_mm = 2000;
    int top = 10, simulate_count = 12;
    bool simulate = false, quiet = false, force = false;
    std::string rig, out;
    std::string predictors_from, predictor; // empty: the shipped file; the best of it
};

// Candidates are ranked in memory and each is printed to the CSV once per range: more
// than this many baselines (or baseline x lens pairs) is a typo, not a design question.
constexpr size_t kMaxBaselines = 100000;
constexpr size_t kMaxCandidates = 1000000;

std::string num(double v) {
    std::ostringstream os;
    os << v;
    return os.str();
}

// An example of each list option's value, for its messages.
std::string exampleOf(const std::string &option) {
    return option == "--lenses" ? "2.8,4,8" : option == "--baselines" ? "100,150,190 or 100:200:10"
                                          : option == "--band"        ? "5000,12000"
                                                                      : "6000,12000";
}

// Numbers separated by commas, at least one: "" and "6000," are refused, not read as fewer.
std::vector<double> numberList(const std::string &option, const std::string &text, char separator = ',') {
    std::vector<double> out;
    const std::string shown = option + " " + sdk::printable(text);
    if (text.empty()) throw UsageError(shown + ": expected at least one number (e.g. " + exampleOf(option) + ")");
    for (size_t start = 0;;) {
        const size_t end = text.find(separator, start);
        const std::string item = text.substr(start, end == std::string::npos ? std::string::npos : end - start);
        double v = 0;
        std::string why;
        if (!sdk::parseDecimalReal(item, v, &why)) // decimal and finite: no "nan", "inf" or "0x1p3"
            throw UsageError(shown + ": '" + sdk::printable(item) + "' is not valid: " + why + " (e.g. " + exampleOf(option) + ")");
        out.push_back(v);
        if (end == std::string::npos) return out;
        start = end + 1;
    }
}

// "100:200:10" (min:max:step) or a list "100,150,190".
std::vector<double> baselines(const std::string &text) {
    if (text.find(':') == std::string::npos) return numberList("--baselines", text);
    const std::vector<double> p = numberList("--baselines", text, ':');
    if (p.size() != 3 || !(p[2] > 0) || p[1] < p[0]) throw UsageError("--baselines " + text + ": expected MIN:MAX:STEP in mm, e.g. 100:200:10");
    // Counted before anything is made: 1:1e9:1 would otherwise fill the memory.
    const double count = std::floor((p[1] - p[0]) / p[2] + 1e-9) + 1;
    if (!(count <= static_cast<double>(kMaxBaselines)))
        throw UsageError("--baselines " + text + ": " + std::to_string(static_cast<long long>(std::min(count, 9e18))) +
                         " baselines; at most " + std::to_string(kMaxBaselines) + " (use a larger STEP)");
    std::vector<double> out;
    for (double b = p[0]; b <= p[1] + 1e-9; b += p[2]) out.push_back(b);
    return out;
}

struct Candidate {
    double baseline_mm, focal_length_mm;
    std::vector<method::DesignFigures> at; // one per range of the band
    double worst_score = 0;                // the ranking predictor at the band's worst range
    bool panel_fits = true, in_search = true;
    double eta_3d = NAN;                   // --simulate
};

// The target ranges: --range's list, or five across --band.
std::vector<double> targetRanges(const DesignArgs &args) {
    std::vector<double> ranges;
    if (!args.range.empty()) ranges = numberList("--range", args.range);
    if (!args.band.empty()) {
        auto b = numberList("--band", args.band);
        if (b.size() != 2 || !(b[0] > 0) || b[1] <= b[0]) throw UsageError("--band " + args.band + ": expected MIN,MAX in mm, e.g. 5000,12000");
        for (int i = 0; i <= 4; ++i) ranges.push_back(b[0] + (b[1] - b[0]) * i / 4.0);
    }
    if (ranges.empty()) throw UsageError("give a target: --range 6000 (mm) or --band 5000,12000");
    for (double r : ranges)
        if (!(r > 0)) throw UsageError("--range: " + std::to_string(r) + " mm: expected a positive range");
    return ranges;
}

// The predictor to rank with: the one whose Spearman rho with measured η3D is highest
// (by default on the simulated E1 with ten repeats; --predictor forces one).
std::string choosePredictor(const DesignArgs &args) {
    const PredictorChoice choice = loadPredictorChoice(args.predictors_from.empty() ? dataFile("configs/predictors/e1-sim.json") : args.predictors_from);
    const std::string predictor = args.predictor.empty() ? choice.best : args.predictor;
    const auto &names = method::predictorNames();
    if (std::find(names.begin(), names.end(), predictor) == names.end()) {
        std::string valid;
        for (const auto &n : names) valid += (valid.empty() ? "" : ", ") + n;
        throw UsageError("--predictor " + predictor + ": unknown (expected one of " + valid + ")");
    }
    spdlog::info("design: Spearman's rho with η3D over {} tests of {} ({}):", choice.tests,
                 choice.experiment.empty() ? "an experiment" : choice.experiment, choice.file);
    for (const auto &[name, rho] : choice.rho)
        spdlog::info("  {:<20} {:6.3f}{}", name, rho, name == predictor ? "   <- ranks" : "");
    spdlog::info("design: ranking by {} ({})", predictor, predictor == choice.best ? "the highest rho" : "chosen with --predictor");
    return predictor;
}

// Every (B, f) with its figures at each range, ranked: configurations that see the whole
// panel and whose search reaches the range first, then the predictor's score at the
// band's worst range, then the finer depth resolution.
// The baselines and lenses on offer, checked and counted before anything is ranked.
struct Hardware {
    std::vector<double> lenses, baselines;
};

Hardware hardwareOf(const DesignArgs &args) {
    Hardware h{numberList("--lenses", args.lenses), baselines(args.baselines)};
    for (double v : h.lenses)
        if (!(v > 0)) throw UsageError("--lenses: focal lengths must be positive mm");
    for (double v : h.baselines)
        if (!(v > 0)) throw UsageError("--baselines: baselines must be positive mm");
    if (h.baselines.size() * h.lenses.size() > kMaxCandidates)
        throw UsageError("--baselines x --lenses: " + std::to_string(h.baselines.size() * h.lenses.size()) +
                         " configurations; at most " + std::to_string(kMaxCandidates));
    return h;
}

std::vector<Candidate> rankCandidates(const DesignArgs &args, const Hardware &hw, const std::vector<double> &ranges,
                                      const std::string &predictor) {
    method::PanelPlacement panel;
    panel.width_mm = args.panel_width_mm;
    panel.height_mm = args.panel_height_mm;
    std::vector<Candidate> cands;
    for (double b : hw.baselines)
        for (double f : hw.lenses) {
            Candidate c{b, f, {}, INFINITY, true, true, NAN};
            const method::StereoDesign head = args.head.configured(b, f, args.head.camera_height_mm, args.head.inclination_deg);
            for (double r : ranges) {
                c.at.push_back(method::designFigures(head, r, method::kMatchingErrorPx, &panel));
                const auto &x = c.at.back();
                c.worst_score = std::min(c.worst_score, method::predictors(head, r, panel).get(predictor));
                c.panel_fits = c.panel_fits && x.panel_fits_width;
                c.in_search = c.in_search && (!std::isfinite(x.min_range_mm) || x.min_range_mm <= r);
            }
            cands.push_back(c);
        }
    auto byFigures = [](const Candidate &a, const Candidate &b) {
        if (a.panel_fits != b.panel_fits) return a.panel_fits;
        if (a.in_search != b.in_search) return a.in_search;
        if (std::fabs(a.worst_score - b.worst_score) > 1e-9) return a.worst_score > b.worst_score;
        return a.at.back().depth_resolution_mm < b.at.back().depth_resolution_mm;
    };
    std::stable_sort(cands.begin(), cands.end(), byFigures);
    return cands;
}

// --simulate: η3D measured on the simulated rig for the best `--simulate-count` by
// figures, averaged over the band (a configuration is as good as it is across it).
void simulate(const DesignArgs &args, const std::vector<double> &ranges, std::vector<Candidate> &cands) {
    const size_t n = std::min(cands.size(), static_cast<size_t>(args.simulate_count));
    PluginHost host;
    // No scan: the rig opens only the plugins it names.
    const std::string rig = args.rig.empty() ? dataFile("configs/rigs/sim-e1.yaml") : args.rig;
    std::vector<TestGeometry> tests;
    std::vector<size_t> which;
    for (size_t i = 0; i < n; ++i)
        for (double r : ranges) {
            tests.push_back({cands[i].baseline_mm, cands[i].focal_length_mm, r, args.head.camera_height_mm, args.head.inclination_deg});
            which.push_back(i);
        }
    Experiment e = makeExperiment("design", rig, tests, host);
    ExperimentOptions opt;
    opt.out_dir = (args.out.empty() ? std::string("out/design") : args.out) + "/simulated";
    opt.progress = !args.quiet;
    const ExperimentResult result = runExperiment(e, host, opt);
    std::vector<double> sum(n, 0), cnt(n, 0);
    for (size_t t = 0; t < result.rows.size() && t < which.size(); ++t) {
        const double eta = result.rows[t].get("eta_3d_percent");
        if (!std::isfinite(eta)) continue;
        sum[which[t]] += eta;
        cnt[which[t]] += 1;
    }
    for (size_t i = 0; i < n; ++i) cands[i].eta_3d = cnt[i] ? sum[i] / cnt[i] : 0.0;
    std::stable_sort(cands.begin(), cands.begin() + static_cast<long>(n),
                     [](const Candidate &a, const Candidate &b) { return a.eta_3d > b.eta_3d; });
}

// The table on stdout; design.json and design.csv in --out.
void writeRanking(const DesignArgs &args, const std::vector<Candidate> &cands, const std::string &predictor) {
    const bool sim = args.simulate;
    const size_t top = static_cast<size_t>(args.top);
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
        Json j = {{"rank", i + 1},
                  {"baseline_mm", c.baseline_mm},
                  {"focal_length_mm", c.focal_length_mm},
                  {"panel_fits", c.panel_fits},
                  {"search_reaches_range", c.in_search},
                  {"predictor", predictor},
                  {"score", c.worst_score}};
        if (std::isfinite(c.eta_3d)) j["eta_3d_percent"] = c.eta_3d;
        Json per = Json::array();
        for (const auto &f : c.at) {
            per.push_back({{"range_mm", f.range_mm},
                           {"form_factor", f.form_factor},
                           {"reading", method::formFactorReading(f.form_factor)},
                           {"disparity_px", f.disparity_px},
                           {"depth_resolution_mm", f.depth_resolution_mm},
                           {"min_range_mm", f.min_range_mm},
                           {"horizontal_fov_deg", f.horizontal_fov_deg},
                           {"stereo_field_width_mm", f.stereo_field_width_mm}});
            char row[256];
            std::snprintf(row, sizeof row, "%zu,%g,%g,%g,%.4f,%.4f,%.2f,%.1f,%.1f,%d,%s\n", i + 1, c.baseline_mm,
                          c.focal_length_mm, f.range_mm, f.form_factor, f.disparity_px, f.depth_resolution_mm, f.min_range_mm,
                          f.stereo_field_width_mm, c.panel_fits ? 1 : 0,
                          std::isfinite(c.eta_3d) ? std::to_string(c.eta_3d).c_str() : "");
            csv += row;
        }
        j["ranges"] = std::move(per);
        list.push_back(std::move(j));
    }
    if (!args.out.empty()) {
        std::error_code ec;
        fs::create_directories(args.out, ec);
        writeFileAtomic(args.out + "/design.json", dumpJson(Json{{"candidates", std::move(list)}}));
        writeFileAtomic(args.out + "/design.csv", csv);
        spdlog::info("design: {} configurations ranked; design.json and design.csv in {}", cands.size(), args.out);
    }
}

int design(const DesignArgs &args) {
    const std::vector<double> ranges = targetRanges(args);
    const Hardware hw = hardwareOf(args);
    const std::string predictor = choosePredictor(args);
    std::vector<Candidate> cands = rankCandidates(args, hw, ranges, predictor);
    // --out is the design's own folder (marked): another command's, or the user's own
    // files, are refused unless --force.
    std::optional<OutputFolder> folder;
    if (!args.out.empty()) folder.emplace(args.out, OutputClaim{OutputKind::Design, args.force, "binocle design"});
    if (args.simulate) simulate(args, ranges, cands);
    writeRanking(args, cands, predictor);
    return 0;
}

Register designCommand{{"design", "rank baselines and lenses for a target range or band by FF (Eq. 7), or by simulated η3D",
              "Ranks every combination of the available baselines and lenses for the target\n"
              "range(s): configurations that see the whole test panel and whose disparity search\n"
              "reaches the range first, then by the predictor whose Spearman rho with measured\n"
              "η3D is highest (it prints each rho; by default measured on the simulated E1 with\n"
              "ten repeats, configs/predictors/e1-sim.json): form_factor (FF = 10·B·f/R, Eq. 7),\n"
              "ff_band (closeness to the paper's best band 1.2-2.0), expected_disparity,\n"
              "depth_resolution (-dR/R) or sensor_aware (η3D predicted from the design); the\n"
              "band's worst range counts. Beside FF it reports the expected disparity d = B·f/(R·p), the\n"
              "depth resolution dR = R²·p·Δd/(B·f) for Δd = " + num(method::kMatchingErrorPx) + " px, the minimum range of the\n"
              "disparity search and whether the panel fits the stereo field.\n"
              "One of --range or --band is required.",
              define<DesignArgs>(
                  [](CLI::App &app, DesignArgs &a) {
                      app.add_option("--range", a.range, "target range(s) in mm, e.g. 6000,12000")->type_name("MM[,MM...]");
                      app.add_option("--band", a.band, "a range band in mm (5 ranges across it), e.g. 5000,12000")
                                       ->type_name("MIN,MAX");
                      app.add_option("--lenses", a.lenses, std::string("focal lengths available, mm (default: the Videre set ") + method::kVidereLensesMm + ")")
                          ->type_name("MM,MM...");
                      app.add_option("--baselines", a.baselines, "baselines, mm: MIN:MAX:STEP or a list (default 100:200:10)")
                          ->type_name("SPEC");
                      addNumber(app, "--pixel-pitch-um", a.head.pixel_pitch_um,
                                "effective pixel pitch (default: the Videre head decimated by 4, 20.8)", "UM", positiveNumber());
                      addNumber(app, "--image-width", a.head.image_width_px, "image width in pixels (default 320)", "PX", atLeast(1));
                      addNumber(app, "--image-height", a.head.image_height_px, "image height in pixels (default 240)", "PX", atLeast(1));
                      addNumber(app, "--num-disparities", a.head.num_disparities, "the matcher's disparity search (default 64)", "N", atLeast(1));
                      addNumber(app, "--camera-height-mm", a.head.camera_height_mm,
                                "camera height (default " + num(method::kDefaultCameraHeightMm) + ")", "MM", decimalNumber());
                      addNumber(app, "--inclination-deg", a.head.inclination_deg, "inclination (default 0)", "DEG", decimalNumber())
                          ->check(CLI::Range(-89.0, 89.0));
                      addNumber(app, "--panel-width-mm", a.panel_width_mm, "width of the object that must fit (default 2500)", "MM", positiveNumber());
                      addNumber(app, "--panel-height-mm", a.panel_height_mm, "height of the object that must fit (default 2000)", "MM", positiveNumber());
                      addNumber(app, "--top", a.top, "rows printed (default 10)", "N", atLeast(1));
                      app.add_option("--predictors-from", a.predictors_from,
                                     "results.json whose predictors' rho chooses the ranking (default configs/predictors/e1-sim.json)")
                          ->type_name("FILE");
                      app.add_option("--predictor", a.predictor, "rank by this predictor instead of the one of highest rho")
                          ->type_name("NAME");
                      app.add_flag("--simulate", a.simulate, "measure η3D on the simulated rig for the best candidates");
                      addNumber(app, "--simulate-count", a.simulate_count, "how many candidates to simulate (default 12)", "N", atLeast(1));
                      app.add_option("--rig", a.rig, "base rig for --simulate (default configs/rigs/sim-e1.yaml)")->type_name("FILE");
                      app.add_option("--out", a.out, "write design.json and design.csv (and simulated/ runs)")->type_name("DIR");
                      app.add_flag("--force", a.force, "replace what --out holds when another command (or you) wrote it");
                      app.add_flag("--quiet", a.quiet, "no progress display");
                  },
                  design)}};

} // namespace
} // namespace binocle::cli
