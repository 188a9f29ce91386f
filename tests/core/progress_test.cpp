// SPDX-License-Identifier: MIT
// The one progress display: what a line says, and when a periodic display prints.
#include "common/test_util.hpp"
#include "core/progress.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <thread>
#include <unistd.h>

namespace {

using binocle::Progress;

// Runs `body` with stderr sent to a file; returns what was written.
template <class F>
std::string captureStderr(F body) {
    binocle::test::TempDir dir;
    const std::string path = dir.str("stderr.txt");
    std::fflush(stderr);
    const int saved = ::dup(2);
    FILE *f = std::fopen(path.c_str(), "w");
    ::dup2(::fileno(f), 2);
    body();
    std::fflush(stderr);
    ::dup2(saved, 2);
    ::close(saved);
    std::fclose(f);
    std::ifstream in(path);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

TEST(Progress, LineShowsCountTotalAndDetail) {
    Progress p(Progress::Mode::Off, "frame", 10, std::chrono::milliseconds(1000));
    const std::string line = p.line(4, "test 3");
    EXPECT_NE(line.find("frame 4/10"), std::string::npos) << line;
    EXPECT_NE(line.find("[########------------]"), std::string::npos) << line;
    EXPECT_NE(line.find("test 3"), std::string::npos) << line;
    Progress open(Progress::Mode::Off, "frame", -1, std::chrono::milliseconds(1000));
    EXPECT_NE(open.line(7, "").find("frame 7 "), std::string::npos) << open.line(7, "");
}

TEST(Progress, PeriodicPrintsAtMostOncePerPeriodAndItsLastState) {
    const std::string out = captureStderr([] {
        Progress p(Progress::Mode::Periodic, "frame", 100, std::chrono::milliseconds(200));
        for (int i = 1; i <= 50; ++i) p.update(i); // well within one period: nothing yet
        std::this_thread::sleep_for(std::chrono::milliseconds(250));
        p.update(51); // the period is over: one line
        p.update(52); // pending
        p.finish();   // the last state, once
    });
    EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 2) << out;
    EXPECT_NE(out.find("frame 51/100"), std::string::npos) << out;
    EXPECT_NE(out.find("frame 52/100"), std::string::npos) << out;
    EXPECT_EQ(out.find('\r'), std::string::npos) << out; // no terminal control in a file
}

TEST(Progress, OffPrintsNothing) {
    const std::string out = captureStderr([] {
        Progress p(false, "frame", 3);
        for (int i = 1; i <= 3; ++i) p.update(i);
        p.finish("done");
    });
    EXPECT_EQ(out, "");
}

TEST(Progress, LiveRewritesOneLine) {
    const std::string out = captureStderr([] {
        Progress p(Progress::Mode::Live, "test", 2, std::chrono::milliseconds(0));
        p.update(1);
        p.update(2);
        p.finish();
    });
    EXPECT_EQ(std::count(out.begin(), out.end(), '\r'), 2) << out;
    EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 1) << out;
}

} // namespace
