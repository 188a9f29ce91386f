// SPDX-License-Identifier: MIT
// `binocle plugin-check` as an author runs it: the mock fixtures pass, every broken
// fixture fails with its reason (and the battery goes on past a crash or a hang), and the
// JUnit report says the same.
#include "conformance/kit.hpp"
#include "host/fixture_host.hpp"
#include "host/plugin_kinds.hpp"

#include <set>

namespace binocle::conformance {
// The list generated from cases_<kind>.cpp (framework/CMakeLists.txt).
std::vector<std::pair<const char *, void (*)(Battery &)>> familiesByFile();
} // namespace binocle::conformance

namespace binocle::test {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

ProcessResult check(const std::vector<std::string> &args) {
    std::vector<std::string> all{"plugin-check"};
    all.insert(all.end(), args.begin(), args.end());
    return runBinocle(all, BINOCLE_TEST_PLUGIN_DIR);
}

void expectFailure(const ProcessResult &r, const std::string &line) {
    ASSERT_TRUE(r.exited) << "plugin-check was killed by signal " << r.signal << "\n" << r.err;
    EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
    EXPECT_THAT(r.out, HasSubstr(line)) << r.err;
}

TEST(PluginCheck, EveryKindHasItsFamilyOfCases) {
    std::set<std::string> families;
    for (const auto &[name, cases] : conformance::familiesByFile()) {
        EXPECT_NE(pluginKindNamed(name), nullptr) << "cases_" << name << ".cpp names no plugin kind";
        EXPECT_NE(cases, nullptr) << name;
        families.insert(name);
    }
    for (const PluginKind *k : pluginKinds()) EXPECT_EQ(families.count(k->name), 1u) << k->name << " has no cases_" << k->name << ".cpp";
}

TEST(PluginCheck, WorkingFixturesOfEveryKindPass) {
    for (const char *name : {"mock_matcher", "c_matcher", "mock_source", "mock_transform", "mock_evaluator", "frozen_source"}) {
        const ProcessResult r = check({name});
        ASSERT_TRUE(r.exited) << name << "\n" << r.err;
        EXPECT_EQ(r.exit_code, 0) << name << "\n" << r.out << r.err;
        EXPECT_THAT(r.out, Not(HasSubstr("FAIL"))) << name;
    }
}

TEST(PluginCheck, SourceCasesCoverTheLendingRules) {
    const ProcessResult r = check({"mock_source", "--set", "frames=5"});
    EXPECT_EQ(r.exit_code, 0) << r.out;
    for (const char *c : {"PASS  create_destroy", "PASS  grab_before_start", "PASS  lend_release_accounting: 4 frames lent at once",
                          "PASS  release_from_another_thread", "PASS  busy", "PASS  end_of_stream: END_OF_STREAM after 5 frames"})
        EXPECT_THAT(r.out, HasSubstr(c));
}

TEST(PluginCheck, ThrowingMatcherFailsWithItsMessage) {
    expectFailure(check({"throws"}), "FAIL  compute_in_host_buffers: compute on a textured 320x240 pair failed "
                                     "(BINOCLE_ERR_INTERNAL: deliberate failure from throws plugin)");
}

TEST(PluginCheck, CrashAndHangInComputeFailTheirCasesAndTheBatteryGoesOn) {
    ProcessResult r = check({"faulty_matcher"});
    expectFailure(r, "FAIL  compute_in_host_buffers: crashed: killed by signal 11 (SIGSEGV)");
    EXPECT_THAT(r.out, HasSubstr("PASS  create_destroy")); // the cases around it ran
    r = check({"faulty_matcher", "--set", "fault=hang", "--timeout-ms", "3000"});
    expectFailure(r, "FAIL  compute_in_host_buffers: did not finish within 3000 ms (a call hangs?); killed");
    r = check({"faulty_matcher", "--set", "fault=nan"});
    expectFailure(r, "disparities are not finite (write BINOCLE_INVALID_DISPARITY instead)");
}

TEST(PluginCheck, WritesOutsideTheHostsBuffersAreCaught) {
    expectFailure(check({"overrun_matcher"}), "FAIL  compute_in_host_buffers: crashed: killed by signal 11 (SIGSEGV)");
    expectFailure(check({"overrun_matcher", "--set", "target=left"}), "FAIL  compute_in_host_buffers: crashed: killed by signal 11");
    expectFailure(check({"garbage_matcher"}), "changed the host's disparity image description instead of writing into it");
    expectFailure(check({"garbage_transform"}), "apply returned a garbage cloud");
}

TEST(PluginCheck, BrokenSourcesFail) {
    expectFailure(check({"throws_source"}), "deliberate failure from throws plugin");
    expectFailure(check({"garbage_source"}), "FAIL  lend_release_accounting: grab lent an invalid image");
}

TEST(PluginCheck, EveryFixtureTheHostRefusesFailsAtLoadWithTheSameReason) {
    ASSERT_GE(fixtureHost().refused().size(), 10u);
    for (const auto &refusal : fixtureHost().refused())
        expectFailure(check({refusal.path}), "FAIL  load: " + refusal.reason);
}

TEST(PluginCheck, FilesWhoseCodeFailsAtLoadFailWithTheSignalOrTheTimeout) {
    const std::string unsafe = std::string(BINOCLE_TEST_UNSAFE_PLUGIN_DIR) + "/binocle_";
    expectFailure(check({unsafe + "crash_at_load.so"}), "FAIL  load: crashed while loading (its code runs at load): killed by signal 11 (SIGSEGV)");
    expectFailure(check({unsafe + "hang_at_load.so", "--timeout-ms", "3000"}), "FAIL  load: still loading after 3000 ms");
    expectFailure(check({unsafe + "undefined_symbol.so"}), "undefined symbol: binocle_fixture_symbol_nobody_defines");
}

TEST(PluginCheck, WritesAJUnitReport) {
    TempDir dir;
    const std::string xml = dir.str("report.xml");
    const ProcessResult r = check({"faulty_matcher", "--junit", xml});
    EXPECT_EQ(r.exit_code, 1);
    const std::string text = readAll(xml);
    EXPECT_THAT(text, HasSubstr("<testsuite name=\"plugin_check.matcher.faulty_matcher\""));
    EXPECT_THAT(text, HasSubstr("<testcase classname=\"plugin_check.matcher.faulty_matcher\" name=\"create_destroy\""));
    EXPECT_THAT(text, HasSubstr("name=\"compute_in_host_buffers\""));
    EXPECT_THAT(text, HasSubstr("<failure message=\"crashed: killed by signal 11 (SIGSEGV)\"/>"));
}

TEST(PluginCheck, AnUnknownNameSaysWhereItLooked) {
    const ProcessResult r = check({"not_a_plugin"});
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_THAT(r.err, HasSubstr("no file binocle_not_a_plugin.so in the search path (" BINOCLE_TEST_PLUGIN_DIR));
}


TEST(PluginCheck, AnUnknownOrBadSetIsAUsageErrorNamingTheKey) {
    // Before: 6 of 9 cases skipped and "0 failed", exit 0, for a key the plugin lacks.
    ProcessResult r = check({"mock_matcher", "--set", "nonsense=1"});
    ASSERT_TRUE(r.exited) << r.err;
    EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
    EXPECT_THAT(r.err, HasSubstr("--set nonsense=1 refused"));
    EXPECT_THAT(r.err, HasSubstr("nonsense"));
    EXPECT_THAT(r.out, Not(HasSubstr("PASS  compute")));
    r = check({"mock_matcher", "--set", "disparity_px=-3"});
    EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
    EXPECT_THAT(r.err, HasSubstr("disparity_px"));
    r = check({"mock_matcher", "--set", "mode=sideways"});
    EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
    EXPECT_THAT(r.err, HasSubstr("mode"));
    r = check({"mock_matcher", "--set", "=1"});
    EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
}

TEST(PluginCheck, SkippedCasesAreNeverReadAsAPass) {
    // The mock source ends its stream; frames=0 makes it end at once: cases that need a
    // frame are skipped, and the summary says that they checked nothing.
    const ProcessResult r = check({"mock_source", "--set", "frames=0"});
    ASSERT_TRUE(r.exited) << r.err;
    EXPECT_THAT(r.out, HasSubstr("SKIP  "));
    EXPECT_THAT(r.out, HasSubstr("did not run and checked nothing: not a full pass"));
    const ProcessResult full = check({"mock_matcher"});
    EXPECT_THAT(full.out, HasSubstr(" 0 failed, 0 skipped\n"));
    EXPECT_THAT(full.out, Not(HasSubstr("not a full pass")));
}

} // namespace
} // namespace binocle::test
