// SPDX-License-Identifier: MIT
// A camera that stops answering, found and reopened: the gige source notices the loss
// (control lost, trigger unanswered, no image for lost_after_ms), closes the camera and
// retries it on background threads (Aravis's timeouts last seconds; grab never waits for
// them), and takes the camera back between two grabs.
#pragma once

#include "gige_slot.hpp"
#include "pairing.hpp"

#include <binocle/plugin.hpp>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace binocle::gige {

struct ReconnectionSettings {
    bool reconnect = true;
    std::chrono::milliseconds retryInterval{1000};
    std::chrono::milliseconds lostAfter{1000};
    Trigger trigger = Trigger::FreeRun;
    int width = 0, height = 0; // what a camera must deliver again when it is back
};

class Reconnection {
public:
    Reconnection(const ReconnectionSettings &settings, Slots &slots, Pairing &pairing, std::shared_ptr<Notifier> notifier,
                 sdk::Host &host, const std::atomic<bool> &running);
    ~Reconnection() { shutdown(); }
    // Ends the retries and closes the lost cameras (may wait for Aravis's timeouts).
    void shutdown();

    // Finds cameras that went away since the last look, hands each to a background
    // thread, and returns the message to report ("" when none).
    std::string detectLoss(Clock::time_point now);
    // Takes in the cameras the background threads have reopened.
    void adoptReconnected();
    bool anyDisconnected() const;
    std::string disconnectedMessage();
    uint64_t reconnections() const { return reconnections_; }

private:
    void loseCamera(Slot &slot);
    void reconnectLoop(Slot &slot);
    std::string retrying() const;

    ReconnectionSettings settings_;
    Slots &slots_;
    Pairing &pairing_;
    std::shared_ptr<Notifier> notifier_;
    sdk::Host &host_;
    const std::atomic<bool> &running_;
    uint64_t reconnections_ = 0;

    // Shared with the background threads.
    std::mutex mutex_;
    std::condition_variable wake_;
    bool closing_ = false;
    std::vector<std::thread> background_;
};

} // namespace binocle::gige
