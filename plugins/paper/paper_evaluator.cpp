// SPDX-License-Identifier: MIT
// paper: Evaluator of METHOD.md. Experiment 1: reads the test panel's X', Y', Z' from the
// ground-frame cloud and scores Eq. 2-6; Experiment 2: ground-plane and known-object
// indicators. Both report the form factor (Eq. 7), the sensor-aware figures and the
// objects localised in the density grids.
#include "method/density_grid.hpp"
#include "method/density_render.hpp"
#include "method/design.hpp"
#include "method/ground_plane.hpp"
#include "method/panel.hpp"
#include "method/relative_errors.hpp"
#include "paper/oracle_cloud.hpp"
#include "paper/rig_facts.hpp"

#include <binocle/plugin.hpp>

#include <nlohmann/json.hpp>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace method = binocle::method;
namespace paper = binocle::paper;
using binocle::sdk::Error;
using binocle::sdk::Param;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// "[a, b]" of a DOUBLE_LIST setting as an interval with a < b.
method::Extent interval(const binocle::sdk::CheckedParams &p, const char *key) {
    const std::string text = p.string(key);
    std::vector<double> v;
    try {
        v = YAML::Load(text).as<std::vector<double>>();
    } catch (const YAML::Exception &) {
        v.clear();
    }
    if (v.size() != 2 || !(v[0] < v[1]) || !std::isfinite(v[0]) || !std::isfinite(v[1]))
        p.refuse(key, text, "[min, max] in mm with min < max");
    return {v[0], v[1]};
}

std::optional<std::vector<double>> triple(const binocle::sdk::CheckedParams &p, const char *key) {
    const std::string text = p.string(key);
    std::vector<double> v;
    try {
        v = YAML::Load(text).as<std::vector<double>>();
    } catch (const YAML::Exception &) {
        v = {kNaN};
    }
    if (v.empty()) return std::nullopt;
    if (v.size() != 3)
        p.refuse(key, text, "[X, Y, Z] in mm, or [] for none");
    return v;
}

std::string fixed(double v, int decimals) {
    char buf[48];
    std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
    return buf;
}

// Δd's default as a setting's text, from the one constant `design` and experiments use.
const std::string kMatchingErrorText = [] {
    std::ostringstream os;
    os << method::kMatchingErrorPx;
    return os.str();
}();

class PaperEvaluator : public binocle::sdk::Evaluator {
public:
    static std::vector<binocle_param_desc> parameters() {
        return {
            Param::choice("experiment", "e1", "e1|e2")
                .help("e1: test panel, Eq. 2-6; e2: ground plane and known-object indicators"),
            Param::real("cell_size_mm", "100").min(1).unit("mm").help("side of a density-grid cell"),
            Param::integer("density_threshold", "3").min(1).help("points per cell for a cell to be occupied"),
            Param::real("ground_band_mm", "200").unit("mm").help("points lower than this are ground, not objects"),
            Param::integer("min_object_cells", "3").min(1).help("smaller occupied regions are noise"),
            Param::realList("grid_x_mm", "[-6000, 6000]").unit("mm").help("lateral extent of the density grids"),
            Param::realList("grid_y_mm", "[0, 25000]").unit("mm").help("range extent of the density grids"),
            Param::realList("grid_z_mm", "[-500, 4500]").unit("mm").help("height extent of the density grids"),
            Param::real("panel_true_width_mm", "0").min(0).unit("mm")
                .help("true X of the panel (tape-measured); unset: the frame metadata's panel"),
            Param::real("panel_true_range_mm", "0").min(0).unit("mm")
                .help("true Y: range of the panel's face; unset: the frame metadata's panel"),
            Param::real("panel_true_height_mm", "0").min(0).unit("mm")
                .help("true Z of the panel; unset: the frame metadata's panel"),
            Param::real("range_margin_mm", "500").min(1).unit("mm")
                .help("half-depth of the range band the panel is read in"),
            Param::real("range_search_percent", "30").min(0).max(100).unit("%")
                .help("the panel's band is looked for within the true range +- this"),
            Param::real("lateral_margin_mm", "0").min(0).unit("mm")
                .help("> 0: read the panel only within its true lateral span +- this; 0: the whole grid"),
            Param::choice("reading", "region", "region|band")
                .help("region: the dense cells connected to the panel's stated position (a person's reading); "
                      "band: every occupied cell of the range band (the reading before issue 33)"),
            Param::real("panel_true_center_x_mm", "0").unit("mm")
                .help("the panel's lateral middle (rough is enough); unset: the frame metadata's panel, else 0"),
            Param::real("seed_half_width_mm", "1000").min(1).unit("mm")
                .help("region reading: the panel has points within this of its stated lateral middle"),
            Param::real("relative_density", "0.5").min(0).max(1)
                .help("region reading: the panel's cells hold at least this share of its typical cell"),
            Param::real("bridge_mm", "500").min(0).unit("mm")
                .help("region reading: gaps inside the panel up to this wide are bridged"),
            Param::boolean("oracle", true)
                .help("e1: read the panel also on the cloud of the frame's gt_disparity (the sim's): *_oracle_* figures"),
            Param::real("max_width_ratio", "2").min(1.01)
                .help("region reading: a region wider than this times the true width is not separated (rejected)"),
            Param::integer("min_panel_points", "50").min(1).help("fewer panel points: not registered (rejected)"),
            Param::boolean("write_views", false)
                .help("write the top, front and side density views as PNG into the output folder"),
            Param::real("matching_error_px", kMatchingErrorText.c_str()).min(0).unit("px")
                .help("matching error used for the depth resolution figure"),
            Param::real("baseline_mm", "0").min(0).unit("mm").help("B for Eq. 7; 0: from the metadata or calibration"),
            Param::real("focal_length_mm", "0").min(0).unit("mm").help("f for Eq. 7; 0: from the metadata (or the calibration's focal_length_px and p)"),
            Param::real("pixel_pitch_um", "0").min(0).unit("um")
                .help("effective pixel pitch; 0: from the metadata (or f and the calibration's focal_length_px)"),
            Param::string("object", "").help("e2: name of the known object in the metadata; empty: its main_object"),
            Param::realList("object_center_mm", "[]").unit("mm")
                .help("e2: true centre [X, Y, Z] of the known object when the metadata has none"),
            Param::realList("object_size_mm", "[]").unit("mm")
                .help("e2: true size [width, depth, height] of the known object when the metadata has none"),
            Param::real("object_margin_mm", "500").min(0).unit("mm")
                .help("e2: the known object is read within its true lateral span +- this"),
            Param::real("true_inclination_deg", "0").min(-90).max(90).unit("deg")
                .help("e2: the camera's true inclination; unset: the metadata's rig.inclination_deg"),
            Param::real("ground_inlier_mm", "50").min(1).unit("mm").help("e2: RANSAC inlier distance to the ground plane"),
            Param::real("ground_max_tilt_deg", "30").min(0).max(89).unit("deg")
                .help("e2: steeper planes are not taken for the ground"),
        };
    }

    PaperEvaluator(const binocle::sdk::CheckedParams &p, binocle::sdk::Host &host) : host_(host), p_(p) {
        e2_ = p.string("experiment") == "e2";
        grid_.cell_mm = p.real("cell_size_mm");
        grid_.density_threshold = static_cast<int>(p.integer("density_threshold"));
        grid_.ground_band_mm = p.real("ground_band_mm");
        grid_.min_object_cells = static_cast<int>(p.integer("min_object_cells"));
        grid_.x = interval(p, "grid_x_mm");
        grid_.y = interval(p, "grid_y_mm");
        grid_.z = interval(p, "grid_z_mm");
        try {
            grid_.validate();
        } catch (const std::invalid_argument &e) {
            throw Error(BINOCLE_ERR_INVALID_ARGUMENT, std::string("paper: ") + e.what() +
                                                          " (cell_size_mm, density_threshold, grid_*_mm)");
        }
        objectName_ = p.string("object");
        objectCenter_ = triple(p, "object_center_mm");
        objectSize_ = triple(p, "object_size_mm");
        if (objectCenter_.has_value() != objectSize_.has_value())
            throw Error(BINOCLE_ERR_INVALID_ARGUMENT,
                        "paper: object_center_mm and object_size_mm go together: set both or neither");
    }

    void evaluate(const binocle_eval_input &in) override {
        if (!in.cloud) throw Error(BINOCLE_ERR_INVALID_ARGUMENT, "paper: the input has no cloud");
        if (in.cloud->frame != BINOCLE_FRAME_GROUND)
            throw Error(BINOCLE_ERR_INVALID_ARGUMENT,
                        "paper evaluator needs the cloud in the ground frame: add the ground transform");
        const paper::FrameTruth truth = paper::parseFrameTruth(in.frame ? in.frame->metadata : nullptr);
        const std::string calibrationText = in.calibration_yaml ? in.calibration_yaml : "";
        if (!calibrationParsed_ || calibrationText != calibrationText_) {
            calibration_ = paper::parseCalibrationFacts(in.calibration_yaml);
            oracle_.setCalibration(calibrationText);
            calibrationText_ = calibrationText;
            calibrationParsed_ = true;
        }
        rig_ = calibration_;
        paper::addHostFacts(rig_, in);
        const method::CloudView cloud(*in.cloud);
        sequence_ = in.frame ? in.frame->sequence : frames_;
        ++frames_;

        const std::vector<method::LocalisedObject> objects = method::localiseObjects(cloud, grid_);
        host_.text("objects", method::objectsJson(objects));
        metric("objects_found", static_cast<double>(objects.size()));

        Drawings drawings;
        for (const method::LocalisedObject &o : objects)
            drawings.top.push_back({{o.x_min_mm, o.x_max_mm}, {o.y_min_mm, o.y_max_mm}, "#" + std::to_string(o.id), {150, 90, 30}, {}, 0});
        double range = kNaN;
        std::optional<method::PanelPlacement> panel;
        if (e2_) range = evaluateE2(cloud, truth, drawings);
        else range = evaluatePanel(cloud, truth, drawings, panel, in.frame);
        reportDesign(truth, range, panel ? &*panel : nullptr);
        host_.text("view_overlays", overlaysJson(drawings));
        if (p_.boolean("write_views")) writeViews(cloud, in.output_dir, drawings);
    }

    // Over the run: the mean of every figure over the frames where it was not missing
    // (registered: the fraction of frames with the panel or object registered).
    void finish() override {
        for (const Total &t : totals_) host_.metric(t.name, t.n > 0 ? t.sum / t.n : kNaN, t.unit);
        host_.metric("frames", static_cast<double>(frames_));
    }

private:
    struct Drawings {
        std::vector<method::ViewOverlay> top, front, side;
    };
    struct Total {
        std::string name, unit;
        double sum = 0;
        int64_t n = 0;
    };

    // Eq. 2-6 of one reading, named with `suffix` after the quantity ("" for the matcher's
    // cloud, "_oracle" for the ground truth's): registered, epsilon_x_percent, ... measured_width_mm.
    void scoreMetrics(const method::PanelReading &r, const method::PanelScore &s, const std::string &suffix) {
        metric("registered" + suffix, r.registered ? 1 : 0);
        metric("epsilon_x" + suffix + "_percent", s.epsilon_x_percent, "%");
        metric("epsilon_y" + suffix + "_percent", s.epsilon_y_percent, "%");
        metric("epsilon_z" + suffix + "_percent", s.epsilon_z_percent, "%");
        metric("eta_2d" + suffix + "_percent", s.eta_2d_percent, "%");
        metric("eta_3d" + suffix + "_percent", s.eta_3d_percent, "%");
        metric("measured_width" + suffix + "_mm", r.width_mm, "mm");
    }

    void metric(const std::string &name, double value, const std::string &unit = "") {
        host_.metric(name, value, unit);
        Total *t = nullptr;
        for (Total &existing : totals_)
            if (existing.name == name) t = &existing;
        if (!t) {
            totals_.push_back({name, unit});
            t = &totals_.back();
        }
        if (std::isfinite(value)) {
            t->sum += value;
            ++t->n;
        }
    }

    // A setting the YAML gave, else what the frame metadata knows.
    double given(const char *key, const std::optional<double> &fallback) const {
        if (p_.isExplicit(key)) return p_.real(key);
        return fallback.value_or(kNaN);
    }

    double evaluatePanel(const method::CloudView &cloud, const paper::FrameTruth &truth, Drawings &drawings,
                         std::optional<method::PanelPlacement> &placement, const binocle_stereo_frame *frame) {
        const method::PanelSize trueSize{given("panel_true_width_mm", truth.panel_width_mm),
                                         given("panel_true_range_mm", truth.panel_range_mm),
                                         given("panel_true_height_mm", truth.panel_height_mm)};
        std::string missing;
        if (!(trueSize.width_mm > 0)) missing += " panel_true_width_mm";
        if (!(trueSize.range_mm > 0)) missing += " panel_true_range_mm";
        if (!(trueSize.height_mm > 0)) missing += " panel_true_height_mm";
        if (!missing.empty())
            throw Error(BINOCLE_ERR_INVALID_ARGUMENT,
                        "paper: no true panel size for Eq. 2-4 (missing:" + missing +
                            "): set them in the evaluator's YAML (tape-measured), or use a source whose frame metadata "
                            "has a `panel:` entry (sim)");
        const double centerX = given("panel_true_center_x_mm", truth.panel_center_x_mm.value_or(0.0));
        method::PanelReadingOptions o = readingOptions();
        o.expected_range_mm = trueSize.range_mm;
        o.expected_x_mm = centerX;
        o.expected_width_mm = trueSize.width_mm;
        if (p_.real("lateral_margin_mm") > 0) {
            const double half = trueSize.width_mm / 2 + p_.real("lateral_margin_mm");
            o.lateral = {centerX - half, centerX + half};
        }
        const method::PanelReading r = method::readPanel(cloud, o);
        const method::PanelScore s = method::scorePanel(r.size(), trueSize, r.registered);
        if (!r.registered)
            host_.warning("frame " + std::to_string(sequence_) + ": panel not registered (rejected configuration): " +
                          r.reason);
        scoreMetrics(r, s, "");
        metric("measured_range_mm", r.range_mm, "mm");
        metric("measured_height_mm", r.height_mm, "mm");
        metric("true_width_mm", trueSize.width_mm, "mm");
        metric("true_range_mm", trueSize.range_mm, "mm");
        metric("true_height_mm", trueSize.height_mm, "mm");
        metric("panel_points", static_cast<double>(r.points));
        metric("panel_ground_z_mm", r.ground_z_mm, "mm");
        metric("panel_cell_threshold", r.cell_threshold);
        metric("panel_band_depth_mm", r.band.valid() ? r.band.size() : kNaN, "mm");
        drawReading(r, drawings);
        if (p_.boolean("oracle")) scoreOracle(frame, o, trueSize, s);
        placement = method::PanelPlacement{trueSize.width_mm, trueSize.height_mm, centerX,
                                           truth.panel_base_z_mm.value_or(0.0)};
        return trueSize.range_mm;
    }

    double evaluateE2(const method::CloudView &cloud, const paper::FrameTruth &truth,
                      Drawings &drawings) {
        // The known object.
        method::KnownObject known;
        const std::string name = objectName_.empty() ? truth.main_object : objectName_;
        bool have = false;
        if (objectCenter_) {
            known.name = name.empty() ? "object" : name;
            for (size_t a = 0; a < 3; ++a) {
                known.center_mm[a] = (*objectCenter_)[a];
                known.size_mm[a] = (*objectSize_)[a];
            }
            have = true;
        } else {
            for (const method::KnownObject &k : truth.objects)
                if (!name.empty() && k.name == name) {
                    known = k;
                    have = true;
                }
        }
        if (!have)
            throw Error(BINOCLE_ERR_INVALID_ARGUMENT,
                        "paper (experiment e2): no known object" + (name.empty() ? std::string() : " named '" + name + "'") +
                            " in the frame metadata: set `object` to the name of one of its objects, or "
                            "object_center_mm and object_size_mm");
        const method::PanelReadingOptions o = readingOptions();
        const method::ObjectOffset off = method::locateKnownObject(cloud, known, o, p_.real("object_margin_mm"));
        if (!off.found)
            host_.warning("frame " + std::to_string(sequence_) + ": known object '" + known.name +
                          "' not found within " + fixed(p_.real("object_margin_mm"), 0) + " mm of its lateral span");
        metric("registered", off.found ? 1 : 0);
        metric("epsilon_y_percent",
               off.found ? method::relativeErrorPercent(off.measured_range_mm, off.true_range_mm) : kNaN, "%"); // Eq. 3
        metric("measured_range_mm", off.found ? off.measured_range_mm : kNaN, "mm");
        metric("true_range_mm", off.true_range_mm, "mm");
        metric("object_offset_lateral_mm", off.found ? off.lateral_mm : kNaN, "mm");
        metric("object_offset_range_mm", off.found ? off.range_mm : kNaN, "mm");
        if (off.found) { // what was read as the known object, outlined (README: the views)
            const method::PanelReading &r = off.reading;
            drawings.top.push_back({{r.x_min_mm, r.x_max_mm},
                                    {off.measured_range_mm, off.measured_range_mm + known.size_mm[1]},
                                    known.name + " Y' " + fixed(off.measured_range_mm / 1000, 2) + " m",
                                    {40, 40, 220}, r.top_cells, grid_.cell_mm});
            drawings.front.push_back({{r.x_min_mm, r.x_max_mm}, {r.z_bottom_mm, r.z_top_mm},
                                      known.name + " X " + fixed(off.measured_x_mm / 1000, 2) + " m",
                                      {40, 40, 220}, r.front_cells, grid_.cell_mm});
        }

        // The ground plane, and the inclination it gives back (Eq. 1 applied with the
        // ground transform's inclination).
        method::GroundPlaneOptions g;
        g.inlier_mm = p_.real("ground_inlier_mm");
        g.max_tilt_deg = p_.real("ground_max_tilt_deg");
        const method::GroundPlane plane = method::fitGroundPlane(cloud, g);
        const double recovered = method::recoveredInclinationDeg(rig_.applied_inclination_deg, plane);
        const double trueInclination = given("true_inclination_deg", truth.inclination_deg);
        metric("ground_offset_mm", plane.found ? plane.offset_mm : kNaN, "mm");
        metric("ground_pitch_deg", plane.found ? plane.pitch_deg : kNaN, "deg");
        metric("ground_roll_deg", plane.found ? plane.roll_deg : kNaN, "deg");
        metric("ground_inliers", static_cast<double>(plane.inliers));
        metric("ground_rms_mm", plane.found ? plane.rms_mm : kNaN, "mm");
        metric("inclination_applied_deg", rig_.applied_inclination_deg, "deg");
        metric("inclination_recovered_deg", recovered, "deg");
        metric("inclination_true_deg", trueInclination, "deg");
        metric("angular_error_deg", recovered - trueInclination, "deg");
        return off.true_range_mm;
    }

    // The same reading on the cloud of the ground-truth disparity (oracle_cloud.hpp): what
    // the camera configuration alone allows; the difference is what the matcher costs.
    // Nothing is reported when the frame carries no gt_disparity.
    void scoreOracle(const binocle_stereo_frame *frame, const method::PanelReadingOptions &o,
                     const method::PanelSize &trueSize, const method::PanelScore &measured) {
        const auto cloud = oracle_.groundCloud(frame, rig_.applied_camera_height_mm, rig_.applied_inclination_deg);
        if (!cloud) return;
        const method::PanelReading r = method::readPanel(method::CloudView(*cloud), o);
        const method::PanelScore s = method::scorePanel(r.size(), trueSize, r.registered);
        if (!r.registered)
            host_.warning("frame " + std::to_string(sequence_) + ": panel not registered on the ground-truth cloud (oracle): " + r.reason);
        scoreMetrics(r, s, "_oracle");
        metric("eta_3d_matcher_loss_percent", s.eta_3d_percent - measured.eta_3d_percent, "%");
    }

    // How the panel (e1) or the known object (e2) is read, from the settings.
    method::PanelReadingOptions readingOptions() const {
        method::PanelReadingOptions o;
        o.grid = grid_;
        o.range_search_percent = p_.real("range_search_percent");
        o.range_margin_mm = p_.real("range_margin_mm");
        o.min_points = p_.integer("min_panel_points");
        o.method = p_.string("reading") == "band" ? method::PanelReadingMethod::Band : method::PanelReadingMethod::Region;
        o.seed_half_width_mm = p_.real("seed_half_width_mm");
        o.relative_density = p_.real("relative_density");
        o.bridge_mm = p_.real("bridge_mm");
        o.max_width_ratio = p_.real("max_width_ratio");
        return o;
    }

    // What the reading took, drawn over the views: the outline of the panel's cells in
    // the front (X, Z) and top (X, Y) views, its box and X', Y', Z' (README: the report
    // and `binocle view` show them, so that a person can check each figure by eye).
    void drawReading(const method::PanelReading &r, Drawings &drawings) const {
        const cv::Scalar red{40, 40, 220};
        const double cell = grid_.cell_mm;
        if (!r.registered) {
            if (r.front_cells.empty()) return;
            drawings.front.push_back({{r.x_min_mm, r.x_max_mm}, {r.z_bottom_mm, r.z_top_mm}, "not separated", red,
                                      r.front_cells, cell});
            return;
        }
        drawings.front.push_back({{r.x_min_mm, r.x_max_mm}, {r.z_bottom_mm, r.z_top_mm},
                                  "panel X' " + fixed(r.width_mm / 1000, 2) + " m, Z' " + fixed(r.height_mm / 1000, 2) + " m",
                                  red, r.front_cells, cell});
        drawings.top.push_back({{r.x_min_mm, r.x_max_mm}, r.band,
                                "panel X' " + fixed(r.width_mm / 1000, 2) + " m, Y' " + fixed(r.range_mm / 1000, 2) + " m",
                                red, r.top_cells, cell});
        drawings.side.push_back({r.band, {r.z_bottom_mm, r.z_top_mm}, "Y' " + fixed(r.range_mm / 1000, 2) + " m", red, {}, 0});
    }

    // Eq. 7 and the sensor-aware figures, when B, f and p are known.
    void reportDesign(const paper::FrameTruth &truth, double range, const method::PanelPlacement *panel) {
        method::StereoDesign d;
        auto pick = [&](const char *key, std::initializer_list<std::optional<double>> sources) {
            if (p_.real(key) > 0) return p_.real(key);
            for (const auto &s : sources)
                if (s && *s > 0) return *s;
            return kNaN;
        };
        d.baseline_mm = pick("baseline_mm", {truth.baseline_mm, rig_.baseline_mm});
        d.focal_length_mm = pick("focal_length_mm", {truth.focal_length_mm});
        d.pixel_pitch_um = pick("pixel_pitch_um", {truth.pixel_pitch_um});
        const std::optional<double> fpx = truth.focal_length_px ? truth.focal_length_px : rig_.focal_length_px;
        if (!(d.focal_length_mm > 0) && d.pixel_pitch_um > 0 && fpx) d.focal_length_mm = *fpx * d.pixel_pitch_um / 1000;
        if (!(d.pixel_pitch_um > 0) && d.focal_length_mm > 0 && fpx) d.pixel_pitch_um = d.focal_length_mm * 1000 / *fpx;
        if (!(d.baseline_mm > 0 && d.focal_length_mm > 0 && d.pixel_pitch_um > 0 && range > 0)) {
            if (!designWarned_)
                host_.info("form factor and sensor figures not reported: baseline_mm, focal_length_mm or "
                           "pixel_pitch_um unknown (set them in the evaluator's YAML)");
            designWarned_ = true;
            return;
        }
        d.image_width_px = truth.image_width.value_or(rig_.image_width.value_or(0));
        d.image_height_px = truth.image_height.value_or(rig_.image_height.value_or(0));
        d.min_disparity_px = rig_.min_disparity;
        d.num_disparities = rig_.num_disparities;
        d.camera_height_mm = truth.camera_height_mm.value_or(rig_.applied_camera_height_mm);
        d.inclination_deg = truth.inclination_deg.value_or(rig_.applied_inclination_deg);
        const method::DesignFigures f = method::designFigures(d, range, p_.real("matching_error_px"), panel);
        metric("form_factor", f.form_factor); // Eq. 7
        metric("baseline_mm", d.baseline_mm, "mm");
        metric("focal_length_mm", d.focal_length_mm, "mm");
        metric("disparity_px", f.disparity_px, "px");
        metric("depth_resolution_mm", f.depth_resolution_mm, "mm");
        metric("min_range_mm", f.min_range_mm, "mm");
        metric("horizontal_fov_deg", f.horizontal_fov_deg, "deg");
        metric("vertical_fov_deg", f.vertical_fov_deg, "deg");
        metric("field_width_mm", f.field_width_mm, "mm");
        metric("stereo_field_width_mm", f.stereo_field_width_mm, "mm");
        if (panel) {
            metric("panel_fits", f.panel_fits_width && f.panel_fits_height ? 1 : 0);
            metric("panel_width_ratio", f.panel_width_ratio);
        }
    }

    // The boxes drawn on the density views, for hosts that draw the views themselves
    // (the live viewer): {"top": [{"u_mm": [a, b], "v_mm": [a, b], "label": .., "bgr": [..]}], ...}.
    static std::string overlaysJson(const Drawings &d) {
        nlohmann::ordered_json j = nlohmann::ordered_json::object();
        auto list = [](const std::vector<method::ViewOverlay> &v) {
            nlohmann::ordered_json a = nlohmann::ordered_json::array();
            for (const method::ViewOverlay &o : v) {
                a.push_back({{"u_mm", {o.u.min_mm, o.u.max_mm}},
                             {"v_mm", {o.v.min_mm, o.v.max_mm}},
                             {"label", o.label},
                             {"bgr", {o.color[0], o.color[1], o.color[2]}}});
                if (o.cells.empty()) continue;
                nlohmann::ordered_json cells = nlohmann::ordered_json::array();
                for (const auto &c : o.cells) cells.push_back({c[0], c[1]});
                a.back()["cell_mm"] = o.cell_mm;
                a.back()["cells_mm"] = std::move(cells);
            }
            return a;
        };
        j["top"] = list(d.top);
        j["front"] = list(d.front);
        j["side"] = list(d.side);
        return j.dump();
    }

    void writeViews(const method::CloudView &cloud, const char *outputDir, const Drawings &drawings) {
        if (!outputDir || !*outputDir) {
            if (!viewsWarned_) host_.warning("write_views: the host gives no output folder; no view written");
            viewsWarned_ = true;
            return;
        }
        char stem[32];
        std::snprintf(stem, sizeof stem, "%06llu", static_cast<unsigned long long>(sequence_));
        struct Item {
            method::View view;
            const std::vector<method::ViewOverlay> *overlays;
            bool aboveGround;
        };
        const Item items[] = {{method::View::Top, &drawings.top, true},
                              {method::View::Front, &drawings.front, false},
                              {method::View::Side, &drawings.side, false}};
        for (const Item &item : items) {
            const method::DensityView view =
                method::binView(cloud, item.view, grid_, item.aboveGround ? method::aboveGround(grid_) : nullptr);
            method::RenderOptions r;
            r.density_threshold = grid_.density_threshold;
            r.overlays = *item.overlays;
            std::string name = method::viewName(item.view);
            name[0] = static_cast<char>(name[0] - 'a' + 'A');
            r.title = name + " view (" + method::viewAxes(item.view) + "), frame " + std::to_string(sequence_) + ": " +
                      std::to_string(view.total()) + " points" +
                      (item.aboveGround ? " above " + fixed(grid_.ground_band_mm, 0) + " mm" : "") + ", cell " +
                      fixed(grid_.cell_mm, 0) + " mm";
            const std::string path =
                (std::filesystem::path(outputDir) / ("paper_" + std::string(method::viewName(item.view)) + "_" + stem + ".png"))
                    .string();
            try {
                method::writePngAtomic(path, method::renderDensityView(view, r));
            } catch (const std::runtime_error &e) {
                throw Error(BINOCLE_ERR_IO, std::string("paper: ") + e.what());
            }
        }
    }

    binocle::sdk::Host &host_;
    // The checked settings, a copy (strings included) kept for every frame.
    binocle::sdk::CheckedParams p_;
    std::string objectName_;
    bool e2_ = false;
    method::GridSpec grid_;
    std::optional<std::vector<double>> objectCenter_, objectSize_;
    paper::OracleProjector oracle_;
    paper::RigFacts calibration_, rig_; // the calibration's facts; with the host's of this frame
    std::string calibrationText_;
    bool calibrationParsed_ = false;
    bool designWarned_ = false, viewsWarned_ = false;
    uint64_t sequence_ = 0;
    int64_t frames_ = 0;
    std::vector<Total> totals_;
};

} // namespace

BINOCLE_EXPORT_EVALUATOR(PaperEvaluator, "paper", "1.1.0",
                         "METHOD.md: E1 panel relative errors and efficiencies (Eq. 2-6) read as a person reads the "
                         "views, with the ground-truth oracle; E2 ground and object indicators, form factor (Eq. 7), "
                         "density-grid views and objects")
