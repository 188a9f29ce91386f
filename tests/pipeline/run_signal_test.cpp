// SPDX-License-Identifier: MIT
// `binocle run` of an endless simulated rig stopped by SIGINT / SIGTERM: it ends within
// 5 s, exits 128 + signal, and leaves summary.json (status interrupted, the frame count),
// one frames.jsonl line per finished frame, and no temporary file.
#include "common/test_util.hpp"
#include "core/atomic_file.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <spawn.h>
#include <sys/wait.h>
#include <thread>

extern char **environ;

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
    const std::string cli = BINOCLE_CLI, log = dir.str("log");
    std::vector<std::string> args{cli, "run", rig, "--quiet", "--out", out, "--set", "source.frames=0"};
    std::vector<char *> argv;
    for (auto &a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, 1, 2);
    setenv("BINOCLE_PLUGIN_PATH", BINOCLE_BUILD_PLUGIN_DIR, 1);
    pid_t pid = 0;
    ASSERT_EQ(posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ), 0);
    posix_spawn_file_actions_destroy(&actions);
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

} // namespace
} // namespace binocle::test
