// SPDX-License-Identifier: MIT
// JSON as Binocle writes it: integers stay integers, non-finite numbers become null, and
// a string with broken UTF-8 never makes an invalid file.
#include "core/json.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>

namespace {

using binocle::Json;

TEST(Json, IntegersAbove2To53KeepEveryDigit) {
    const int64_t big = (int64_t{1} << 53) + 1; // the first integer a double cannot hold
    const uint64_t sequence = std::numeric_limits<uint64_t>::max();
    const std::string text = binocle::dumpJson(Json{{"count", big}, {"sequence", sequence}});
    EXPECT_NE(text.find("9007199254740993"), std::string::npos) << text;
    EXPECT_NE(text.find("18446744073709551615"), std::string::npos) << text;
    const Json back = Json::parse(text);
    EXPECT_EQ(back["count"].get<int64_t>(), big);
    EXPECT_EQ(back["sequence"].get<uint64_t>(), sequence);
    EXPECT_TRUE(back["count"].is_number_integer());
}

TEST(Json, NonFiniteNumbersAreWrittenAsNull) {
    const std::string text = binocle::dumpJson(Json{{"nan", NAN}, {"inf", INFINITY}, {"x", 1.5}});
    const Json back = Json::parse(text);
    EXPECT_TRUE(back["nan"].is_null()) << text;
    EXPECT_TRUE(back["inf"].is_null()) << text;
    EXPECT_DOUBLE_EQ(back["x"].get<double>(), 1.5);
}

TEST(Json, InvalidUtf8IsReplacedNotWrittenRaw) {
    const std::string broken = std::string("plugin said \xff\xfe ok");
    const std::string text = binocle::dumpJson(Json{{"error", broken}});
    const Json back = Json::parse(text); // throws on invalid UTF-8
    EXPECT_NE(back["error"].get<std::string>().find("\xEF\xBF\xBD"), std::string::npos) << text; // U+FFFD
    EXPECT_EQ(text.back(), '\n');
}

TEST(Json, KeysKeepTheirOrder) {
    Json j = Json::object();
    j["zeta"] = 1;
    j["alpha"] = 2;
    const std::string text = binocle::dumpJson(j);
    EXPECT_LT(text.find("zeta"), text.find("alpha")) << text;
}

} // namespace
