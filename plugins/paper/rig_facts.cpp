// SPDX-License-Identifier: MIT
// Frame metadata, calibration and the host's facts, read for the paper evaluator.
#include "paper/rig_facts.hpp"

#include <binocle/plugin.hpp>

#include <opencv2/core.hpp>
#include <yaml-cpp/yaml.h>

#include <cmath>

namespace binocle::paper {

namespace {

using sdk::Error;

template <class T>
std::optional<T> scalar(const YAML::Node &map, const char *key, const std::string &where) {
    if (!map || !map.IsMap()) return std::nullopt;
    const YAML::Node n = map[key];
    if (!n || n.IsNull()) return std::nullopt;
    try {
        return n.as<T>();
    } catch (const YAML::Exception &) {
        throw Error(BINOCLE_ERR_INVALID_ARGUMENT, where + ": " + key + " = '" + YAML::Dump(n) + "': expected a number");
    }
}

std::optional<std::vector<double>> triple(const YAML::Node &map, const char *key, const std::string &where) {
    if (!map || !map.IsMap() || !map[key]) return std::nullopt;
    const YAML::Node n = map[key];
    std::vector<double> v;
    try {
        v = n.as<std::vector<double>>();
    } catch (const YAML::Exception &) {
        v.clear();
    }
    if (v.size() != 3)
        throw Error(BINOCLE_ERR_INVALID_ARGUMENT,
                    where + ": " + key + " = " + YAML::Dump(n) + ": expected three numbers [X, Y, Z] in mm");
    return v;
}

YAML::Node load(const char *text, const std::string &what) {
    if (!text || !*text) return YAML::Node();
    try {
        return YAML::Load(text);
    } catch (const YAML::Exception &e) {
        throw Error(BINOCLE_ERR_INVALID_ARGUMENT, what + " is not valid YAML: " + e.what());
    }
}

} // namespace

FrameTruth parseFrameTruth(const char *metadata) {
    FrameTruth t;
    const YAML::Node root = load(metadata, "frame metadata");
    if (!root || !root.IsMap()) return t;
    if (const YAML::Node panel = root["panel"]) {
        const std::string where = "frame metadata, panel";
        t.panel_width_mm = scalar<double>(panel, "width_mm", where);
        t.panel_range_mm = scalar<double>(panel, "range_mm", where);
        t.panel_height_mm = scalar<double>(panel, "height_mm", where);
        const auto center = triple(panel, "center_mm", where);
        const auto size = triple(panel, "size_mm", where);
        if (size) {
            if (!t.panel_width_mm) t.panel_width_mm = (*size)[0];
            if (!t.panel_height_mm) t.panel_height_mm = (*size)[2];
            if (!t.panel_range_mm && center) t.panel_range_mm = (*center)[1] - (*size)[1] / 2;
        }
        if (center) {
            t.panel_center_x_mm = (*center)[0];
            if (t.panel_height_mm) t.panel_base_z_mm = (*center)[2] - *t.panel_height_mm / 2;
        }
    }
    if (const YAML::Node rig = root["rig"]) {
        const std::string where = "frame metadata, rig";
        t.baseline_mm = scalar<double>(rig, "baseline_mm", where);
        t.focal_length_mm = scalar<double>(rig, "focal_length_mm", where);
        t.pixel_pitch_um = scalar<double>(rig, "pixel_pitch_um", where);
        t.focal_length_px = scalar<double>(rig, "focal_length_px", where);
        t.camera_height_mm = scalar<double>(rig, "camera_height_mm", where);
        t.inclination_deg = scalar<double>(rig, "inclination_deg", where);
        t.image_width = scalar<int>(rig, "image_width", where);
        t.image_height = scalar<int>(rig, "image_height", where);
    }
    if (root["main_object"] && root["main_object"].IsScalar()) t.main_object = root["main_object"].as<std::string>();
    if (const YAML::Node objects = root["objects"]; objects && objects.IsSequence()) {
        for (size_t i = 0; i < objects.size(); ++i) {
            const YAML::Node o = objects[i];
            const std::string where = "frame metadata, objects[" + std::to_string(i) + "]";
            const auto center = triple(o, "center_mm", where);
            const auto size = triple(o, "size_mm", where);
            if (!center || !size) continue;
            method::KnownObject k;
            k.name = o["name"] && o["name"].IsScalar() ? o["name"].as<std::string>() : "";
            for (int a = 0; a < 3; ++a) {
                k.center_mm[a] = (*center)[static_cast<size_t>(a)];
                k.size_mm[a] = (*size)[static_cast<size_t>(a)];
            }
            t.objects.push_back(k);
        }
    }
    return t;
}

RigFacts parseCalibrationFacts(const char *calibration_yaml) {
    RigFacts f;
    if (calibration_yaml && *calibration_yaml) {
        try {
            cv::FileStorage fs(calibration_yaml, cv::FileStorage::READ | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
            auto real = [&](const char *key) -> std::optional<double> {
                const cv::FileNode n = fs[key];
                if (n.empty() || !(n.isReal() || n.isInt())) return std::nullopt;
                return static_cast<double>(n);
            };
            f.baseline_mm = real("baseline_mm");
            f.focal_length_px = real("focal_length_px");
            if (auto w = real("image_width")) f.image_width = static_cast<int>(*w);
            if (auto h = real("image_height")) f.image_height = static_cast<int>(*h);
        } catch (const cv::Exception &) {
            // The pipeline has parsed it already; anything unreadable here only costs figures.
        }
    }
    return f;
}

void addHostFacts(RigFacts &f, const binocle_eval_input &in) {
    if (BINOCLE_EVAL_INPUT_HAS(in, num_disparities)) {
        f.min_disparity = in.min_disparity;
        f.num_disparities = in.num_disparities;
    }
    f.ground_pose_known = BINOCLE_EVAL_INPUT_HAS(in, inclination_deg) && in.ground_pose_known;
    if (f.ground_pose_known) {
        f.applied_camera_height_mm = in.camera_height_mm;
        f.applied_inclination_deg = in.inclination_deg;
    }
}

} // namespace binocle::paper
