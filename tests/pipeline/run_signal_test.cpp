// SPDX-License-Identifier: MIT
// `binocle run` of an endless simulated rig stopped by SIGINT / SIGTERM / SIGHUP: it ends within
// 5 s, exits 128 + signal, and leaves summary.json (status interrupted, the frame count),
// one frames.jsonl line per finished frame, and no temporary file.
#include "common/test_util.hpp"
#include "files/atomic_file.hpp"
#include "spawn_cli.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sys/wait.h>
#include <thread>

namespace binocle::test {
namespace {

using Clock = std::chrono::steady_clock;

size_t lineCount(const std::string &path) {
    std::ifstream in(path);
    size_t n = 0;
    for (std::string line; std::getline(in, line);) ++n;
    return n;
}

void stopWith(int sig) {
    TempDir dir;
    const std::string out = dir.str("out"), rig = std::string(BINOCLE_SOURCE_DIR) + "/configs/rigs/sim-videre.yaml";
    const std::string log = dir.str("log");
    const pid_t pid = spawnCli({"run", rig, "--quiet", "--out", out, "--set", "source.frames=0"}, log);
    ASSERT_GT(pid, 0);
    // Wait for a few finished frames (the machine may be busy: up to 60 s).
    const auto begin = Clock::now();
    while (lineCount(out + "/frames.jsonl") < 3 && Clock::now() - begin < std::chrono::seconds(60))
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
    ASSERT_GE(lineCount(out + "/frames.jsonl"), 3u) << readTextFile(log);
    const auto t0 = Clock::now();
    ASSERT_EQ(kill(pid, sig), 0);
    int status = 0;
    pid_t done = 0;
    while ((done = waitpid(pid, &status, WNOHANG)) == 0 && Clock::now() - t0 < std::chrono::seconds(5))
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    if (done == 0) {
        kill(pid, SIGKILL);
        waitpid(pid, &status, 0);
        FAIL() << "binocle run did not stop within 5 s of signal " << sig;
    }
    ASSERT_TRUE(WIFEXITED(status)) << readTextFile(log);
    EXPECT_EQ(WEXITSTATUS(status), 128 + sig) << readTextFile(log);
    const auto summary = nlohmann::json::parse(readTextFile(out + "/summary.json"));
    EXPECT_EQ(summary["status"], "interrupted");
    EXPECT_GE(summary["frame_count"].get<int64_t>(), 3);
    EXPECT_EQ(static_cast<size_t>(summary["frame_count"].get<int64_t>()), lineCount(out + "/frames.jsonl"));
    for (const auto &e : std::filesystem::directory_iterator(out))
        EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
    // Every frame in frames.jsonl has its outputs.
    EXPECT_TRUE(std::filesystem::exists(out + "/cloud_000000.ply"));
}

TEST(RunSignal, SigintStopsAnEndlessRunCleanly) { stopWith(SIGINT); }
TEST(RunSignal, SigtermStopsAnEndlessRunCleanly) { stopWith(SIGTERM); }
// A closed terminal or a dropped SSH session: like SIGTERM, not a death without summary.
TEST(RunSignal, SighupStopsAnEndlessRunCleanly) { stopWith(SIGHUP); }

} // namespace
} // namespace binocle::test
