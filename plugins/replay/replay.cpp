// SPDX-License-Identifier: MIT
// replay: a StereoSource that plays stereo pairs back from files: glob patterns,
// Middlebury scenes, a KITTI tree or a folder written by `binocle record`.
//
// Read top to bottom: settings, the layouts (what a layout yields is in replay_plan.hpp;
// the rosbag2 MCAP bags of layout mcap in replay_mcap.hpp) and their detection, the
// source itself, and the registration line at the very end. The file formats are
// described in README.md.
#include "replay_files.hpp"
#include "replay_metadata.hpp"
#include "replay_plan.hpp"
#include "replay_scenes.hpp"

#include "common/frame_pacer.hpp"
#include "input/image_file.hpp"

#include <binocle/plugin.hpp>
#include <binocle/recording.hpp>
#include <binocle/settings.hpp>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace fs = std::filesystem;

namespace binocle::replay {
namespace {

using plugins::FramePacer;
using sdk::Error;

// ---- Settings ----------------------------------------------------------------------------

std::vector<binocle_param_desc> parameterTable() {
    using sdk::Param;
    return {
        Param::choice("layout", "auto", "auto|glob|middlebury|kitti|recording|mcap")
            .help("how the files are laid out; auto: glob when left/right are set, else detected from folder"),
        Param::path("left", "").help("glob layout: pattern of the left images, e.g. /data/run1/left_*.png"),
        Param::path("right", "").help("glob layout: pattern of the right images, as many as the left ones"),
        Param::path("ground_truth", "")
            .help("glob layout: pattern of disparity images (16-bit PNG d*256, 8-bit PNG d, PFM), one per pair"),
        Param::real("ground_truth_scale", "1").min(0)
            .help("ground-truth disparities are multiplied by this after decoding; set, it replaces a dataset's own rule"),
        Param::path("folder", "")
            .help("middlebury (a scene folder, a folder of scenes or a glob over scene folders), kitti or recording folder"),
        Param::path("bag", "").help("mcap: a rosbag2 MCAP file (.mcap) or a rosbag2 folder (metadata.yaml)"),
        Param::string("left_topic", "").help("mcap: the left image topic (default: the bag's */left/X + */right/X pair)"),
        Param::string("right_topic", "").help("mcap: the right image topic"),
        Param::real("pair_tolerance_ms", "5").min(0).unit("ms")
            .help("mcap: largest difference of the header stamps of a pair; images without a partner are counted"),
        Param::real("start_s", "0").min(0).unit("s").help("mcap: play from this time after the bag's first message"),
        Param::real("duration_s", "0").min(0).unit("s").help("mcap: play this long (0 = to the end)"),
        Param::boolean("nominal_calibration", false)
            .help("middlebury: a scene without calibration files gets a nominal rectified one (f = width px, B = 1 mm): "
                  "disparities only, ranges meaningless"),
        Param::path("calibration", "")
            .help("OpenCV FileStorage YAML calibration that replaces the one the layout provides"),
        Param::boolean("loop", false).help("start again from the first frame after the last one"),
        Param::integer("first_frame", "0").min(0).help("index of the first frame played, in the layout's order"),
        Param::integer("max_frames", "0").min(0).help("play at most this many frames (0 = all)"),
        Param::choice("color", "bgr", "gray|bgr").help("deliver BGR8 or GRAY8 images"),
        Param::real("rate_hz", "0").min(0).unit("Hz")
            .help("pace grab to this rate; 0 = as fast as possible (time stamps then use a nominal 30 Hz)"),
    };
}

struct Settings {
    std::string layout = "auto";
    std::string left, right, groundTruth, folder, calibration;
    double groundTruthScale = 1.0;
    bool groundTruthScaleGiven = false; // replaces the scale rule of a dataset's scene folders
    bool nominalCalibration = false;
    bool loop = false;
    int64_t firstFrame = 0, maxFrames = 0;
    bool gray = false;
    double rateHz = 0.0;
    McapSettings bag;
};


// The table above is the one home of each setting's default, bounds and choices: the
// SDK checked `c` against it before the constructor (a setting the host did not pass is
// its default). Only the rules it cannot state are written here.
Settings readSettings(const sdk::CheckedParams &c) {
    Settings s;
    // An unset PATH is empty whatever the host made of the empty default.
    auto path = [&](const char *name, std::string &out) {
        if (c.isExplicit(name)) out = c.string(name);
    };
    s.layout = c.string("layout");
    path("left", s.left);
    path("right", s.right);
    path("ground_truth", s.groundTruth);
    path("folder", s.folder);
    path("calibration", s.calibration);
    s.groundTruthScale = c.real("ground_truth_scale");
    s.groundTruthScaleGiven = c.isExplicit("ground_truth_scale");
    s.nominalCalibration = c.boolean("nominal_calibration");
    s.loop = c.boolean("loop");
    s.firstFrame = c.integer("first_frame");
    s.maxFrames = c.integer("max_frames");
    s.gray = c.string("color") == "gray";
    s.rateHz = c.real("rate_hz");
    path("bag", s.bag.bag);
    if (c.isExplicit("left_topic")) s.bag.leftTopic = c.string("left_topic");
    if (c.isExplicit("right_topic")) s.bag.rightTopic = c.string("right_topic");
    s.bag.pairToleranceMs = c.real("pair_tolerance_ms");
    s.bag.startS = c.real("start_s");
    s.bag.durationS = c.real("duration_s");
    if (!(s.groundTruthScale > 0))
        c.refuse("ground_truth_scale", sdk::settingNumberText(s.groundTruthScale), "a number > 0");
    // Below 1 mHz the frame period (ns) would not fit 64 bits.
    if (s.rateHz > 0 && s.rateHz < 1e-3)
        c.refuse("rate_hz", sdk::settingNumberText(s.rateHz), "0 (as fast as possible) or a rate >= 0.001 Hz");
    return s;
}


// ---- glob layout ---------------------------------------------------------------------------

std::vector<fs::path> globFiles(const std::string &setting, const std::string &pattern) {
    std::vector<fs::path> files;
    for (fs::path &p : globPaths(pattern))
        if (fs::is_regular_file(p)) files.push_back(std::move(p));
    if (files.empty())
        throw Error(BINOCLE_ERR_NOT_FOUND, "replay: " + setting + " pattern '" + pattern + "' matched no file");
    return files;
}

Plan planGlob(const Settings &s) {
    if (s.left.empty() || s.right.empty())
        throw Error(BINOCLE_ERR_INVALID_ARGUMENT,
                    "replay: the glob layout needs both `left` and `right` patterns (left '" + s.left + "', right '" +
                        s.right + "')");
    Plan plan;
    plan.layout = "glob";
    const auto lefts = globFiles("left", s.left);
    const auto rights = globFiles("right", s.right);
    if (lefts.size() != rights.size())
        throw Error(BINOCLE_ERR_INVALID_ARGUMENT, "replay: left pattern '" + s.left + "' matched " +
                                                      std::to_string(lefts.size()) + " files but right pattern '" +
                                                      s.right + "' matched " + std::to_string(rights.size()) +
                                                      "; expected as many right images as left ones");
    std::vector<fs::path> truths;
    if (!s.groundTruth.empty()) {
        truths = globFiles("ground_truth", s.groundTruth);
        if (truths.size() != lefts.size())
            throw Error(BINOCLE_ERR_INVALID_ARGUMENT, "replay: ground_truth pattern '" + s.groundTruth + "' matched " +
                                                          std::to_string(truths.size()) + " files but left pattern '" +
                                                          s.left + "' matched " + std::to_string(lefts.size()) +
                                                          "; expected one ground truth per pair");
    }
    for (size_t i = 0; i < lefts.size(); ++i) {
        FrameFiles f;
        f.left = lefts[i];
        f.right = rights[i];
        if (!truths.empty()) f.groundTruth = truths[i];
        f.groundTruthScale = s.groundTruthScale;
        plan.frames.push_back(std::move(f));
    }
    return plan;
}

// ---- middlebury layout -------------------------------------------------------------------
// Scene folders of the public datasets (replay_scenes.hpp): Middlebury 2001-2014,
// MiddEval3, a KITTI pair in a folder of its own; one scene or a folder of them.

// calib.txt: see replay_metadata.hpp.
PinholePair readMiddleburyCalib(const fs::path &file, const fs::path &leftImage,
                                std::vector<std::pair<std::string, std::string>> &facts) {
    const MiddleburyCalib c = parseMiddleburyCalib(readText(file, "Middlebury calibration"), file.string());
    PinholePair pair;
    pair.M1 = cv::Matx33d(c.cam0.data());
    pair.M2 = cv::Matx33d(c.cam1.data());
    pair.baselineMm = c.baselineMm;
    pair.imageSize = c.width > 0 ? cv::Size(c.width, c.height) : imageSizeOf(leftImage);
    facts.insert(facts.end(), c.facts.begin(), c.facts.end());
    return pair;
}

Plan planMiddlebury(const Settings &s, const sdk::Host &host) {
    Plan plan;
    plan.layout = "middlebury";
    std::vector<std::pair<fs::path, PinholePair>> calibrations;
    for (const fs::path &scene : sceneFolders(s.folder)) {
        FrameFiles f = sceneFrame(scene, s.groundTruthScaleGiven ? s.groundTruthScale : 0.0);
        const fs::path calib = scene / "calib.txt";
        if (fs::is_regular_file(calib)) {
            PinholePair pair = readMiddleburyCalib(calib, f.left, f.facts);
            pair.addFacts(f, calib);
            calibrations.emplace_back(calib, pair);
        } else if (s.calibration.empty() && !s.nominalCalibration) {
            host.warning("replay: scene " + inQuotes(scene) + " has no calib.txt; it brings no calibration");
        }
        plan.frames.push_back(std::move(f));
    }
    plan.calibration = publishFirst(calibrations, host);
    if (plan.calibration.empty() && s.nominalCalibration) { // disparities only: see nominal_calibration
        PinholePair nominal;
        nominal.imageSize = imageSizeOf(plan.frames.front().left);
        const double w = nominal.imageSize.width, h = nominal.imageSize.height;
        nominal.M1 = nominal.M2 = cv::Matx33d(w, 0, (w - 1) / 2, 0, w, (h - 1) / 2, 0, 0, 1);
        nominal.baselineMm = 1;
        plan.calibration = nominal.toYaml();
        host.info("replay: no calibration in the scene; a nominal one (f = " + std::to_string(static_cast<int>(w)) +
                  " px, B = 1 mm) is published: disparities are scored, ranges mean nothing");
    }
    return plan;
}

// ---- kitti layout --------------------------------------------------------------------------
// KITTI 2015 (image_2/, image_3/, disp_occ_0/, disp_noc_0/) or 2012 (image_0/, image_1/,
// disp_occ/, disp_noc/); pairs matched by file name. Calibration from P2/P3
// (P_rect_02/P_rect_03; P0/P1 for image_0/1) in calib_cam_to_cam.txt or calib*/ *.txt.

struct KittiCameras {
    std::string leftDir, rightDir;
    int leftIndex = 2, rightIndex = 3;
};

bool kittiCameras(const fs::path &folder, KittiCameras &out) {
    if (fs::is_directory(folder / "image_2") && fs::is_directory(folder / "image_3")) {
        out = {"image_2", "image_3", 2, 3};
        return true;
    }
    if (fs::is_directory(folder / "image_0") && fs::is_directory(folder / "image_1")) {
        out = {"image_0", "image_1", 0, 1};
        return true;
    }
    return false;
}

// "KEY: numbers" lines, see replay_metadata.hpp; false when the file has no projection
// for the pair's cameras.
bool readKittiCalib(const fs::path &file, const KittiCameras &cams, const fs::path &leftImage, PinholePair &out) {
    const auto c = parseKittiCalib(readText(file, "KITTI calibration"), file.string(), cams.leftIndex, cams.rightIndex);
    if (!c) return false;
    out.M1 = c->left.get_minor<3, 3>(0, 0);
    out.M2 = c->right.get_minor<3, 3>(0, 0);
    out.baselineMm = c->baselineMm;
    out.imageSize = c->width > 0 ? cv::Size(c->width, c->height) : imageSizeOf(leftImage);
    return true;
}

std::vector<fs::path> kittiCalibFiles(const fs::path &folder) {
    if (fs::is_regular_file(folder / "calib_cam_to_cam.txt")) return {folder / "calib_cam_to_cam.txt"};
    for (const char *dir : {"calib_cam_to_cam", "calib"}) {
        std::vector<fs::path> files;
        for (fs::path &p : listFolder(folder / dir, false))
            if (p.extension() == ".txt") files.push_back(std::move(p));
        if (!files.empty()) return files;
    }
    return {};
}

Plan planKitti(const Settings &s, const sdk::Host &host) {
    const fs::path folder = s.folder;
    if (!fs::is_directory(folder))
        throw Error(BINOCLE_ERR_NOT_FOUND, "replay: folder " + inQuotes(folder) + " does not exist or is not a folder");
    KittiCameras cams;
    if (!kittiCameras(folder, cams))
        throw Error(BINOCLE_ERR_NOT_FOUND, "replay: folder " + inQuotes(folder) +
                                              " holds neither image_2/ and image_3/ nor image_0/ and image_1/; expected a KITTI tree");
    fs::path truthDir;
    for (const char *dir : {"disp_occ_0", "disp_noc_0", "disp_occ", "disp_noc"})
        if (truthDir.empty() && fs::is_directory(folder / dir)) truthDir = folder / dir;

    Plan plan;
    plan.layout = "kitti";
    for (const fs::path &left : listFolder(folder / cams.leftDir, false)) {
        if (!isImageFile(left)) continue;
        FrameFiles f;
        f.left = left;
        f.right = folder / cams.rightDir / left.filename();
        if (!fs::is_regular_file(f.right))
            throw Error(BINOCLE_ERR_NOT_FOUND, "replay: KITTI left image " + inQuotes(left) + " has no right image " +
                                                   inQuotes(f.right));
        if (!truthDir.empty() && fs::is_regular_file(truthDir / left.filename())) f.groundTruth = truthDir / left.filename();
        f.groundTruthScale = s.groundTruthScale;
        if (!f.groundTruth.empty()) // the noc ground truth's known pixels are the non-occluded ones
            for (const char *dir : {"disp_noc_0", "disp_noc"})
                if (f.nonoccTruth.empty() && fs::is_regular_file(folder / dir / left.filename()))
                    f.nonoccTruth = folder / dir / left.filename();
        plan.frames.push_back(std::move(f));
    }
    if (plan.frames.empty())
        throw Error(BINOCLE_ERR_NOT_FOUND, "replay: KITTI folder " + inQuotes(folder / cams.leftDir) + " holds no image");

    // One calibration file for all, or one per frame named after its stem ("000000.txt"
    // for "000000_10.png").
    const auto calibFiles = kittiCalibFiles(folder);
    std::map<std::string, std::pair<fs::path, PinholePair>> byStem;
    for (const fs::path &file : calibFiles) {
        PinholePair pair;
        if (readKittiCalib(file, cams, plan.frames.front().left, pair))
            byStem[file.stem().string()] = {file, pair};
        else
            host.warning("replay: KITTI calibration " + inQuotes(file) + " has no P" + std::to_string(cams.leftIndex) +
                         "/P" + std::to_string(cams.rightIndex) + " lines; ignored");
    }
    std::vector<std::pair<fs::path, PinholePair>> used;
    for (FrameFiles &f : plan.frames) {
        const std::string name = f.left.stem().string();
        auto it = byStem.find(name.substr(0, name.find('_')));
        if (it == byStem.end() && byStem.size() == 1) it = byStem.begin();
        if (it == byStem.end()) continue;
        it->second.second.addFacts(f, it->second.first);
        used.push_back(it->second);
    }
    if (calibFiles.empty() && s.calibration.empty())
        host.info("replay: KITTI folder " + inQuotes(folder) + " holds no calibration; none is published");
    plan.calibration = publishFirst(used, host);
    return plan;
}

// ---- recording layout ------------------------------------------------------------------------
// frames.csv (sequence,timestamp_left_ns,timestamp_right_ns,left,right; paths relative to
// the folder), calibration.yml, rig.yaml. A recording cut short stays readable up to its
// last complete frame.

Plan planRecording(const Settings &s, const sdk::Host &host) {
    const fs::path folder = s.folder;
    const fs::path csv = folder / recording::kIndexFile;
    if (!fs::is_directory(folder))
        throw Error(BINOCLE_ERR_NOT_FOUND, "replay: folder " + inQuotes(folder) + " does not exist or is not a folder");
    if (!fs::is_regular_file(csv))
        throw Error(BINOCLE_ERR_NOT_FOUND, "replay: recording folder " + inQuotes(folder) + " holds no frames.csv");
    const std::string where = csv.string();
    recording::Index index;
    try {
        index = recording::parseIndex(readText(csv, "recording index"), where);
    } catch (const Error &e) {
        throw Error(e.code(), std::string("replay: ") + e.what());
    }

    Plan plan;
    plan.layout = "recording";
    plan.lenientLastFrame = true;
    if (!index.dropped_last.empty()) {
        host.warning("replay: " + index.dropped_last + ": a recording cut short; it is ignored");
        ++plan.droppedAtEnd;
    }
    std::vector<int> lineOf;
    for (const recording::Row &p : index.rows) {
        FrameFiles f;
        f.hasTimestamps = true;
        f.timestampLeftNs = p.timestamp_left_ns;
        f.timestampRightNs = p.timestamp_right_ns;
        f.left = folder / p.left;
        f.right = folder / p.right;
        f.facts.emplace_back("recorded_sequence", std::to_string(p.sequence));
        plan.frames.push_back(std::move(f));
        lineOf.push_back(p.line);
    }
    // Images missing at the end: the recorder stopped before writing them.
    while (!plan.frames.empty() &&
           (!fs::is_regular_file(plan.frames.back().left) || !fs::is_regular_file(plan.frames.back().right))) {
        const FrameFiles &f = plan.frames.back();
        host.warning("replay: " + where + ":" + std::to_string(lineOf.back()) + " names " +
                     inQuotes(fs::is_regular_file(f.left) ? f.right : f.left) +
                     ", which does not exist: a recording cut short; the frame is ignored");
        plan.frames.pop_back();
        lineOf.pop_back();
        ++plan.droppedAtEnd;
    }
    for (size_t i = 0; i < plan.frames.size(); ++i)
        for (const fs::path *p : {&plan.frames[i].left, &plan.frames[i].right})
            if (!fs::is_regular_file(*p))
                throw Error(BINOCLE_ERR_NOT_FOUND, "replay: " + where + ":" + std::to_string(lineOf[i]) + " names " +
                                                       inQuotes(*p) + ", which does not exist");
            else if (const std::string out = recording::outsideOf(folder, *p); !out.empty())
                throw Error(BINOCLE_ERR_INVALID_ARGUMENT, "replay: " + where + ":" + std::to_string(lineOf[i]) + " names " +
                                                              inQuotes(*p) + ", which leads out of the recording to " +
                                                              inQuotes(out) + " (a symbolic link); expected the images inside " +
                                                              inQuotes(folder));
    if (plan.frames.empty())
        throw Error(BINOCLE_ERR_NOT_FOUND, "replay: recording " + inQuotes(folder) + " holds no complete frame");

    const fs::path calibration = folder / recording::kCalibrationFile;
    if (fs::is_regular_file(calibration)) {
        plan.calibration = readText(calibration, "calibration");
        plan.calibrationOrigin = calibration.string();
    }
    else if (s.calibration.empty())
        host.warning("replay: recording " + inQuotes(folder) + " has no calibration.yml; it brings no calibration");
    return plan;
}

// ---- mcap layout -----------------------------------------------------------------------------
// A rosbag2 MCAP bag (`bag`, or a `folder` holding one): see replay_mcap.hpp.

Plan planMcap(const Settings &s, const sdk::Host &host) {
    McapSettings m = s.bag;
    if (m.bag.empty()) m.bag = s.folder;
    return planBag(m, !s.calibration.empty(), host);
}

// ---- Layout detection --------------------------------------------------------------------------

std::string detectLayout(const Settings &s) {
    if (!s.left.empty() || !s.right.empty()) return "glob";
    if (!s.bag.bag.empty()) return "mcap";
    if (s.folder.empty())
        throw Error(BINOCLE_ERR_INVALID_ARGUMENT,
                    "replay: nothing to replay: set `left` and `right` (glob patterns) or `folder` (a Middlebury, KITTI "
                    "or recording folder)");
    if (hasWildcard(s.folder)) return "middlebury";
    const fs::path folder = s.folder;
    if (!fs::is_directory(folder))
        throw Error(BINOCLE_ERR_NOT_FOUND, "replay: folder " + inQuotes(folder) + " does not exist or is not a folder");
    KittiCameras cams;
    if (fs::is_regular_file(folder / recording::kIndexFile)) return "recording";
    if (isMcapBag(folder.string())) return "mcap";
    if (isSceneFolder(folder)) return "middlebury";
    if (kittiCameras(folder, cams)) return "kitti";
    for (const fs::path &sub : listFolder(folder, true))
        if (isSceneFolder(sub)) return "middlebury";
    throw Error(BINOCLE_ERR_INVALID_ARGUMENT,
                "replay: folder " + inQuotes(folder) +
                    " holds none of the known layouts: frames.csv (recording), a stereo pair im0/im1, view1/view5, "
                    "imL/imR, im2/im6 or left/right (middlebury scene, also in sub-folders), image_2/ and image_3/ "
                    "(kitti), metadata.yaml or *.mcap (mcap); set `layout` "
                    "or use `left`/`right` patterns");
}

Plan makePlan(const Settings &s, const sdk::Host &host) {
    const std::string layout = s.layout == "auto" ? detectLayout(s) : s.layout;
    const bool usesFolder = layout != "glob";
    if (usesFolder && s.folder.empty() && !(layout == "mcap" && !s.bag.bag.empty()))
        throw Error(BINOCLE_ERR_INVALID_ARGUMENT, "replay: layout " + layout + " needs `folder`" +
                                                      (layout == "mcap" ? std::string(" or `bag`") : std::string()));
    if (usesFolder && (!s.left.empty() || !s.right.empty() || !s.groundTruth.empty()))
        host.warning("replay: `left`, `right` and `ground_truth` are ignored by layout " + layout);
    if (!usesFolder && !s.folder.empty()) host.warning("replay: `folder` is ignored by layout glob");

    Plan plan = layout == "glob"         ? planGlob(s)
                : layout == "middlebury" ? planMiddlebury(s, host)
                : layout == "kitti"      ? planKitti(s, host)
                : layout == "mcap"       ? planMcap(s, host)
                                         : planRecording(s, host);

    if (!s.calibration.empty()) {
        const std::string text = readText(s.calibration, "calibration");
        bool readable = false;
        try {
            cv::FileStorage fs(text, cv::FileStorage::READ | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
            readable = fs.isOpened() && !fs["M1"].empty() && !fs["T"].empty();
        } catch (const cv::Exception &) {
        }
        if (!readable)
            throw Error(BINOCLE_ERR_INVALID_ARGUMENT, "replay: calibration " + inQuotes(s.calibration) +
                                                          " is not an OpenCV FileStorage YAML calibration with M1 and T");
        // The frames are triangulated with this baseline: the layout's own files (a
        // recording's calibration.yml, each frame's calib.txt) must not say another one.
        if (const auto b = calibrationBaselineMm(text)) {
            if (!plan.calibrationOrigin.empty())
                if (const auto own = calibrationBaselineMm(plan.calibration))
                    checkBaselineAgrees(*own, plan.calibrationOrigin, *b, s.calibration);
            for (const FrameFiles &f : plan.frames)
                if (!f.calibrationFile.empty()) checkBaselineAgrees(f.baselineMm, f.calibrationFile.string(), *b, s.calibration);
        }
        plan.calibration = text;
        plan.calibrationOrigin = s.calibration;
    }

    const auto available = static_cast<int64_t>(plan.frames.size());
    if (s.firstFrame >= available)
        throw Error(BINOCLE_ERR_INVALID_ARGUMENT, "replay: first_frame " + std::to_string(s.firstFrame) +
                                                      " is past the last frame: the " + plan.layout + " layout holds " +
                                                      std::to_string(available) + " frames (0 .. " +
                                                      std::to_string(available - 1) + ")");
    plan.frames.erase(plan.frames.begin(), plan.frames.begin() + s.firstFrame);
    if (s.maxFrames > 0 && static_cast<int64_t>(plan.frames.size()) > s.maxFrames) {
        plan.frames.resize(static_cast<size_t>(s.maxFrames));
        plan.lenientLastFrame = false; // the cut-short frame, if any, is not played
    }
    return plan;
}

// ---- The source --------------------------------------------------------------------------------

// Pixels of one lent frame; lives until the host releases it.
struct Pixels {
    cv::Mat left, right, gtDisparity, gtValid, gtNonocc, gtDisc;
};

binocle_image lend(const cv::Mat &m, int32_t format) {
    return sdk::makeImage(m.cols, m.rows, format, m.data, static_cast<int32_t>(m.step[0]));
}

std::string sizeText(const cv::Mat &m) { return std::to_string(m.cols) + "x" + std::to_string(m.rows); }

constexpr double kNominalRateHz = 30.0; // time stamps when rate_hz is 0 and the files carry none

class ReplaySource : public sdk::StereoSource {
public:
    static std::vector<binocle_param_desc> parameters() { return parameterTable(); }

    ReplaySource(const sdk::CheckedParams &p, sdk::Host &host)
        : host_(host), settings_(readSettings(p)), plan_(makePlan(settings_, host_)) {
        periodNs_ = static_cast<int64_t>(std::llround(1e9 / (settings_.rateHz > 0 ? settings_.rateHz : kNominalRateHz)));
        // A recording played in a loop keeps its time stamps increasing: each pass is
        // shifted by the recording's span plus one mean frame interval.
        const auto &frames = plan_.frames;
        if (frames.front().hasTimestamps) {
            const int64_t span = frames.back().timestampLeftNs - frames.front().timestampLeftNs;
            passNs_ = frames.size() > 1 ? span + span / static_cast<int64_t>(frames.size() - 1) : periodNs_;
            if (passNs_ <= 0) passNs_ = periodNs_ * static_cast<int64_t>(frames.size());
        }
        host_.info("replay: " + std::to_string(frames.size()) + (frames.size() == 1 ? " frame" : " frames") +
                   ", layout " + plan_.layout +
                   (plan_.calibration.empty() ? ", no calibration" : ", with calibration"));
    }

    void start() override {
        started_ = true;
        pacer_.start(periodNs_, "replay", "rate_hz " + std::to_string(settings_.rateHz));
    }

    void stop() override { started_ = false; }

    std::unique_ptr<sdk::Frame> grab(int32_t timeout_ms) override {
        if (!started_) throw Error(BINOCLE_ERR_INVALID_ARGUMENT, "replay: grab before start (or after stop)");
        for (;;) {
            if (next_ >= plan_.frames.size()) {
                if (!settings_.loop || plan_.frames.empty())
                    throw Error(BINOCLE_ERR_END_OF_STREAM, "replay: end of the " + std::to_string(plan_.frames.size()) +
                                                               " frames");
                next_ = 0;
                ++pass_;
            }
            // rate_hz > 0: frames are due one period apart.
            if (settings_.rateHz > 0) pacer_.wait(timeout_ms);
            auto pixels = std::make_shared<Pixels>();
            const FrameFiles &files = plan_.frames[next_];
            if (!decode(files, *pixels)) continue; // a cut-short last frame was dropped
            return makeFrame(files, std::move(pixels));
        }
    }

    std::string calibration() override { return plan_.calibration; }

    std::string statistics() override {
        YAML::Emitter out;
        out << YAML::BeginMap;
        out << YAML::Key << "layout" << YAML::Value << plan_.layout;
        out << YAML::Key << "frames" << YAML::Value << delivered_;
        out << YAML::Key << "frames_per_pass" << YAML::Value << plan_.frames.size();
        out << YAML::Key << "passes_completed" << YAML::Value << pass_;
        out << YAML::Key << "frames_dropped_at_end" << YAML::Value << plan_.droppedAtEnd;
        if (plan_.bag) {
            out << YAML::Key << "left_topic" << YAML::Value << plan_.bag->leftTopic();
            out << YAML::Key << "right_topic" << YAML::Value << plan_.bag->rightTopic();
            out << YAML::Key << "unpaired_left" << YAML::Value << plan_.bag->unpaired(0);
            out << YAML::Key << "unpaired_right" << YAML::Value << plan_.bag->unpaired(1);
        }
        out << YAML::EndMap;
        return out.c_str();
    }

private:
    // Decodes the pair and its ground truth; false when the frame was the cut-short end
    // of a recording and has been dropped.
    bool decode(const FrameFiles &files, Pixels &px) {
        if (plan_.bag) {
            plan_.bag->decode(static_cast<size_t>(files.bagPair), settings_.gray, px.left, px.right);
            if (px.left.size() != px.right.size())
                throw Error(BINOCLE_ERR_INVALID_ARGUMENT, "replay: bag " + plan_.bag->files() + ": pair at stamp " +
                                                              std::to_string(files.timestampLeftNs) + " ns: left image is " +
                                                              sizeText(px.left) + " but right is " + sizeText(px.right) +
                                                              "; a pair must have one size");
            return true;
        }
        // Pixels as stored: the calibration speaks of the sensor's rows, whatever EXIF says.
        const int flags = (settings_.gray ? cv::IMREAD_GRAYSCALE : cv::IMREAD_COLOR) | cv::IMREAD_IGNORE_ORIENTATION;
        // Headers are checked before decoding, and a cut-short file is refused rather
        // than decoded into a partial image (input/image_file.hpp).
        for (const bool isLeft : {true, false}) {
            const fs::path &path = isLeft ? files.left : files.right;
            const std::string side = isLeft ? "left" : "right";
            try {
                (isLeft ? px.left : px.right) = input::readImage(path.string(), flags, side + " image");
            } catch (const input::ImageFileError &e) {
                if (plan_.lenientLastFrame && next_ + 1 == plan_.frames.size()) {
                    host_.warning(std::string("replay: cannot use the last recorded frame: ") + e.what() +
                                  ": a recording cut short; the frame is ignored");
                    plan_.frames.pop_back();
                    plan_.lenientLastFrame = false;
                    ++plan_.droppedAtEnd;
                    return false;
                }
                throw Error(e.notFound() ? BINOCLE_ERR_NOT_FOUND : BINOCLE_ERR_IO, std::string("replay: ") + e.what());
            }
        }
        if (px.left.size() != px.right.size())
            throw Error(BINOCLE_ERR_INVALID_ARGUMENT, "replay: left image " + inQuotes(files.left) + " is " +
                                                          sizeText(px.left) + " but right image " + inQuotes(files.right) +
                                                          " is " + sizeText(px.right) + "; a pair must have one size");
        if (!files.groundTruth.empty()) {
            FrameTruth gt = readFrameTruth(files, px.left.size());
            px.gtDisparity = gt.disparity;
            px.gtValid = gt.valid;
            px.gtNonocc = gt.nonocc;
            px.gtDisc = gt.disc;
        }
        return true;
    }

    std::unique_ptr<sdk::Frame> makeFrame(const FrameFiles &files, std::shared_ptr<Pixels> px) {
        auto frame = std::make_unique<sdk::Frame>();
        frame->sequence = sequence_;
        if (files.hasTimestamps) {
            frame->timestamp_left_ns = files.timestampLeftNs + pass_ * passNs_;
            frame->timestamp_right_ns = files.timestampRightNs + pass_ * passNs_;
        } else {
            frame->timestamp_left_ns = frame->timestamp_right_ns = static_cast<int64_t>(sequence_) * periodNs_;
        }
        const int32_t format = settings_.gray ? BINOCLE_PIXEL_GRAY8 : BINOCLE_PIXEL_BGR8;
        frame->left = lend(px->left, format);
        frame->right = lend(px->right, format);
        if (!px->gtDisparity.empty()) {
            frame->extras.emplace_back("gt_disparity", lend(px->gtDisparity, BINOCLE_PIXEL_FLOAT32));
            frame->extras.emplace_back("gt_valid", lend(px->gtValid, BINOCLE_PIXEL_GRAY8));
            if (!px->gtNonocc.empty()) frame->extras.emplace_back("gt_nonocc", lend(px->gtNonocc, BINOCLE_PIXEL_GRAY8));
            if (!px->gtDisc.empty()) frame->extras.emplace_back("gt_disc", lend(px->gtDisc, BINOCLE_PIXEL_GRAY8));
        }
        frame->metadata = metadata(files);
        frame->owner = std::move(px);
        ++sequence_;
        ++delivered_;
        ++next_;
        return frame;
    }

    std::string metadata(const FrameFiles &files) const {
        YAML::Emitter out;
        out << YAML::BeginMap;
        out << YAML::Key << "frame_index" << YAML::Value << next_ + static_cast<size_t>(settings_.firstFrame);
        if (plan_.bag) {
            out << YAML::Key << "bag" << YAML::Value << plan_.bag->files();
        } else {
            out << YAML::Key << "left_file" << YAML::Value << files.left.string();
            out << YAML::Key << "right_file" << YAML::Value << files.right.string();
        }
        if (!files.groundTruth.empty())
            out << YAML::Key << "ground_truth_file" << YAML::Value << files.groundTruth.string();
        for (const auto &[key, value] : files.facts) out << YAML::Key << key << YAML::Value << value;
        out << YAML::EndMap;
        return out.c_str();
    }

    sdk::Host host_;
    Settings settings_;
    Plan plan_;
    int64_t periodNs_ = 0;
    int64_t passNs_ = 0;
    bool started_ = false;
    FramePacer pacer_;
    size_t next_ = 0;        // index in plan_.frames of the next frame
    uint64_t sequence_ = 0;  // of the next frame delivered
    uint64_t delivered_ = 0;
    int64_t pass_ = 0;       // completed passes (loop)
};

} // namespace
} // namespace binocle::replay

BINOCLE_EXPORT_SOURCE(binocle::replay::ReplaySource, "replay", "1.0.0",
                      "Plays stereo pairs back from files: glob patterns, Middlebury, KITTI or a binocle recording")
