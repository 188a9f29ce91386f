// SPDX-License-Identifier: MIT
// The one progress display of run, record and experiment.
#include "core/progress.hpp"

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <unistd.h>

namespace binocle {

namespace {
// Between two lines in a log file or a CI job: often enough to see it move, seldom
// enough not to drown the log.
constexpr std::chrono::milliseconds kPeriod{3000};
// Whether a live line stands on stderr without its newline (only one display runs at once).
std::atomic<bool> liveLineShown{false};
}

void Progress::clearLiveLine() {
    if (liveLineShown.exchange(false)) std::fputs("\r\033[K", stderr);
} // namespace

Progress::Progress(bool enabled, std::string what, int64_t total)
    : Progress(!enabled ? Mode::Off : ::isatty(2) ? Mode::Live : Mode::Periodic, std::move(what), total, kPeriod) {}

Progress::Progress(Mode mode, std::string what, int64_t total, std::chrono::milliseconds period)
    : mode_(mode), what_(std::move(what)), total_(total), period_(period), start_(std::chrono::steady_clock::now()),
      last_(start_) {}

Progress::~Progress() { finish(); }

std::string Progress::line(int64_t done, const std::string &detail) const {
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    char buf[160];
    if (total_ > 0) {
        const int width = 20;
        const int filled = static_cast<int>(width * std::min<int64_t>(done, total_) / total_);
        std::snprintf(buf, sizeof buf, "[%s%s] %s %lld/%lld", std::string(filled, '#').c_str(),
                      std::string(width - filled, '-').c_str(), what_.c_str(), static_cast<long long>(done),
                      static_cast<long long>(total_));
    } else {
        std::snprintf(buf, sizeof buf, "%s %lld", what_.c_str(), static_cast<long long>(done));
    }
    std::string out = buf;
    std::snprintf(buf, sizeof buf, "  %.1f s, %.1f %s/s", s, s > 0 ? done / s : 0.0, what_.c_str());
    out += buf;
    if (!detail.empty()) out += "  " + detail;
    return out;
}

void Progress::print(const std::string &text) {
    if (mode_ == Mode::Live) {
        std::fprintf(stderr, "\r\033[K%s", text.c_str());
        liveLineShown = true;
    }
    else std::fprintf(stderr, "%s\n", text.c_str());
    std::fflush(stderr);
    printed_ = true;
}

void Progress::update(int64_t done, const std::string &detail) {
    if (mode_ == Mode::Off || finished_) return;
    done_ = done;
    detail_ = detail;
    const auto now = std::chrono::steady_clock::now();
    if (mode_ == Mode::Periodic && now - last_ < period_) {
        pending_ = true;
        return;
    }
    last_ = now;
    pending_ = false;
    print(line(done, detail));
}

void Progress::finish(const std::string &detail) {
    if (mode_ == Mode::Off || finished_) return;
    finished_ = true;
    if (!detail.empty()) detail_ = detail;
    // A periodic display prints where it ended if its last state was not shown yet.
    if (mode_ == Mode::Periodic && (pending_ || !detail.empty()) && printed_) print(line(done_, detail_));
    if (mode_ == Mode::Live && printed_) {
        if (!detail.empty()) print(line(done_, detail_));
        if (liveLineShown.exchange(false)) std::fputs("\n", stderr);
        std::fflush(stderr);
    }
}

} // namespace binocle
