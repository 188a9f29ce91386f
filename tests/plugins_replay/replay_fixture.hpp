// SPDX-License-Identifier: MIT
// The replay tests' fixture: the plugin loaded through the host, a fresh folder per test,
// and writers of the files the tests build.
#pragma once

#include "config/rig_config.hpp"
#include "core/error.hpp"
#include "host/plugin_host.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <yaml-cpp/yaml.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <unistd.h>
#include <vector>

namespace fs = std::filesystem;
using binocle::LentFrame;
using binocle::Source;

namespace {

inline const binocle::PluginRecord &replayRecord() {
    static binocle::PluginHost host(std::vector<std::string>{BINOCLE_BUILD_PLUGIN_DIR});
    static const binocle::PluginRecord &record = [] () -> const binocle::PluginRecord & {
        host.scan();
        return host.require("replay", BINOCLE_KIND_STEREO_SOURCE);
    }();
    return record;
}

// A fresh folder per test, removed afterwards.
class Replay : public ::testing::Test {
protected:
    void SetUp() override {
        const auto *info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir_ = fs::temp_directory_path() /
               ("binocle_replay_" + std::to_string(::getpid()) + "_" + info->name());
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override {
        std::error_code ec;
        if (!HasFailure()) fs::remove_all(dir_, ec);
    }

    fs::path path(const std::string &relative) const { return dir_ / relative; }

    std::unique_ptr<Source> open(const std::string &yaml) {
        auto src = std::make_unique<Source>(replayRecord(), binocle::paramsFromYaml(replayRecord(), yaml));
        src->start();
        return src;
    }

    // The message of the error that opening with `yaml` must raise.
    std::string openError(const std::string &yaml) {
        try {
            open(yaml);
        } catch (const binocle::Error &e) {
            return e.what();
        }
        ADD_FAILURE() << "opening succeeded: " << yaml;
        return {};
    }

    fs::path dir_;
};

// Random pixels, different for every seed.
inline cv::Mat noise(cv::Size size, int type, int seed) {
    cv::Mat m(size, type);
    cv::RNG rng(static_cast<uint64_t>(seed) + 1);
    rng.fill(m, cv::RNG::UNIFORM, 0, 256);
    return m;
}

inline void write(const fs::path &p, const cv::Mat &m) {
    fs::create_directories(p.parent_path());
    ASSERT_TRUE(cv::imwrite(p.string(), m)) << p;
}

inline void writeText(const fs::path &p, const std::string &text) {
    fs::create_directories(p.parent_path());
    std::ofstream(p, std::ios::binary) << text;
}

inline bool equal(const cv::Mat &a, const cv::Mat &b) {
    return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0;
}

// PFM written by hand, big-endian (positive scale), rows bottom to top.
inline void writePfmBigEndian(const fs::path &p, const cv::Mat &m) {
    ASSERT_EQ(m.type(), CV_32FC1);
    std::ofstream out(p, std::ios::binary);
    out << "Pf\n" << m.cols << " " << m.rows << "\n1.0\n";
    for (int v = m.rows - 1; v >= 0; --v)
        for (int u = 0; u < m.cols; ++u) {
            unsigned char b[4];
            std::memcpy(b, &m.at<float>(v, u), 4);
            const char be[4] = {static_cast<char>(b[3]), static_cast<char>(b[2]), static_cast<char>(b[1]),
                                static_cast<char>(b[0])};
            out.write(be, 4);
        }
}

inline YAML::Node metadataOf(const LentFrame &f) { return YAML::Load(f.metadata()); }

} // namespace
