// SPDX-License-Identifier: MIT
// Image files from untrusted folders: the header is read and checked against stated
// limits before anything is decoded, and a file cut short is refused instead of being
// decoded into a partial image.
//
// Checked from the bytes themselves: PNG (IHDR size, every chunk inside the file, IEND
// present), JPEG (SOF size, segments inside the file, EOI present), PFM and binary
// PGM/PPM (header, pixel data inside the file), BMP (header, pixel data inside the
// file). Other formats (TIFF, WebP, ...) are left to OpenCV, whose own pixel limit the
// `binocle` command lowers to kMaxImagePixels.
#pragma once

#include <opencv2/core.hpp>

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace binocle::input {

// The limits stated in the README: 32768 px a side, 64 Mpx (8192 x 8192) in all, 1 GiB a file.
constexpr int64_t kMaxImageSide = 32768;
constexpr int64_t kMaxImagePixels = int64_t{1} << 26;
constexpr uint64_t kMaxImageFileBytes = uint64_t{1} << 30;

struct ImageLimits {
    int64_t maxSide = kMaxImageSide;
    int64_t maxPixels = kMaxImagePixels;
    uint64_t maxFileBytes = kMaxImageFileBytes;
};

struct ImageInfo {
    std::string format; // "png", "jpeg", "pfm", "pnm", "bmp"; "" when not recognised
    int64_t width = 0, height = 0;
    int channels = 0;
    size_t dataOffset = 0; // PFM, PGM/PPM: where the pixels start
    double scale = 0;      // PFM: the scale (its sign gives the byte order)
};

// Reads the header in `data` and checks the file's structure and size against `limits`.
// Returns false with the reason in `problem` ("header claims 30000x30000 pixels; the
// limit is ..."). An unrecognised format returns true with info.format empty.
bool inspectImage(const uint8_t *data, size_t size, ImageInfo &info, std::string &problem,
                  const ImageLimits &limits = {});

class ImageFileError : public std::runtime_error {
public:
    ImageFileError(const std::string &message, bool notFound) : std::runtime_error(message), notFound_(notFound) {}
    bool notFound() const noexcept { return notFound_; }

private:
    bool notFound_;
};

// The whole file, refused (ImageFileError) when missing, not a regular file or larger
// than limits.maxFileBytes. `what` names the file's role in messages ("left image").
std::vector<uint8_t> readImageFileBytes(const std::string &path, const std::string &what,
                                        const ImageLimits &limits = {});

// Reads, inspects and decodes (cv::imdecode with `flags`). Throws ImageFileError
// "<what> '<path>': <reason>" on a missing, oversized, truncated or undecodable file.
cv::Mat readImage(const std::string &path, int flags, const std::string &what = "image",
                  const ImageLimits &limits = {});

// The same from bytes in memory; `name` starts every message ("left image 'x.png'").
cv::Mat decodeImage(const uint8_t *data, size_t size, int flags, const std::string &name, const ImageLimits &limits = {});

// Portable Float Map, the one PFM path of Binocle: the header is checked against the
// limits and the data's size before anything is allocated, then the data is read as the
// format's authors and Middlebury's tools read it: the scale's sign gives the byte order
// (negative = little-endian), its magnitude is NOT applied (Middlebury writes -1/255;
// OpenCV's codec would return 255 x the disparity). "Pf" gives CV_32FC1, "PF" CV_32FC3 in
// OpenCV's BGR order; top row first, values as stored (inf stays inf). Anything else is
// refused (ImageFileError).
cv::Mat readPfm(const std::string &path, const std::string &what = "PFM file", const ImageLimits &limits = {});
cv::Mat decodePfm(const uint8_t *data, size_t size, const std::string &name, const ImageLimits &limits = {});
// The file's bytes: scale -1 (little-endian), rows bottom to top; CV_32FC1 or CV_32FC3 (BGR).
std::string encodePfm(const cv::Mat &image);

} // namespace binocle::input
