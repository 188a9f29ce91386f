// SPDX-License-Identifier: MIT
// The GenICam pixel formats the gige source accepts, and how each becomes a Binocle image.
#include "pixel_formats.hpp"

#include <opencv2/imgproc.hpp>

namespace binocle::gige {

namespace {

// GenICam names Bayer patterns by their first two rows (RG/GB = R at (0,0));
// OpenCV's RGGB-style aliases use the same convention.
const PixelFormat kFormats[] = {
    {"Mono8", ARV_PIXEL_FORMAT_MONO_8, 1, BINOCLE_PIXEL_GRAY8, -1},
    {"BGR8Packed", ARV_PIXEL_FORMAT_BGR_8_PACKED, 3, BINOCLE_PIXEL_BGR8, -1},
    {"BGR8", ARV_PIXEL_FORMAT_BGR_8_PACKED, 3, BINOCLE_PIXEL_BGR8, -1},
    {"RGB8Packed", ARV_PIXEL_FORMAT_RGB_8_PACKED, 3, BINOCLE_PIXEL_BGR8, cv::COLOR_RGB2BGR},
    {"RGB8", ARV_PIXEL_FORMAT_RGB_8_PACKED, 3, BINOCLE_PIXEL_BGR8, cv::COLOR_RGB2BGR},
    {"BayerRG8", ARV_PIXEL_FORMAT_BAYER_RG_8, 1, BINOCLE_PIXEL_BGR8, cv::COLOR_BayerRGGB2BGR},
    {"BayerGR8", ARV_PIXEL_FORMAT_BAYER_GR_8, 1, BINOCLE_PIXEL_BGR8, cv::COLOR_BayerGRBG2BGR},
    {"BayerGB8", ARV_PIXEL_FORMAT_BAYER_GB_8, 1, BINOCLE_PIXEL_BGR8, cv::COLOR_BayerGBRG2BGR},
    {"BayerBG8", ARV_PIXEL_FORMAT_BAYER_BG_8, 1, BINOCLE_PIXEL_BGR8, cv::COLOR_BayerBGGR2BGR},
};

} // namespace

const char *pixelFormatChoices() {
    return "Mono8|BGR8Packed|BGR8|RGB8Packed|RGB8|BayerRG8|BayerGR8|BayerGB8|BayerBG8";
}

const PixelFormat *findPixelFormat(const std::string &name) {
    for (const auto &f : kFormats)
        if (name == f.name) return &f;
    return nullptr;
}

const PixelFormat *findPixelFormat(ArvPixelFormat value) {
    for (const auto &f : kFormats)
        if (f.arv == value) return &f;
    return nullptr;
}

std::string supportedPixelFormats() {
    std::string all;
    for (const auto &f : kFormats) all += (all.empty() ? "" : ", ") + std::string(f.name);
    return all;
}

void convertPixels(const PixelFormat &format, const cv::Mat &raw, cv::Mat &out) {
    if (format.conversion < 0) {
        raw.copyTo(out);
        return;
    }
    cv::cvtColor(raw, out, format.conversion);
}

} // namespace binocle::gige
