// SPDX-License-Identifier: MIT
// Helpers of the device plugins' tests (v4l2 here, videre1394 too): a source class served
// in-process through the plugin's own C table, its failures as code and message, and
// image comparisons.
#pragma once

#include "config/rig_config.hpp"
#include "core/error.hpp"
#include "host/plugin_host.hpp"

#include <binocle/plugin.hpp>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace binocle::test {

// The table BINOCLE_EXPORT_SOURCE(Class, name ...) makes, as a record the host's
// wrappers accept: the same code path as the built plugin, with whatever device layer
// the test executable links.
template <class Class>
const PluginRecord &inProcessSource(const char *name) {
    static const PluginRecord r = [name] {
        PluginRecord rec;
        rec.path = std::string("(") + name + " logic on a fake device layer)";
        rec.name = name;
        rec.kind = BINOCLE_KIND_STEREO_SOURCE;
        rec.table = &sdk::detail::sourceTable<Class>(name, "test", "on a fake device layer")->header;
        rec.abi_version = rec.table->abi_version;
        rec.api_version = rec.table->api_version;
        return rec;
    }();
    return r;
}

// A source from YAML settings, validated as a rig's are.
inline std::unique_ptr<Source> makeSource(const PluginRecord &record, const std::string &yaml) {
    return std::make_unique<Source>(record, paramsFromYaml(record, yaml));
}

// The same, started.
inline std::unique_ptr<Source> startSource(const PluginRecord &record, const std::string &yaml) {
    auto s = makeSource(record, yaml);
    s->start();
    return s;
}

struct Failure {
    int code = BINOCLE_OK;
    std::string message;
};

// The code and message of the PluginError `f` throws; code BINOCLE_OK when none.
template <class F>
Failure failureOf(F &&f) {
    try {
        f();
    } catch (const PluginError &e) {
        return {e.code(), e.what()};
    }
    return {};
}

// Largest absolute difference of two images of one size and type.
inline double maxDiff(const cv::Mat &a, const cv::Mat &b) {
    EXPECT_EQ(a.size(), b.size());
    EXPECT_EQ(a.type(), b.type());
    if (a.size() != b.size() || a.type() != b.type()) return 1e9;
    double m = 0;
    cv::minMaxLoc(cv::abs(a - b), nullptr, &m);
    return m;
}

// True when p points into one of the memory ranges (a driver's buffers).
inline bool inside(const void *p, const std::vector<std::pair<const uint8_t *, size_t>> &ranges) {
    const auto *b = static_cast<const uint8_t *>(p);
    for (const auto &r : ranges)
        if (b >= r.first && b < r.first + r.second) return true;
    return false;
}

} // namespace binocle::test
