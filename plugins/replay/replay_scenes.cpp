// SPDX-License-Identifier: MIT
// Scene folders of the public stereo datasets (see replay_scenes.hpp and README.md).
#include "replay_scenes.hpp"

#include "replay_files.hpp"

#include "input/image_file.hpp"

#include <binocle/plugin.hpp>

#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace binocle::replay {

using sdk::Error;

namespace {

struct PairNames {
    const char *left, *right;
};
// In the order looked for; the first pair present names the scene's images.
constexpr PairNames kPairs[] = {{"im0", "im1"},   {"view1", "view5"}, {"imL", "imR"}, {"im2", "im6"},
                                 {"scene1.row3.col3", "scene1.row3.col4"}, // Tsukuba as first published
                                 {"left", "right"}};

fs::path imageNamed(const fs::path &folder, const std::string &stem) {
    for (const char *ext : {".png", ".ppm", ".pgm", ".jpg", ".bmp", ".tif"})
        if (fs::is_regular_file(folder / (stem + ext))) return folder / (stem + ext);
    return {};
}

// How a dataset stores its disparities.
enum class Rule {
    AsStored,  // PFM (2014, MiddEval3): the floats are the disparities
    BySize2005, // 2005/2006 PNG: full-size disparities, divided by the size's factor
    BySizeV2,   // 2001/2003 and the v2 evaluation: value / factor of the scene and size
    Kitti,      // 16-bit PNG: value / 256
};

struct TruthName {
    const char *file;
    Rule rule;
    const char *dataset;
};
constexpr TruthName kTruths[] = {
    {"disp0GT.pfm", Rule::AsStored, "middlebury-2014"}, // MiddEval3's name
    {"disp0.pfm", Rule::AsStored, "middlebury-2014"},
    {"disp1.png", Rule::BySize2005, "middlebury-2005/2006"},
    {"groundtruth.png", Rule::BySizeV2, "middlebury-2001/2003"}, // the v2 evaluation's name
    {"disp2.png", Rule::BySizeV2, "middlebury-2001/2003"},
    {"disp2.pgm", Rule::BySizeV2, "middlebury-2001/2003"},
    {"truedisp.row3.col3.pgm", Rule::BySizeV2, "middlebury-2001/2003"}, // Tsukuba as first published
};

// The factor the stored values are divided by, from the left image's size.
// 2005/2006: full size is 1110 rows high, half 555, third 370; the files hold full-size
// disparities (the datasets' pages: divide by 2 at half size, by 3 at third size).
// 2001/2003 (v2): Tsukuba (384 x 288) x16; the 2001 scenes (Venus, Sawtooth ..., 380-383
// rows) x8; 2003 Teddy/Cones x4 at quarter size (375 rows), x2 at half (750), x1 full (1500).
double divisorFor(Rule rule, cv::Size size) {
    if (rule == Rule::BySize2005) {
        if (size.height == 1110) return 1;
        if (size.height == 555) return 2;
        if (size.height == 370) return 3;
        return 0;
    }
    if (size == cv::Size(384, 288)) return 16;
    if (size.height >= 380 && size.height <= 383) return 8;
    if (size.height == 375) return 4;
    if (size.height == 750) return 2;
    if (size.height == 1500) return 1;
    return 0;
}

std::string ruleText(Rule rule) {
    return rule == Rule::BySize2005
               ? "Middlebury 2005/2006 stores full-size disparities: 1110 rows (x1), 555 (half, x2) or 370 (third, x3)"
               : "Middlebury 2001/2003 stores disparity x16 (Tsukuba 384x288), x8 (2001, 380-383 rows), x4/x2/x1 (2003 at "
                 "375/750/1500 rows)";
}

// KITTI in a scene folder: disp_occ*.png and disp_noc*.png with the same suffix
// ("disp_occ_000070_10.png"); the noc file alone is ground truth too.
bool kittiTruth(const fs::path &folder, FrameFiles &f) {
    fs::path occ, noc;
    for (const fs::path &p : listFolder(folder, false)) {
        const std::string name = p.filename().string();
        if (p.extension() != ".png") continue;
        if (occ.empty() && name.rfind("disp_occ", 0) == 0) occ = p;
        if (noc.empty() && name.rfind("disp_noc", 0) == 0) noc = p;
    }
    if (occ.empty() && noc.empty()) return false;
    if (!occ.empty()) {
        const fs::path pairNoc = folder / ("disp_noc" + occ.filename().string().substr(8));
        noc = fs::is_regular_file(pairNoc) ? pairNoc : fs::path();
    }
    f.groundTruth = occ.empty() ? noc : occ;
    f.nonoccTruth = noc;
    return true;
}

// A mask of 0/255 (Middlebury's masks, some palette PNGs): 255 where the file holds 255.
cv::Mat readMask(const fs::path &path, cv::Size size) {
    cv::Mat raw;
    try {
        raw = input::readImage(path.string(), cv::IMREAD_GRAYSCALE, "mask");
    } catch (const input::ImageFileError &e) {
        throw Error(e.notFound() ? BINOCLE_ERR_NOT_FOUND : BINOCLE_ERR_IO, std::string("replay: ") + e.what());
    }
    if (raw.size() != size)
        throw Error(BINOCLE_ERR_INVALID_ARGUMENT, "replay: mask " + inQuotes(path) + " is " + std::to_string(raw.cols) + "x" +
                                                      std::to_string(raw.rows) + " but the left image is " +
                                                      std::to_string(size.width) + "x" + std::to_string(size.height));
    cv::Mat m;
    cv::compare(raw, 255, m, cv::CMP_EQ);
    return m;
}

} // namespace

bool isSceneFolder(const fs::path &folder) {
    for (const PairNames &p : kPairs)
        if (!imageNamed(folder, p.left).empty()) return true;
    return false;
}

FrameFiles sceneFrame(const fs::path &folder, double givenScale) {
    FrameFiles f;
    for (const PairNames &p : kPairs) {
        f.left = imageNamed(folder, p.left);
        if (f.left.empty()) continue;
        f.right = imageNamed(folder, p.right);
        if (f.right.empty())
            throw Error(BINOCLE_ERR_NOT_FOUND, "replay: scene " + inQuotes(folder) + " has " + f.left.filename().string() +
                                                   " but no " + p.right + " image (png, ppm, pgm, jpg, bmp or tif)");
        break;
    }
    if (f.left.empty())
        throw Error(BINOCLE_ERR_NOT_FOUND, "replay: folder " + inQuotes(folder) +
                                               " holds no stereo pair: expected im0.png/im1.png, view1/view5, imL/imR, im2/im6 or "
                                               "left/right images");
    f.facts.emplace_back("scene", folder.filename().string());
    const TruthName *truth = nullptr;
    for (const TruthName &t : kTruths)
        if (!truth && fs::is_regular_file(folder / t.file)) truth = &t;
    std::string dataset;
    double divisor = 1;
    if (truth) {
        f.groundTruth = folder / truth->file;
        dataset = truth->dataset;
        if (truth->rule == Rule::AsStored) {
            if (fs::is_regular_file(folder / "mask0nocc.png")) f.nonoccMask = folder / "mask0nocc.png";
        } else {
            divisor = divisorFor(truth->rule, imageSizeOf(f.left));
            if (divisor == 0 && !(givenScale > 0)) {
                const cv::Size size = imageSizeOf(f.left);
                throw Error(BINOCLE_ERR_INVALID_ARGUMENT,
                            "replay: ground truth " + inQuotes(f.groundTruth) + ": the left image is " +
                                std::to_string(size.width) + "x" + std::to_string(size.height) +
                                ", a size whose disparity scale the dataset's rule does not give (" + ruleText(truth->rule) +
                                "); set ground_truth_scale (1 / the factor)");
            }
            if (truth->rule == Rule::BySizeV2) {
                const std::pair<const char *, fs::path *> masks[] = {
                    {"nonocc.png", &f.nonoccMask}, {"all.png", &f.allMask}, {"disc.png", &f.discMask}};
                for (const auto &[name, mask] : masks)
                    if (fs::is_regular_file(folder / name)) *mask = folder / name;
            }
        }
    } else if (kittiTruth(folder, f)) {
        dataset = "kitti";
    }
    f.groundTruthScale = givenScale > 0 ? givenScale : 1.0 / divisor;
    if (dataset == "kitti") divisor = 256; // the fact: 16-bit PNGs are divided by 256 as they are decoded
    if (!f.groundTruth.empty()) {
        f.facts.emplace_back("dataset", dataset);
        std::ostringstream d;
        d << (givenScale > 0 ? 1.0 / givenScale : divisor);
        f.facts.emplace_back("ground_truth_divisor", d.str());
    }
    return f;
}

std::vector<fs::path> sceneFolders(const std::string &folder) {
    std::vector<fs::path> scenes;
    if (hasWildcard(folder)) {
        for (fs::path &p : globPaths(folder))
            if (fs::is_directory(p)) scenes.push_back(std::move(p));
        if (scenes.empty())
            throw Error(BINOCLE_ERR_NOT_FOUND, "replay: folder pattern '" + folder + "' matched no folder");
        for (const fs::path &p : scenes)
            if (!isSceneFolder(p))
                throw Error(BINOCLE_ERR_NOT_FOUND, "replay: folder pattern '" + folder + "' matched " + inQuotes(p) +
                                                       ", which holds no stereo pair; expected scene folders "
                                                       "(im0.png/im1.png, view1/view5, imL/imR, im2/im6 or left/right)");
        return scenes;
    }
    if (!fs::is_directory(folder))
        throw Error(BINOCLE_ERR_NOT_FOUND, "replay: folder '" + folder + "' does not exist or is not a folder");
    if (isSceneFolder(folder)) return {fs::path(folder)};
    for (fs::path &p : listFolder(folder, true))
        if (isSceneFolder(p)) scenes.push_back(std::move(p));
    if (scenes.empty())
        throw Error(BINOCLE_ERR_NOT_FOUND, "replay: folder '" + folder +
                                               "' holds no stereo pair (im0.png/im1.png, view1/view5, imL/imR, im2/im6 or "
                                               "left/right), nor any sub-folder that does; expected a scene folder");
    return scenes;
}

FrameTruth readFrameTruth(const FrameFiles &frame, cv::Size leftSize) {
    auto checkSize = [&](const cv::Mat &m, const fs::path &file) {
        if (m.size() != leftSize)
            throw Error(BINOCLE_ERR_INVALID_ARGUMENT, "replay: ground truth " + inQuotes(file) + " is " +
                                                          std::to_string(m.cols) + "x" + std::to_string(m.rows) +
                                                          " but left image " + inQuotes(frame.left) + " is " +
                                                          std::to_string(leftSize.width) + "x" +
                                                          std::to_string(leftSize.height));
    };
    GroundTruth gt = readGroundTruth(frame.groundTruth, frame.groundTruthScale, leftSize.width);
    checkSize(gt.disparity, frame.groundTruth);
    FrameTruth t;
    t.disparity = gt.disparity;
    t.valid = gt.valid;
    if (!frame.allMask.empty()) t.valid &= readMask(frame.allMask, leftSize);
    if (!frame.nonoccMask.empty()) {
        t.nonocc = readMask(frame.nonoccMask, leftSize) & t.valid;
    } else if (!frame.nonoccTruth.empty()) {
        GroundTruth noc = readGroundTruth(frame.nonoccTruth, frame.groundTruthScale, leftSize.width);
        checkSize(noc.valid, frame.nonoccTruth);
        t.nonocc = noc.valid & t.valid;
    }
    if (!frame.discMask.empty()) t.disc = readMask(frame.discMask, leftSize) & t.valid;
    return t;
}

} // namespace binocle::replay
