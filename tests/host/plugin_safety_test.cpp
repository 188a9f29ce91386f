// SPDX-License-Identifier: MIT
// Loading that survives bad files: RTLD_NOW names a missing symbol; an isolated scan
// refuses files that crash or hang at load, with the signal or the timeout, and goes on;
// a lookup opens only the file it names; unsafe folders, files and relative entries of
// the search path are refused with the reason; matcher values and failed releases are
// checked at run.
#include "fixture_host.hpp"
#include "host/install_prefix.hpp"
#include "host/isolation.hpp"

#include <chrono>
#include <fstream>
#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>
#include <sys/stat.h>

namespace binocle::test {
namespace {

using ::testing::HasSubstr;

std::string unsafeFixture(const std::string &name) {
    return std::string(BINOCLE_TEST_UNSAFE_PLUGIN_DIR) + "/binocle_" + name + ".so";
}

std::string reasonFor(const PluginHost &host, const std::string &path) {
    for (const auto &r : host.refused())
        if (r.path == path) return r.reason;
    return "";
}

TEST(PluginSafety, UndefinedSymbolIsARefusalNamingTheSymbol) {
    PluginHost host(std::vector<std::string>{});
    try {
        host.load(unsafeFixture("undefined_symbol"));
        FAIL() << "a plugin with an undefined symbol was accepted";
    } catch (const Error &e) {
        EXPECT_THAT(e.what(), HasSubstr("cannot be loaded"));
        EXPECT_THAT(e.what(), HasSubstr("undefined symbol: binocle_fixture_symbol_nobody_defines"));
    }
}

TEST(PluginSafety, IsolatedScanRefusesCrashAndHangAtLoadAndGoesOn) {
    PluginHost host(std::vector<std::string>{BINOCLE_TEST_UNSAFE_PLUGIN_DIR, BINOCLE_TEST_PLUGIN_DIR});
    const auto t0 = std::chrono::steady_clock::now();
    host.scan(ScanMode::Isolated, 3000);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_LT(seconds, 20.0); // the 3 s of the hang, and a shared CI machine
    EXPECT_THAT(reasonFor(host, unsafeFixture("crash_at_load")),
                HasSubstr("crashed while loading (its code runs at load): killed by signal 11 (SIGSEGV)"));
    EXPECT_THAT(reasonFor(host, unsafeFixture("hang_at_load")),
                HasSubstr("still loading after 3000 ms (a library constructor hangs?); its examination was killed"));
    EXPECT_THAT(reasonFor(host, unsafeFixture("undefined_symbol")),
                HasSubstr("undefined symbol: binocle_fixture_symbol_nobody_defines"));
    // The listing went on: the fixtures of the next folder are all there.
    EXPECT_EQ(host.plugins().size(), fixtureHost().plugins().size());
    EXPECT_NE(host.find("mock_matcher", BINOCLE_KIND_MATCHER), nullptr);
}

// The case: a folder holding an undefined symbol, a crash and a hang at load.
TEST(PluginSafety, PluginsCommandListsTheThreeAsRefusedAndRunIgnoresThem) {
    const std::string path = std::string(BINOCLE_TEST_UNSAFE_PLUGIN_DIR) + ":" + BINOCLE_TEST_PLUGIN_DIR;
    auto timed = [](const std::string &p, ProcessResult &out) {
        const auto t0 = std::chrono::steady_clock::now();
        out = runBinocle({"plugins"}, p);
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    };
    ProcessResult r;
    // The hang costs its 5 s timeout, nothing more: compared with the same listing
    // without the three files, in the same test (CI machines are shared and slow).
    const double baseline = timed(BINOCLE_TEST_PLUGIN_DIR, r);
    const double seconds = timed(path, r);
    ASSERT_TRUE(r.exited) << "killed by signal " << r.signal;
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_LT(seconds - baseline, 10.0) << seconds << " s against " << baseline << " s without the three files";
    EXPECT_THAT(r.out, HasSubstr(unsafeFixture("undefined_symbol") + ": cannot be loaded: " + unsafeFixture("undefined_symbol") +
                                 ": undefined symbol: binocle_fixture_symbol_nobody_defines"));
    EXPECT_THAT(r.out, HasSubstr(unsafeFixture("crash_at_load") + ": crashed while loading (its code runs at load): killed by signal 11 (SIGSEGV)"));
    EXPECT_THAT(r.out, HasSubstr(unsafeFixture("hang_at_load") + ": still loading after 5000 ms"));
    EXPECT_THAT(r.out, HasSubstr("mock_matcher")); // the listing went on

    TempDir dir;
    writeText(dir.str("rig.yaml"), "source:\n  plugin: mock_source\nmatcher:\n  plugin: mock_matcher\noutputs:\n"
                                   "  disparity_png: false\n  disparity_color: false\n  cloud_ply: false\n");
    r = runBinocle({"run", dir.str("rig.yaml"), "--quiet"}, path);
    ASSERT_TRUE(r.exited) << "killed by signal " << r.signal;
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_THAT(r.out, HasSubstr("\"status\": \"ok\""));
}

TEST(PluginSafety, LookupOpensOnlyTheFileItNames) {
    PluginHost host(std::vector<std::string>{BINOCLE_TEST_UNSAFE_PLUGIN_DIR, BINOCLE_TEST_PLUGIN_DIR});
    const PluginRecord *r = host.lookup("mock_matcher", BINOCLE_KIND_MATCHER);
    ASSERT_NE(r, nullptr);
    EXPECT_EQ(r->path, fixturePath("mock_matcher"));
    EXPECT_EQ(host.plugins().size(), 1u);
    EXPECT_TRUE(host.refused().empty());
    EXPECT_EQ(host.lookup("mock_matcher", BINOCLE_KIND_STEREO_SOURCE), nullptr); // wrong kind
    EXPECT_EQ(host.lookup("not_there"), nullptr);
    EXPECT_EQ(host.plugins().size(), 1u);
    // A refused file is remembered with its reason.
    EXPECT_EQ(host.lookup("wrong_abi"), nullptr);
    EXPECT_THAT(reasonFor(host, fixturePath("wrong_abi")), HasSubstr("built for ABI version"));
}

TEST(PluginSafety, FoldersWritableByOthersAndRelativeEntriesAreRefused) {
    TempDir dir;
    const std::string open = dir.str("open");
    std::filesystem::create_directories(open);
    std::filesystem::copy_file(fixturePath("mock_matcher"), open + "/binocle_mock_matcher.so");
    ::chmod(open.c_str(), 0777);
    PluginHost host(std::vector<std::string>{open, "relative/plugins"});
    host.scan();
    EXPECT_TRUE(host.plugins().empty());
    EXPECT_THAT(reasonFor(host, open), HasSubstr("folder is writable by others than its owner and root (mode 777)"));
    EXPECT_THAT(reasonFor(host, "relative/plugins"), HasSubstr("relative search path entry"));
    EXPECT_EQ(host.lookup("mock_matcher"), nullptr);
}

TEST(PluginSafety, FilesWritableByOthersAreRefused) {
    TempDir dir;
    const std::string folder = dir.str("plugins");
    std::filesystem::create_directories(folder);
    ::chmod(folder.c_str(), 0755);
    const std::string file = folder + "/binocle_mock_matcher.so";
    std::filesystem::copy_file(fixturePath("mock_matcher"), file);
    ::chmod(file.c_str(), 0664);
    PluginHost host(std::vector<std::string>{folder});
    EXPECT_EQ(host.lookup("mock_matcher"), nullptr);
    EXPECT_THAT(reasonFor(host, file), HasSubstr("file is writable by others than its owner and root (mode 664)"));
    ::chmod(file.c_str(), 0644);
    PluginHost fixed(std::vector<std::string>{folder});
    EXPECT_NE(fixed.lookup("mock_matcher"), nullptr);
}

TEST(PluginSafety, NoBuildTreePathIsCompiledIn) {
    ::setenv("BINOCLE_PLUGIN_PATH", "/opt/example/plugins", 1);
    const auto path = PluginHost::defaultSearchPath();
    ::setenv("BINOCLE_PLUGIN_PATH", BINOCLE_BUILD_PLUGIN_DIR, 1);
    ASSERT_EQ(path.size(), 2u);
    EXPECT_EQ(path[0], "/opt/example/plugins");
    // The second entry is derived from this executable's location, not from the build.
    EXPECT_EQ(std::filesystem::path(path[1]).filename(), "plugins");
    EXPECT_NE(path[1], BINOCLE_BUILD_PLUGIN_DIR); // tests do not live in bin/
}

// A program that carries the framework but is not bin/binocle (the Python module inside
// python3) names its prefix: the plugins and the helper are looked for there, and only there.
TEST(PluginSafety, ANamedInstallPrefixLeadsToItsPluginsAndHelper) {
    namespace fs = std::filesystem;
    const fs::path prefix = fs::temp_directory_path() / ("binocle-prefix-" + std::to_string(::getpid()));
    fs::create_directories(prefix / "libexec/binocle");
    EXPECT_THROW(setInstallPrefix("relative/prefix"), Error);
    setInstallPrefix(prefix.string());
    ::setenv("BINOCLE_PLUGIN_PATH", "/opt/example/plugins", 1);
    const auto path = PluginHost::defaultSearchPath();
    ::setenv("BINOCLE_PLUGIN_PATH", BINOCLE_BUILD_PLUGIN_DIR, 1);
    EXPECT_EQ(path, (std::vector<std::string>{"/opt/example/plugins", (prefix / "lib/binocle/plugins").string()}));
    const char *helperEnv = std::getenv("BINOCLE_PLUGIN_HELPER");
    const std::string savedHelper = helperEnv ? helperEnv : "";
    ::unsetenv("BINOCLE_PLUGIN_HELPER");
    try {
        helperExecutable();
        ADD_FAILURE() << "a helper was found under a prefix that has none";
    } catch (const Error &e) {
        EXPECT_THAT(e.what(), HasSubstr("not installed under " + prefix.string()));
    }
    const fs::path helper = prefix / "libexec/binocle/binocle-plugin-helper";
    std::ofstream(helper.string()) << "#!/bin/sh\n";
    EXPECT_EQ(helperExecutable(), helper.string());
    if (!savedHelper.empty()) ::setenv("BINOCLE_PLUGIN_HELPER", savedHelper.c_str(), 1);
    setInstallPrefix("");
    EXPECT_FALSE(installPrefixIsSet());
    EXPECT_NE(installPrefix(), prefix.string());
    fs::remove_all(prefix);
}

// Captures what the host logs through spdlog's default logger while alive.
class LogCapture {
public:
    LogCapture() : previous_(spdlog::default_logger()) {
        auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(stream_);
        spdlog::set_default_logger(std::make_shared<spdlog::logger>("capture", sink));
        spdlog::set_level(spdlog::level::debug);
    }
    ~LogCapture() { spdlog::set_default_logger(previous_); }
    std::string text() const { return stream_.str(); }

private:
    std::ostringstream stream_;
    std::shared_ptr<spdlog::logger> previous_;
};

TEST(PluginValues, NonFiniteAndAbsurdDisparitiesAreMadeInvalidAndCounted) {
    for (const char *fault : {"inf", "nan", "huge"}) {
        LogCapture log;
        auto m = newInstance<Matcher>("faulty_matcher", BINOCLE_KIND_MATCHER, std::string("{fault: ") + fault + "}");
        cv::Mat left(20, 40, CV_8UC1, cv::Scalar(0));
        cv::Mat d = m->compute(left, left);
        EXPECT_EQ(cv::countNonZero(d == 4.0f), 400) << fault;             // the good half stays
        EXPECT_EQ(cv::countNonZero(d == BINOCLE_INVALID_DISPARITY), 400) << fault; // the bad half is invalid
        EXPECT_EQ(m->invalidatedDisparities(), 400u) << fault;
        m->compute(left, left);
        EXPECT_EQ(m->invalidatedDisparities(), 800u) << fault;
        EXPECT_THAT(log.text(), HasSubstr("matcher plugin 'faulty_matcher': 400 disparities not finite or beyond the image width"));
    }
    auto good = newInstance<Matcher>("faulty_matcher", BINOCLE_KIND_MATCHER, "{fault: none}");
    cv::Mat left(20, 40, CV_8UC1, cv::Scalar(0));
    good->compute(left, left);
    EXPECT_EQ(good->invalidatedDisparities(), 0u);
}

binocle_result failingRelease(binocle_source *, uint64_t) { return BINOCLE_ERR_INVALID_ARGUMENT; }
const char *releaseError(binocle_source *) { return "no such frame"; }

TEST(PluginValues, AFailedReleaseIsLogged) {
    LogCapture log;
    binocle_source_api api{};
    api.header.name = "leaky_source";
    api.release_frame = &failingRelease;
    api.last_error = &releaseError;
    binocle_stereo_frame f{};
    f.frame_id = 42;
    f.sequence = 7;
    { LentFrame lent(nullptr, &api, nullptr, f); }
    EXPECT_THAT(log.text(), HasSubstr("source plugin 'leaky_source': release_frame of frame 42 (sequence 7) failed "
                                      "(BINOCLE_ERR_INVALID_ARGUMENT): no such frame"));
}

} // namespace
} // namespace binocle::test
