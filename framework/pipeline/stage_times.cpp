// SPDX-License-Identifier: MIT
// Per-stage times of a run: bounded samples, median and 95th percentile.
#include "pipeline/stage_times.hpp"

#include <algorithm>
#include <cmath>

namespace binocle {

void StageTimes::add(double seconds) {
    ++count_;
    if (samples_.size() < kKept) {
        samples_.push_back(seconds);
        return;
    }
    // Reservoir: the n-th sample replaces a kept one with probability kKept / n.
    random_ ^= random_ << 13;
    random_ ^= random_ >> 7;
    random_ ^= random_ << 17;
    const uint64_t slot = random_ % static_cast<uint64_t>(count_);
    if (slot < kKept) samples_[slot] = seconds;
}

double StageTimes::quantile(double q) const {
    if (samples_.empty()) return 0;
    std::vector<double> sorted = samples_;
    const size_t rank = static_cast<size_t>(std::ceil(std::clamp(q, 0.0, 1.0) * static_cast<double>(sorted.size())));
    const size_t at = rank == 0 ? 0 : rank - 1;
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(at), sorted.end());
    return sorted[at];
}

RunTimes::RunTimes() : stages_(pipelineStages().size()) {}

void RunTimes::add(const std::string &stage, double seconds) {
    const auto &names = pipelineStages();
    const auto it = std::find(names.begin(), names.end(), stage);
    if (it != names.end()) stages_[static_cast<size_t>(it - names.begin())].add(seconds);
}

nlohmann::ordered_json RunTimes::summary() const {
    nlohmann::ordered_json out = nlohmann::ordered_json::object();
    for (size_t i = 0; i < stages_.size(); ++i) {
        const StageTimes &t = stages_[i];
        if (t.count() == 0) continue;
        out[pipelineStages()[i]] = {{"median", t.quantile(0.5)}, {"p95", t.quantile(0.95)}, {"frames", t.count()}};
    }
    return out;
}

} // namespace binocle
