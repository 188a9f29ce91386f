// SPDX-License-Identifier: MIT
// design(): the hardware and the targets read, the predictor chosen, every (B, f) ranked,
// the best simulated when asked, the ranking written into the design's folder.
#include "app/design.hpp"

#include "app/data_file.hpp"
#include "core/output_folder.hpp"
#include "experiment/experiment.hpp"
#include "experiment/predictor_choice.hpp"
#include "files/atomic_file.hpp"
#include "method/predictors.hpp"

#include <binocle/numbers.hpp>
#include <binocle/text.hpp>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <optional>
#include <spdlog/spdlog.h>
#include <sstream>

namespace binocle::app {

namespace {

std::string numberText(double v) {
    std::ostringstream os;
    os << v;
    return os.str();
}

// An example of each list argument's value, for its messages.
std::string exampleOf(const std::string &name) {
    return name == "lenses" ? "2.8,4,8" : name == "baselines" ? "100,150,190 or 100:200:10" : name == "band" ? "5000,12000" : "6000,12000";
}

// Numbers separated by commas, at least one: "" and "6000," are refused, not read as fewer.
std::vector<double> numberList(const Caller &caller, const std::string &name, const std::string &text, char separator = ',') {
    std::vector<double> out;
    const std::string shown = caller.shown(name, text);
    if (text.empty()) throw RequestError(shown + ": expected at least one number (e.g. " + exampleOf(name) + ")");
    for (size_t start = 0;;) {
        const size_t end = text.find(separator, start);
        const std::string item = text.substr(start, end == std::string::npos ? std::string::npos : end - start);
        double v = 0;
        std::string why;
        if (!sdk::parseDecimalReal(item, v, &why)) // decimal and finite: no "nan", "inf" or "0x1p3"
            throw RequestError(shown + ": '" + sdk::printable(item) + "' is not valid: " + why + " (e.g. " + exampleOf(name) + ")");
        out.push_back(v);
        if (end == std::string::npos) return out;
        start = end + 1;
    }
}

// "100:200:10" (min:max:step) or a list "100,150,190".
std::vector<double> baselinesOf(const Caller &caller, const std::string &text) {
    if (text.find(':') == std::string::npos) return numberList(caller, "baselines", text);
    const std::vector<double> p = numberList(caller, "baselines", text, ':');
    const std::string shown = caller.shown("baselines", text);
    if (p.size() != 3 || !(p[2] > 0) || p[1] < p[0]) throw RequestError(shown + ": expected MIN:MAX:STEP in mm, e.g. 100:200:10");
    // Counted before anything is made: 1:1e9:1 would otherwise fill the memory.
    const double count = std::floor((p[1] - p[0]) / p[2] + 1e-9) + 1;
    if (!(count <= static_cast<double>(kMaxBaselines)))
        throw RequestError(shown + ": " + std::to_string(static_cast<long long>(std::min(count, 9e18))) + " baselines; at most " +
                           std::to_string(kMaxBaselines) + " (use a larger STEP)");
    std::vector<double> out;
    for (double b = p[0]; b <= p[1] + 1e-9; b += p[2]) out.push_back(b);
    return out;
}

// The target ranges: range's list, or five across the band.
std::vector<double> targetRanges(const DesignRequest &request) {
    const Caller &caller = request.caller;
    std::vector<double> ranges;
    if (!request.range.empty()) ranges = numberList(caller, "range", request.range);
    if (!request.band.empty()) {
        auto b = numberList(caller, "band", request.band);
        if (b.size() != 2 || !(b[0] > 0) || b[1] <= b[0])
            throw RequestError(caller.shown("band", request.band) + ": expected MIN,MAX in mm, e.g. 5000,12000");
        for (int i = 0; i <= 4; ++i) ranges.push_back(b[0] + (b[1] - b[0]) * i / 4.0);
    }
    if (ranges.empty())
        throw RequestError("give a target: " + caller.shown("range", "6000") + " (mm) or " + caller.shown("band", "5000,12000"));
    for (double r : ranges)
        if (!(r > 0)) throw RequestError(caller.arg("range") + ": " + std::to_string(r) + " mm: expected a positive range");
    return ranges;
}

// The numbers of the head, the panel and simulate (the command line's own validators
// check them first there; a Python call meets these).
void checkNumbers(const DesignRequest &request) {
    const Caller &caller = request.caller;
    auto positive = [&](const char *name, double v) {
        if (!(v > 0) || !std::isfinite(v)) throw RequestError(caller.shown(name, numberText(v)) + ": expected a positive number");
    };
    auto atLeastOne = [&](const char *name, long long v) {
        if (v < 1) throw RequestError(caller.shown(name, std::to_string(v)) + ": expected a whole number >= 1");
    };
    positive("pixel_pitch_um", request.head.pixel_pitch_um);
    positive("panel_width_mm", request.panel_width_mm);
    positive("panel_height_mm", request.panel_height_mm);
    atLeastOne("image_width", request.head.image_width_px);
    atLeastOne("image_height", request.head.image_height_px);
    atLeastOne("num_disparities", request.head.num_disparities);
    atLeastOne("simulate_count", request.simulate_count);
    if (!std::isfinite(request.head.camera_height_mm))
        throw RequestError(caller.shown("camera_height_mm", numberText(request.head.camera_height_mm)) + ": expected a finite number");
    if (!(request.head.inclination_deg >= -89 && request.head.inclination_deg <= 89))
        throw RequestError(caller.shown("inclination_deg", numberText(request.head.inclination_deg)) +
                           ": expected a number from -89 to 89 (degrees)");
}

// The predictor to rank with: the one whose Spearman rho with measured η3D is highest
// (by default on the simulated E1 with ten repeats; `predictor` forces one).
std::string choosePredictor(const DesignRequest &request) {
    const PredictorChoice choice =
        loadPredictorChoice(request.predictors_from.empty() ? dataFile("configs/predictors/e1-sim.json") : request.predictors_from);
    const std::string predictor = request.predictor.empty() ? choice.best : request.predictor;
    const auto &names = method::predictorNames();
    if (std::find(names.begin(), names.end(), predictor) == names.end()) {
        std::string valid;
        for (const auto &n : names) valid += (valid.empty() ? "" : ", ") + n;
        throw RequestError(request.caller.shown("predictor", predictor) + ": unknown (expected one of " + valid + ")");
    }
    spdlog::info("design: Spearman's rho with η3D over {} tests of {} ({}):", choice.tests,
                 choice.experiment.empty() ? "an experiment" : choice.experiment, choice.file);
    for (const auto &[name, rho] : choice.rho)
        spdlog::info("  {:<20} {:6.3f}{}", name, rho, name == predictor ? "   <- ranks" : "");
    spdlog::info("design: ranking by {} ({})", predictor,
                 predictor == choice.best ? "the highest rho" : "chosen with " + request.caller.arg("predictor"));
    return predictor;
}

// The baselines and lenses on offer, checked and counted before anything is ranked.
struct Hardware {
    std::vector<double> lenses, baselines;
};

Hardware hardwareOf(const DesignRequest &request) {
    const Caller &caller = request.caller;
    Hardware h{numberList(caller, "lenses", request.lenses), baselinesOf(caller, request.baselines)};
    for (double v : h.lenses)
        if (!(v > 0)) throw RequestError(caller.arg("lenses") + ": focal lengths must be positive mm");
    for (double v : h.baselines)
        if (!(v > 0)) throw RequestError(caller.arg("baselines") + ": baselines must be positive mm");
    if (h.baselines.size() * h.lenses.size() > kMaxCandidates)
        throw RequestError(caller.arg("baselines") + " x " + caller.arg("lenses") + ": " +
                           std::to_string(h.baselines.size() * h.lenses.size()) + " configurations; at most " +
                           std::to_string(kMaxCandidates));
    return h;
}

// Every (B, f) with its figures at each range, ranked: configurations that see the whole
// panel and whose search reaches the range first, then the predictor's score at the
// band's worst range, then the finer depth resolution.
std::vector<DesignCandidate> rankCandidates(const DesignRequest &request, const Hardware &hw, const std::vector<double> &ranges,
                                            const std::string &predictor) {
    method::PanelPlacement panel;
    panel.width_mm = request.panel_width_mm;
    panel.height_mm = request.panel_height_mm;
    const method::StereoDesign &base = request.head;
    std::vector<DesignCandidate> cands;
    for (double b : hw.baselines)
        for (double f : hw.lenses) {
            DesignCandidate c{b, f, {}, INFINITY, true, true, NAN};
            const method::StereoDesign head = base.configured(b, f, base.camera_height_mm, base.inclination_deg);
            for (double r : ranges) {
                c.at.push_back(method::designFigures(head, r, method::kMatchingErrorPx, &panel));
                const auto &x = c.at.back();
                c.worst_score = std::min(c.worst_score, method::predictors(head, r, panel).get(predictor));
                c.panel_fits = c.panel_fits && x.panel_fits_width;
                c.in_search = c.in_search && (!std::isfinite(x.min_range_mm) || x.min_range_mm <= r);
            }
            cands.push_back(c);
        }
    auto byFigures = [](const DesignCandidate &a, const DesignCandidate &b) {
        if (a.panel_fits != b.panel_fits) return a.panel_fits;
        if (a.in_search != b.in_search) return a.in_search;
        if (std::fabs(a.worst_score - b.worst_score) > 1e-9) return a.worst_score > b.worst_score;
        return a.at.back().depth_resolution_mm < b.at.back().depth_resolution_mm;
    };
    std::stable_sort(cands.begin(), cands.end(), byFigures);
    return cands;
}

// A private folder under $TMPDIR (mkdtemp: 0700, a fresh name), removed with its content
// when this goes: the simulated runs of a design without an output folder, which nobody
// asked to keep and which must not land, unclaimed, in the working folder.
class ScratchFolder {
public:
    ScratchFolder() {
        std::string pattern = (std::filesystem::temp_directory_path() / "binocle-design.XXXXXX").string();
        if (!::mkdtemp(pattern.data()))
            throw Error("design: cannot make a folder for the simulated runs under " +
                        std::filesystem::temp_directory_path().string() + ": " + std::strerror(errno) + " (set TMPDIR, or give an output folder)");
        path_ = pattern;
    }
    ~ScratchFolder() {
        std::error_code ignored;
        std::filesystem::remove_all(path_, ignored);
    }
    ScratchFolder(const ScratchFolder &) = delete;
    ScratchFolder &operator=(const ScratchFolder &) = delete;
    const std::string &path() const { return path_; }

private:
    std::string path_;
};

// simulate: η3D measured on the simulated rig for the best `simulate_count` by figures,
// averaged over the band (a configuration is as good as it is across it). The runs go
// into OUT/simulated, or, without an output folder, into a scratch folder removed after.
void simulate(const DesignRequest &request, const std::vector<double> &ranges, std::vector<DesignCandidate> &cands) {
    const size_t n = std::min(cands.size(), static_cast<size_t>(request.simulate_count));
    PluginHost host;
    // No scan: the rig opens only the plugins it names.
    const std::string rig = request.rig.empty() ? dataFile("configs/rigs/sim-e1.yaml") : request.rig;
    std::vector<TestGeometry> tests;
    std::vector<size_t> which;
    for (size_t i = 0; i < n; ++i)
        for (double r : ranges) {
            tests.push_back({cands[i].baseline_mm, cands[i].focal_length_mm, r, request.head.camera_height_mm, request.head.inclination_deg});
            which.push_back(i);
        }
    Experiment e = makeExperiment("design", rig, tests, host);
    std::optional<ScratchFolder> scratch;
    if (request.out.empty()) scratch.emplace();
    ExperimentOptions opt;
    opt.out_dir = (scratch ? scratch->path() : request.out) + "/simulated";
    opt.progress = request.progress;
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
                     [](const DesignCandidate &a, const DesignCandidate &b) { return a.eta_3d > b.eta_3d; });
}

} // namespace

DesignResult design(const DesignRequest &request) {
    checkNumbers(request);
    DesignResult result;
    result.ranges = targetRanges(request);
    const Hardware hw = hardwareOf(request);
    result.predictor = choosePredictor(request);
    result.candidates = rankCandidates(request, hw, result.ranges, result.predictor);
    // out is the design's own folder (marked): another command's, or the user's own
    // files, are refused unless forced.
    std::optional<OutputFolder> folder;
    if (!request.out.empty()) folder.emplace(request.out, request.caller.claim(OutputKind::Design, request.force));
    if (request.simulate) simulate(request, result.ranges, result.candidates);
    result.simulated = request.simulate;
    if (!request.out.empty()) {
        writeFileAtomic(request.out + "/design.json", dumpJson(designJson(result)));
        writeFileAtomic(request.out + "/design.csv", designCsv(result));
        spdlog::info("design: {} configurations ranked; design.json and design.csv in {}", result.candidates.size(), request.out);
    }
    return result;
}

Json designJson(const DesignResult &result) {
    Json list = Json::array();
    for (size_t i = 0; i < result.candidates.size(); ++i) {
        const DesignCandidate &c = result.candidates[i];
        Json j = {{"rank", i + 1},
                  {"baseline_mm", c.baseline_mm},
                  {"focal_length_mm", c.focal_length_mm},
                  {"panel_fits", c.panel_fits},
                  {"search_reaches_range", c.in_search},
                  {"predictor", result.predictor},
                  {"score", c.worst_score}};
        if (std::isfinite(c.eta_3d)) j["eta_3d_percent"] = c.eta_3d;
        Json per = Json::array();
        for (const auto &f : c.at)
            per.push_back({{"range_mm", f.range_mm},
                           {"form_factor", f.form_factor},
                           {"reading", method::formFactorReading(f.form_factor)},
                           {"disparity_px", f.disparity_px},
                           {"depth_resolution_mm", f.depth_resolution_mm},
                           {"min_range_mm", f.min_range_mm},
                           {"horizontal_fov_deg", f.horizontal_fov_deg},
                           {"stereo_field_width_mm", f.stereo_field_width_mm}});
        j["ranges"] = std::move(per);
        list.push_back(std::move(j));
    }
    return Json{{"candidates", std::move(list)}};
}

std::string designCsv(const DesignResult &result) {
    std::string csv = "rank,baseline_mm,focal_length_mm,range_mm,form_factor,disparity_px,depth_resolution_mm,min_range_mm,"
                      "stereo_field_width_mm,panel_fits,eta_3d_percent\n";
    for (size_t i = 0; i < result.candidates.size(); ++i) {
        const DesignCandidate &c = result.candidates[i];
        for (const auto &f : c.at) {
            char row[256];
            std::snprintf(row, sizeof row, "%zu,%g,%g,%g,%.4f,%.4f,%.2f,%.1f,%.1f,%d,%s\n", i + 1, c.baseline_mm,
                          c.focal_length_mm, f.range_mm, f.form_factor, f.disparity_px, f.depth_resolution_mm, f.min_range_mm,
                          f.stereo_field_width_mm, c.panel_fits ? 1 : 0,
                          std::isfinite(c.eta_3d) ? std::to_string(c.eta_3d).c_str() : "");
            csv += row;
        }
    }
    return csv;
}

} // namespace binocle::app
