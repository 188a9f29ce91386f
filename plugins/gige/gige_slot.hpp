// SPDX-License-Identifier: MIT
// What the gige source keeps per camera position (left, right, or the side-by-side
// camera), shared by its pairing and its reconnection: the camera, the images waiting for
// a partner, and the counters its statistics report.
#pragma once

#include "gige_camera.hpp"

#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <string>

namespace binocle::gige {

inline std::string sizeText(const Camera &c) {
    return std::to_string(c.width()) + "x" + std::to_string(c.height()) + " " + c.format().name;
}

// A buffer taken from a stream, waiting for its partner.
struct Pending {
    ArvBuffer *buffer = nullptr;
    std::shared_ptr<BufferHome> home;
    int64_t timestamp_ns = 0;
    uint64_t frame_id = 0;
};

struct Slot {
    CameraSettings settings;
    std::shared_ptr<Camera> camera;      // null while the camera is away
    std::shared_ptr<Camera> reconnected; // set by the background thread (Reconnection's mutex)
    std::deque<Pending> pending;
    std::optional<Clock::time_point> awaitingSince; // an image is due since then
    int64_t lastSequence = -1;                      // last frame this camera took part in
    std::string lostWhy;                            // why it is away
    int attempts = 0;                               // reconnection attempts (Reconnection's mutex)
    std::string lastAttemptError;                   // (Reconnection's mutex)
    StreamCounters retired;                         // counters of closed streams
    uint64_t images = 0, losses = 0, unpaired = 0, idGap = 0;
    std::optional<uint64_t> lastFrameId; // of the current camera
    std::map<std::string, uint64_t> failures;
    std::unique_ptr<TriggerWorker> trigger; // software trigger: of the current camera
    bool answered = false;                  // software trigger: an image came for the last one
};

using Slots = std::vector<std::unique_ptr<Slot>>;

} // namespace binocle::gige
