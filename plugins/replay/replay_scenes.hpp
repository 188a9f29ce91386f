// SPDX-License-Identifier: MIT
// Scene folders of the public stereo datasets, read as the datasets' own tools read them:
// which files are the pair, the ground truth and its masks, and the scale of the ground
// truth by the dataset's rule (README.md, "Scene folders").
#pragma once

#include "replay_plan.hpp"

#include <opencv2/core.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace binocle::replay {

// True when the folder holds a stereo pair under one of the dataset names: im0/im1
// (Middlebury 2014, MiddEval3), view1/view5 (2005, 2006), imL/imR (the v2 evaluation's
// 2001/2003 scenes), im2/im6 (2001, 2003), scene1.row3.col3/col4 (Tsukuba), left/right.
bool isSceneFolder(const std::filesystem::path &folder);

// The scene folders `folder` names: a scene, a folder whose sub-folders are scenes (in
// natural order), or a glob over scene folders. Throws sdk::Error naming it when none.
std::vector<std::filesystem::path> sceneFolders(const std::string &folder);

// The frame of one scene folder: the pair, the ground truth found by its dataset name
// (disp0GT.pfm, disp0.pfm, disp1.png, groundtruth.png, disp2.png|pgm,
// truedisp.row3.col3.pgm, disp_occ*.png, disp_noc*.png), its scale by the dataset's rule, the masks, and the facts `dataset`,
// `ground_truth_divisor`. `givenScale` > 0 (`ground_truth_scale` set) replaces the rule.
// Throws sdk::Error naming the folder when the pair is incomplete or the rule does not
// know the image's size.
FrameFiles sceneFrame(const std::filesystem::path &folder, double givenScale);

// The ground truth of a frame with its masks, as frame extras want them: disparity
// (CV_32F, -1 where unknown), valid (known and in the dataset's "all" mask), nonocc
// (valid and non-occluded; empty when the dataset has no occlusion mask), disc (empty
// when none). Every plane is checked to be of the left image's size, and the ground truth
// to hold disparities of the image (>= 0 and less than its width), else sdk::Error names
// the file.
struct FrameTruth {
    cv::Mat disparity, valid, nonocc, disc;
};
FrameTruth readFrameTruth(const FrameFiles &frame, cv::Size leftSize);

} // namespace binocle::replay
