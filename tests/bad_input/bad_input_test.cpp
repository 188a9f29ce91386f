// SPDX-License-Identifier: MIT
// The bad-input corpus (tests/bad_input/<case>/): each case runs the real `binocle`
// command on bad input and checks the exit status and the error text, that it ends
// in time (a hang guard) and, outside sanitizer builds, within 1 GiB.
#include "bad_bags.hpp"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>
#include <vector>

namespace fs = std::filesystem;

namespace {

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kSanitized = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kSanitized = true;
#else
constexpr bool kSanitized = false;
#endif
#else
constexpr bool kSanitized = false;
#endif

// A hang guard, not a speed claim: every case ends in well under a second when the
// machine is idle; the limit leaves room for a loaded machine and sanitizers.
constexpr int kTimeLimitSeconds = kSanitized ? 120 : 30;
constexpr long kMaxRssKiB = 1024L * 1024L; // 1 GiB

const fs::path kCases = fs::path(BINOCLE_SOURCE_DIR) / "tests" / "bad_input";

std::vector<std::string> caseNames() {
    std::vector<std::string> names;
    for (const auto &e : fs::directory_iterator(kCases))
        if (e.is_directory() && fs::exists(e.path() / "cmd")) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
}

std::vector<std::string> linesOf(const fs::path &file) {
    std::vector<std::string> lines;
    std::ifstream in(file);
    for (std::string line; std::getline(in, line);)
        if (!line.empty() && line[0] != '#') lines.push_back(line);
    return lines;
}

std::string readAll(const fs::path &file) {
    std::ifstream in(file, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

struct Placeholders {
    std::string caseDir, tmp, out;
    std::string apply(std::string s) const {
        const std::pair<std::string, std::string> subs[] = {{"{case}", caseDir},
                                                            {"{tmp}", tmp},
                                                            {"{out}", out},
                                                            {"{source}", BINOCLE_SOURCE_DIR},
                                                            {"{opencv}", BINOCLE_OPENCV_DATA_DIR}};
        for (const auto &[k, v] : subs)
            for (size_t p; (p = s.find(k)) != std::string::npos;) s.replace(p, k.size(), v);
        return s;
    }
};

std::vector<std::string> words(const std::string &line) {
    std::istringstream in(line);
    std::vector<std::string> w;
    for (std::string x; in >> x;) w.push_back(x);
    return w;
}

void generate(const std::string &line, const Placeholders &ph) {
    const auto w = words(ph.apply(line));
    ASSERT_FALSE(w.empty());
    if (w[0] == "png") {
        ASSERT_EQ(w.size(), 4u) << line;
        cv::Mat m(std::stoi(w[3]), std::stoi(w[2]), CV_8UC1, cv::Scalar(128));
        fs::create_directories(fs::path(w[1]).parent_path()); // left/ of a recording
        ASSERT_TRUE(cv::imwrite(w[1], m)) << line;
    } else if (w[0] == "truncate") {
        ASSERT_EQ(w.size(), 4u) << line;
        std::string bytes = readAll(w[1]);
        ASSERT_GT(bytes.size(), std::stoul(w[3])) << line;
        std::ofstream(w[2], std::ios::binary) << bytes.substr(0, std::stoul(w[3]));
    } else if (w[0] == "truncate_close") { // cut short, then given back a JPEG end marker
        ASSERT_EQ(w.size(), 4u) << line;
        std::string bytes = readAll(w[1]);
        ASSERT_GT(bytes.size(), std::stoul(w[3])) << line;
        std::ofstream(w[2], std::ios::binary) << bytes.substr(0, std::stoul(w[3])) << "\xFF\xD9";
    } else if (w[0] == "big_yaml") {
        ASSERT_EQ(w.size(), 3u) << line;
        std::ofstream out(w[1], std::ios::binary);
        out << "name: \"" << std::string(std::stoul(w[2]), 'x') << "\"\nsource: {plugin: sim}\nmatcher: {plugin: bm}\n";
    } else if (w[0] == "copy") {
        ASSERT_EQ(w.size(), 3u) << line;
        fs::copy(w[1], w[2], fs::copy_options::recursive);
    } else if (w[0] == "nested_yaml") { // nested_yaml PATH DEPTH: a rig whose source is lists DEPTH deep
        ASSERT_EQ(w.size(), 3u) << line;
        const size_t depth = std::stoul(w[2]);
        std::ofstream(w[1], std::ios::binary) << "name: deep\nsource: " << std::string(depth, '[') << std::string(depth, ']')
                                              << "\nmatcher: {plugin: bm}\n";
    } else if (w[0] == "empty") { // a file of 0 bytes, its folder made
        ASSERT_EQ(w.size(), 2u) << line;
        fs::create_directories(fs::path(w[1]).parent_path());
        std::ofstream(w[1], std::ios::binary);
    } else if (w[0] == "fifo") {
        ASSERT_EQ(w.size(), 2u) << line;
        fs::create_directories(fs::path(w[1]).parent_path());
        ASSERT_EQ(::mkfifo(w[1].c_str(), 0644), 0) << line;
    } else if (w[0] == "symlink") { // symlink TARGET LINK
        ASSERT_EQ(w.size(), 3u) << line;
        fs::create_directories(fs::path(w[2]).parent_path());
        fs::create_symlink(w[1], w[2]);
    } else if (w[0] == "bag") { // bag DIR VARIANT (bad_bags.hpp)
        ASSERT_EQ(w.size(), 3u) << line;
        writeBadBag(w[1], w[2]);
    } else {
        FAIL() << "unknown generator: " << line;
    }
}

struct Outcome {
    int exitCode = -1;
    bool timedOut = false;
    long maxRssKiB = 0;
    double seconds = 0;
    std::string out, err;
};

Outcome runCli(const std::vector<std::string> &args, const fs::path &dir) {
    const fs::path outFile = dir / "stdout.txt", errFile = dir / "stderr.txt";
    const auto start = std::chrono::steady_clock::now();
    const pid_t pid = ::fork();
    if (pid == 0) {
        const int o = ::open(outFile.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        const int e = ::open(errFile.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        ::dup2(o, 1);
        ::dup2(e, 2);
        std::vector<char *> argv{const_cast<char *>(BINOCLE_CLI)};
        for (const auto &a : args) argv.push_back(const_cast<char *>(a.c_str()));
        argv.push_back(nullptr);
        ::execv(BINOCLE_CLI, argv.data());
        ::_exit(127);
    }
    Outcome r;
    int status = 0;
    struct rusage usage {};
    while (true) {
        const pid_t done = ::wait4(pid, &status, WNOHANG, &usage);
        if (done == pid) break;
        if (std::chrono::steady_clock::now() - start > std::chrono::seconds(kTimeLimitSeconds)) {
            ::kill(pid, SIGKILL);
            ::wait4(pid, &status, 0, &usage);
            r.timedOut = true;
            break;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    r.maxRssKiB = usage.ru_maxrss;
    r.out = readAll(outFile);
    r.err = readAll(errFile);
    return r;
}

class BadInput : public testing::TestWithParam<std::string> {};

TEST_P(BadInput, ClearErrorInTimeNothingLost) {
    const fs::path caseDir = kCases / GetParam();
    const fs::path tmp = fs::temp_directory_path() / ("binocle-bad-input-" + GetParam() + "-" + std::to_string(::getpid()));
    fs::remove_all(tmp);
    fs::create_directories(tmp);
    // The case runs from a copy, with the placeholders of its text files filled in: the
    // source tree is never written to, and a rig can name {tmp} or {source}.
    const fs::path work = tmp / "case";
    fs::copy(caseDir, work, fs::copy_options::recursive);
    const Placeholders ph{work.string(), tmp.string(), (tmp / "out").string()};
    for (const auto &e : fs::recursive_directory_iterator(work)) {
        const std::string ext = e.path().extension().string();
        if (!e.is_regular_file() || (ext != ".yaml" && ext != ".yml" && ext != ".txt" && ext != ".csv")) continue;
        const std::string text = readAll(e.path());
        const std::string filled = ph.apply(text);
        if (filled != text) std::ofstream(e.path(), std::ios::binary) << filled;
    }
    if (fs::exists(caseDir / "generate"))
        for (const auto &line : linesOf(caseDir / "generate")) {
            generate(line, ph);
            if (HasFatalFailure()) return;
        }
    std::vector<std::string> args;
    for (const auto &line : linesOf(caseDir / "cmd")) args.push_back(ph.apply(line));
    const fs::path logs = tmp / "logs";
    fs::create_directories(logs);
    const Outcome r = runCli(args, logs);
    SCOPED_TRACE("binocle " + [&] {
        std::string s;
        for (const auto &a : args) s += a.size() > 200 ? a.substr(0, 200) + "... " : a + " ";
        return s;
    }() + "\nstderr:\n" + r.err.substr(0, 4000));
    EXPECT_FALSE(r.timedOut) << "no answer within " << kTimeLimitSeconds << " s";
    if (!kSanitized) EXPECT_LE(r.maxRssKiB, kMaxRssKiB) << "peak memory " << r.maxRssKiB / 1024 << " MiB";
    for (const auto &line : linesOf(caseDir / "expect")) {
        const std::string text = ph.apply(line);
        if (text.rfind("exit ", 0) == 0) {
            EXPECT_EQ(r.exitCode, std::stoi(text.substr(5)));
        } else if (text.rfind("stderr: ", 0) == 0) {
            EXPECT_NE(r.err.find(text.substr(8)), std::string::npos) << "expected in stderr: " << text.substr(8);
        } else if (text.rfind("exists: ", 0) == 0) {
            EXPECT_TRUE(fs::exists(text.substr(8))) << text;
        } else if (text.rfind("absent: ", 0) == 0) {
            EXPECT_FALSE(fs::exists(text.substr(8))) << text;
        } else {
            ADD_FAILURE() << "unknown line in expect: " << line;
        }
    }
    // No raw terminal escape: whatever a file holds reaches the log escaped (issue 35).
    EXPECT_EQ(r.err.find('\x1b'), std::string::npos) << "a raw ESC in the error output";
    // No crash or sanitizer report, whatever the exit status.
    EXPECT_EQ(r.err.find("terminate called"), std::string::npos);
    EXPECT_EQ(r.err.find("Sanitizer"), std::string::npos);
    EXPECT_EQ(r.err.find("runtime error:"), std::string::npos);
    if (!HasFailure()) fs::remove_all(tmp);
}

INSTANTIATE_TEST_SUITE_P(Corpus, BadInput, testing::ValuesIn(caseNames()),
                         [](const testing::TestParamInfo<std::string> &i) {
                             std::string n = i.param;
                             std::replace_if(n.begin(), n.end(), [](char c) { return !std::isalnum(static_cast<unsigned char>(c)); }, '_');
                             return n;
                         });

} // namespace
