// SPDX-License-Identifier: MIT
// Parts of a run's summary.json that read the rig and the source's statistics: the head
// (rig, matcher, runtime policy) and where frames were dropped.
#pragma once

#include "config/rig_config.hpp"

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

namespace binocle {

// rig, name, source, matcher, units and the runtime block as the run applies it.
nlohmann::ordered_json runHeader(const RigConfig &rig, RuntimeOptions::Policy policy, bool live);

// {by_policy, by_pairing, by_camera_or_transport, camera_or_transport, total}: frames the
// policy dropped, and those the source says it lost (its statistics' counters).
nlohmann::ordered_json droppedSummary(int64_t droppedByPolicy, const std::string &sourceStatistics);

} // namespace binocle
