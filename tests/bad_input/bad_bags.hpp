// SPDX-License-Identifier: MIT
// The bad-input corpus's `bag DIR VARIANT` generator (README.md there): a rosbag2 folder
// DIR holding DIR/<name>_0.mcap with two stereo pairs of 32x24 images and their CameraInfo
// under /cam, and one fault (`plain`: none): mono16_odd_step (rows one byte longer than the pixels),
// unknown_encoding (yuv422), camera_info_focal_1e300, topics_with_escapes (terminal
// escapes in the namespace, and no pair within the tolerance). No metadata.yaml: the case
// brings one when it needs one.
#pragma once

#include <string>

void writeBadBag(const std::string &dir, const std::string &variant);
