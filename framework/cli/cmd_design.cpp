// SPDX-License-Identifier: MIT
// `binocle design`: which baseline and which lens for a target range (or band)? The
// options into a DesignRequest, the ranking (app/design.hpp) printed as a table.
#include "app/design.hpp"
#include "cli/command.hpp"
#include "method/design.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>

namespace binocle::cli {
namespace {

struct DesignArgs {
    app::DesignRequest request;
    int top = 10;
    bool quiet = false;
};

std::string num(double v) {
    std::ostringstream os;
    os << v;
    return os.str();
}

// The best `top` on stdout, at the middle of the band (or the range).
void printRanking(const app::DesignResult &result, size_t top) {
    const bool sim = result.simulated;
    std::printf("%-4s %8s %7s %7s %9s %10s %9s %7s %s\n", "rank", "B (mm)", "f (mm)", "FF", "d (px)", "dR (mm)", "Rmin (m)",
                "panel", sim ? "η3D (%)" : "reading");
    for (size_t i = 0; i < result.candidates.size() && i < top; ++i) {
        const app::DesignCandidate &c = result.candidates[i];
        const auto &x = c.at[c.at.size() / 2];
        std::printf("%-4zu %8.0f %7.1f %7.2f %9.2f %10.1f %9.2f %7s %s\n", i + 1, c.baseline_mm, c.focal_length_mm,
                    x.form_factor, x.disparity_px, x.depth_resolution_mm, x.min_range_mm / 1000,
                    c.panel_fits ? "fits" : "cut", sim ? (std::isfinite(c.eta_3d) ? std::to_string(c.eta_3d).substr(0, 5).c_str() : "-")
                                                       : method::formFactorReading(x.form_factor));
    }
}

int design(DesignArgs args) {
    args.request.progress = !args.quiet;
    printRanking(app::design(args.request), static_cast<size_t>(args.top));
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
                  [](CLI::App &app, DesignArgs &args) {
                      app::DesignRequest &a = args.request;
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
                      addNumber(app, "--top", args.top, "rows printed (default 10)", "N", atLeast(1));
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
                      app.add_flag("--quiet", args.quiet, "no progress display");
                  },
                  design)}};

} // namespace
} // namespace binocle::cli
