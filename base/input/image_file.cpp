// SPDX-License-Identifier: MIT
// Image headers checked before decoding; truncated files refused.
// Beyond image_file.hpp: PGM/PPM headers are read exactly as OpenCV's PxM decoder reads
// them; decodeImage has libjpeg decode a JPEG's entropy-coded data and refuses on its
// "Corrupt JPEG data" warnings, and refuses an image decoded to another size than the
// header checked.
#include "input/image_file.hpp"

#include "input/integer_range.hpp"

#include <binocle/numbers.hpp>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <jerror.h>
#include <jpeglib.h>

#include <cctype>
#include <cerrno>
#include <csetjmp>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

namespace fs = std::filesystem;

namespace binocle::input {

namespace {

uint32_t be32(const uint8_t *p) {
    return (uint32_t{p[0]} << 24) | (uint32_t{p[1]} << 16) | (uint32_t{p[2]} << 8) | uint32_t{p[3]};
}
uint16_t be16(const uint8_t *p) { return static_cast<uint16_t>((p[0] << 8) | p[1]); }
uint32_t le32(const uint8_t *p) {
    return uint32_t{p[0]} | (uint32_t{p[1]} << 8) | (uint32_t{p[2]} << 16) | (uint32_t{p[3]} << 24);
}
uint16_t le16(const uint8_t *p) { return static_cast<uint16_t>(p[0] | (p[1] << 8)); }

bool fail(std::string &problem, const std::string &what) {
    problem = what;
    return false;
}

bool checkSize(const ImageInfo &info, std::string &problem, const ImageLimits &limits) {
    const std::string claim = "header claims " + std::to_string(info.width) + "x" + std::to_string(info.height) + " pixels";
    if (info.width <= 0 || info.height <= 0) return fail(problem, claim + "; expected a positive size");
    if (info.width > limits.maxSide || info.height > limits.maxSide)
        return fail(problem, claim + "; the limit is " + std::to_string(limits.maxSide) + " pixels a side");
    if (info.width * info.height > limits.maxPixels)
        return fail(problem, claim + "; the limit is " + std::to_string(limits.maxPixels) + " pixels in all");
    return true;
}

bool inspectPng(const uint8_t *d, size_t size, ImageInfo &info, std::string &problem, const ImageLimits &limits) {
    info.format = "png";
    size_t pos = 8;
    bool sawHeader = false, sawData = false;
    while (true) {
        if (pos + 12 > size)
            return fail(problem, "PNG ends at byte " + std::to_string(size) + " without its IEND chunk: the file is cut short");
        const uint32_t length = be32(d + pos);
        const std::string type(reinterpret_cast<const char *>(d + pos + 4), 4);
        if (length > 0x7FFFFFFFu) return fail(problem, "PNG chunk '" + type + "' claims " + std::to_string(length) + " bytes");
        if (pos + 12 + length > size)
            return fail(problem, "PNG chunk '" + type + "' at byte " + std::to_string(pos) + " needs " +
                                     std::to_string(length) + " bytes but the file ends at " + std::to_string(size) +
                                     ": the file is cut short");
        const uint8_t *body = d + pos + 8;
        if (!sawHeader) {
            if (type != "IHDR" || length != 13) return fail(problem, "PNG does not start with its IHDR chunk");
            sawHeader = true;
            info.width = be32(body);
            info.height = be32(body + 4);
            const uint8_t colour = body[9];
            info.channels = colour == 0 ? 1 : colour == 2 ? 3 : colour == 3 ? 3 : colour == 4 ? 2 : colour == 6 ? 4 : 0;
            if (!checkSize(info, problem, limits)) return false;
        } else if (type == "IDAT") {
            sawData = true;
        } else if (type == "IEND") {
            if (!sawData) return fail(problem, "PNG has no IDAT chunk (no pixel data)");
            return true;
        }
        pos += 12 + length;
    }
}

bool inspectJpeg(const uint8_t *d, size_t size, ImageInfo &info, std::string &problem, const ImageLimits &limits) {
    info.format = "jpeg";
    const std::string cut = "JPEG ends at byte " + std::to_string(size) + " without its end-of-image marker: the file is cut short";
    size_t pos = 2;
    bool sawFrame = false;
    while (true) {
        // A marker: 0xFF (fill bytes may repeat it) then the code.
        if (pos >= size) return fail(problem, cut);
        if (d[pos] != 0xFF) return fail(problem, "JPEG: expected a marker at byte " + std::to_string(pos));
        while (pos < size && d[pos] == 0xFF) ++pos;
        if (pos >= size) return fail(problem, cut);
        const uint8_t marker = d[pos++];
        if (marker == 0xD9) {
            if (!sawFrame) return fail(problem, "JPEG has no frame header (SOF)");
            return true;
        }
        if ((marker >= 0xD0 && marker <= 0xD7) || marker == 0x01) continue; // no length
        if (pos + 2 > size) return fail(problem, cut);
        const size_t length = be16(d + pos);
        if (length < 2) return fail(problem, "JPEG segment at byte " + std::to_string(pos) + " has a length below 2");
        if (pos + length > size) return fail(problem, cut);
        const bool frame = marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
        if (frame && !sawFrame) {
            if (length < 8) return fail(problem, "JPEG frame header is too short");
            info.height = be16(d + pos + 3);
            info.width = be16(d + pos + 5);
            info.channels = d[pos + 7];
            if (info.height == 0) return fail(problem, "JPEG frame header gives a height of 0 (defined later by DNL): not supported");
            if (!checkSize(info, problem, limits)) return false;
            sawFrame = true;
        }
        pos += length;
        if (marker == 0xDA) {
            // Entropy-coded data up to the next marker that is neither a stuffed 0xFF00
            // nor a restart marker.
            while (true) {
                const void *ff = std::memchr(d + pos, 0xFF, size - pos);
                if (!ff) return fail(problem, cut);
                pos = static_cast<size_t>(static_cast<const uint8_t *>(ff) - d);
                if (pos + 1 >= size) return fail(problem, cut);
                const uint8_t next = d[pos + 1];
                if (next == 0x00 || (next >= 0xD0 && next <= 0xD7) || next == 0xFF) {
                    pos += next == 0xFF ? 1 : 2;
                    continue;
                }
                break;
            }
        }
    }
}

// The entropy-coded data of a JPEG decoded by libjpeg, whose warnings OpenCV only
// prints: a file cut short and given back its end marker decodes as grey "with success"
// ("Corrupt JPEG data: premature end of data segment"). Decoded at 1/8 scale: every
// coefficient is still Huffman-decoded (that is where the corruption shows), only the
// inverse DCT is cheap. No C++ object lives across the setjmp/longjmp of libjpeg's
// error exit.
struct JpegListener {
    jpeg_error_mgr mgr;
    std::jmp_buf jump;
    char message[JMSG_LENGTH_MAX];
};

void jpegErrorExit(j_common_ptr cinfo) {
    auto *l = reinterpret_cast<JpegListener *>(cinfo->err);
    (*cinfo->err->format_message)(cinfo, l->message);
    std::longjmp(l->jump, 1);
}

// Warnings that mean pixels are missing or made up; the others (an unknown JFIF
// revision or Adobe transform) are about metadata.
void jpegMessage(j_common_ptr cinfo, int level) {
    if (level >= 0) return; // trace messages
    const int code = cinfo->err->msg_code;
    if (code == JWRN_HIT_MARKER || code == JWRN_JPEG_EOF || code == JWRN_HUFF_BAD_CODE || code == JWRN_MUST_RESYNC ||
        code == JWRN_EXTRANEOUS_DATA || code == JWRN_NOT_SEQUENTIAL || code == JWRN_BOGUS_PROGRESSION)
        jpegErrorExit(cinfo);
    // The arithmetic decoder's "Corrupt JPEG data: bad arithmetic code" (its code depends
    // on the libjpeg version), by its text.
    char text[JMSG_LENGTH_MAX];
    (*cinfo->err->format_message)(cinfo, text);
    if (std::strstr(text, "bad arithmetic code")) jpegErrorExit(cinfo);
}

// Returns false with libjpeg's message in `problem` when the data is corrupt.
bool jpegDataIsWhole(const uint8_t *d, size_t size, std::string &problem) {
    jpeg_decompress_struct cinfo;
    JpegListener listener;
    cinfo.err = jpeg_std_error(&listener.mgr);
    listener.mgr.error_exit = jpegErrorExit;
    listener.mgr.emit_message = jpegMessage;
    listener.message[0] = 0;
    jpeg_create_decompress(&cinfo);
    if (setjmp(listener.jump)) {
        jpeg_destroy_decompress(&cinfo);
        problem = std::string("JPEG data is corrupt (libjpeg: \"") + listener.message +
                  "\"); expected complete, uncorrupted JPEG data";
        return false;
    }
    jpeg_mem_src(&cinfo, const_cast<unsigned char *>(d), static_cast<unsigned long>(size));
    jpeg_read_header(&cinfo, TRUE);
    cinfo.scale_num = 1;
    cinfo.scale_denom = 8;
    cinfo.dct_method = JDCT_IFAST;
    jpeg_start_decompress(&cinfo);
    JSAMPARRAY row = (*cinfo.mem->alloc_sarray)(reinterpret_cast<j_common_ptr>(&cinfo), JPOOL_IMAGE,
                                                cinfo.output_width * cinfo.output_components, 1);
    while (cinfo.output_scanline < cinfo.output_height) jpeg_read_scanlines(&cinfo, row, 1);
    jpeg_finish_decompress(&cinfo);
    jpeg_destroy_decompress(&cinfo);
    return true;
}

// Whitespace-separated header tokens of PFM.
struct Tokens {
    const uint8_t *d;
    size_t size, pos;
    bool next(std::string &out) {
        out.clear();
        while (pos < size && std::isspace(d[pos])) ++pos;
        while (pos < size && !std::isspace(d[pos]) && out.size() < 32) out += static_cast<char>(d[pos++]);
        return !out.empty() && out.size() < 32;
    }
};

// One number of a binary PGM/PPM header, read exactly as OpenCV's PxM decoder reads it
// (ReadNumber in grfmt_pxm.cpp): whitespace and '#' comments skipped, a comment ending at
// '\n' OR '\r', then decimal digits, then ONE byte of any kind consumed. Reading the
// header any other way lets the size checked here differ from the size OpenCV decodes
// ("# c\r 3" is a comment then 3 to OpenCV, a comment to the end of the line to netpbm).
// Refused where OpenCV would throw; `value` is capped well above any size limit.
bool pxmNumber(const uint8_t *d, size_t size, size_t &pos, int64_t &value) {
    while (true) {
        if (pos >= size) return false;
        const uint8_t c = d[pos];
        if (std::isdigit(c)) break;
        if (c == '#') {
            ++pos;
            while (pos < size && d[pos] != '\n' && d[pos] != '\r') ++pos;
            if (pos >= size) return false;
            ++pos; // the end of the comment
        } else if (std::isspace(c)) {
            ++pos;
        } else {
            return false;
        }
    }
    value = 0;
    while (pos < size && std::isdigit(d[pos])) {
        value = value * 10 + (d[pos++] - '0');
        if (value > INT32_MAX) return false; // OpenCV asserts here too
    }
    if (pos >= size) return false; // OpenCV reads one byte past the digits
    ++pos;
    return true;
}

bool inspectPfm(const uint8_t *d, size_t size, ImageInfo &info, std::string &problem, const ImageLimits &limits) {
    info.format = "pfm";
    info.channels = d[1] == 'F' ? 3 : 1;
    Tokens t{d, size, 2};
    std::string w, h, third, why;
    int64_t width = 0, height = 0;
    if (!t.next(w) || !t.next(h) || !t.next(third))
        return fail(problem, "PFM header is incomplete: expected width, height and scale");
    if (!parseInteger(w, width, &why, 1, INT64_MAX) || !parseInteger(h, height, &why, 1, INT64_MAX))
        return fail(problem, "PFM header: width '" + w + "' and height '" + h + "' must be positive decimal integers");
    info.width = width;
    info.height = height;
    if (!checkSize(info, problem, limits)) return false;
    double scale = 0;
    if (!sdk::parseDecimalReal(third, scale, &why) || scale == 0)
        return fail(problem, "PFM header: scale '" + third + "' must be a non-zero decimal number");
    info.scale = scale;
    info.dataOffset = t.pos + 1; // one whitespace character ends the header
    return true;
}

bool inspectPnm(const uint8_t *d, size_t size, ImageInfo &info, std::string &problem, const ImageLimits &limits,
                uint64_t &bytesPerSample) {
    info.format = "pnm";
    info.channels = d[1] == '6' ? 3 : 1;
    size_t pos = 2;
    int64_t width = 0, height = 0, maxValue = 0;
    if (!pxmNumber(d, size, pos, width) || !pxmNumber(d, size, pos, height) || !pxmNumber(d, size, pos, maxValue))
        return fail(problem, "PGM/PPM header is incomplete or malformed: expected width, height and maximum value as "
                             "decimal digits, separated by whitespace or '#' comments");
    info.width = width;
    info.height = height;
    if (!checkSize(info, problem, limits)) return false;
    if (maxValue < 1 || maxValue > 65535)
        return fail(problem, "PGM/PPM header: maximum value " + std::to_string(maxValue) + " must be 1..65535");
    bytesPerSample = maxValue > 255 ? 2 : 1;
    info.dataOffset = pos;
    return true;
}

// The pixel data of a PFM or binary PGM/PPM must be in the file.
bool checkNetpbmData(size_t size, const ImageInfo &info, uint64_t bytesPerSample, std::string &problem) {
    const uint64_t need =
        static_cast<uint64_t>(info.width) * static_cast<uint64_t>(info.height) * info.channels * bytesPerSample;
    const uint64_t have = size > info.dataOffset ? size - info.dataOffset : 0;
    if (have < need)
        return fail(problem, std::string(info.format == "pfm" ? "PFM" : "PGM/PPM") + " pixel data is cut short: " +
                                 std::to_string(info.width) + "x" + std::to_string(info.height) + "x" +
                                 std::to_string(info.channels) + " samples need " + std::to_string(need) +
                                 " bytes, the file holds " + std::to_string(have));
    return true;
}

bool inspectNetpbm(const uint8_t *d, size_t size, ImageInfo &info, std::string &problem, const ImageLimits &limits) {
    const bool pfm = d[1] == 'f' || d[1] == 'F';
    if (pfm) return inspectPfm(d, size, info, problem, limits) && checkNetpbmData(size, info, 4, problem);
    uint64_t bytesPerSample = 1;
    return inspectPnm(d, size, info, problem, limits, bytesPerSample) &&
           checkNetpbmData(size, info, bytesPerSample, problem);
}

bool inspectBmp(const uint8_t *d, size_t size, ImageInfo &info, std::string &problem, const ImageLimits &limits) {
    info.format = "bmp";
    if (size < 30) return fail(problem, "BMP header is cut short");
    const uint32_t offset = le32(d + 10);
    const auto width = static_cast<int32_t>(le32(d + 18));
    const auto height = static_cast<int32_t>(le32(d + 22));
    const uint16_t bpp = le16(d + 28);
    info.width = width;
    info.height = height == INT32_MIN ? 0 : (height < 0 ? -int64_t{height} : height);
    info.channels = bpp >= 24 ? 3 : 1;
    if (!checkSize(info, problem, limits)) return false;
    const uint32_t compression = size >= 34 ? le32(d + 30) : 0;
    if (compression == 0 && bpp > 0 && bpp <= 32) { // BI_RGB: rows of known size
        const uint64_t row = (static_cast<uint64_t>(bpp) * info.width + 31) / 32 * 4;
        if (offset > size || row * info.height > size - offset)
            return fail(problem, "BMP pixel data is cut short: " + std::to_string(info.width) + "x" +
                                     std::to_string(info.height) + " at " + std::to_string(bpp) + " bits need " +
                                     std::to_string(row * info.height) + " bytes after the header");
    }
    return true;
}

} // namespace

bool inspectImage(const uint8_t *data, size_t size, ImageInfo &info, std::string &problem, const ImageLimits &limits) {
    info = {};
    problem.clear();
    static const uint8_t kPng[8] = {0x89, 'P', 'N', 'G', 0x0D, 0x0A, 0x1A, 0x0A};
    // Checked here, the one entry every image passes before a decoder sees it: OpenCV
    // answers an empty buffer with an assertion ("!buf.empty()").
    if (size == 0) return fail(problem, "it is empty (0 bytes); expected an image (PNG, JPEG, PGM/PPM, PFM or BMP)");
    if (size > static_cast<uint64_t>(limits.maxFileBytes))
        return fail(problem, "the file holds " + std::to_string(size) + " bytes; the limit is " +
                                 std::to_string(limits.maxFileBytes));
    if (size >= 8 && std::memcmp(data, kPng, 8) == 0) return inspectPng(data, size, info, problem, limits);
    if (size >= 3 && data[0] == 0xFF && data[1] == 0xD8 && data[2] == 0xFF) return inspectJpeg(data, size, info, problem, limits);
    if (size >= 3 && data[0] == 'P' && (data[1] == 'f' || data[1] == 'F' || data[1] == '5' || data[1] == '6') &&
        std::isspace(data[2]))
        return inspectNetpbm(data, size, info, problem, limits);
    if (size >= 2 && data[0] == 'B' && data[1] == 'M') return inspectBmp(data, size, info, problem, limits);
    return true;
}

std::vector<uint8_t> readImageFileBytes(const std::string &path, const std::string &what, const ImageLimits &limits) {
    const std::string name = what + " '" + path + "'";
    std::error_code ec;
    const auto status = fs::status(path, ec);
    if (ec || !fs::exists(status)) throw ImageFileError(name + ": no such file", true);
    if (!fs::is_regular_file(status)) throw ImageFileError(name + ": not a regular file", false);
    const uint64_t size = fs::file_size(path, ec);
    if (ec) throw ImageFileError(name + ": cannot read its size: " + ec.message(), false);
    if (size > limits.maxFileBytes)
        throw ImageFileError(name + ": the file holds " + std::to_string(size) + " bytes; the limit is " +
                                 std::to_string(limits.maxFileBytes),
                             false);
    std::ifstream in(path, std::ios::binary);
    if (!in) throw ImageFileError(name + ": cannot open: " + std::strerror(errno), false);
    std::vector<uint8_t> bytes(static_cast<size_t>(size));
    in.read(reinterpret_cast<char *>(bytes.data()), static_cast<std::streamsize>(size));
    if (static_cast<uint64_t>(in.gcount()) != size)
        throw ImageFileError(name + ": read " + std::to_string(in.gcount()) + " of " + std::to_string(size) + " bytes",
                             false);
    return bytes;
}

cv::Mat decodeImage(const uint8_t *data, size_t size, int flags, const std::string &name, const ImageLimits &limits) {
    ImageInfo info;
    std::string problem;
    if (!inspectImage(data, size, info, problem, limits)) throw ImageFileError(name + ": " + problem, false);
    if (info.format == "jpeg" && !jpegDataIsWhole(data, size, problem)) throw ImageFileError(name + ": " + problem, false);
    if (info.format == "pfm") { // never OpenCV's PFM codec: it divides by the scale's magnitude
        cv::Mat f = decodePfm(data, size, name, limits);
        const bool gray = flags != cv::IMREAD_UNCHANGED && (flags & cv::IMREAD_COLOR) == 0;
        if (gray && f.channels() == 3) cv::cvtColor(f, f, cv::COLOR_BGR2GRAY);
        if (!gray && flags != cv::IMREAD_UNCHANGED && f.channels() == 1) cv::cvtColor(f, f, cv::COLOR_GRAY2BGR);
        return f;
    }
    cv::Mat m;
    try {
        m = cv::imdecode(cv::Mat(1, static_cast<int>(size), CV_8UC1, const_cast<uint8_t *>(data)), flags);
    } catch (const cv::Exception &e) {
        throw ImageFileError(name + ": cannot decode: " + e.err, false);
    }
    if (m.empty())
        throw ImageFileError(name + ": cannot decode" + (info.format.empty() ? ": not an image format OpenCV reads" : " the " + info.format + " data"), false);
    // Belt and braces: the limits were checked on the header as read here; pixels that
    // OpenCV read to another size would have escaped them. (Width and height swapped is
    // a JPEG's EXIF orientation applied: the same pixels, within the same limits.)
    const bool same = m.cols == info.width && m.rows == info.height;
    const bool turned = m.cols == info.height && m.rows == info.width;
    if (!info.format.empty() && !same && !turned)
        throw ImageFileError(name + ": the " + info.format + " header reads as " + std::to_string(info.width) + "x" +
                                 std::to_string(info.height) + " pixels but decodes as " + std::to_string(m.cols) + "x" +
                                 std::to_string(m.rows) + "; refused as ambiguous",
                             false);
    return m;
}

cv::Mat readImage(const std::string &path, int flags, const std::string &what, const ImageLimits &limits) {
    const std::vector<uint8_t> bytes = readImageFileBytes(path, what, limits);
    return decodeImage(bytes.data(), bytes.size(), flags, what + " '" + path + "'", limits);
}

cv::Mat readPfm(const std::string &path, const std::string &what, const ImageLimits &limits) {
    const std::vector<uint8_t> bytes = readImageFileBytes(path, what, limits);
    return decodePfm(bytes.data(), bytes.size(), what + " '" + path + "'", limits);
}

cv::Mat decodePfm(const uint8_t *data, size_t size, const std::string &name, const ImageLimits &limits) {
    ImageInfo info;
    std::string problem;
    if (!inspectImage(data, size, info, problem, limits)) throw ImageFileError(name + ": " + problem, false);
    if (info.format != "pfm")
        throw ImageFileError(name + ": not a PFM file (expected a header 'Pf' or 'PF', width, height and a non-zero scale)", false);
    // As the format's authors and Middlebury's own tools read it: the scale's SIGN gives the
    // byte order (negative: little-endian), its magnitude is not applied to the values
    // (OpenCV's codec divides by it, which turns Middlebury's -1/255 files into 255 x the
    // disparity). Rows are stored bottom to top. inspectImage checked the data's size.
    const int rows = static_cast<int>(info.height), cols = static_cast<int>(info.width), channels = info.channels;
    cv::Mat m(rows, cols, channels == 3 ? CV_32FC3 : CV_32FC1);
    const bool littleEndian = info.scale < 0;
    const size_t rowBytes = static_cast<size_t>(cols) * static_cast<size_t>(channels) * 4;
    for (int r = 0; r < rows; ++r) {
        const uint8_t *src = data + info.dataOffset + static_cast<size_t>(rows - 1 - r) * rowBytes;
        auto *dst = m.ptr<float>(r);
        for (size_t k = 0; k < rowBytes / 4; ++k) {
            const uint8_t *b = src + 4 * k;
            const uint32_t bits = littleEndian ? (uint32_t{b[3]} << 24 | uint32_t{b[2]} << 16 | uint32_t{b[1]} << 8 | b[0])
                                               : be32(b);
            float v;
            std::memcpy(&v, &bits, 4);
            dst[k] = v;
        }
    }
    if (channels == 3) cv::cvtColor(m, m, cv::COLOR_RGB2BGR); // "PF" stores R, G, B
    return m;
}

std::string encodePfm(const cv::Mat &image) {
    CV_Assert(image.depth() == CV_32F && (image.channels() == 1 || image.channels() == 3));
    cv::Mat m = image;
    if (image.channels() == 3) cv::cvtColor(image, m, cv::COLOR_BGR2RGB);
    // Scale -1: little-endian data, values as they are.
    std::string out = std::string(m.channels() == 3 ? "PF" : "Pf") + "\n" + std::to_string(m.cols) + " " +
                      std::to_string(m.rows) + "\n-1\n";
    const size_t rowBytes = static_cast<size_t>(m.cols) * static_cast<size_t>(m.channels()) * 4;
    out.reserve(out.size() + rowBytes * static_cast<size_t>(m.rows));
    for (int r = m.rows - 1; r >= 0; --r) {
        const auto *src = m.ptr<float>(r);
        for (size_t k = 0; k < rowBytes / 4; ++k) {
            uint32_t bits;
            std::memcpy(&bits, &src[k], 4);
            for (int byte = 0; byte < 4; ++byte) out += static_cast<char>((bits >> (8 * byte)) & 0xFF);
        }
    }
    return out;
}

} // namespace binocle::input
