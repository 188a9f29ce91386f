// SPDX-License-Identifier: MIT
// Chessboard pairs in a folder: left*.png|jpg and right*.* matched by their number
// (left01.jpg with right01.jpg, as in opencv-doc's stereo calibration sample).
#pragma once

#include <string>
#include <vector>

namespace binocle {

struct ImagePair {
    std::string id; // the number as written in the left file's name ("01")
    std::string left, right;
};

struct PairListing {
    std::vector<ImagePair> pairs;   // by number
    std::vector<std::string> unmatched; // "left15.png: no right image numbered 15"
};

// Throws binocle::Error when `dir` is not a readable folder.
PairListing listImagePairs(const std::string &dir);

} // namespace binocle
