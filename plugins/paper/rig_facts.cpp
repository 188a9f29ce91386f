// SPDX-License-Identifier: MIT
// Frame metadata, rig and calibration, read for the paper evaluator.
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

RigFacts parseRigFacts(const char *rig_yaml, const char *calibration_yaml) {
    RigFacts f;
    const YAML::Node rig = load(rig_yaml, "rig");
    if (rig && rig.IsMap()) {
        const YAML::Node source = rig["source"];
        f.baseline_mm = scalar<double>(source, "baseline_mm", "rig, source");
        f.focal_length_mm = scalar<double>(source, "focal_length_mm", "rig, source");
        f.pixel_pitch_um = scalar<double>(source, "pixel_pitch_um", "rig, source");
        f.image_width = scalar<int>(source, "image_width", "rig, source");
        f.image_height = scalar<int>(source, "image_height", "rig, source");
        const YAML::Node matcher = rig["matcher"];
        f.min_disparity = scalar<int>(matcher, "min_disparity", "rig, matcher").value_or(0);
        f.num_disparities = scalar<int>(matcher, "num_disparities", "rig, matcher").value_or(0);
        if (const YAML::Node transforms = rig["transforms"]; transforms && transforms.IsSequence()) {
            for (size_t i = 0; i < transforms.size(); ++i) {
                const YAML::Node t = transforms[i];
                if (!t.IsMap() || !t["plugin"] || t["plugin"].as<std::string>() != "ground") continue;
                const std::string where = "rig, transforms[" + std::to_string(i) + "]";
                f.ground_transform = true;
                f.applied_inclination_deg = scalar<double>(t, "inclination_deg", where).value_or(0.0);
                f.applied_camera_height_mm = scalar<double>(t, "camera_height_mm", where).value_or(1500.0);
            }
        }
    }
    if (calibration_yaml && *calibration_yaml) {
        try {
            cv::FileStorage fs(calibration_yaml, cv::FileStorage::READ | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
            auto real = [&](const char *key) -> std::optional<double> {
                const cv::FileNode n = fs[key];
                if (n.empty() || !(n.isReal() || n.isInt())) return std::nullopt;
                return static_cast<double>(n);
            };
            if (!f.baseline_mm) f.baseline_mm = real("baseline_mm");
            f.focal_length_px = real("focal_length_px");
            if (!f.image_width) {
                if (auto w = real("image_width")) f.image_width = static_cast<int>(*w);
            }
            if (!f.image_height) {
                if (auto h = real("image_height")) f.image_height = static_cast<int>(*h);
            }
        } catch (const cv::Exception &) {
            // The pipeline has parsed it already; anything unreadable here only costs figures.
        }
    }
    return f;
}

} // namespace binocle::paper
