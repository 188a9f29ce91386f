// SPDX-License-Identifier: MIT
// Fuzz harness: image header checks (base/input/image_file.cpp) for PNG, JPEG,
// PFM, PGM/PPM and BMP. What the check accepts, OpenCV must decode to the size the
// header gave (small images only: decoding is the slow part).
#include "input/image_file.hpp"

#include <opencv2/imgcodecs.hpp>

#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerInitialize(int *, char ***) {
    cv::setNumThreads(1);
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    binocle::input::ImageInfo info;
    std::string problem;
    binocle::input::ImageLimits limits;
    limits.maxPixels = 1 << 16; // keeps each decode cheap; the checks are the same
    const bool ok = binocle::input::inspectImage(data, size, info, problem, limits);
    if (!ok && problem.empty()) std::abort(); // a refusal always says why
    if (!ok || info.format.empty()) return 0;
    if (info.width <= 0 || info.height <= 0 || info.width * info.height > limits.maxPixels) std::abort();
    try {
        const cv::Mat m = cv::imdecode(std::vector<uint8_t>(data, data + size), cv::IMREAD_UNCHANGED);
        if (!m.empty() && (m.cols != info.width || m.rows != info.height)) std::abort();
    } catch (const cv::Exception &) {
    }
    return 0;
}
