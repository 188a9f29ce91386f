// SPDX-License-Identifier: MIT
// The head of a run's summary and its account of dropped frames.
#include "pipeline/run_summary.hpp"

#include <yaml-cpp/yaml.h>

namespace binocle {

using Json = nlohmann::ordered_json;

namespace {

// Frames a source lost before it could deliver them, from the counters of its
// statistics that source.h names: `unpaired` at the top level (pairing), and
// `failed_buffers`, `underrun_buffers`, `corrupt`, `dropped_by_driver` anywhere
// (camera or transport), each named by where it sits ("cameras.left.failed_buffers").
void sourceDrops(const YAML::Node &node, const std::string &path, Json &camera) {
    static const char *kCameraKeys[] = {"failed_buffers", "underrun_buffers", "corrupt", "dropped_by_driver"};
    if (node.IsMap()) {
        for (const auto &kv : node) {
            const std::string key = kv.first.as<std::string>("");
            const std::string where = path.empty() ? key : path + "." + key;
            bool counted = false;
            for (const char *k : kCameraKeys)
                if (key == k && kv.second.IsScalar()) {
                    camera[where] = kv.second.as<int64_t>(0);
                    counted = true;
                }
            if (!counted) sourceDrops(kv.second, where, camera);
        }
    } else if (node.IsSequence()) {
        for (size_t i = 0; i < node.size(); ++i) {
            std::string name = std::to_string(i);
            if (node[i].IsMap() && node[i]["role"] && node[i]["role"].IsScalar()) name = node[i]["role"].Scalar();
            sourceDrops(node[i], path + "." + name, camera);
        }
    }
}

} // namespace

Json runHeader(const RigConfig &rig, RuntimeOptions::Policy policy, bool live) {
    const RuntimeOptions &rt = rig.runtime;
    Json summary = Json::object();
    summary["rig"] = rig.file;
    summary["name"] = rig.name;
    summary["source"] = rig.source().plugin;
    summary["matcher"] = rig.matcher().plugin;
    summary["units"] = {{"length", "mm"}, {"disparity", "px"}, {"disparity_png_scale", 256}};
    summary["runtime"] = {{"policy", policy == RuntimeOptions::Policy::Latest ? "latest" : "lossless"},
                          {"policy_from", rt.policy ? "rig" : live ? "source (live)" : "source (not live)"},
                          {"queue_depth", rt.queue_depth},
                          {"matcher_instances", rt.matcher_instances},
                          {"on_source_error", rt.on_source_error == RuntimeOptions::OnSourceError::Retry ? "retry" : "stop"}};
    if (rt.on_source_error == RuntimeOptions::OnSourceError::Retry) summary["runtime"]["retry_for_s"] = rt.retry_for_s;
    return summary;
}

Json droppedSummary(int64_t droppedByPolicy, const std::string &stats) {
    Json dropped = Json::object();
    dropped["by_policy"] = droppedByPolicy;
    Json camera = Json::object();
    int64_t unpaired = 0;
    if (!stats.empty()) {
        try {
            const YAML::Node n = YAML::Load(stats);
            if (n.IsMap() && n["unpaired"] && n["unpaired"].IsScalar()) unpaired = n["unpaired"].as<int64_t>(0);
            sourceDrops(n, "", camera);
        } catch (const YAML::Exception &) {
        }
    }
    dropped["by_pairing"] = unpaired;
    int64_t cameraTotal = 0;
    for (const auto &[k, v] : camera.items()) cameraTotal += v.get<int64_t>();
    dropped["by_camera_or_transport"] = cameraTotal;
    dropped["camera_or_transport"] = camera;
    dropped["total"] = droppedByPolicy + unpaired + cameraTotal;
    return dropped;
}

} // namespace binocle
