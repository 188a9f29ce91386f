// SPDX-License-Identifier: MIT
// The SDK's one number reader and settings checker (binocle/numbers.hpp,
// binocle/settings.hpp), as a third-party plugin uses them: no framework code here.
// Also the settings a plugin's constructor gets through the SDK's `create` (plugin.hpp):
// checked ones, or the raw ones for a constructor written before that.
#include <binocle/plugin.hpp>
#include <binocle/settings.hpp>

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace {

using namespace binocle::sdk;

std::string whyInteger(const std::string &text) {
    int64_t v = 0;
    std::string why;
    EXPECT_FALSE(parseDecimalInteger(text, v, &why)) << text << " read as " << v;
    return why;
}

std::string whyReal(const std::string &text) {
    double v = 0;
    std::string why;
    EXPECT_FALSE(parseDecimalReal(text, v, &why)) << text << " read as " << v;
    return why;
}

TEST(Numbers, ALeadingZeroIsAnErrorThatNamesBothReadingsAndWhatToWrite) {
    EXPECT_EQ(whyInteger("0640"), "expected a decimal integer without leading zeros (0640 would read as octal 416 "
                                  "elsewhere: write 640)");
    EXPECT_EQ(whyInteger("-010"), "expected a decimal integer without leading zeros (-010 would read as octal -8 "
                                  "elsewhere: write -10)");
    EXPECT_EQ(whyInteger("0099"), "expected a decimal integer without leading zeros (0099 would read as octal "
                                  "elsewhere: write 99)");
    EXPECT_EQ(whyInteger("00"), "expected a decimal integer without leading zeros (00 would read as octal 0 elsewhere: "
                                "write 0)");
    EXPECT_EQ(whyReal("010"), "expected a decimal number without leading zeros (010 would read as octal 8 elsewhere: "
                              "write 10)");
    EXPECT_NE(whyReal("010.5").find("write 10.5"), std::string::npos);
}

TEST(Numbers, RadixPrefixesAreErrorsThatNameTheDecimalValue) {
    EXPECT_EQ(whyInteger("0x10"), "expected a decimal integer (0x10 is hexadecimal: write 16)");
    EXPECT_EQ(whyInteger("-0X1f"), "expected a decimal integer (-0X1f is hexadecimal: write -31)");
    EXPECT_EQ(whyInteger("0o17"), "expected a decimal integer (0o17 is octal: write 15)");
    EXPECT_EQ(whyInteger("0b101"), "expected a decimal integer (0b101 is binary: write 5)");
    EXPECT_EQ(whyInteger("0xZZ"), "expected a decimal integer (0xZZ is hexadecimal)");
    EXPECT_EQ(whyInteger("0x"), "expected a decimal integer (0x is hexadecimal)");
    EXPECT_EQ(whyReal("0x1p3"), "expected a decimal number (0x1p3 is hexadecimal)");
    EXPECT_EQ(whyReal("0x10"), "expected a decimal number (0x10 is hexadecimal: write 16)");
}

TEST(Numbers, PlainDecimalsRead) {
    int64_t i = -1;
    EXPECT_TRUE(parseDecimalInteger("0", i) && i == 0);
    EXPECT_TRUE(parseDecimalInteger("-0", i) && i == 0);
    EXPECT_TRUE(parseDecimalInteger("+10", i) && i == 10);
    EXPECT_TRUE(parseDecimalInteger("640", i) && i == 640);
    double d = -1;
    EXPECT_TRUE(parseDecimalReal("0", d) && d == 0);
    EXPECT_TRUE(parseDecimalReal("0.5", d) && d == 0.5);
    EXPECT_TRUE(parseDecimalReal("-0.25", d) && d == -0.25);
    EXPECT_TRUE(parseDecimalReal("0e3", d) && d == 0);
    EXPECT_TRUE(parseDecimalReal("1e-05", d) && d == 1e-5); // a zero in the exponent is no octal
    EXPECT_TRUE(parseDecimalReal(".5", d) && d == 0.5);
    for (const char *bad : {"", " 1", "1 ", "1_000", "1,5", "inf", "nan", "1e999"}) {
        EXPECT_FALSE(parseDecimalReal(bad, d)) << bad;
        EXPECT_FALSE(parseDecimalInteger(bad, i)) << bad;
    }
}

TEST(Numbers, WhyDetailFollowsACallersOwnWords) {
    EXPECT_EQ(numberWhyDetail("expected a decimal integer"), "");
    EXPECT_EQ(numberWhyDetail("expected a decimal integer (0x10 is hexadecimal: write 16)"),
              " (0x10 is hexadecimal: write 16)");
    EXPECT_EQ(numberWhyDetail("expected a decimal integer without leading zeros (010 would read as octal 8 elsewhere: "
                              "write 10)"),
              ", without leading zeros (010 would read as octal 8 elsewhere: write 10)");
    EXPECT_EQ(numberWhyDetail("expected an integer within 64 bits"), ", within 64 bits");
}

TEST(Numbers, BooleansAreYamlWords) {
    bool b = false;
    for (const char *t : {"true", "True", "TRUE", "yes", "on", "y", "Y"}) EXPECT_TRUE(parseBoolean(t, b) && b) << t;
    for (const char *f : {"false", "False", "NO", "off", "n"}) EXPECT_TRUE(parseBoolean(f, b) && !b) << f;
    for (const char *bad : {"", "1", "0", "tRUE", "maybe", "yes "}) EXPECT_FALSE(parseBoolean(bad, b)) << bad;
}

const std::vector<binocle_param_desc> &table() {
    static const std::vector<binocle_param_desc> t = {
        Param::integer("num_disparities", "64").min(16).max(1024).multipleOf(16),
        Param::integer("block_size", "5").min(1).odd(),
        Param::integer("count", "3").min(0),
        Param::real("baseline_mm", "120").min(0),
        Param::choice("mode", "bm", "bm|sgbm"),
        Param::choice("format", "grey", "grey|yuyv|mjpeg"),
        Param::boolean("loop", false),
        Param::intList("ids", "[1, 2]"),
        Param::string("name", "x"),
    };
    return t;
}

const binocle_param_desc &desc(const std::string &name) {
    for (const auto &d : table())
        if (name == d.name) return d;
    throw std::logic_error(name);
}

TEST(SettingsChecker, SaysWhatASettingAccepts) {
    EXPECT_EQ(settingExpects(desc("num_disparities")), "an integer multiple of 16 >= 16 <= 1024");
    EXPECT_EQ(settingExpects(desc("block_size")), "an odd integer >= 1");
    EXPECT_EQ(settingExpects(desc("baseline_mm")), "a decimal number >= 0");
    EXPECT_EQ(settingExpects(desc("mode")), "bm or sgbm");
    EXPECT_EQ(settingExpects(desc("format")), "one of grey, yuyv, mjpeg");
    EXPECT_EQ(settingExpects(desc("loop")), "true or false");
}

TEST(SettingsChecker, ReadsAndChecksText) {
    SettingValue v;
    EXPECT_FALSE(readSetting(desc("num_disparities"), "128", v));
    EXPECT_EQ(v.integer, 128);
    SettingProblem p = readSetting(desc("num_disparities"), "0100", v);
    EXPECT_EQ(p.expected, "an integer multiple of 16 >= 16 <= 1024, without leading zeros (0100 would read as octal "
                          "64 elsewhere: write 100)");
    EXPECT_EQ(p.rule.rfind("is not an integer: expected a decimal integer without leading zeros", 0), 0u) << p.rule;
    EXPECT_EQ(readSetting(desc("num_disparities"), "100", v).rule, "is not a multiple of 16");
    EXPECT_EQ(readSetting(desc("num_disparities"), "2048", v).rule, "is above its max 1024");
    EXPECT_EQ(readSetting(desc("block_size"), "4", v).rule, "is not odd");
    EXPECT_EQ(readSetting(desc("block_size"), "0", v).rule, "is below its min 1");
    EXPECT_EQ(readSetting(desc("count"), "2147483648", v).rule, "is not within 32 bits");
    EXPECT_EQ(readSetting(desc("count"), "2147483648", v).expected, "an integer >= 0 (within 32 bits)");
    EXPECT_EQ(readSetting(desc("baseline_mm"), "-1", v).rule, "is below its min 0");
    EXPECT_EQ(readSetting(desc("baseline_mm"), "0x1p3", v).expected, "a decimal number >= 0 (0x1p3 is hexadecimal)");
    EXPECT_FALSE(readSetting(desc("baseline_mm"), "1e3", v));
    EXPECT_EQ(v.real, 1000);
    EXPECT_EQ(readSetting(desc("mode"), "fast", v).rule, "is not one of its choices 'bm|sgbm'");
    EXPECT_TRUE(readSetting(desc("mode"), "", v));
    EXPECT_FALSE(readSetting(desc("loop"), "yes", v));
    EXPECT_TRUE(v.boolean);
    EXPECT_EQ(readSetting(desc("loop"), "1", v).rule, "is not a boolean (true or false)");
    EXPECT_FALSE(readSetting(desc("ids"), "[1, 2, -3]", v));
    EXPECT_FALSE(readSetting(desc("ids"), "[]", v));
    EXPECT_NE(readSetting(desc("ids"), "[1, 010]", v).expected.find("'010': expected a decimal integer without leading"),
              std::string::npos);
    EXPECT_TRUE(readSetting(desc("ids"), "1, 2", v));
    EXPECT_FALSE(readSetting(desc("name"), "0100", v)); // a text is a text
}

// What a plugin receives, as the C++ helper hands it over.
Params paramsOf(std::vector<binocle_param> values) { return Params(values.data(), static_cast<int32_t>(values.size())); }

binocle_param intParam(const char *name, int64_t v) {
    binocle_param p{};
    p.name = name;
    p.type = BINOCLE_PARAM_INT;
    p.i = v;
    p.explicit_ = 1;
    return p;
}

std::string refusal(const Params &p) {
    try {
        CheckedParams c(p, table(), "my_matcher");
    } catch (const Error &e) {
        EXPECT_EQ(e.code(), BINOCLE_ERR_INVALID_ARGUMENT);
        return e.what();
    }
    return "";
}

TEST(CheckedParams, AbsentSettingsReadAsTheirDefaultsAndOthersAsGiven) {
    const CheckedParams c(paramsOf({intParam("num_disparities", 128)}), table(), "my_matcher");
    EXPECT_EQ(c.integer("num_disparities"), 128);
    EXPECT_TRUE(c.isExplicit("num_disparities"));
    EXPECT_EQ(c.integer("block_size"), 5);
    EXPECT_FALSE(c.isExplicit("block_size"));
    EXPECT_EQ(c.real("baseline_mm"), 120);
    EXPECT_EQ(c.string("mode"), "bm");
    EXPECT_FALSE(c.boolean("loop"));
    EXPECT_EQ(c.string("ids"), "[1, 2]");
    EXPECT_THROW(c.integer("undeclared"), Error);
}

TEST(CheckedParams, ValuesOutsideTheTableAreRefusedInTheHostsWords) {
    EXPECT_EQ(refusal(paramsOf({intParam("num_disparities", 100)})),
              "my_matcher: num_disparities = 100: expected an integer multiple of 16 >= 16 <= 1024");
    EXPECT_EQ(refusal(paramsOf({intParam("block_size", 8)})), "my_matcher: block_size = 8: expected an odd integer >= 1");
    binocle_param mode{};
    mode.name = "mode";
    mode.type = BINOCLE_PARAM_ENUM;
    mode.s = "fast";
    EXPECT_EQ(refusal(paramsOf({mode})), "my_matcher: mode = 'fast': expected bm or sgbm");
    binocle_param nan{};
    nan.name = "baseline_mm";
    nan.type = BINOCLE_PARAM_DOUBLE;
    nan.d = std::nan("");
    EXPECT_EQ(refusal(paramsOf({nan})), "my_matcher: baseline_mm = nan: expected a decimal number >= 0");
    EXPECT_EQ(refusal(paramsOf({intParam("count", int64_t{1} << 40)})),
              "my_matcher: count = 1099511627776: expected an integer >= 0 (within 32 bits)");
}

TEST(CheckedParams, APluginsRuleAcrossSettingsUsesTheSameWords) {
    const CheckedParams c(paramsOf({}), table(), "v4l2");
    try {
        c.refuse("width", "65", "an even width with layout side_by_side");
        FAIL();
    } catch (const Error &e) {
        EXPECT_STREQ(e.what(), "v4l2: width = 65: expected an even width with layout side_by_side");
    }
}

TEST(CheckedParams, ABadDefaultIsThePluginsMistakeAndSaysSo) {
    const std::vector<binocle_param_desc> bad = {Param::integer("window_px", "010").min(1)};
    try {
        CheckedParams c(paramsOf({}), bad, "mine");
        FAIL();
    } catch (const Error &e) {
        EXPECT_NE(std::string(e.what()).find("mine: window_px = '010' (its default): expected an integer >= 1, without "
                                              "leading zeros"),
                  std::string::npos)
            << e.what();
    }
}

// ---- What `create` hands a plugin's constructor (plugin.hpp) ---------------------------

// Written the one way: the constructor takes the settings the SDK checked against the table.
class CheckedMatcher : public Matcher {
public:
    static std::vector<binocle_param_desc> parameters() { return table(); }
    CheckedMatcher(const CheckedParams &p, Host &) : block(p.integer("block_size")), mode(p.string("mode")) {}
    void compute(const binocle_image &, const binocle_image &, binocle_image &) override {}
    int64_t block;
    std::string mode;
};

// Written against the SDK before it built CheckedParams: the raw values, still built.
class RawMatcher : public Matcher {
public:
    static std::vector<binocle_param_desc> parameters() { return table(); }
    RawMatcher(const Params &p, Host &) : passedBlock(p.has("block_size")) {}
    void compute(const binocle_image &, const binocle_image &, binocle_image &) override {}
    bool passedBlock;
};

static_assert(detail::takesCheckedParams<CheckedMatcher> && !detail::takesRawParams<CheckedMatcher>);
static_assert(detail::takesRawParams<RawMatcher> && !detail::takesCheckedParams<RawMatcher>);

// An instance made through the plugin's C table, as the host makes it.
template <class T>
struct Made {
    const binocle_matcher_api *api = detail::matcherTable<T>("my_matcher", "1.0.0", "a test matcher");
    binocle_matcher *handle = nullptr;
    binocle_result rc = BINOCLE_OK;
    std::string error;
    explicit Made(std::vector<binocle_param> values) {
        rc = api->create(values.data(), static_cast<int32_t>(values.size()), nullptr, &handle);
        if (rc != BINOCLE_OK) error = api->last_error(nullptr);
    }
    Made(const Made &) = delete;
    Made &operator=(const Made &) = delete;
    ~Made() {
        if (handle) api->destroy(handle);
    }
    T &impl() { return *reinterpret_cast<detail::MatcherInstance<T> *>(handle)->impl; }
};

TEST(PluginSettings, AConstructorTakingCheckedParamsGetsDefaultsFilledIn) {
    Made<CheckedMatcher> made({intParam("block_size", 7)});
    ASSERT_EQ(made.rc, BINOCLE_OK) << made.error;
    EXPECT_EQ(made.impl().block, 7);
    EXPECT_EQ(made.impl().mode, "bm"); // not passed: the table's default
    Made<CheckedMatcher> none({});
    ASSERT_EQ(none.rc, BINOCLE_OK) << none.error;
    EXPECT_EQ(none.impl().block, 5);
}

TEST(PluginSettings, AConstructorTakingRawParamsStillBuildsAndGetsTheValuesAsPassed) {
    Made<RawMatcher> made({intParam("block_size", 7)});
    ASSERT_EQ(made.rc, BINOCLE_OK) << made.error;
    EXPECT_TRUE(made.impl().passedBlock);
    Made<RawMatcher> none({});
    ASSERT_EQ(none.rc, BINOCLE_OK) << none.error;
    EXPECT_FALSE(none.impl().passedBlock);
}

TEST(PluginSettings, AValueOutsideTheTableFailsCreateBeforeEitherConstructorRuns) {
    for (const std::string &error : {Made<CheckedMatcher>({intParam("block_size", 8)}).error,
                                     Made<RawMatcher>({intParam("block_size", 8)}).error})
        EXPECT_EQ(error, "my_matcher: block_size = 8: expected an odd integer >= 1");
    Made<CheckedMatcher> bad({intParam("num_disparities", 100)});
    EXPECT_EQ(bad.rc, BINOCLE_ERR_INVALID_ARGUMENT);
    EXPECT_EQ(bad.handle, nullptr);
}

} // namespace
