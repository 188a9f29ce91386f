// SPDX-License-Identifier: MIT
// v4l2: the plugin's registration; the logic is in v4l2_source.cpp, the device layer on
// libv4l2 in v4l2_device_linux.cpp.
#include "v4l2_source.hpp"

BINOCLE_EXPORT_SOURCE(binocle::v4l2::V4l2Source, "v4l2", "1.0.0",
                      "USB stereo rigs on Video4Linux2: two devices paired by time stamp, or one side-by-side device")
