// SPDX-License-Identifier: MIT
// binocle.design(): the arguments read into an app::DesignRequest (the one `binocle
// design` fills from its options), the ranking returned as design.json's candidates.
#include "python/design_call.hpp"

#include "python/arguments.hpp"
#include "python/convert.hpp"
#include "python/lifecycle.hpp"

#include "app/design.hpp"

#include <limits>

namespace binocle::python {

namespace {

constexpr int64_t kMaxInt = std::numeric_limits<int>::max();

// A list of numbers as `binocle design` takes it: the same text ("6000,12000",
// "100:200:10"), one number, or a list or tuple of numbers (written as Python writes them).
// None: `fallback`.
std::string numbersText(const py::handle &value, const std::string &name, const std::string &fallback) {
    if (value.is_none()) return fallback;
    if (py::isinstance<py::str>(value)) return value.cast<std::string>();
    auto one = [&](const py::handle &v) { return py::repr(py::float_(realNumber(v, name))).cast<std::string>(); };
    if (!py::isinstance<py::list>(value) && !py::isinstance<py::tuple>(value)) return one(value);
    std::string text;
    for (const py::handle item : value) text += (text.empty() ? "" : ",") + one(item);
    return text;
}

// A number of the head: None keeps `value` (the Videre head's).
template <class T> void headNumber(const py::handle &given, const std::string &name, T &value) {
    if (given.is_none()) return;
    if constexpr (std::is_integral_v<T>)
        value = static_cast<T>(*wholeNumber(given, name, 1, kMaxInt));
    else
        value = realNumber(given, name);
}

} // namespace

void defineDesign(py::module_ &m) {
    m.def(
        "design",
        [](const py::object &range, const py::object &band, const py::object &lenses, const py::object &baselines,
           const py::object &pixel_pitch_um, const py::object &image_width, const py::object &image_height,
           const py::object &num_disparities, const py::object &camera_height_mm, const py::object &inclination_deg,
           const py::object &panel_width_mm, const py::object &panel_height_mm, const py::object &predictors_from,
           const py::object &predictor, const py::object &simulate, const py::object &simulate_count, const py::object &rig,
           const py::object &out, const py::object &force, const py::object &progress) {
            app::DesignRequest r;
            r.caller.command = "binocle.design";
            r.range = numbersText(range, "range", "");
            r.band = numbersText(band, "band", "");
            r.lenses = numbersText(lenses, "lenses", r.lenses);
            r.baselines = numbersText(baselines, "baselines", r.baselines);
            headNumber(pixel_pitch_um, "pixel_pitch_um", r.head.pixel_pitch_um);
            headNumber(image_width, "image_width", r.head.image_width_px);
            headNumber(image_height, "image_height", r.head.image_height_px);
            headNumber(num_disparities, "num_disparities", r.head.num_disparities);
            headNumber(camera_height_mm, "camera_height_mm", r.head.camera_height_mm);
            headNumber(inclination_deg, "inclination_deg", r.head.inclination_deg);
            headNumber(panel_width_mm, "panel_width_mm", r.panel_width_mm);
            headNumber(panel_height_mm, "panel_height_mm", r.panel_height_mm);
            r.predictors_from = pathText(predictors_from, "predictors_from", "configs/predictors/e1-sim.json").value_or("");
            r.predictor = text(predictor, "predictor", "the predictor of highest rho").value_or("");
            r.simulate = flag(simulate, "simulate");
            r.simulate_count = static_cast<int>(*wholeNumber(simulate_count, "simulate_count", 1, kMaxInt));
            r.rig = pathText(rig, "rig", "configs/rigs/sim-e1.yaml").value_or("");
            r.out = pathText(out, "out", "nothing written").value_or("");
            r.force = flag(force, "force");
            r.progress = flag(progress, "progress");
            Json ranking;
            withoutGil([&] { ranking = app::designJson(app::design(r)); });
            return toPython(ranking["candidates"]).cast<py::list>();
        },
        py::kw_only(), py::arg("range") = py::none(), py::arg("band") = py::none(), py::arg("lenses") = py::none(),
        py::arg("baselines") = py::none(), py::arg("pixel_pitch_um") = py::none(), py::arg("image_width") = py::none(),
        py::arg("image_height") = py::none(), py::arg("num_disparities") = py::none(), py::arg("camera_height_mm") = py::none(),
        py::arg("inclination_deg") = py::none(), py::arg("panel_width_mm") = py::none(), py::arg("panel_height_mm") = py::none(),
        py::arg("predictors_from") = py::none(), py::arg("predictor") = py::none(), py::arg("simulate") = false,
        py::arg("simulate_count") = 12, py::arg("rig") = py::none(), py::arg("out") = py::none(), py::arg("force") = false,
        py::arg("progress") = false,
        "Ranks baselines and lenses for a target range or band as `binocle design` does, and returns the\n"
        "ranking as design.json lists it: [{'rank', 'baseline_mm', 'focal_length_mm', 'panel_fits',\n"
        "'search_reaches_range', 'predictor', 'score', ('eta_3d_percent' with simulate), 'ranges': [{'range_mm',\n"
        "'form_factor', 'reading', 'disparity_px', 'depth_resolution_mm', 'min_range_mm', 'horizontal_fov_deg',\n"
        "'stereo_field_width_mm'}]}], best first. Each argument is the option of the same name (range= for\n"
        "--range ...): range, band, lenses and baselines as the CLI's text ('6000,12000', '100:200:10') or\n"
        "numbers ([6000, 12000]); the head's numbers default to the Videre head's; out= writes design.json,\n"
        "design.csv (and simulated/) there, force=True as --force.");
}

} // namespace binocle::python
