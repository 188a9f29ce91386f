// SPDX-License-Identifier: MIT
// Where the time of a run goes: each stage's time per frame, summarised as its median and
// 95th percentile in summary.json (`stage_seconds_per_frame`).
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace binocle {

// The stages, in the order a frame goes through them.
inline const std::vector<std::string> &pipelineStages() {
    static const std::vector<std::string> stages{"acquire", "rectify", "match", "cloud", "transforms", "evaluators", "write"};
    return stages;
}

// The times of one stage. Every sample is kept up to kKept; past that a uniform sample of
// kKept (reservoir sampling) stands for them, so an endless run holds bounded memory and
// its quantiles stay unbiased.
class StageTimes {
public:
    static constexpr size_t kKept = 1 << 16;
    void add(double seconds);
    int64_t count() const { return count_; }
    // The q-quantile (0..1) of the samples, by the nearest rank; 0 without samples.
    double quantile(double q) const;

private:
    std::vector<double> samples_;
    int64_t count_ = 0;
    uint64_t random_ = 0x9e3779b97f4a7c15ull; // xorshift state: the same run, the same sample
};

// Every stage's times, by name (pipelineStages()).
class RunTimes {
public:
    RunTimes();
    void add(const std::string &stage, double seconds);
    // {"acquire": {"median": s, "p95": s, "frames": n}, ...}, in stage order; stages without
    // a sample are left out.
    nlohmann::ordered_json summary() const;

private:
    std::vector<StageTimes> stages_;
};

} // namespace binocle
