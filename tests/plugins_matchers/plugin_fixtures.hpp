// SPDX-License-Identifier: MIT
// Helpers of the bm, sgbm and ground plugin tests: the built plugins through the host,
// instances from YAML, stereo pairs with known disparity, and disparity scores.
#pragma once

#include "config/rig_config.hpp"
#include "host/plugin_host.hpp"

#include <binocle/abi.h>
#include <binocle/plugin.hpp>

#include <gtest/gtest.h>

#include <iostream>
#include <memory>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

namespace binocle::test {

// The plugins of this build tree, as the host loads them.
inline const PluginHost &builtPlugins() {
    static const std::unique_ptr<PluginHost> host = [] {
        auto h = std::make_unique<PluginHost>(std::vector<std::string>{BINOCLE_BUILD_PLUGIN_DIR});
        h->scan();
        return h;
    }();
    return *host;
}

inline const PluginRecord &matcherRecord(const std::string &name) {
    return builtPlugins().require(name, BINOCLE_KIND_MATCHER);
}

// A matcher with its defaults and `yaml` (a map of settings) on top, validated as a rig is.
inline Matcher makeMatcher(const std::string &name, const std::string &yaml = "{}") {
    const PluginRecord &record = matcherRecord(name);
    return Matcher(record, paramsFromYaml(record, yaml));
}

// The message of the exception `f` throws, or "" when it throws none.
template <class F>
std::string errorOf(F &&f) {
    try {
        f();
    } catch (const std::exception &e) {
        return e.what();
    }
    return "";
}

// `key: value` is refused twice: by the rig validation (message naming the key and
// containing `configExpected`) and, when a host skips validation, by the plugin itself
// when created (message containing `pluginExpected`). Instance: Matcher, CloudTransform.
template <class Instance>
void expectRefused(const PluginRecord &record, const std::string &key, const std::string &value,
                   const std::string &configExpected, const std::string &pluginExpected) {
    const std::string config = errorOf([&] { paramsFromYaml(record, "{" + key + ": " + value + "}"); });
    EXPECT_NE(config.find(key), std::string::npos) << config;
    EXPECT_NE(config.find(configExpected), std::string::npos) << config;

    ParamValues p = paramsFromYaml(record);
    for (const binocle_param_desc &d : record.params()) {
        if (key != d.name) continue;
        if (d.type == BINOCLE_PARAM_INT) p.setInt(key, std::stoll(value));
        else if (d.type == BINOCLE_PARAM_DOUBLE) p.setDouble(key, std::stod(value));
        else p.setText(key, d.type, value);
    }
    const std::string plugin = errorOf([&] { Instance instance(record, p); });
    EXPECT_NE(plugin.find(pluginExpected), std::string::npos) << plugin;
}

// A matcher driven through its C table directly, for what the host's wrapper would
// check (or fix) before the plugin sees it.
class RawMatcher {
public:
    RawMatcher(const std::string &name, const std::string &yaml = "{}")
        : api_(reinterpret_cast<const binocle_matcher_api *>(matcherRecord(name).table)) {
        const ParamValues params = paramsFromYaml(matcherRecord(name), yaml);
        if (api_->create(params.data(), params.size(), nullptr, &handle_) != BINOCLE_OK)
            throw std::runtime_error(api_->last_error(nullptr));
    }
    ~RawMatcher() { api_->destroy(handle_); }
    RawMatcher(const RawMatcher &) = delete;
    RawMatcher &operator=(const RawMatcher &) = delete;

    // Returns the result code; the message is in lastError().
    binocle_result compute(const binocle_image &left, const binocle_image &right, binocle_image &disparity) {
        return api_->compute(handle_, &left, &right, &disparity);
    }
    std::string lastError() const { return api_->last_error(handle_); }

private:
    const binocle_matcher_api *api_;
    binocle_matcher *handle_ = nullptr;
};

inline binocle_image imageOf(const cv::Mat &m, int32_t format) {
    return sdk::makeImage(m.cols, m.rows, format, m.data, static_cast<int32_t>(m.step[0]));
}

struct StereoPair {
    cv::Mat left, right;
};

// Blurred random texture seen by two cameras such that every pixel has disparity
// `disparityPx`: left(u) = right(u - disparityPx). Grey, 8-bit.
inline StereoPair shiftedPair(cv::Size size, int disparityPx, uint64_t seed = 42) {
    cv::Mat texture(size.height, size.width + disparityPx, CV_8UC1);
    cv::RNG rng(seed);
    rng.fill(texture, cv::RNG::UNIFORM, 0, 256);
    cv::GaussianBlur(texture, texture, cv::Size(3, 3), 0.8);
    return {texture.colRange(0, size.width).clone(), texture.colRange(disparityPx, disparityPx + size.width).clone()};
}

// The pair of OpenCV's samples (rectified, 1282x1110, BGR) and its ground truth: 8-bit
// disparities in pixels at this very size (checked: matchers agree with it to a mean of
// under 1 px), 0 = unknown. Values 43..211 px.
struct AloePair {
    cv::Mat left, right, gt; // gt: CV_32F, <= 0 where unknown
};

inline AloePair loadAloe() {
    const std::string dir = std::string(BINOCLE_OPENCV_DATA_DIR) + "/";
    AloePair a;
    a.left = cv::imread(dir + "aloeL.jpg", cv::IMREAD_COLOR);
    a.right = cv::imread(dir + "aloeR.jpg", cv::IMREAD_COLOR);
    cv::Mat gt8 = cv::imread(dir + "aloeGT.png", cv::IMREAD_GRAYSCALE);
    if (a.left.empty() || a.right.empty() || gt8.empty())
        throw std::runtime_error("cannot read aloeL.jpg, aloeR.jpg or aloeGT.png in " + dir + " (package opencv-doc)");
    gt8.convertTo(a.gt, CV_32F);
    return a;
}

struct DisparityScore {
    double density = 0; // valid estimates / pixels with a known truth
    double bad = 0;     // |d - truth| > threshold / pixels with both
    double meanError = 0; // mean of d - truth over pixels with both, px
};

// Compares `disparity` with `truth` (both CV_32F, <= 0 = invalid or unknown) in `region`.
inline DisparityScore scoreDisparity(const cv::Mat &disparity, const cv::Mat &truth, double thresholdPx,
                                     cv::Rect region) {
    long known = 0, both = 0, bad = 0;
    double sum = 0;
    for (int v = region.y; v < region.y + region.height; ++v)
        for (int u = region.x; u < region.x + region.width; ++u) {
            const float t = truth.at<float>(v, u), d = disparity.at<float>(v, u);
            if (t <= 0) continue;
            ++known;
            if (d <= 0) continue;
            ++both;
            sum += d - t;
            if (std::abs(d - t) > thresholdPx) ++bad;
        }
    DisparityScore s;
    s.density = known ? static_cast<double>(both) / known : 0;
    s.bad = both ? static_cast<double>(bad) / both : 1;
    s.meanError = both ? sum / both : 0;
    return s;
}

// `plugin` with `yaml` on the aloe pair, scored against the ground truth with a 3 px
// threshold over the whole image; the figures are printed and recorded in the XML report.
inline DisparityScore aloeScore(const std::string &plugin, const std::string &yaml) {
    const AloePair a = loadAloe();
    Matcher m = makeMatcher(plugin, yaml);
    const cv::Mat d = m.compute(a.left, a.right);
    const DisparityScore s = scoreDisparity(d, a.gt, 3.0, cv::Rect(0, 0, d.cols, d.rows));
    std::cout << plugin << " " << yaml << " on aloe: bad 3 px " << 100 * s.bad << " %, density " << 100 * s.density
              << " %, mean error " << s.meanError << " px\n";
    ::testing::Test::RecordProperty("bad_3px_percent", std::to_string(100 * s.bad));
    ::testing::Test::RecordProperty("density_percent", std::to_string(100 * s.density));
    return s;
}

} // namespace binocle::test
