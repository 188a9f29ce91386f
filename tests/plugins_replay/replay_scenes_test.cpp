// SPDX-License-Identifier: MIT
// The replay source on scene folders of every public layout, each built here in the
// dataset's exact encoding: MiddEval3/2014 (PFM with scale -1/255, mask0nocc.png),
// 2005/2006 (view1/view5, disp1.png at the size's scale), 2001/2003 and the v2 evaluation
// (imL/imR, im2/im6, a 4-bit palette groundtruth.png like Tsukuba's, nonocc/all/disc),
// KITTI 2012 and 2015 (noc and occ); and the shared stereo-gt folder when it is there.
#include "replay_fixture.hpp"

#include <opencv2/imgcodecs.hpp>

#include <array>
#include <cmath>
#include <limits>

namespace {

class Scenes : public Replay {};

// PFM as Middlebury writes it: little-endian, the scale field "-0.003922" (-1/255).
void writeMiddleburyPfm(const fs::path &p, const cv::Mat &m) {
    std::ofstream out(p, std::ios::binary);
    out << "Pf\n" << m.cols << " " << m.rows << "\n-0.003922\n";
    for (int v = m.rows - 1; v >= 0; --v) out.write(reinterpret_cast<const char *>(m.ptr<float>(v)), 4 * m.cols);
}

uint32_t crc32(const std::string &bytes) {
    uint32_t c = 0xFFFFFFFFu;
    for (unsigned char b : bytes) {
        c ^= b;
        for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
    }
    return ~c;
}

std::string be32(uint32_t v) {
    return {static_cast<char>(v >> 24), static_cast<char>(v >> 16), static_cast<char>(v >> 8), static_cast<char>(v)};
}

std::string chunk(const std::string &type, const std::string &data) {
    return be32(static_cast<uint32_t>(data.size())) + type + data + be32(crc32(type + data));
}

// A 4-bit palette PNG (colour type 3, bit depth 4) with a grey palette of 16 entries
// 0, 16, ... 240, as Tsukuba's groundtruth.png: `values` are multiples of 16. The image
// data is zlib with stored (uncompressed) deflate blocks.
void writePalette4Png(const fs::path &p, const cv::Mat &values) {
    std::string raw;
    for (int v = 0; v < values.rows; ++v) {
        raw += '\0'; // filter: none
        for (int u = 0; u < values.cols; u += 2) {
            const int hi = values.at<uint8_t>(v, u) / 16, lo = u + 1 < values.cols ? values.at<uint8_t>(v, u + 1) / 16 : 0;
            raw += static_cast<char>(hi << 4 | lo);
        }
    }
    std::string z = "\x78\x01";
    for (size_t pos = 0; pos < raw.size() || pos == 0; pos += 65535) {
        const size_t n = std::min<size_t>(65535, raw.size() - pos);
        z += static_cast<char>(pos + n >= raw.size() ? 1 : 0);
        z += {static_cast<char>(n & 0xFF), static_cast<char>(n >> 8), static_cast<char>(~n & 0xFF), static_cast<char>((~n >> 8) & 0xFF)};
        z += raw.substr(pos, n);
        if (pos + n >= raw.size()) break;
    }
    uint32_t a = 1, b = 0;
    for (unsigned char c : raw) a = (a + c) % 65521, b = (b + a) % 65521;
    z += be32(b << 16 | a);
    std::string palette;
    for (int i = 0; i < 16; ++i) palette += std::string(3, static_cast<char>(16 * i));
    const std::string ihdr = be32(values.cols) + be32(values.rows) + std::string("\x04\x03\x00\x00\x00", 5);
    std::ofstream(p, std::ios::binary) << std::string("\x89PNG\r\n\x1a\n", 8) << chunk("IHDR", ihdr) << chunk("PLTE", palette)
                                       << chunk("IDAT", z) << chunk("IEND", "");
}

void writePair(const fs::path &folder, const std::string &left, const std::string &right, cv::Size size) {
    write(folder / left, noise(size, CV_8UC3, 1));
    write(folder / right, noise(size, CV_8UC3, 2));
}

std::unique_ptr<binocle::LentFrame> grabOne(Source &src) {
    auto f = src.grab();
    EXPECT_TRUE(f);
    return f;
}

TEST_F(Scenes, MiddEval3PfmScaleIsTheByteOrderOnlyAndMask0noccGivesGtNonocc) {
    const fs::path scene = path("trainingQ/Adirondack");
    writePair(scene, "im0.png", "im1.png", {32, 6});
    writeText(scene / "calib.txt", "cam0=[100 0 16; 0 100 3; 0 0 1]\ncam1=[100 0 18; 0 100 3; 0 0 1]\ndoffs=2\n"
                                   "baseline=176.252\nwidth=32\nheight=6\nndisp=32\n");
    cv::Mat d(6, 32, CV_32FC1, cv::Scalar(12.5f));
    d.at<float>(0, 0) = std::numeric_limits<float>::infinity(); // unknown
    d.at<float>(5, 31) = 30.25f;
    writeMiddleburyPfm(scene / "disp0GT.pfm", d);
    cv::Mat mask(6, 32, CV_8UC1, cv::Scalar(255));
    mask.at<uint8_t>(0, 0) = 0;   // unknown
    mask.at<uint8_t>(2, 3) = 128; // occluded
    write(scene / "mask0nocc.png", mask);

    auto src = open("{folder: " + path("trainingQ").string() + "}"); // a folder of scenes, detected
    auto f = grabOne(*src);
    ASSERT_TRUE(f);
    const cv::Mat gt = f->extra("gt_disparity");
    EXPECT_FLOAT_EQ(gt.at<float>(1, 1), 12.5f); // not 255 x 12.5
    EXPECT_FLOAT_EQ(gt.at<float>(5, 31), 30.25f);
    EXPECT_LE(gt.at<float>(0, 0), 0.0f);
    const cv::Mat nonocc = f->extra("gt_nonocc");
    ASSERT_EQ(nonocc.type(), CV_8UC1);
    EXPECT_EQ(cv::countNonZero(nonocc), 32 * 6 - 2); // neither the unknown nor the occluded pixel
    EXPECT_EQ(nonocc.at<uint8_t>(2, 3), 0);
    const YAML::Node m = metadataOf(*f);
    EXPECT_EQ(m["dataset"].as<std::string>(), "middlebury-2014");
    EXPECT_EQ(m["ground_truth_divisor"].as<double>(), 1.0);
    EXPECT_EQ(m["scene"].as<std::string>(), "Adirondack");
    EXPECT_NEAR(m["baseline_mm"].as<double>(), 176.252, 1e-9);
}

TEST_F(Scenes, Middlebury2014Disp0WithoutMaskHasNoNonoccPlane) {
    writePair(path("Piano"), "im0.png", "im1.png", {16, 4});
    writeMiddleburyPfm(path("Piano/disp0.pfm"), cv::Mat(4, 16, CV_32FC1, cv::Scalar(7.5f)));
    auto src = open("{folder: " + path("Piano").string() + ", nominal_calibration: true}");
    auto f = grabOne(*src);
    ASSERT_TRUE(f);
    EXPECT_EQ(f->raw().extra_count, 2); // gt_disparity, gt_valid
    EXPECT_FLOAT_EQ(f->extra("gt_disparity").at<float>(3, 15), 7.5f);
    // No calib.txt: the nominal calibration asked for, of the image's size.
    cv::FileStorage fs(src->calibration(), cv::FileStorage::READ | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
    EXPECT_EQ(static_cast<int>(fs["image_width"]), 16);
    EXPECT_EQ(static_cast<double>(fs["baseline_mm"]), 1.0);
}

TEST_F(Scenes, Middlebury2005And2006StoreFullSizeDisparitiesDividedBySize) {
    for (const auto &[rows, divisor] : std::vector<std::pair<int, double>>{{555, 2}, {370, 3}, {1110, 1}}) {
        const fs::path scene = path("Art" + std::to_string(rows));
        writePair(scene, "view1.png", "view5.png", {240, rows});
        cv::Mat raw(rows, 240, CV_8UC1, cv::Scalar(150));
        raw.at<uint8_t>(0, 0) = 0;
        write(scene / "disp1.png", raw);
        write(scene / "disp5.png", raw);
        auto src = open("{folder: " + scene.string() + ", nominal_calibration: true}");
        auto f = grabOne(*src);
        ASSERT_TRUE(f);
        EXPECT_FLOAT_EQ(f->extra("gt_disparity").at<float>(1, 1), static_cast<float>(150 / divisor)) << rows;
        EXPECT_EQ(f->extra("gt_valid").at<uint8_t>(0, 0), 0);
        EXPECT_EQ(metadataOf(*f)["dataset"].as<std::string>(), "middlebury-2005/2006");
        EXPECT_EQ(metadataOf(*f)["ground_truth_divisor"].as<double>(), divisor);
    }
    // A size the rule does not know: refused, naming the file and the way out.
    writePair(path("Odd"), "view1.png", "view5.png", {240, 100});
    write(path("Odd/disp1.png"), cv::Mat(100, 240, CV_8UC1, cv::Scalar(40)));
    const std::string e = openError("{folder: " + path("Odd").string() + "}");
    EXPECT_NE(e.find("disp1.png"), std::string::npos) << e;
    EXPECT_NE(e.find("ground_truth_scale"), std::string::npos) << e;
    // ground_truth_scale set replaces the rule.
    auto src = open("{folder: " + path("Odd").string() + ", ground_truth_scale: 0.25, nominal_calibration: true}");
    auto f = grabOne(*src);
    ASSERT_TRUE(f);
    EXPECT_FLOAT_EQ(f->extra("gt_disparity").at<float>(1, 1), 10.0f);
}

TEST_F(Scenes, MiddleburyV2TsukubaPalettePngWithNonoccAllAndDiscMasks) {
    const fs::path scene = path("tsukuba");
    const cv::Size size(384, 288);
    writePair(scene, "imL.png", "imR.png", size);
    cv::Mat values(size, CV_8UC1, cv::Scalar(5 * 16)); // d = 5
    values(cv::Rect(0, 0, 100, 50)).setTo(14 * 16);     // d = 14
    values.at<uint8_t>(200, 200) = 0;                   // unknown
    writePalette4Png(scene / "groundtruth.png", values);
    ASSERT_EQ(cv::imread((scene / "groundtruth.png").string(), cv::IMREAD_UNCHANGED).channels(), 3); // a real palette PNG
    cv::Mat all(size, CV_8UC1, cv::Scalar(255)), nonocc, disc(size, CV_8UC1, cv::Scalar(128));
    all.row(0).setTo(0); // the border left out of "all"
    nonocc = all.clone();
    nonocc(cv::Rect(10, 10, 4, 4)).setTo(0); // occluded
    disc(cv::Rect(20, 20, 2, 3)).setTo(255);
    write(scene / "all.png", all);
    write(scene / "nonocc.png", nonocc);
    write(scene / "disc.png", disc);

    auto src = open("{folder: " + scene.string() + ", nominal_calibration: true}");
    auto f = grabOne(*src);
    ASSERT_TRUE(f);
    const cv::Mat gt = f->extra("gt_disparity");
    EXPECT_FLOAT_EQ(gt.at<float>(100, 300), 5.0f);
    EXPECT_FLOAT_EQ(gt.at<float>(10, 10), 14.0f);
    EXPECT_LE(gt.at<float>(200, 200), 0.0f);
    const int known = size.area() - 1 - size.width; // less the unknown pixel and the border row
    EXPECT_EQ(cv::countNonZero(f->extra("gt_valid")), known);
    EXPECT_EQ(cv::countNonZero(f->extra("gt_nonocc")), known - 16);
    EXPECT_EQ(cv::countNonZero(f->extra("gt_disc")), 6);
    EXPECT_EQ(metadataOf(*f)["ground_truth_divisor"].as<double>(), 16.0);
}

TEST_F(Scenes, Middlebury2001And2003Im2Im6ByTheirSizes) {
    for (const auto &[w, h, divisor] : std::vector<std::array<int, 3>>{{434, 383, 8}, {450, 375, 4}, {900, 750, 2}}) {
        const fs::path scene = path("s" + std::to_string(h));
        writePair(scene, "im2.png", "im6.png", {w, h});
        write(scene / "disp2.png", cv::Mat(h, w, CV_8UC1, cv::Scalar(120)));
        auto src = open("{folder: " + scene.string() + ", nominal_calibration: true}");
        auto f = grabOne(*src);
        ASSERT_TRUE(f);
        EXPECT_FLOAT_EQ(f->extra("gt_disparity").at<float>(0, 0), 120.0f / static_cast<float>(divisor)) << h;
        EXPECT_EQ(f->raw().extra_count, 2) << "no masks in a 2001/2003 scene folder";
    }
    // Tsukuba as first published: PPM views, a PGM ground truth x16.
    writePair(path("tsukuba"), "scene1.row3.col3.ppm", "scene1.row3.col4.ppm", {384, 288});
    write(path("tsukuba/truedisp.row3.col3.pgm"), cv::Mat(288, 384, CV_8UC1, cv::Scalar(7 * 16)));
    auto src = open("{folder: " + path("tsukuba").string() + ", nominal_calibration: true}");
    auto f = grabOne(*src);
    ASSERT_TRUE(f);
    EXPECT_FLOAT_EQ(f->extra("gt_disparity").at<float>(5, 5), 7.0f);
    EXPECT_EQ(metadataOf(*f)["ground_truth_divisor"].as<double>(), 16.0);
}

TEST_F(Scenes, KittiPairFolderAnd2012TreeGiveNocAsGtNonocc) {
    const cv::Size size(60, 8);
    cv::Mat occ(size, CV_16UC1, cv::Scalar(20 * 256 + 128)), noc = occ.clone();
    occ.at<uint16_t>(0, 0) = 0;
    noc.colRange(0, 10).setTo(0); // occluded at the left border
    // A pair in a folder of its own, as ../shared/data/stereo-gt/kitti2012-000070.
    const fs::path pair = path("pairs/kitti-000070");
    writePair(pair, "left.png", "right.png", size);
    write(pair / "disp_occ_000070_10.png", occ);
    write(pair / "disp_noc_000070_10.png", noc);
    // KITTI 2012's training tree.
    const fs::path tree = path("kitti2012");
    writePair(tree, "image_0/000070_10.png", "image_1/000070_10.png", size);
    write(tree / "disp_occ/000070_10.png", occ);
    write(tree / "disp_noc/000070_10.png", noc);
    for (const fs::path &folder : {path("pairs"), tree}) {
        auto src = open("{folder: " + folder.string() + ", nominal_calibration: true}");
        auto f = grabOne(*src);
        ASSERT_TRUE(f);
        EXPECT_FLOAT_EQ(f->extra("gt_disparity").at<float>(4, 30), 20.5f) << folder;
        EXPECT_EQ(cv::countNonZero(f->extra("gt_valid")), size.area() - 1) << folder;
        EXPECT_EQ(cv::countNonZero(f->extra("gt_nonocc")), size.area() - 10 * size.height) << folder;
    }
}

TEST_F(Scenes, GroundTruthThatCannotBeADisparityOfTheImageIsRefused) {
    // The fault: a MiddEval3 PFM read by its scale's magnitude gives 255 x d.
    writePair(path("big"), "im0.png", "im1.png", {32, 4});
    writeMiddleburyPfm(path("big/disp0GT.pfm"), cv::Mat(4, 32, CV_32FC1, cv::Scalar(26.5f * 255)));
    auto src = open("{folder: " + path("big").string() + ", nominal_calibration: true}");
    try {
        src->grab();
        FAIL() << "a ground truth beyond the image width was delivered";
    } catch (const binocle::Error &e) {
        EXPECT_NE(std::string(e.what()).find("disp0GT.pfm"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("width 32"), std::string::npos) << e.what();
    }
    writePair(path("neg"), "im0.png", "im1.png", {32, 4});
    cv::Mat d(4, 32, CV_32FC1, cv::Scalar(3.0f));
    d.at<float>(1, 2) = -4.0f;
    writeMiddleburyPfm(path("neg/disp0GT.pfm"), d);
    auto neg = open("{folder: " + path("neg").string() + ", nominal_calibration: true}");
    try {
        neg->grab();
        FAIL() << "a negative ground truth was delivered";
    } catch (const binocle::Error &e) {
        EXPECT_NE(std::string(e.what()).find("negative"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("disp0GT.pfm"), std::string::npos) << e.what();
    }
}

// The shared folder of 19 public pairs (never copied into the repository): every pair is
// detected by its ground truth's name and read at the scale its manifest states.
TEST_F(Scenes, SharedStereoGtPairsAtTheirManifestScale) {
    const fs::path shared = fs::path(BINOCLE_SOURCE_DIR) / ".." / "shared" / "data" / "stereo-gt";
    if (!fs::exists(shared / "manifest.json")) GTEST_SKIP() << shared << " is not there";
    const YAML::Node manifest = YAML::LoadFile((shared / "manifest.json").string()); // JSON is YAML
    auto src = open("{folder: " + shared.string() + ", nominal_calibration: true, color: gray}");
    size_t seen = 0;
    while (auto f = src->grab()) {
        const YAML::Node m = metadataOf(*f);
        YAML::Node pair;
        for (const YAML::Node p : manifest)
            if (p["name"].as<std::string>() == m["scene"].as<std::string>()) pair.reset(p);
        ASSERT_TRUE(pair) << m["scene"];
        EXPECT_EQ(m["ground_truth_divisor"].as<double>(), pair["gt_scale"].as<double>()) << pair["name"];
        const bool masked = pair["masks"].IsMap() && pair["masks"].size() > 0;
        const bool kitti = pair["gt_format"].as<std::string>() == "png16";
        EXPECT_EQ(f->raw().extra_count, masked || kitti ? (pair["masks"]["disc.png"] ? 4 : 3) : 2) << pair["name"];
        ++seen;
    }
    EXPECT_EQ(seen, 19u);
}

} // namespace
