// SPDX-License-Identifier: MIT
// The HTML report says when the results are not the whole experiment and when an image
// is missing or cut short, instead of leaving them out.
#include "common/test_util.hpp"
#include "report/html_report.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include <filesystem>
#include <fstream>

using binocle::test::TempDir;
using binocle::test::writeText;

namespace {

std::string readAll(const std::string &path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

// A results.json of two tests; `status` as given ("" for none, as older binocle wrote).
void writeResults(const TempDir &dir, const std::string &status) {
    std::string doc = R"({"experiment": "t", "file": "/x/t.yaml", "test_ids": ["1", "2", "3"],)";
    if (!status.empty()) doc += R"("status": ")" + status + R"(",)";
    doc += R"("tests": [{"test": "1", "status": "ok", "eta_3d_percent": 80}, {"test": "2", "status": "ok", "eta_3d_percent": 70}]})";
    writeText(dir.str("results.json"), doc);
}

TEST(HtmlReport, InterruptedAndPartialResultsAreMarkedNotPresentedAsTheWhole) {
    TempDir dir;
    writeResults(dir, "interrupted");
    std::string html = readAll(binocle::report::writeExperimentReport(dir.str()));
    EXPECT_NE(html.find("INCOMPLETE: the run stopped after 2 of 3 tests (status: interrupted)"), std::string::npos);
    writeResults(dir, "partial");
    html = readAll(binocle::report::writeExperimentReport(dir.str()));
    EXPECT_NE(html.find("INCOMPLETE: 2 of 3 tests (status: partial"), std::string::npos);
    writeResults(dir, "complete");
    html = readAll(binocle::report::writeExperimentReport(dir.str()));
    EXPECT_EQ(html.find("INCOMPLETE"), std::string::npos);
    writeResults(dir, ""); // written before binocle said
    html = readAll(binocle::report::writeExperimentReport(dir.str()));
    EXPECT_EQ(html.find("INCOMPLETE"), std::string::npos);
}

TEST(HtmlReport, ATruncatedImageIsNamedAndAMissingOneCounted) {
    TempDir dir;
    writeResults(dir, "complete");
    std::filesystem::create_directories(dir.str("test_1"));
    std::filesystem::create_directories(dir.str("test_2"));
    const cv::Mat image(20, 30, CV_8UC3, cv::Scalar(10, 200, 30));
    ASSERT_TRUE(cv::imwrite(dir.str("test_1/disparity_color_000000.png"), image));
    ASSERT_TRUE(cv::imwrite(dir.str("test_2/disparity_color_000000.png"), image));
    const std::string whole = readAll(dir.str("test_2/disparity_color_000000.png"));
    writeText(dir.str("test_2/disparity_color_000000.png"), whole.substr(0, whole.size() - 20)); // cut short
    const std::string html = readAll(binocle::report::writeExperimentReport(dir.str()));
    EXPECT_NE(html.find("test_2/disparity_color_000000.png is truncated or not a PNG"), std::string::npos);
    EXPECT_NE(html.find("alt=\"test 1 disparity\""), std::string::npos); // the whole one is shown
    EXPECT_EQ(html.find("alt=\"test 2 disparity\""), std::string::npos);
    // Each test lacks its three density views; test 2's disparity is unreadable.
    EXPECT_NE(html.find("images: 6 missing, 1 unreadable"), std::string::npos);
}

} // namespace
