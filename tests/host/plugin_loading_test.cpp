// SPDX-License-Identifier: MIT
// PluginHost over the fixture plugins: the working ones are accepted with their tables
// read right, and every broken one is refused, before any of its entries runs, with a
// reason that names what is wrong.
#include "fixture_host.hpp"

#include <algorithm>

namespace binocle::test {
namespace {

using ::testing::HasSubstr;

TEST(PluginLoading, AcceptsTheWorkingFixturesWithTheirKinds) {
    const std::vector<std::pair<std::string, int32_t>> expected = {
        {"mock_source", BINOCLE_KIND_STEREO_SOURCE},   {"mock_matcher", BINOCLE_KIND_MATCHER},
        {"mock_transform", BINOCLE_KIND_CLOUD_TRANSFORM}, {"mock_evaluator", BINOCLE_KIND_EVALUATOR},
        {"c_matcher", BINOCLE_KIND_MATCHER},           {"throws", BINOCLE_KIND_MATCHER},
        {"throws_source", BINOCLE_KIND_STEREO_SOURCE}, {"garbage_source", BINOCLE_KIND_STEREO_SOURCE},
        {"garbage_matcher", BINOCLE_KIND_MATCHER},     {"garbage_transform", BINOCLE_KIND_CLOUD_TRANSFORM},
        {"faulty_matcher", BINOCLE_KIND_MATCHER},      {"frozen_matcher", BINOCLE_KIND_MATCHER},
        {"faulty_source", BINOCLE_KIND_STEREO_SOURCE}, {"faulty_transform", BINOCLE_KIND_CLOUD_TRANSFORM},
        {"faulty_evaluator", BINOCLE_KIND_EVALUATOR},
        {"overrun_matcher", BINOCLE_KIND_MATCHER},
        {"frozen_source", BINOCLE_KIND_STEREO_SOURCE}, {"future_matcher", BINOCLE_KIND_MATCHER}};
    for (const auto &[name, kind] : expected) {
        const PluginRecord *r = fixtureHost().find(name, kind);
        ASSERT_NE(r, nullptr) << name << " was not accepted; refusal: " << refusalOf(name);
        EXPECT_EQ(r->path, fixturePath(name));
        EXPECT_EQ(r->abi_version, BINOCLE_ABI_VERSION);
        if (name == "future_matcher") continue; // API 2, version 2.0.0: see abi_evolution_test
        EXPECT_EQ(r->api_version, BINOCLE_API_VERSION);
        EXPECT_EQ(r->version, "1.0.0");
        EXPECT_FALSE(r->description.empty());
        EXPECT_TRUE(r->library);
    }
    EXPECT_EQ(fixtureHost().plugins().size(), expected.size());
}

TEST(PluginLoading, RefusesExactlyTheBrokenFixtures) {
    std::vector<std::string> refused;
    for (const auto &r : fixtureHost().refused()) {
        refused.push_back(std::filesystem::path(r.path).filename().string());
        EXPECT_EQ(std::filesystem::path(r.path).parent_path(), std::filesystem::path(BINOCLE_TEST_PLUGIN_DIR));
        EXPECT_FALSE(r.reason.empty()) << r.path;
    }
    std::sort(refused.begin(), refused.end());
    EXPECT_EQ(refused, (std::vector<std::string>{"binocle_bad_default.so", "binocle_bad_name.so", "binocle_bad_params.so",
                                                 "binocle_bad_setting_name.so", "binocle_duplicate_setting.so", "binocle_init_null.so",
                                                 "binocle_init_throws.so", "binocle_mock_matcher_duplicate.so",
                                                 "binocle_no_init.so", "binocle_null_entries.so",
                                                 "binocle_short_table.so", "binocle_small_header.so",
                                                 "binocle_unknown_kind.so", "binocle_wrong_abi.so"}));
}

TEST(PluginLoading, WrongAbiNamesBothVersions) {
    const std::string reason = refusalOf("wrong_abi");
    EXPECT_THAT(reason, HasSubstr("ABI version " + std::to_string(BINOCLE_ABI_VERSION + 1)));
    EXPECT_THAT(reason, HasSubstr("this host speaks ABI version " + std::to_string(BINOCLE_ABI_VERSION)));
    EXPECT_EQ(fixtureHost().find("wrong_abi"), nullptr);
}

TEST(PluginLoading, LoadOfAWrongAbiFileNamesTheFileAndBothVersions) {
    PluginHost host(std::vector<std::string>{});
    try {
        host.load(fixturePath("wrong_abi"));
        FAIL() << "wrong_abi was accepted";
    } catch (const Error &e) {
        EXPECT_THAT(e.what(), HasSubstr(fixturePath("wrong_abi")));
        EXPECT_THAT(e.what(), HasSubstr("ABI version " + std::to_string(BINOCLE_ABI_VERSION + 1)));
        EXPECT_THAT(e.what(), HasSubstr("ABI version " + std::to_string(BINOCLE_ABI_VERSION)));
    }
    EXPECT_TRUE(host.plugins().empty());
}

TEST(PluginLoading, NoInitNamesTheMissingSymbol) {
    EXPECT_THAT(refusalOf("no_init"), HasSubstr("no init symbol '" BINOCLE_PLUGIN_INIT_SYMBOL "'"));
}

TEST(PluginLoading, InitReturningNullIsRefused) {
    EXPECT_THAT(refusalOf("init_null"), HasSubstr("init returned no table"));
}

TEST(PluginLoading, NullMandatoryEntryIsNamed) {
    EXPECT_THAT(refusalOf("null_entries"), HasSubstr("leaves mandatory entries NULL: compute"));
}

TEST(PluginLoading, StructSizeSmallerThanTheHeaderIsRefused) {
    const std::string reason = refusalOf("small_header");
    EXPECT_THAT(reason, HasSubstr("table size 8"));
    EXPECT_THAT(reason, HasSubstr("smaller than the plugin header (" + std::to_string(sizeof(binocle_plugin_header))));
}

TEST(PluginLoading, StructSizeSmallerThanTheKindsTableIsRefused) {
    const std::string reason = refusalOf("short_table");
    EXPECT_THAT(reason, HasSubstr("table size " + std::to_string(sizeof(binocle_plugin_header))));
    EXPECT_THAT(reason, HasSubstr("smaller than the source table"));
    EXPECT_THAT(reason, HasSubstr(std::to_string(sizeof(binocle_source_api)) + " bytes"));
}

TEST(PluginLoading, ANameThatIsNotTheFileNameIsRefused) {
    EXPECT_THAT(refusalOf("mock_matcher_duplicate"),
                HasSubstr("declares the name 'mock_matcher' but its file is binocle_mock_matcher_duplicate.so (the file of "
                          "plugin <name> must be binocle_<name>.so)"));
    const PluginRecord *kept = fixtureHost().find("mock_matcher");
    ASSERT_NE(kept, nullptr);
    EXPECT_EQ(kept->path, fixturePath("mock_matcher"));
    EXPECT_EQ(kept->version, "1.0.0"); // not the duplicate's 9.9.9
}

TEST(PluginLoading, InitThrowingIsRefusedWithoutTerminating) {
    EXPECT_THAT(refusalOf("init_throws"), HasSubstr("init symbol threw an exception"));
}

TEST(PluginLoading, InvalidNameIsRefused) {
    EXPECT_THAT(refusalOf("bad_name"), HasSubstr("invalid plugin name 'Bad-Name' (expected [a-z0-9_]+)"));
}

TEST(PluginLoading, UnknownKindIsRefused) { EXPECT_THAT(refusalOf("unknown_kind"), HasSubstr("unknown plugin kind 99")); }

TEST(PluginLoading, GarbageSettingsTableIsRefused) {
    EXPECT_THAT(refusalOf("bad_params"), HasSubstr("garbage settings table (count -1)"));
}

TEST(PluginLoading, SettingsTableProblemsNameTheSettingAndTheReason) {
    EXPECT_THAT(refusalOf("duplicate_setting"),
                HasSubstr("plugin 'duplicate_setting' declares setting #1 'window_px': the name is declared twice (also setting #0)"));
    EXPECT_THAT(refusalOf("bad_default"), HasSubstr("setting #1 'window_px': default '4' is not odd"));
    EXPECT_THAT(refusalOf("bad_setting_name"),
                HasSubstr("setting #1 'Window-Size': invalid name (expected [a-z0-9_]+, e.g. window_px)"));
}

TEST(PluginLoading, DefaultsAreCheckedAgainstTheirOwnConstraints) {
    auto problem = [](binocle_param_desc d) { return settingsTableProblem(&d, 1); };
    binocle_param_desc d{"window_px", BINOCLE_PARAM_INT, BINOCLE_PARAM_FLAG_HAS_MIN | BINOCLE_PARAM_FLAG_HAS_MAX, "5", 3, 9, 0,
                         nullptr, "px", ""};
    EXPECT_EQ(problem(d), "");
    d.default_value = "11";
    EXPECT_THAT(problem(d), HasSubstr("default '11' is above its max 9"));
    d.default_value = "1";
    EXPECT_THAT(problem(d), HasSubstr("default '1' is below its min 3"));
    d.default_value = "five";
    EXPECT_THAT(problem(d), HasSubstr("default 'five' is not an integer"));
    d.default_value = "6";
    d.multiple_of = 4;
    EXPECT_THAT(problem(d), HasSubstr("default '6' is not a multiple of 4"));
    binocle_param_desc e{"mode", BINOCLE_PARAM_ENUM, 0, "fast", 0, 0, 0, "bm|sgbm", "", ""};
    EXPECT_THAT(problem(e), HasSubstr("setting #0 'mode': default 'fast' is not one of its choices 'bm|sgbm'"));
    binocle_param_desc r{"scale", BINOCLE_PARAM_DOUBLE, BINOCLE_PARAM_FLAG_HAS_MIN, "0.5", 1, 0, 0, nullptr, "", ""};
    EXPECT_THAT(problem(r), HasSubstr("default '0.5' is below its min 1"));
    binocle_param_desc b{"on", BINOCLE_PARAM_BOOL, 0, "maybe", 0, 0, 0, nullptr, "", ""};
    EXPECT_THAT(problem(b), HasSubstr("default 'maybe' is not a boolean"));
    binocle_param_desc q{"path", BINOCLE_PARAM_PATH, BINOCLE_PARAM_FLAG_REQUIRED, nullptr, 0, 0, 0, nullptr, "", ""};
    EXPECT_EQ(problem(q), "");
    q.flags = 0;
    EXPECT_THAT(problem(q), HasSubstr("no default, and not flagged BINOCLE_PARAM_FLAG_REQUIRED"));
}

TEST(PluginLoading, RequireOfARefusedPluginGivesTheReason) {
    try {
        fixtureHost().require("wrong_abi", BINOCLE_KIND_MATCHER);
        FAIL() << "require found wrong_abi";
    } catch (const Error &e) {
        EXPECT_THAT(e.what(), HasSubstr("no matcher plugin named 'wrong_abi'"));
        EXPECT_THAT(e.what(), HasSubstr(fixturePath("wrong_abi") + " was refused: built for ABI version"));
        EXPECT_THAT(e.what(), HasSubstr("mock_matcher")); // what is available instead
    }
}

TEST(PluginLoading, LoadOfAMissingFileNamesIt) {
    PluginHost host(std::vector<std::string>{});
    const std::string missing = std::string(BINOCLE_TEST_PLUGIN_DIR) + "/binocle_not_there.so";
    try {
        host.load(missing);
        FAIL() << "a missing file was loaded";
    } catch (const Error &e) {
        EXPECT_THAT(e.what(), HasSubstr(missing));
        EXPECT_THAT(e.what(), HasSubstr("cannot be loaded"));
    }
}

TEST(PluginLoading, LoadThenScanKeepsOneRecordPerFile) {
    PluginHost host({BINOCLE_TEST_PLUGIN_DIR});
    const PluginRecord &loaded = host.load(fixturePath("mock_source"));
    EXPECT_EQ(loaded.name, "mock_source");
    EXPECT_EQ(&host.load(fixturePath("mock_source")), &host.plugins().front()); // loaded once
    host.scan();
    EXPECT_EQ(std::count_if(host.plugins().begin(), host.plugins().end(),
                            [](const PluginRecord &r) { return r.name == "mock_source"; }),
              1);
    EXPECT_EQ(host.plugins().size(), fixtureHost().plugins().size());
    EXPECT_EQ(host.refused().size(), fixtureHost().refused().size());
}

TEST(PluginLoading, SettingsTablesAreReadFromCAndCppPlugins) {
    const auto cParams = fixture("c_matcher", BINOCLE_KIND_MATCHER).params();
    ASSERT_EQ(cParams.size(), 1u);
    EXPECT_STREQ(cParams[0].name, "disparity_px");
    EXPECT_EQ(cParams[0].type, BINOCLE_PARAM_DOUBLE);
    EXPECT_STREQ(cParams[0].default_value, "8");
    EXPECT_STREQ(cParams[0].unit, "px");

    std::vector<std::string> names;
    for (const auto &d : fixture("mock_source", BINOCLE_KIND_STEREO_SOURCE).params()) names.emplace_back(d.name);
    EXPECT_EQ(names, (std::vector<std::string>{"frames", "width", "height", "disparity_px", "baseline_mm", "focal_length_px",
                                               "publish_calibration", "live", "frame_interval_ms", "fail_after", "fail_for_ms",
                                               "fail_code", "grow_after"}));
}

} // namespace
} // namespace binocle::test
