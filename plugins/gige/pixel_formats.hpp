// SPDX-License-Identifier: MIT
// The GenICam pixel formats the gige source accepts, and how each becomes a Binocle image.
#pragma once

#include <arv.h>
#include <binocle/abi.h>
#include <opencv2/core.hpp>

#include <string>

namespace binocle::gige {

struct PixelFormat {
    const char *name;      // SFNC name used in YAML ("Mono8", "BayerRG8" ...)
    ArvPixelFormat arv;    // PFNC value, what the camera's PixelFormat enumeration holds
    int bytes_per_pixel;   // in the camera buffer
    int32_t output;        // BINOCLE_PIXEL_GRAY8 or BINOCLE_PIXEL_BGR8
    int conversion;        // cv::COLOR_* code, or -1: lent as it is, without copy
};

// "Mono8|RGB8Packed|..." for the settings table.
const char *pixelFormatChoices();
// nullptr when not supported.
const PixelFormat *findPixelFormat(const std::string &name);
const PixelFormat *findPixelFormat(ArvPixelFormat value);
// "Mono8, RGB8Packed, ..." for messages.
std::string supportedPixelFormats();

// Converts a camera image (a view on its buffer) to the output format into `out`.
void convertPixels(const PixelFormat &format, const cv::Mat &raw, cv::Mat &out);

} // namespace binocle::gige
