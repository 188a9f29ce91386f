// SPDX-License-Identifier: MIT
// Rig YAML: validation against plugin tables, errors with file:line:col, --set overrides.
#include "common/test_util.hpp"
#include "config/rig_config.hpp"
#include "core/calibration.hpp"
#include "core/error.hpp"
#include "host/plugin_kinds.hpp"
#include "input/names.hpp"

#include <gtest/gtest.h>

#include <algorithm>

using namespace binocle;
using binocle::test::TempDir;
using binocle::test::writeText;

namespace {

class RigConfigTest : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        host_ = new PluginHost({BINOCLE_BUILD_PLUGIN_DIR});
        host_->scan();
    }
    static void TearDownTestSuite() { delete host_; }

    // A valid rig; `matcher` replaces the matcher block's lines.
    std::string rig(const std::string &matcher = "  plugin: sgbm\n  num_disparities: 64\n  block_size: 5\n") {
        return "name: test\n"
               "source:\n"
               "  plugin: replay\n"
               "  layout: glob\n"
               "  left: " BINOCLE_OPENCV_DATA_DIR "/aloeL.jpg\n"
               "  right: " BINOCLE_OPENCV_DATA_DIR "/aloeR.jpg\n"
               "matcher:\n" +
               matcher +
               "transforms:\n"
               "  - plugin: ground\n"
               "    camera_height_mm: 1200\n"
               "    inclination_deg: 5\n";
    }
    std::string write(const std::string &text) {
        const std::string path = dir_.str("rig.yaml");
        writeText(path, text);
        return path;
    }
    std::string errorOf(const std::string &text, const std::vector<Override> &overrides = {}) {
        const std::string path = write(text);
        try {
            loadRig(path, overrides, *host_);
        } catch (const Error &e) {
            return e.what();
        }
        return "";
    }

    static PluginHost *host_;
    TempDir dir_;
};

PluginHost *RigConfigTest::host_ = nullptr;

TEST_F(RigConfigTest, ValidRigResolvesPluginsAndDefaults) {
    RigConfig r = loadRig(write(rig()), {}, *host_);
    EXPECT_EQ(r.name, "test");
    EXPECT_EQ(r.source().plugin, "replay");
    EXPECT_EQ(r.matcher().plugin, "sgbm");
    ASSERT_NE(r.matcher().params.find("num_disparities"), nullptr);
    EXPECT_EQ(r.matcher().params.find("num_disparities")->i, 64);
    EXPECT_EQ(r.matcher().params.find("num_disparities")->explicit_, 1);
    // Every declared setting reaches the plugin, defaults marked as such.
    EXPECT_EQ(r.matcher().params.size(), static_cast<int32_t>(r.matcher().record->params().size()));
    ASSERT_EQ(r.transforms().size(), 1u);
    EXPECT_DOUBLE_EQ(r.transforms()[0].params.find("inclination_deg")->d, 5.0);
}

TEST_F(RigConfigTest, EveryKindsBlocksAreReadWhereItsDescriptorSays) {
    const RigConfig r = loadRig(write(rig()), {}, *host_);
    for (const PluginKind *k : pluginKinds()) {
        const auto &blocks = r.blocks(k->kind);
        if (k->inRig == PluginKind::InRig::One) ASSERT_EQ(blocks.size(), 1u) << k->name;
        for (size_t i = 0; i < blocks.size(); ++i) {
            EXPECT_EQ(blocks[i].record->kind, k->kind) << k->name;
            EXPECT_EQ(blocks[i].where, k->inRig == PluginKind::InRig::List ? std::string(k->rigKey) + "[" + std::to_string(i) + "]"
                                                                           : std::string(k->rigKey));
        }
    }
    EXPECT_TRUE(r.evaluators().empty()); // a list the rig leaves out is empty
    // Every kind's rig key is a valid top-level key, named when another is misspelt.
    const std::string err = errorOf(rig() + "matchr: {}\n");
    for (const PluginKind *k : pluginKinds()) EXPECT_NE(err.find(k->rigKey), std::string::npos) << err;
}

TEST_F(RigConfigTest, MisspeltKeyNamesLineColumnAndValidKey) {
    const std::string err = errorOf(rig("  plugin: sgbm\n  num_disparity: 64\n"));
    // matcher block starts on line 7; the misspelt key is on line 9, column 3.
    EXPECT_NE(err.find("rig.yaml:9:3"), std::string::npos) << err;
    EXPECT_NE(err.find("unknown key 'num_disparity'"), std::string::npos) << err;
    EXPECT_NE(err.find("did you mean 'num_disparities'"), std::string::npos) << err;
}

TEST_F(RigConfigTest, WrongTypeIsAnErrorWithValueAndExpectation) {
    const std::string err = errorOf(rig("  plugin: sgbm\n  num_disparities: lots\n"));
    EXPECT_NE(err.find("rig.yaml:9:20"), std::string::npos) << err;
    EXPECT_NE(err.find("matcher.num_disparities"), std::string::npos) << err;
    EXPECT_NE(err.find("'lots'"), std::string::npos) << err;
    EXPECT_NE(err.find("multiple of 16"), std::string::npos) << err;
}

TEST_F(RigConfigTest, OutOfRangeValuesAreRefused) {
    std::string err = errorOf(rig("  plugin: sgbm\n  num_disparities: 100\n"));
    EXPECT_NE(err.find("'100'"), std::string::npos) << err;
    EXPECT_NE(err.find("multiple of 16"), std::string::npos) << err;
    err = errorOf(rig("  plugin: bm\n  block_size: 8\n"));
    EXPECT_NE(err.find("matcher.block_size"), std::string::npos) << err;
    EXPECT_NE(err.find("odd"), std::string::npos) << err;
    err = errorOf(rig() + "    extra: 1\n");
    EXPECT_NE(err.find("unknown key 'extra'"), std::string::npos) << err;
}

TEST_F(RigConfigTest, MissingPluginSuggestsTheNearestOne) {
    const std::string err = errorOf(rig("  plugin: sgbn\n"));
    EXPECT_NE(err.find("rig.yaml:8:11"), std::string::npos) << err;
    EXPECT_NE(err.find("no matcher plugin named 'sgbn'"), std::string::npos) << err;
    EXPECT_NE(err.find("did you mean 'sgbm'"), std::string::npos) << err;
}

TEST_F(RigConfigTest, UnknownTopLevelKeyAndMissingBlock) {
    std::string err = errorOf(rig() + "matchr: {}\n");
    EXPECT_NE(err.find("unknown key 'matchr'"), std::string::npos) << err;
    err = errorOf("source: {plugin: replay}\n");
    EXPECT_NE(err.find("missing block 'matcher'"), std::string::npos) << err;
}

TEST_F(RigConfigTest, SetOverridesAnyValueAndIsNamedInErrors) {
    RigConfig r = loadRig(write(rig()), {Override::parse("matcher.num_disparities=128"),
                                         Override::parse("transforms.0.inclination_deg=10"),
                                         Override::parse("matcher.plugin=bm")},
                          *host_);
    EXPECT_EQ(r.matcher().plugin, "bm");
    EXPECT_EQ(r.matcher().params.find("num_disparities")->i, 128);
    EXPECT_DOUBLE_EQ(r.transforms()[0].params.find("inclination_deg")->d, 10.0);
    const std::string err = errorOf(rig(), {Override::parse("matcher.num_disparities=100")});
    EXPECT_NE(err.find("command line --set matcher.num_disparities=100"), std::string::npos) << err;
    EXPECT_THROW(Override::parse("novalue"), Error);
    EXPECT_THROW(loadRig(write(rig()), {Override::parse("transforms.7.x=1")}, *host_), Error);
}

TEST_F(RigConfigTest, AWholeBlockSwappedWithSetIsLocatedOnTheCommandLine) {
    const std::string set = "matcher={plugin: bm, block_size: 4}";
    RigConfig r = loadRig(write(rig()), {Override::parse("matcher={plugin: bm, block_size: 7}")}, *host_);
    EXPECT_EQ(r.matcher().plugin, "bm");
    EXPECT_EQ(r.matcher().params.find("block_size")->i, 7);
    const std::string err = errorOf(rig(), {Override::parse(set)});
    EXPECT_NE(err.find("command line --set " + set + ": matcher.block_size"), std::string::npos) << err;
    EXPECT_EQ(err.find("rig.yaml:"), std::string::npos) << err;
}

TEST_F(RigConfigTest, SwappingBmForSgbmIsOneLine) {
    const std::string sgbm = rig("  plugin: sgbm\n  num_disparities: 64\n  block_size: 5\n");
    std::string bm = sgbm;
    bm.replace(bm.find("plugin: sgbm"), 12, "plugin: bm  ");
    EXPECT_EQ(loadRig(write(sgbm), {}, *host_).matcher().plugin, "sgbm");
    EXPECT_EQ(loadRig(write(bm), {}, *host_).matcher().plugin, "bm");
}

TEST_F(RigConfigTest, RelativePathsResolveAgainstTheRigFolder) {
    StereoCalibration::ideal({1282, 1110}, 3740, 160).save(dir_.str("cal.yml"));
    RigConfig r = loadRig(write(rig() + "calibration: cal.yml\n"), {}, *host_);
    ASSERT_TRUE(r.calibration_file.has_value());
    EXPECT_EQ(*r.calibration_file, dir_.str("cal.yml"));
    const std::string err = errorOf(rig() + "calibration: nowhere.yml\n");
    EXPECT_NE(err.find("nowhere.yml' does not exist"), std::string::npos) << err;
}

TEST_F(RigConfigTest, YamlSyntaxErrorHasLineAndColumn) {
    const std::string err = errorOf("source: [plugin: replay\nmatcher: x\n");
    EXPECT_NE(err.find("rig.yaml:"), std::string::npos) << err;
    EXPECT_NE(err.find("YAML syntax error"), std::string::npos) << err;
}

TEST(Nearest, FindsCloseNamesOnly) {
    EXPECT_EQ(input::nearestWord("num_disparity", {"num_disparities", "block_size"}), "num_disparities");
    EXPECT_EQ(input::nearestWord("blok_size", {"num_disparities", "block_size"}), "block_size");
    EXPECT_EQ(input::nearestWord("zzz", {"num_disparities", "block_size"}), "");
}

} // namespace

namespace {

TEST_F(RigConfigTest, RuntimeBlockDefaultsAndValues) {
    RigConfig plain = loadRig(write(rig()), {}, *host_);
    EXPECT_FALSE(plain.runtime.policy.has_value()); // the source decides
    EXPECT_EQ(plain.runtime.queue_depth, 4);
    EXPECT_EQ(plain.runtime.matcher_instances, 1);
    EXPECT_EQ(plain.runtime.on_source_error, RuntimeOptions::OnSourceError::Stop);

    RigConfig r = loadRig(write(rig() + "runtime:\n  policy: latest\n  queue_depth: 8\n  matcher_instances: 2\n"
                                        "  on_source_error: retry\n  retry_for_s: 2.5\n"),
                          {}, *host_);
    ASSERT_TRUE(r.runtime.policy.has_value());
    EXPECT_EQ(*r.runtime.policy, RuntimeOptions::Policy::Latest);
    EXPECT_EQ(r.runtime.queue_depth, 8);
    EXPECT_EQ(r.runtime.matcher_instances, 2);
    EXPECT_EQ(r.runtime.on_source_error, RuntimeOptions::OnSourceError::Retry);
    EXPECT_DOUBLE_EQ(r.runtime.retry_for_s, 2.5);

    RigConfig o = loadRig(write(rig()), {Override::parse("runtime.policy=lossless")}, *host_);
    ASSERT_TRUE(o.runtime.policy.has_value());
    EXPECT_EQ(*o.runtime.policy, RuntimeOptions::Policy::Lossless);
}

TEST_F(RigConfigTest, RuntimeBlockErrorsNameLineKeyValueAndWhatIsExpected) {
    // The rig has 14 lines; runtime: is line 15, its first key line 16.
    std::string err = errorOf(rig() + "runtime:\n  polcy: latest\n");
    EXPECT_NE(err.find("rig.yaml:16:3"), std::string::npos) << err;
    EXPECT_NE(err.find("unknown key 'polcy'"), std::string::npos) << err;
    EXPECT_NE(err.find("did you mean 'policy'"), std::string::npos) << err;

    err = errorOf(rig() + "runtime:\n  policy: newest\n");
    EXPECT_NE(err.find("rig.yaml:16:11"), std::string::npos) << err;
    EXPECT_NE(err.find("runtime.policy: value 'newest' is not valid: expected lossless or latest"), std::string::npos) << err;

    err = errorOf(rig() + "runtime:\n  queue_depth: 0\n");
    EXPECT_NE(err.find("runtime.queue_depth: value '0' is not valid: expected an integer >= 1"), std::string::npos) << err;
    err = errorOf(rig() + "runtime:\n  queue_depth: two\n");
    EXPECT_NE(err.find("runtime.queue_depth: value 'two' is not valid"), std::string::npos) << err;
    err = errorOf(rig() + "runtime:\n  matcher_instances: 1.5\n");
    EXPECT_NE(err.find("runtime.matcher_instances: value '1.5' is not valid"), std::string::npos) << err;
    err = errorOf(rig() + "runtime:\n  on_source_error: retry\n  retry_for_s: -1\n");
    EXPECT_NE(err.find("rig.yaml:17:16"), std::string::npos) << err;
    EXPECT_NE(err.find("expected a positive number of seconds"), std::string::npos) << err;
    err = errorOf(rig() + "runtime:\n  retry_for_s: 5\n");
    EXPECT_NE(err.find("is only used with on_source_error: retry"), std::string::npos) << err;
    err = errorOf(rig() + "runtime: fast\n");
    EXPECT_NE(err.find("runtime: expected a map"), std::string::npos) << err;
    err = errorOf(rig(), {Override::parse("runtime.on_source_error=ignore")});
    EXPECT_NE(err.find("command line --set runtime.on_source_error=ignore"), std::string::npos) << err;
    EXPECT_NE(err.find("expected stop or retry"), std::string::npos) << err;
}

} // namespace

namespace {

// The message of a refusal without its place ("rig.yaml:17:16: " or "command line --set
// ...: "): what must read the same wherever the value came from.
std::string withoutPlace(const std::string &message, const std::string &key) {
    const auto at = message.find(key + ": value");
    return at == std::string::npos ? message : message.substr(at);
}

// One settings checker (issue 23): a value gets the same answer in the rig file and on the
// command line, for a plugin setting and for the rig's own keys alike.
TEST_F(RigConfigTest, TheSameValueGetsTheSameAnswerInTheFileAndWithSet) {
    struct Case {
        std::string key, value, fileText;
    };
    const std::vector<Case> cases = {
        {"matcher.num_disparities", "0100", rig("  plugin: sgbm\n  num_disparities: 0100\n  block_size: 5\n")},
        {"runtime.queue_depth", "010", rig() + "runtime:\n  queue_depth: 010\n"},
        {"runtime.queue_depth", "0x10", rig() + "runtime:\n  queue_depth: 0x10\n"},
        {"matcher.call_timeout_ms", "010",
         rig("  plugin: sgbm\n  isolation: process\n  call_timeout_ms: 010\n")},
        {"matcher.call_timeout_ms", "0x10",
         rig("  plugin: sgbm\n  isolation: process\n  call_timeout_ms: 0x10\n")},
        {"matcher.max_restarts", "03", rig("  plugin: sgbm\n  isolation: process\n  max_restarts: 03\n")},
        {"transforms[0].inclination_deg", "05", [&] {
             std::string t = rig();
             return t.replace(t.find("inclination_deg: 5"), 18, "inclination_deg: 05");
         }()},
        {"outputs.max_range_mm", "050000", rig() + "outputs:\n  max_range_mm: 050000\n"},
    };
    for (const Case &c : cases) {
        SCOPED_TRACE(c.key + " = " + c.value);
        std::string setPath = c.key;
        for (auto p = setPath.find('['); p != std::string::npos; p = setPath.find('[')) setPath.replace(p, 1, ".");
        setPath.erase(std::remove(setPath.begin(), setPath.end(), ']'), setPath.end());
        std::string base = rig();
        if (c.key.rfind("matcher.call", 0) == 0 || c.key.rfind("matcher.max", 0) == 0)
            base = rig("  plugin: sgbm\n  isolation: process\n");
        const std::string fromSet = errorOf(base, {Override::parse(setPath + "=" + c.value)});
        EXPECT_NE(fromSet.find("command line --set " + setPath + "=" + c.value), std::string::npos) << fromSet;
        EXPECT_NE(fromSet.find(c.key + ": value '" + c.value + "' is not valid: expected "), std::string::npos) << fromSet;
        if (c.value.rfind("0x", 0) == 0) EXPECT_NE(fromSet.find("is hexadecimal: write 16"), std::string::npos) << fromSet;
        else EXPECT_NE(fromSet.find("without leading zeros"), std::string::npos) << fromSet;
        const std::string fromFile = errorOf(c.fileText);
        EXPECT_NE(fromFile.find("rig.yaml:"), std::string::npos) << fromFile;
        EXPECT_EQ(withoutPlace(fromFile, c.key), withoutPlace(fromSet, c.key));
    }
}

TEST_F(RigConfigTest, LeadingZerosNameTheirOctalReadingAndTheDecimalToWrite) {
    const std::string err = errorOf(rig() + "runtime:\n  queue_depth: 010\n");
    EXPECT_NE(err.find("rig.yaml:16:16: runtime.queue_depth: value '010' is not valid: expected an integer >= 1 <= 1024, "
                       "without leading zeros (010 would read as octal 8 elsewhere: write 10)"),
              std::string::npos)
        << err;
    // yaml-cpp would read these with base detection (8 and 16 ms): refused instead.
    for (const char *v : {"010", "0x10", "0o10", "+010"}) {
        const std::string e = errorOf(rig("  plugin: sgbm\n  isolation: process\n  call_timeout_ms: " + std::string(v) + "\n"));
        EXPECT_NE(e.find("matcher.call_timeout_ms: value '" + std::string(v) + "' is not valid: expected an integer >= 0"),
                  std::string::npos)
            << e;
    }
}

TEST_F(RigConfigTest, PlainDecimalsAndZeroStillRead) {
    RigConfig r = loadRig(write(rig("  plugin: sgbm\n  num_disparities: 128\n") +
                                "runtime:\n  queue_depth: 10\noutputs:\n  max_range_mm: 0.5e5\n"),
                          {Override::parse("transforms.0.inclination_deg=0.5")}, *host_);
    EXPECT_EQ(r.runtime.queue_depth, 10);
    EXPECT_EQ(r.matcher().params.find("num_disparities")->i, 128);
    EXPECT_DOUBLE_EQ(r.outputs.max_range_mm, 50000);
    EXPECT_DOUBLE_EQ(r.transforms()[0].params.find("inclination_deg")->d, 0.5);
}

TEST_F(RigConfigTest, AMistakeInSetIsAnOverrideErrorAndOneInTheFileIsNot) {
    const std::string path = write(rig());
    EXPECT_THROW(loadRig(path, {Override::parse("matcher.num_disparities=0100")}, *host_), OverrideError);
    EXPECT_THROW(loadRig(path, {Override::parse("matcher.num_disparity=64")}, *host_), OverrideError);
    EXPECT_THROW(loadRig(path, {Override::parse("transforms.7.inclination_deg=1")}, *host_), OverrideError);
    EXPECT_THROW(Override::parse("no_equals_sign"), OverrideError);
    try {
        loadRig(write(rig("  plugin: sgbm\n  num_disparities: 0100\n")), {}, *host_);
        ADD_FAILURE() << "0100 accepted";
    } catch (const OverrideError &e) {
        ADD_FAILURE() << "a mistake in the file reported as one on the command line: " << e.what();
    } catch (const Error &) {
    }
}

} // namespace
