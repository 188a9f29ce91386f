// SPDX-License-Identifier: MIT
// The one progress display of run, record and experiment: a live line on a terminal,
// a line every few seconds when stderr is a file or a pipe, nothing when quiet.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>

namespace binocle {

class Progress {
public:
    enum class Mode { Off, Live, Periodic };

    // `what` names the unit counted ("frame", "test"); `total` < 0 when unknown.
    // The mode follows stderr: Live on a terminal, Periodic otherwise, Off when !enabled.
    Progress(bool enabled, std::string what, int64_t total = -1);
    Progress(Mode mode, std::string what, int64_t total, std::chrono::milliseconds period);
    ~Progress();
    Progress(const Progress &) = delete;
    Progress &operator=(const Progress &) = delete;

    // `done` units so far; `detail` says what is going on (shown after the count).
    void update(int64_t done, const std::string &detail = "");
    // Ends the live line (a periodic display prints its last state once).
    void finish(const std::string &detail = "");

    Mode mode() const { return mode_; }
    // Erases the live line, if one is shown, so that a log message starts on a clean line
    // (the next update draws it again). Called by the log's stderr sink.
    static void clearLiveLine();
    // The line as it would be shown now, without terminal control characters.
    std::string line(int64_t done, const std::string &detail) const;

private:
    void print(const std::string &text);

    Mode mode_;
    std::string what_;
    int64_t total_;
    std::chrono::milliseconds period_;
    std::chrono::steady_clock::time_point start_, last_{};
    int64_t done_ = 0;
    std::string detail_;
    bool printed_ = false, finished_ = false, pending_ = false;
};

} // namespace binocle
