// SPDX-License-Identifier: MIT
// Frames one period apart, as a camera delivers them: the sources that can go faster
// than their rate (replay's rate_hz, sim's pace) wait in grab() until the next frame is due.
//
// Header-only; plugins/common has no CMakeLists.txt on purpose (every folder with one
// is built as a plugin).
#pragma once

#include <binocle/plugin.hpp>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <string>
#include <thread>
#include <utility>

namespace binocle::plugins {

class FramePacer {
public:
    // The first frame is due now (call at the source's start()). `what` and `rate` name
    // the source and its setting in the timeout's message.
    void start(int64_t periodNs, std::string what, std::string rate) {
        period_ = std::chrono::nanoseconds(periodNs);
        due_ = std::chrono::steady_clock::now();
        what_ = std::move(what);
        rate_ = std::move(rate);
    }

    // Sleeps until the next frame is due; a late consumer gets it at once, with no burst
    // of frames to catch up. A wait longer than timeout_ms (>= 0) sleeps timeout_ms and
    // throws BINOCLE_ERR_TIMEOUT "<what>: next frame due after the timeout of N ms (<rate>)".
    void wait(int32_t timeout_ms) {
        using namespace std::chrono;
        const auto now = steady_clock::now();
        if (due_ > now) {
            if (timeout_ms >= 0 && due_ - now > milliseconds(timeout_ms)) {
                std::this_thread::sleep_for(milliseconds(timeout_ms));
                throw sdk::Error(BINOCLE_ERR_TIMEOUT, what_ + ": next frame due after the timeout of " +
                                                          std::to_string(timeout_ms) + " ms (" + rate_ + ")");
            }
            std::this_thread::sleep_until(due_);
        }
        due_ = std::max(due_, steady_clock::now() - period_) + period_;
    }

private:
    std::chrono::nanoseconds period_{0};
    std::chrono::steady_clock::time_point due_ = std::chrono::steady_clock::now();
    std::string what_, rate_;
};

} // namespace binocle::plugins
