// SPDX-License-Identifier: MIT
// base/input and the SDK readers it builds on: the strict number reader, UTF-8 and path
// checks, image header checks and the YAML loader.
#include "input/image_file.hpp"
#include "input/integer_range.hpp"
#include "input/names.hpp"
#include "input/utf8.hpp"
#include "input/yaml_file.hpp"

#include <binocle/numbers.hpp>
#include <binocle/text.hpp>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <fstream>
#include <sstream>

using namespace binocle::input;
namespace sdk = binocle::sdk;

namespace {

TEST(Numbers, IntegersAreDecimalWholeAndInRange) {
    int64_t v = 0;
    std::string why;
    EXPECT_TRUE(sdk::parseDecimalInteger("640", v) && v == 640);
    EXPECT_TRUE(sdk::parseDecimalInteger("-7", v) && v == -7);
    EXPECT_TRUE(sdk::parseDecimalInteger("+7", v) && v == 7);
    EXPECT_TRUE(sdk::parseDecimalInteger("0", v) && v == 0);
    EXPECT_TRUE(sdk::parseDecimalInteger("-9223372036854775808", v) && v == INT64_MIN);
    EXPECT_FALSE(sdk::parseDecimalInteger("0640", v, &why));
    EXPECT_NE(why.find("leading zeros"), std::string::npos) << why;
    for (const char *bad : {"", "-", "0x10", "1e3", "12px", " 3", "3 ", "1.0", "9223372036854775808", "٣"})
        EXPECT_FALSE(sdk::parseDecimalInteger(bad, v)) << bad;
    EXPECT_FALSE(parseInteger("17", v, &why, 0, 16));
    EXPECT_EQ(why, "expected an integer <= 16");
}

TEST(Numbers, RealsAreDecimalAndFiniteUnlessAsked) {
    double v = 0;
    EXPECT_TRUE(sdk::parseDecimalReal("1.5", v) && v == 1.5);
    EXPECT_TRUE(sdk::parseDecimalReal("-.5", v) && v == -0.5);
    EXPECT_TRUE(sdk::parseDecimalReal("1e3", v) && v == 1000);
    EXPECT_TRUE(sdk::parseDecimalReal("2.", v) && v == 2);
    EXPECT_TRUE(sdk::parseDecimalReal("1e300", v) && v == 1e300);
    for (const char *bad : {"", ".", "nan", ".nan", "inf", ".inf", "0x1p3", "1e", "1e999", "1,5", " 1", "1.5mm"})
        EXPECT_FALSE(sdk::parseDecimalReal(bad, v)) << bad;
    EXPECT_TRUE(sdk::parseDecimalReal(".inf", v, nullptr, true) && std::isinf(v));
    EXPECT_TRUE(sdk::parseDecimalReal(".nan", v, nullptr, true) && std::isnan(v));
    EXPECT_FALSE(fitsInt(1e300));
    EXPECT_FALSE(fitsInt(NAN));
    EXPECT_TRUE(fitsInt(-2147483648.0));
    EXPECT_FALSE(fitsInt(2147483648.0));
    EXPECT_FALSE(fitsInt64(9223372036854775808.0));
}

// One rule for every number (issue 24, "numbers read two ways"): a leading zero or a
// radix prefix is an error for integers and reals alike, with the reading it would get
// elsewhere and the decimal to write.
TEST(Numbers, LeadingZerosAndPrefixesAreErrorsForRealsToo) {
    double v = 0;
    std::string why;
    EXPECT_FALSE(sdk::parseDecimalReal("010", v, &why));
    EXPECT_EQ(why, "expected a decimal number without leading zeros (010 would read as octal 8 elsewhere: write 10)");
    EXPECT_FALSE(sdk::parseDecimalReal("-00.5", v, &why));
    EXPECT_NE(why.find("write -0.5"), std::string::npos) << why;
    EXPECT_FALSE(sdk::parseDecimalReal("0x10", v, &why));
    EXPECT_EQ(why, "expected a decimal number (0x10 is hexadecimal: write 16)");
    for (const char *good : {"0", "0.5", "-0.5", "0e0", "10", "1e05"}) EXPECT_TRUE(sdk::parseDecimalReal(good, v)) << good;
    int64_t i = 0;
    EXPECT_FALSE(sdk::parseDecimalInteger("0x10", i, &why));
    EXPECT_EQ(why, "expected a decimal integer (0x10 is hexadecimal: write 16)");
    EXPECT_FALSE(parseInteger("010", i, &why, 0, 100));
    EXPECT_NE(why.find("octal 8"), std::string::npos) << why;
}

TEST(Text, Utf8PathsAndNames) {
    size_t bad = 0;
    EXPECT_TRUE(isValidUtf8("η3D, εx"));
    EXPECT_FALSE(isValidUtf8("r\xffg", &bad));
    EXPECT_EQ(bad, 1u);
    EXPECT_FALSE(isValidUtf8("\xC0\xAF"));         // overlong '/'
    EXPECT_FALSE(isValidUtf8("\xED\xA0\x80"));     // surrogate
    EXPECT_FALSE(isValidUtf8("\xF4\x90\x80\x80")); // > U+10FFFF
    EXPECT_EQ(sanitizeUtf8("r\xffg"), "r\xEF\xBF\xBDg");
    EXPECT_EQ(sdk::printable("a\nb\x01"), "a\\nb\\x01");
    EXPECT_EQ(sdk::printable(std::string(100, 'x'), 4), "xxxx... (100 bytes)");
    EXPECT_TRUE(sdk::isConfinedRelativePath("left/000001.png"));
    EXPECT_TRUE(sdk::isConfinedRelativePath("a..b/c"));
    for (const char *bad : {"", "/etc/passwd", "../x", "a/../../b", "a/..", ".."})
        EXPECT_FALSE(sdk::isConfinedRelativePath(bad)) << bad;
    EXPECT_TRUE(isSafeName("e1-b150_f8.2"));
    for (const char *bad : {"", ".", "..", "/x", "a/b", "a b", "../x", ".hidden"}) EXPECT_FALSE(isSafeName(bad)) << bad;
}

std::vector<uint8_t> encode(const std::string &ext, const cv::Mat &m) {
    std::vector<uint8_t> out;
    EXPECT_TRUE(cv::imencode(ext, m, out));
    return out;
}

TEST(Text, XmlEscapeKeepsMarkupOutAndDropsWhatXmlRefuses) {
    EXPECT_EQ(xmlEscape("a<b>&\"c'"), "a&lt;b&gt;&amp;&quot;c&apos;");
    EXPECT_EQ(xmlEscape(std::string("bell\x07 nul", 9) + '\0' + "end"), "bell  nul end");
    EXPECT_EQ(xmlEscape("tab\tline\nreturn\r"), "tab\tline\nreturn\r");
    EXPECT_EQ(xmlEscape("sch\xC3\xA4rfe"), "sch\xC3\xA4rfe"); // UTF-8 passes as it is
}

TEST(ImageFile, HeadersGiveTheSizeAndCutFilesAreRefused) {
    cv::Mat m(48, 64, CV_8UC3);
    cv::randu(m, 0, 255);
    for (const char *ext : {".png", ".jpg", ".bmp", ".ppm", ".pgm"}) {
        const cv::Mat img = std::string(ext) == ".pgm" ? m.reshape(1, 48).colRange(0, 64).clone() : m;
        const auto bytes = encode(ext, img);
        ImageInfo info;
        std::string problem;
        ASSERT_TRUE(inspectImage(bytes.data(), bytes.size(), info, problem)) << ext << ": " << problem;
        EXPECT_EQ(info.width, 64) << ext;
        EXPECT_EQ(info.height, 48) << ext;
        // Cut short: refused, and the reason says so.
        ASSERT_FALSE(inspectImage(bytes.data(), bytes.size() * 2 / 3, info, problem)) << ext;
        EXPECT_NE(problem.find("cut short"), std::string::npos) << ext << ": " << problem;
    }
}

TEST(ImageFile, ClaimedSizesAreCheckedBeforeDecoding) {
    // A PFM header of 20 bytes that claims 65536 x 65536: refused from the header.
    const std::string pfm = "Pf\n65536 65536\n-1.0\n";
    ImageInfo info;
    std::string problem;
    EXPECT_FALSE(inspectImage(reinterpret_cast<const uint8_t *>(pfm.data()), pfm.size(), info, problem));
    EXPECT_EQ(problem, "header claims 65536x65536 pixels; the limit is 32768 pixels a side");
    const std::string small = "Pf\n2 2\n-1.0\n" + std::string(16, '\0');
    EXPECT_TRUE(inspectImage(reinterpret_cast<const uint8_t *>(small.data()), small.size(), info, problem)) << problem;
    EXPECT_EQ(info.dataOffset, small.size() - 16);
    EXPECT_LT(info.scale, 0);
    // A PNG whose IHDR claims 30000 x 30000.
    cv::Mat m(4, 4, CV_8UC1, cv::Scalar(1));
    auto png = encode(".png", m);
    for (int k : {16, 20}) png[k] = 0, png[k + 1] = 0, png[k + 2] = 0x75, png[k + 3] = 0x30; // 30000
    EXPECT_FALSE(inspectImage(png.data(), png.size(), info, problem));
    EXPECT_EQ(problem, "header claims 30000x30000 pixels; the limit is 67108864 pixels in all");
}

TEST(ImageFile, PgmHeaderIsReadAsOpenCvReadsIt) {
    // Found by image_header_fuzz: a comment ending in a carriage return. netpbm's rule
    // (comment to the end of the line) gives 1x2 with maximum 25; OpenCV ends the comment
    // at '\r' and decodes 3x1 with maximum 2. The check must see what OpenCV decodes.
    const std::string pgm = "P5\n# c\r 3\n\n1 2\n25\n";
    const auto *bytes = reinterpret_cast<const uint8_t *>(pgm.data());
    ImageInfo info;
    std::string problem;
    ASSERT_TRUE(inspectImage(bytes, pgm.size(), info, problem)) << problem;
    EXPECT_EQ(info.width, 3);
    EXPECT_EQ(info.height, 1);
    EXPECT_EQ(info.dataOffset, pgm.size() - 3);
    const cv::Mat m = decodeImage(bytes, pgm.size(), cv::IMREAD_UNCHANGED, "left image 'x.pgm'");
    EXPECT_EQ(m.cols, 3);
    EXPECT_EQ(m.rows, 1);
    // The limits apply to that reading: "# c\r 40000" is 40000 pixels wide to OpenCV.
    const std::string wide = "P5\n# c\r 40000\n\n1 2\n25\n";
    EXPECT_FALSE(inspectImage(reinterpret_cast<const uint8_t *>(wide.data()), wide.size(), info, problem));
    EXPECT_EQ(problem, "header claims 40000x1 pixels; the limit is 32768 pixels a side");
    // What OpenCV would refuse (a sign, a letter) is refused before decoding.
    for (const std::string bad : {"P5\n+3 1\n255\nabc", "P5\n3 x1\n255\nabc", "P5\n# no end"}) {
        EXPECT_FALSE(inspectImage(reinterpret_cast<const uint8_t *>(bad.data()), bad.size(), info, problem)) << bad;
        EXPECT_NE(problem.find("PGM/PPM header"), std::string::npos) << problem;
    }
    // An ordinary header with a comment still reads as before.
    const std::string plain = "P5\n# Generated by OpenCV\n3 2\n255\nabcdef";
    ASSERT_TRUE(inspectImage(reinterpret_cast<const uint8_t *>(plain.data()), plain.size(), info, problem)) << problem;
    EXPECT_EQ(info.width, 3);
    EXPECT_EQ(info.height, 2);
}

TEST(ImageFile, JpegCutShortAndClosedAgainIsRefused) {
    // Issue 24: a JPEG cut short whose end marker was put back passes the structural check
    // and OpenCV decodes it as grey "successfully" (libjpeg only warns). Refused now, with
    // libjpeg's words.
    cv::Mat m(48, 64, CV_8UC3);
    cv::randu(m, 0, 255);
    auto jpeg = encode(".jpg", m);
    EXPECT_EQ(decodeImage(jpeg.data(), jpeg.size(), cv::IMREAD_COLOR, "whole").size(), m.size());
    jpeg.resize(jpeg.size() * 2 / 3);
    jpeg.push_back(0xFF);
    jpeg.push_back(0xD9);
    ImageInfo info;
    std::string problem;
    ASSERT_TRUE(inspectImage(jpeg.data(), jpeg.size(), info, problem)) << "the structure alone looks whole";
    try {
        decodeImage(jpeg.data(), jpeg.size(), cv::IMREAD_COLOR, "left image 'cut.jpg'");
        FAIL() << "a JPEG cut short was decoded";
    } catch (const ImageFileError &e) {
        EXPECT_EQ(std::string(e.what()), "left image 'cut.jpg': JPEG data is corrupt (libjpeg: \"Corrupt JPEG data: "
                                         "premature end of data segment\"); expected complete, uncorrupted JPEG data");
    }
}

TEST(ImageFile, ReadImageNamesTheFileAndTheReason) {
    const std::string path = ::testing::TempDir() + "cut.png";
    cv::Mat m(32, 32, CV_8UC1, cv::Scalar(9));
    auto png = encode(".png", m);
    std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char *>(png.data()), static_cast<long>(png.size() - 12));
    try {
        readImage(path, cv::IMREAD_UNCHANGED, "left image");
        FAIL() << "a PNG without IEND was decoded";
    } catch (const ImageFileError &e) {
        EXPECT_NE(std::string(e.what()).find("left image '" + path + "': PNG ends at byte"), std::string::npos) << e.what();
        EXPECT_FALSE(e.notFound());
    }
    try {
        readImage(path + ".missing", cv::IMREAD_UNCHANGED);
        FAIL();
    } catch (const ImageFileError &e) {
        EXPECT_TRUE(e.notFound());
    }
}

std::string yamlError(const std::string &text) {
    try {
        parseYaml(text, "x.yaml");
    } catch (const YamlError &e) {
        return e.what();
    }
    return "";
}

TEST(Yaml, DuplicateKeysBadUtf8AndSyntaxSayWhere) {
    EXPECT_EQ(yamlError("a: 1\nb: 2\na: 3\n"), "x.yaml:3:1: key 'a' given twice in one map: first at 1:1, again at 3:1; remove one of them");
    EXPECT_NE(yamlError("m:\n  - {x: 1, y: 2, x: 3}\n").find("x.yaml:2:18: key 'x' given twice"), std::string::npos);
    EXPECT_EQ(yamlError("name: r\xffg\n"), "x.yaml:1:8: byte 0xFF is not valid UTF-8; expected a UTF-8 text (YAML files are UTF-8)");
    EXPECT_NE(yamlError("a: [1, 2\n").find("x.yaml:"), std::string::npos);
    EXPECT_EQ(yamlError("a: 1\nb: {c: 1, d: 2}\n"), "");
    // Whatever follows the first document is read too: a second one is refused, and a
    // broken tail is a syntax error, not silently dropped (YAML::Load stops after one).
    EXPECT_EQ(yamlError("a: 1\n---\nb: 2\n"), "x.yaml:2:1: more follows the first YAML document here; expected one document");
    EXPECT_EQ(yamlError("a: 1\n%YAML 1.2\n[x\n"), "x.yaml:4:1: YAML syntax error: end of sequence flow not found");
    EXPECT_EQ(yamlError(""), "");
    // An alias bomb: each level refers to the one before nine times; checked once each.
    std::ostringstream bomb;
    bomb << "l0: &l0 [a, b, c, d, e, f, g, h, i]\n";
    for (int i = 1; i < 12; ++i) bomb << "l" << i << ": &l" << i << " [*l" << i - 1 << ", *l" << i - 1 << ", *l" << i - 1 << ", *l" << i - 1 << ", *l" << i - 1 << ", *l" << i - 1 << ", *l" << i - 1 << ", *l" << i - 1 << ", *l" << i - 1 << "]\n";
    EXPECT_EQ(yamlError(bomb.str()), "");
}



TEST(Yaml, OneKeyCheckerNamesTheKeyTheNearestAndTheValidOnes) {
    const YAML::Node n = parseYaml("source: x\nmatchr: y\n", "rig.yaml");
    const auto unknown = findUnknownKey(n, {"source", "matcher"});
    ASSERT_TRUE(unknown.has_value());
    EXPECT_EQ(unknown->name, "matchr");
    EXPECT_EQ(unknown->message, "unknown key 'matchr'; did you mean 'matcher'? (valid keys: source, matcher)");
    EXPECT_EQ(located(unknown->key, "rig.yaml"), "rig.yaml:2:1");
    EXPECT_FALSE(findUnknownKey(n, {"source", "matchr"}).has_value());
    const auto owned = findUnknownKey(parseYaml("zzz: 1", "x"), {"block_size"}, "for plugin 'bm'");
    ASSERT_TRUE(owned.has_value());
    EXPECT_EQ(owned->message, "unknown key 'zzz' for plugin 'bm' (valid keys: block_size)");
    try {
        checkKeys(n, {"source"}, "rig", "rig.yaml");
        FAIL() << "an unknown key passed";
    } catch (const YamlError &e) {
        EXPECT_STREQ(e.what(), "rig.yaml:2:1: rig: unknown key 'matchr' (valid keys: source)");
    }
    EXPECT_THROW(checkKeys(parseYaml("[1, 2]", "x"), {"a"}, "list", "x"), YamlError);
    EXPECT_EQ(nearestWord("num_disparity", {"min_disparity", "num_disparities"}), "num_disparities");
    EXPECT_EQ(nearestWord("zzz", {"num_disparities", "block_size"}), "");
}

// Middlebury's PFM files carry the scale -1/255: only its sign counts (little-endian); the
// values are the disparities as stored (OpenCV's codec would give 255 x them).
TEST(ImageFile, PfmScaleGivesTheByteOrderOnlyNeverItsMagnitude) {
    std::string le = "Pf\n2 1\n-0.003922\n";
    for (float v : {12.5f, std::numeric_limits<float>::infinity()}) {
        unsigned char b[4];
        std::memcpy(b, &v, 4); // the host is little-endian (x86-64, arm64)
        le.append(reinterpret_cast<const char *>(b), 4);
    }
    const cv::Mat m = decodePfm(reinterpret_cast<const uint8_t *>(le.data()), le.size(), "mb.pfm");
    EXPECT_EQ(m.at<float>(0, 0), 12.5f);
    EXPECT_TRUE(std::isinf(m.at<float>(0, 1)));
    // Big-endian with a scale of magnitude 255: values unchanged too.
    const unsigned char be[] = {'P', 'f', '\n', '1', ' ', '1', '\n', '2', '5', '5', '\n', 0x41, 0x48, 0, 0};
    EXPECT_EQ(decodePfm(be, sizeof be, "be.pfm").at<float>(0, 0), 12.5f);
    // readImage of a PFM takes the same path.
    const auto path = std::filesystem::temp_directory_path() / "binocle_input_test_scale.pfm";
    { std::ofstream(path, std::ios::binary) << le; }
    EXPECT_EQ(readImage(path.string(), cv::IMREAD_UNCHANGED).at<float>(0, 0), 12.5f);
    std::filesystem::remove(path);
    // The one writer: scale -1, rows bottom to top, read back exactly (grey and colour).
    cv::Mat g = (cv::Mat_<float>(2, 3) << 1, 2, 3, 4, 5, std::numeric_limits<float>::infinity());
    const std::string bytes = encodePfm(g);
    EXPECT_EQ(bytes.substr(0, 10), "Pf\n3 2\n-1\n");
    float first = 0;
    std::memcpy(&first, bytes.data() + 10, 4);
    EXPECT_EQ(first, 4.0f); // the bottom row first
    const cv::Mat gb = decodePfm(reinterpret_cast<const uint8_t *>(bytes.data()), bytes.size(), "g.pfm");
    EXPECT_EQ(cv::countNonZero(gb != g), 0);
    cv::Mat c(2, 2, CV_32FC3, cv::Scalar(1, 2, 3));
    const std::string cbytes = encodePfm(c);
    const cv::Mat cb = decodePfm(reinterpret_cast<const uint8_t *>(cbytes.data()), cbytes.size(), "c.pfm");
    ASSERT_EQ(cb.type(), CV_32FC3);
    EXPECT_EQ(cb.at<cv::Vec3f>(1, 1), cv::Vec3f(1, 2, 3));
}

TEST(ImageFile, OnePfmPathRoundTripsThroughOpenCvsCodec) {
    cv::Mat m(3, 4, CV_32FC1);
    for (int i = 0; i < 12; ++i) m.at<float>(i) = 1.5f * static_cast<float>(i);
    m.at<float>(5) = std::numeric_limits<float>::infinity();
    std::vector<uchar> bytes;
    ASSERT_TRUE(cv::imencode(".pfm", m, bytes));
    const cv::Mat back = decodePfm(bytes.data(), bytes.size(), "x.pfm");
    ASSERT_EQ(back.type(), CV_32FC1);
    EXPECT_EQ(cv::countNonZero(back != m), 0);
    // Big-endian data (a positive scale), rows bottom to top: [1 2] on top of [3 4].
    const unsigned char be[] = {'P', 'f', '\n', '2', ' ', '2', '\n', '1', '.', '0', '\n',
                                0x40, 0x40, 0, 0, 0x40, 0x80, 0, 0, 0x3f, 0x80, 0, 0, 0x40, 0, 0, 0};
    const cv::Mat b = decodePfm(be, sizeof be, "be.pfm");
    EXPECT_EQ(b.at<float>(0, 0), 1.0f);
    EXPECT_EQ(b.at<float>(1, 1), 4.0f);
    // Cut short, claiming more than it holds, or not a PFM: refused with the reason.
    for (size_t cut : {bytes.size() - 1, size_t{8}})
        EXPECT_THROW(decodePfm(bytes.data(), cut, "cut.pfm"), ImageFileError) << cut;
    const std::string huge = "Pf\n65536 65536\n-1.0\n";
    try {
        decodePfm(reinterpret_cast<const uint8_t *>(huge.data()), huge.size(), "huge.pfm");
        FAIL() << "a PFM header claiming 65536 x 65536 was decoded";
    } catch (const ImageFileError &e) {
        EXPECT_NE(std::string(e.what()).find("huge.pfm"), std::string::npos) << e.what();
    }
    std::vector<uchar> png;
    cv::imencode(".png", cv::Mat(2, 2, CV_8UC1, cv::Scalar(1)), png);
    EXPECT_THROW(decodePfm(png.data(), png.size(), "x.png"), ImageFileError);
}

} // namespace
