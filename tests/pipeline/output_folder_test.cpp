// SPDX-License-Identifier: MIT
// Output folders are owned by one process at a time and never mixed: the lock of
// core/output_folder.hpp on its own, and `binocle run` racing another run or aimed at a
// recording.
#include "common/test_util.hpp"
#include "files/atomic_file.hpp"
#include "core/error.hpp"
#include "core/output_folder.hpp"
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
#include <unistd.h>

namespace fs = std::filesystem;

namespace binocle::test {
namespace {

using Clock = std::chrono::steady_clock;

std::string errorOf(const std::function<void()> &f) {
    try {
        f();
    } catch (const Error &e) {
        return e.what();
    }
    return "";
}

TEST(OutputFolder, ASecondOwnerIsRefusedNamingTheFolderAndTheOwnersPid) {
    TempDir dir;
    const std::string out = dir.str("out");
    {
        OutputFolder first(out, OutputClaim{OutputKind::Run, false, "binocle run"});
        EXPECT_TRUE(fs::exists(out + "/" + OutputFolder::kLockFile));
        const std::string why = errorOf([&] { OutputFolder second(out, OutputClaim{OutputKind::Run, false, "binocle run"}); });
        EXPECT_NE(why.find(out), std::string::npos) << why;
        EXPECT_NE(why.find("in use by process " + std::to_string(::getpid()) + " (binocle run)"), std::string::npos) << why;
    }
    // Released with its owner, and the lock file goes with it.
    EXPECT_FALSE(fs::exists(out + "/" + OutputFolder::kLockFile));
    EXPECT_NO_THROW(OutputFolder(out, OutputClaim{OutputKind::Run, false, "binocle run"}));
}

TEST(OutputFolder, AKilledOwnerLeavesNoStaleLock) {
    TempDir dir;
    const std::string out = dir.str("out");
    int ready[2];
    ASSERT_EQ(::pipe(ready), 0);
    const pid_t child = ::fork();
    if (child == 0) {
        OutputFolder held(out, OutputClaim{OutputKind::Run, false, "holder"});
        (void)!::write(ready[1], "x", 1);
        ::pause();
        ::_exit(0);
    }
    char c = 0;
    ASSERT_EQ(::read(ready[0], &c, 1), 1);
    const std::string why = errorOf([&] { OutputFolder(out, OutputClaim{OutputKind::Run, false, "binocle run"}); });
    EXPECT_NE(why.find("in use by process " + std::to_string(child) + " (holder)"), std::string::npos) << why;
    ::kill(child, SIGKILL);
    ::waitpid(child, nullptr, 0);
    // The lock file stays behind, but no lock: the folder is free again.
    EXPECT_NO_THROW(OutputFolder(out, OutputClaim{OutputKind::Run, false, "binocle run"}));
    ::close(ready[0]);
    ::close(ready[1]);
}

TEST(OutputFolder, AFolderHoldingAnotherKindIsRefusedUnlessForced) {
    TempDir dir;
    const std::string rec = dir.str("rec");
    fs::create_directories(rec + "/left");
    writeText(rec + "/frames.csv", "sequence,timestamp_left_ns,timestamp_right_ns,left,right\n");
    writeText(rec + "/summary.json", "{\"status\": \"complete\"}\n");
    EXPECT_EQ(outputKindOf(rec), OutputKind::Recording);
    const std::string why = errorOf([&] { OutputFolder(rec, OutputClaim{OutputKind::Run, false, "binocle run"}); });
    EXPECT_NE(why.find(rec + " holds a recording (frames.csv)"), std::string::npos) << why;
    EXPECT_NE(why.find("--force"), std::string::npos) << why;
    EXPECT_EQ(readTextFile(rec + "/summary.json"), "{\"status\": \"complete\"}\n");
    EXPECT_FALSE(fs::exists(rec + "/" + OutputFolder::kLockFile));
    // A lock-only claim is let in; the same kind is not, unless its command made the
    // folder (its marker): files that look like a recording may be anyone's.
    EXPECT_NO_THROW(OutputFolder(rec, OutputClaim{OutputKind::None, false, ""}));
    EXPECT_NE(errorOf([&] { OutputFolder(rec, OutputClaim{OutputKind::Recording, false, ""}); }), "");
    // Forced: what it held is gone, the folder is the run's (marked so).
    { OutputFolder forced(rec, OutputClaim{OutputKind::Run, true, "binocle run"}); }
    EXPECT_EQ(entriesOf(rec), std::vector<std::string>{});
    EXPECT_EQ(readTextFile(rec + "/" + OutputFolder::kMarkerFile), "run binocle run\n");
    EXPECT_EQ(outputKindOf(rec), OutputKind::Run);
    writeText(rec + "/frames.jsonl", "{}\n");
    EXPECT_NO_THROW(OutputFolder(rec, OutputClaim{OutputKind::Run, false, "binocle run"}));
    const std::string exp = dir.str("exp");
    fs::create_directories(exp);
    writeText(exp + "/results.json", "{}");
    const std::string why2 = errorOf([&] { OutputFolder(exp, OutputClaim{OutputKind::Run, false, "binocle run"}); });
    EXPECT_NE(why2.find("an experiment's results"), std::string::npos) << why2;
}

// Issue 35: a folder belongs to the command that made it. The user's own files (a
// results.csv), an MCAP recording and another command's folder are refused, naming the
// folder, what it holds and the flag; a folder a refused claim made goes again, marker too.
TEST(OutputFolder, AFolderBelongsToTheCommandThatMadeIt) {
    TempDir dir;
    const std::string mine = dir.str("mine");
    fs::create_directories(mine);
    writeText(mine + "/results.csv", "my,own\n1,2\n");
    std::string why = errorOf([&] { OutputFolder(mine, OutputClaim{OutputKind::Experiment, false, "binocle experiment"}); });
    EXPECT_NE(why.find("output folder " + mine + " holds an experiment's results (results.csv)"), std::string::npos) << why;
    EXPECT_NE(why.find("pass --force"), std::string::npos) << why;
    EXPECT_EQ(readTextFile(mine + "/results.csv"), "my,own\n1,2\n");
    writeText(mine + "/notes.txt", "x");
    fs::remove(mine + "/results.csv");
    why = errorOf([&] { OutputFolder(mine, OutputClaim{OutputKind::Design, false, "binocle design"}); });
    EXPECT_NE(why.find("holds files Binocle did not write there (notes.txt)"), std::string::npos) << why;
    // Python's functions are told force=True.
    why = errorOf([&] { OutputFolder(mine, OutputClaim{OutputKind::Run, false, "binocle.Rig.run", "force=True"}); });
    EXPECT_NE(why.find("pass force=True"), std::string::npos) << why;

    const std::string bag = dir.str("bag");
    fs::create_directories(bag);
    writeText(bag + "/bag_0.mcap", "x");
    writeText(bag + "/summary.json", "{}");
    EXPECT_EQ(outputKindOf(bag), OutputKind::Recording);
    why = errorOf([&] { OutputFolder(bag, OutputClaim{OutputKind::Run, false, "binocle run"}); });
    EXPECT_NE(why.find("holds a recording (an MCAP file: bag_0.mcap)"), std::string::npos) << why;

    const std::string made = dir.str("made");
    { OutputFolder run(made, OutputClaim{OutputKind::Run, false, "binocle run"}); writeText(made + "/frames.jsonl", "{}\n"); }
    why = errorOf([&] { OutputFolder(made, OutputClaim{OutputKind::Experiment, false, "binocle experiment"}); });
    EXPECT_NE(why.find("holds the output of a run (frames.jsonl), made by binocle run"), std::string::npos) << why;

    // A claim that wrote nothing takes back the folders it made, parents too.
    const std::string fresh = dir.str("fresh");
    { OutputFolder nothing(fresh + "/deeper/", OutputClaim{OutputKind::View, false, "binocle view"}); }
    EXPECT_FALSE(fs::exists(fresh));
}

TEST(OutputFolder, APlantedSymlinkAsLockFileIsNotFollowed) {
    TempDir dir;
    const std::string out = dir.str("out"), target = dir.str("victim");
    writeText(target, "precious\n");
    fs::create_directories(out);
    fs::create_symlink(target, out + "/" + OutputFolder::kLockFile);
    const std::string why = errorOf([&] { OutputFolder(out, OutputClaim{OutputKind::Run, false, "binocle run"}); });
    EXPECT_NE(why.find("lock file"), std::string::npos) << why;
    EXPECT_EQ(readTextFile(target), "precious\n");
}

TEST(AtomicFile, APlantedSymlinkUnderATemporaryNameIsNeverWrittenThrough) {
    TempDir dir;
    const std::string target = dir.str("victim");
    writeText(target, "precious\n");
    // The names the old scheme used: ".tmp-<pid>-<name>".
    fs::create_symlink(target, dir.str(".tmp-" + std::to_string(::getpid()) + "-summary.json"));
    writeFileAtomic(dir.str("summary.json"), "{}\n");
    EXPECT_EQ(readTextFile(dir.str("summary.json")), "{}\n");
    EXPECT_EQ(readTextFile(target), "precious\n");
    EXPECT_TRUE(fs::is_symlink(dir.str(".tmp-" + std::to_string(::getpid()) + "-summary.json")));
}

TEST(AtomicFile, AFolderInTheWayIsNamedNotReportedAsSuccess) {
    TempDir dir;
    fs::create_directories(dir.str("taken"));
    const std::string why = errorOf([&] { writeFileAtomic(dir.str("taken"), "x"); });
    EXPECT_NE(why.find("cannot write " + dir.str("taken") + ": rename failed: Is a directory (it is a folder; expected a file name)"),
              std::string::npos)
        << why;
    EXPECT_EQ(why.find("Success"), std::string::npos) << why;
    EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()), 1); // no temporary left
}

// ---- `binocle run` ------------------------------------------------------------------------------

std::string simRig() { return std::string(BINOCLE_SOURCE_DIR) + "/configs/rigs/sim-videre.yaml"; }

size_t lineCount(const std::string &path) {
    std::ifstream in(path);
    size_t n = 0;
    for (std::string line; std::getline(in, line);) ++n;
    return n;
}

TEST(RunOutputFolder, TwoRunsIntoOneFolderTheSecondIsRefusedAndTheFirstStaysWhole) {
    TempDir dir;
    const std::string out = dir.str("out"), log = dir.str("log");
    const pid_t pid = spawnCli({"run", simRig(), "--quiet", "--out", out, "--set", "source.frames=0"}, log);
    ASSERT_GT(pid, 0);
    const auto begin = Clock::now();
    while (lineCount(out + "/frames.jsonl") < 2 && Clock::now() - begin < std::chrono::seconds(60))
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
    const CommandResult second = runCli("run '" + simRig() + "' --quiet --frames 2 --out '" + out + "'");
    ::kill(pid, SIGINT);
    int status = 0;
    ::waitpid(pid, &status, 0);
    EXPECT_NE(second.exit_code, 0) << second.output;
    EXPECT_NE(second.output.find("output folder " + out + " is in use by process " + std::to_string(pid) + " (binocle run)"),
              std::string::npos)
        << second.output;
    ASSERT_TRUE(WIFEXITED(status)) << readTextFile(log);
    EXPECT_EQ(WEXITSTATUS(status), 128 + SIGINT) << readTextFile(log);
    // Only the first run's frames, every line whole.
    const auto summary = nlohmann::json::parse(readTextFile(out + "/summary.json"));
    EXPECT_EQ(summary["status"], "interrupted");
    std::ifstream in(out + "/frames.jsonl");
    size_t lines = 0;
    for (std::string line; std::getline(in, line); ++lines) EXPECT_NO_THROW(nlohmann::json::parse(line)) << line;
    EXPECT_EQ(static_cast<int64_t>(lines), summary["frame_count"].get<int64_t>());
    EXPECT_FALSE(fs::exists(out + "/" + OutputFolder::kLockFile));
}

TEST(RunOutputFolder, ARunIntoARecordingIsRefusedAndForceReplacesIt) {
    TempDir dir;
    const std::string rec = dir.str("rec");
    const CommandResult recorded = runCli("record '" + simRig() + "' --quiet --frames 2 --out '" + rec + "'");
    ASSERT_EQ(recorded.exit_code, 0) << recorded.output;
    const std::string summaryBefore = readTextFile(rec + "/summary.json");
    const CommandResult refused = runCli("run '" + simRig() + "' --quiet --frames 1 --out '" + rec + "'");
    EXPECT_NE(refused.exit_code, 0) << refused.output;
    EXPECT_NE(refused.output.find(rec + " holds a recording (frames.csv)"), std::string::npos) << refused.output;
    EXPECT_EQ(readTextFile(rec + "/summary.json"), summaryBefore);
    EXPECT_FALSE(fs::exists(rec + "/frames.jsonl"));
    const CommandResult forced = runCli("run '" + simRig() + "' --quiet --frames 1 --force --out '" + rec + "'");
    EXPECT_EQ(forced.exit_code, 0) << forced.output;
    EXPECT_FALSE(fs::exists(rec + "/frames.csv"));
    EXPECT_FALSE(fs::exists(rec + "/left"));
    EXPECT_EQ(lineCount(rec + "/frames.jsonl"), 1u);
    // A second run into a run's folder is as before: the folder is the same kind.
    const CommandResult again = runCli("run '" + simRig() + "' --quiet --frames 1 --out '" + rec + "'");
    EXPECT_EQ(again.exit_code, 0) << again.output;
}

TEST(RecordOutputFolder, ARecorderIntoAFolderAnotherProcessOwnsIsRefused) {
    TempDir dir;
    const std::string out = dir.str("rec");
    OutputFolder held(out, OutputClaim{OutputKind::None, false, "test"});
    const CommandResult r = runCli("record '" + simRig() + "' --quiet --frames 1 --out '" + out + "'");
    EXPECT_NE(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("is in use by process " + std::to_string(::getpid()) + " (test)"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(out + "/frames.csv"));
}

} // namespace
} // namespace binocle::test
