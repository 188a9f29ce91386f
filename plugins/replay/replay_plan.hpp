// SPDX-License-Identifier: MIT
// What a layout of replay yields: the list of frames (files, or pairs of a bag) and the
// calibration, and the rectified pinhole pair that the Middlebury and KITTI layouts know.
#pragma once

#include "replay_mcap.hpp"

#include <binocle/plugin.hpp>

#include <opencv2/core.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace binocle::replay {

// One stereo pair on disk.
struct FrameFiles {
    std::filesystem::path left, right;
    std::filesystem::path groundTruth; // empty: no ground truth for this pair
    // Decoded ground-truth values are multiplied by this (16-bit PNGs are first divided by
    // 256): the dataset's rule (replay_scenes.hpp), or `ground_truth_scale` when given.
    double groundTruthScale = 1.0;
    // Masks of the dataset, empty when it has none (replay_scenes.hpp): non-occluded pixels
    // (Middlebury nonocc.png / mask0nocc.png, == 255), the pixels of the "all" score
    // (Middlebury v2 all.png), near discontinuities (disc.png); KITTI: the noc ground truth,
    // whose known pixels are the non-occluded ones.
    std::filesystem::path nonoccMask, allMask, discMask, nonoccTruth;
    bool hasTimestamps = false;
    int64_t timestampLeftNs = 0, timestampRightNs = 0;
    // Layout-specific facts for the frame's metadata ("ndisp", "recorded_sequence" ...).
    std::vector<std::pair<std::string, std::string>> facts;
    int64_t bagPair = -1; // mcap: the index of the pair in Plan::bag
    // The calibration file of the frame's own metadata (Middlebury calib.txt, KITTI) and
    // the baseline it states; empty and 0 when the layout has none for this frame.
    std::filesystem::path calibrationFile;
    double baselineMm = 0;
};

struct Plan {
    std::string layout;
    std::vector<FrameFiles> frames;
    std::string calibration; // FileStorage YAML text; empty when unknown
    std::string calibrationOrigin; // the file it was read from (a recording's calibration.yml); empty otherwise
    // Recording: the last frame may have been cut short; if it cannot be decoded the
    // stream ends before it, with a warning, instead of failing.
    bool lenientLastFrame = false;
    size_t droppedAtEnd = 0; // frames of a cut recording left out
    std::shared_ptr<McapPairs> bag; // mcap: the bag the frames come from
};

// A rectified pinhole pair: the calibration the Middlebury and KITTI layouts know.
struct PinholePair {
    cv::Size imageSize;
    cv::Matx33d M1, M2; // intrinsics; M2 keeps its own cx (Middlebury doffs)
    double baselineMm = 0;

    double focalLengthPx() const { return M1(0, 0); }

    // The format of framework/core/calibration.hpp, rectification included, so that a
    // reader needs not recompute it (which would equalise cx and lose doffs).
    std::string toYaml() const {
        const double f = M1(0, 0), cx0 = M1(0, 2), cy = M1(1, 2), cx1 = M2(0, 2);
        cv::Mat P1 = (cv::Mat_<double>(3, 4) << f, 0, cx0, 0, 0, M1(1, 1), cy, 0, 0, 0, 1, 0);
        cv::Mat P2 = (cv::Mat_<double>(3, 4) << M2(0, 0), 0, cx1, -M2(0, 0) * baselineMm, 0, M2(1, 1), M2(1, 2), 0, 0,
                      0, 1, 0);
        // OpenCV's Q for Tx = -B: W = (d + cx1 - cx0) / B, so Z = f B / (d + doffs).
        cv::Mat Q = (cv::Mat_<double>(4, 4) << 1, 0, 0, -cx0, 0, 1, 0, -cy, 0, 0, 0, f, 0, 0, 1.0 / baselineMm,
                     (cx1 - cx0) / baselineMm);
        cv::FileStorage fs(".yml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY);
        fs << "image_width" << imageSize.width << "image_height" << imageSize.height;
        fs << "M1" << cv::Mat(M1) << "D1" << cv::Mat::zeros(1, 5, CV_64F);
        fs << "M2" << cv::Mat(M2) << "D2" << cv::Mat::zeros(1, 5, CV_64F);
        fs << "R" << cv::Mat::eye(3, 3, CV_64F) << "T" << (cv::Mat_<double>(3, 1) << -baselineMm, 0, 0);
        fs << "rectified" << 1;
        fs << "R1" << cv::Mat::eye(3, 3, CV_64F) << "R2" << cv::Mat::eye(3, 3, CV_64F);
        fs << "P1" << P1 << "P2" << P2 << "Q" << Q;
        fs << "baseline_mm" << baselineMm << "focal_length_px" << f;
        return fs.releaseAndGetString();
    }

    // The frame's focal length and baseline facts, and the file that states them.
    void addFacts(FrameFiles &frame, const std::filesystem::path &file) const {
        frame.calibrationFile = file;
        frame.baselineMm = baselineMm;
        std::ostringstream f, b;
        f.precision(10);
        b.precision(10);
        f << focalLengthPx();
        b << baselineMm;
        frame.facts.emplace_back("focal_length_px", f.str());
        frame.facts.emplace_back("baseline_mm", b.str());
    }

    bool sameAs(const PinholePair &o) const {
        auto close = [](double a, double b) { return std::abs(a - b) <= 1e-6 * std::max(1.0, std::abs(a)); };
        return imageSize == o.imageSize && close(focalLengthPx(), o.focalLengthPx()) &&
               close(baselineMm, o.baselineMm) && close(M1(0, 2), o.M1(0, 2)) && close(M2(0, 2), o.M2(0, 2)) &&
               close(M1(1, 2), o.M1(1, 2));
    }
};

// Several scenes may come with several calibrations: the first one is published, each
// frame's metadata carries its own focal length and baseline, and a difference is said.
std::string publishFirst(const std::vector<std::pair<std::filesystem::path, PinholePair>> &calibrations, const sdk::Host &host);

// The frames of an MCAP bag (layout mcap), its CameraInfo as calibration; a warning when it
// has none and `calibrationGiven` is false.
Plan planBag(const McapSettings &settings, bool calibrationGiven, const sdk::Host &host);

} // namespace binocle::replay
