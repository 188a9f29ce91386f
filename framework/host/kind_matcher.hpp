// SPDX-License-Identifier: MIT
// The matcher kind's wrapper: a Matcher instance, in this process or in a helper process
// (kind_matcher.cpp).
#pragma once

#include "host/plugin_instance.hpp"

#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <utility>
#include <vector>

namespace binocle {

// A plane a matcher attached to its disparity (matcher.h: extras), e.g.
// "disparity_filled": the host's copy, of the disparity's size (CV_8U, CV_16U or CV_32F).
struct NamedPlane {
    std::string name;
    cv::Mat image;
};

class Matcher : public PluginInstanceBase {
public:
    // In this process, or in a helper process when isolation.process.
    Matcher(const PluginRecord &record, const ParamValues &params, const IsolationOptions &isolation = {});
    ~Matcher();
    // Returns a CV_32F disparity (host-allocated), invalid pixels <= 0. Disparities that
    // are not finite or exceed the image width are made invalid and counted.
    cv::Mat compute(const cv::Mat &left, const cv::Mat &right);
    // The same into `disparity`, whose buffer is reused when it has the size already.
    void compute(const cv::Mat &left, const cv::Mat &right, cv::Mat &disparity);
    std::pair<int32_t, int32_t> disparityRange();
    // Runs the plugin's compute into `disparity` (CV_32F, left's size), checking that it
    // kept the host's image description; no clean-up of the values.
    void computeInto(const cv::Mat &left, const cv::Mat &right, cv::Mat &disparity);
    // Disparities made invalid so far because they were not finite or absurd.
    uint64_t invalidatedDisparities() const { return invalidated_; }
    // The planes the plugin attached to the last compute's disparity (none when its table
    // has no extras entry, or after a failed compute): new buffers each compute, so a
    // copy of the list stays valid.
    const std::vector<NamedPlane> &extras() const { return extras_; }

    class Impl;

private:
    std::unique_ptr<Impl> impl_;
    std::vector<NamedPlane> extras_;
    uint64_t invalidated_ = 0;
    bool warnedInvalid_ = false;
};

} // namespace binocle
