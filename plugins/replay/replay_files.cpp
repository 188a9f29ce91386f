// SPDX-License-Identifier: MIT
// File helpers of the replay source: glob patterns, natural order, PFM, disparity ground truth.
#include "replay_files.hpp"

#include "replay_metadata.hpp"

#include "input/image_file.hpp"

#include <binocle/plugin.hpp>

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cctype>
#include <cstring>
#include <cerrno>
#include <fstream>
#include <sstream>
#include <limits>
#include <system_error>

namespace fs = std::filesystem;

namespace binocle::replay {

using sdk::Error;

bool hasWildcard(const std::string &text) { return text.find_first_of("*?[") != std::string::npos; }

namespace {

// Matches the bracket expression starting at p[i] == '['; on success sets `next` to the
// index after ']'. A '[' without its ']' is an ordinary character (returns false, next = 0).
bool matchBracket(const std::string &p, size_t i, char c, size_t &next) {
    size_t j = i + 1;
    bool negate = j < p.size() && (p[j] == '!' || p[j] == '^');
    if (negate) ++j;
    bool matched = false;
    bool first = true;
    for (; j < p.size() && (first || p[j] != ']'); ++j, first = false) {
        if (j + 2 < p.size() && p[j + 1] == '-' && p[j + 2] != ']') {
            if (p[j] <= c && c <= p[j + 2]) matched = true;
            j += 2;
        } else if (p[j] == c) {
            matched = true;
        }
    }
    if (j >= p.size()) {
        next = 0;
        return false;
    }
    next = j + 1;
    return matched != negate;
}

bool matchFrom(const std::string &p, size_t pi, const std::string &s, size_t si) {
    while (pi < p.size()) {
        if (p[pi] == '*') {
            while (pi < p.size() && p[pi] == '*') ++pi;
            if (pi == p.size()) return true;
            for (size_t k = si; k <= s.size(); ++k)
                if (matchFrom(p, pi, s, k)) return true;
            return false;
        }
        if (si == s.size()) return false;
        if (p[pi] == '?') {
            ++pi;
            ++si;
            continue;
        }
        if (p[pi] == '[') {
            size_t next = 0;
            bool ok = matchBracket(p, pi, s[si], next);
            if (next != 0) {
                if (!ok) return false;
                pi = next;
                ++si;
                continue;
            }
        }
        if (p[pi] != s[si]) return false;
        ++pi;
        ++si;
    }
    return si == s.size();
}

bool isDigit(char c) { return std::isdigit(static_cast<unsigned char>(c)) != 0; }

void sortNaturally(std::vector<fs::path> &paths) {
    std::sort(paths.begin(), paths.end(),
              [](const fs::path &a, const fs::path &b) { return naturalLess(a.string(), b.string()); });
}

} // namespace

bool wildcardMatch(const std::string &pattern, const std::string &name) {
    if (!name.empty() && name[0] == '.' && (pattern.empty() || pattern[0] != '.')) return false;
    return matchFrom(pattern, 0, name, 0);
}

bool naturalLess(const std::string &a, const std::string &b) {
    size_t i = 0, j = 0;
    while (i < a.size() && j < b.size()) {
        if (isDigit(a[i]) && isDigit(b[j])) {
            size_t ie = i, je = j;
            while (ie < a.size() && isDigit(a[ie])) ++ie;
            while (je < b.size() && isDigit(b[je])) ++je;
            size_t ia = i, jb = j; // skip leading zeros, keeping one digit
            while (ia + 1 < ie && a[ia] == '0') ++ia;
            while (jb + 1 < je && b[jb] == '0') ++jb;
            if (ie - ia != je - jb) return ie - ia < je - jb;
            int c = a.compare(ia, ie - ia, b, jb, je - jb);
            if (c != 0) return c < 0;
            i = ie;
            j = je;
        } else {
            if (a[i] != b[j]) return static_cast<unsigned char>(a[i]) < static_cast<unsigned char>(b[j]);
            ++i;
            ++j;
        }
    }
    if (a.size() - i != b.size() - j) return a.size() - i < b.size() - j;
    return a < b; // equal by value ("7" and "007"): any fixed order will do
}

std::vector<fs::path> globPaths(const std::string &pattern) {
    fs::path whole(pattern);
    std::vector<fs::path> current{whole.has_root_path() ? whole.root_path() : fs::path(".")};
    std::error_code ec;
    for (const fs::path &part : whole.relative_path()) {
        const std::string text = part.string();
        if (text.empty()) continue;
        std::vector<fs::path> next;
        for (const fs::path &base : current) {
            if (!hasWildcard(text)) {
                fs::path candidate = base / part;
                if (fs::exists(candidate, ec)) next.push_back(candidate);
                continue;
            }
            if (!fs::is_directory(base, ec)) continue;
            std::vector<fs::path> matches;
            for (fs::directory_iterator it(base, ec), end; !ec && it != end; it.increment(ec))
                if (wildcardMatch(text, it->path().filename().string())) matches.push_back(it->path());
            sortNaturally(matches);
            next.insert(next.end(), matches.begin(), matches.end());
        }
        current.swap(next);
    }
    if (!whole.has_root_path())
        for (fs::path &p : current) p = p.lexically_relative(".");
    sortNaturally(current);
    return current;
}

std::vector<fs::path> listFolder(const fs::path &folder, bool folders) {
    std::vector<fs::path> out;
    std::error_code ec;
    for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
        if (it->path().filename().string().rfind('.', 0) == 0) continue; // hidden
        if (folders ? it->is_directory(ec) : it->is_regular_file(ec)) out.push_back(it->path());
    }
    sortNaturally(out);
    return out;
}

cv::Mat readPfm(const fs::path &path) {
    try {
        return input::readPfm(path.string());
    } catch (const input::ImageFileError &e) {
        throw Error(e.notFound() ? BINOCLE_ERR_NOT_FOUND : BINOCLE_ERR_IO, std::string("replay: ") + e.what());
    }
}

namespace {
// A palette PNG with a grey palette (Tsukuba's groundtruth.png) decodes to three equal
// channels: one of them is the image. Another three-channel image is refused.
cv::Mat oneChannel(const cv::Mat &raw, const std::string &name) {
    if (raw.channels() == 1) return raw;
    if (raw.channels() == 3 && raw.depth() == CV_8U) {
        std::vector<cv::Mat> c;
        cv::split(raw, c);
        if (cv::countNonZero(c[0] != c[1]) == 0 && cv::countNonZero(c[0] != c[2]) == 0) return c[0];
    }
    throw Error(BINOCLE_ERR_INVALID_ARGUMENT, "replay: ground truth " + name + " has " + std::to_string(raw.channels()) +
                                                  " channels that differ; expected a one-channel disparity image (or a "
                                                  "grey palette)");
}
} // namespace

GroundTruth readGroundTruth(const fs::path &path, double scale, int imageWidth) {
    const std::string name = "'" + path.string() + "'";
    std::string ext = path.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    cv::Mat raw;
    if (ext == ".pfm") {
        raw = readPfm(path);
    } else {
        try {
            raw = input::readImage(path.string(), cv::IMREAD_UNCHANGED, "ground truth");
        } catch (const input::ImageFileError &e) {
            throw Error(e.notFound() ? BINOCLE_ERR_NOT_FOUND : BINOCLE_ERR_IO,
                        std::string("replay: ") + e.what() + " (expected a 16-bit PNG (d*256), 8-bit PNG or PFM)");
        }
    }
    raw = oneChannel(raw, name);
    GroundTruth gt;
    switch (raw.depth()) {
    case CV_16U:
        raw.convertTo(gt.disparity, CV_32F, scale / 256.0);
        cv::compare(raw, 0, gt.valid, cv::CMP_GT);
        break;
    case CV_8U:
        raw.convertTo(gt.disparity, CV_32F, scale);
        cv::compare(raw, 0, gt.valid, cv::CMP_GT);
        break;
    case CV_32F: {
        cv::Mat positive, finite, negative;
        cv::compare(raw, 0.0, positive, cv::CMP_GT); // NaN compares false
        cv::compare(raw, std::numeric_limits<double>::max(), finite, cv::CMP_LT);
        cv::compare(raw, -std::numeric_limits<double>::max(), negative, cv::CMP_GE);
        negative &= ~positive & (raw != 0);
        if (const int n = cv::countNonZero(negative)) {
            cv::Point where;
            cv::minMaxLoc(negative, nullptr, nullptr, nullptr, &where);
            throw Error(BINOCLE_ERR_INVALID_ARGUMENT,
                        "replay: ground truth " + name + " holds " + std::to_string(n) + " negative disparities (first " +
                            std::to_string(raw.at<float>(where)) + " at (" + std::to_string(where.x) + ", " +
                            std::to_string(where.y) + ")); expected disparities >= 0, unknown marked inf, NaN or 0");
        }
        gt.valid = positive & finite;
        raw.convertTo(gt.disparity, CV_32F, scale);
        break;
    }
    default:
        throw Error(BINOCLE_ERR_INVALID_ARGUMENT,
                    "replay: ground truth " + name + " has an unsupported pixel depth; expected 8-bit, 16-bit or float");
    }
    gt.disparity.setTo(-1.0f, ~gt.valid);
    if (imageWidth > 0) {
        double most = 0;
        cv::Point where;
        cv::minMaxLoc(gt.disparity, nullptr, &most, nullptr, &where, gt.valid);
        if (most >= imageWidth)
            throw Error(BINOCLE_ERR_INVALID_ARGUMENT,
                        "replay: ground truth " + name + " holds disparity " + std::to_string(most) + " px at (" +
                            std::to_string(where.x) + ", " + std::to_string(where.y) + "), not less than the image width " +
                            std::to_string(imageWidth) + " px: not a disparity of this image (wrong ground_truth_scale, or "
                            "a PFM read by its scale's magnitude?)");
    }
    return gt;
}

std::string inQuotes(const std::filesystem::path &p) { return "'" + p.string() + "'"; }

// Metadata files are small; a folder or a huge file given in their place is refused
// here rather than read (std::ifstream on a folder throws "basic_filebuf::underflow").
constexpr uintmax_t kMaxMetadataBytes = uintmax_t{16} << 20;

std::string readText(const std::filesystem::path &path, const std::string &what) {
    std::error_code ec;
    const auto status = std::filesystem::status(path, ec);
    if (ec || !std::filesystem::exists(status)) throw sdk::Error(BINOCLE_ERR_NOT_FOUND, "replay: cannot read " + what + " " + inQuotes(path) + ": no such file");
    if (!std::filesystem::is_regular_file(status))
        throw sdk::Error(BINOCLE_ERR_INVALID_ARGUMENT, "replay: " + what + " " + inQuotes(path) + " is not a regular file");
    const uintmax_t size = std::filesystem::file_size(path, ec);
    if (ec || size > kMaxMetadataBytes)
        throw sdk::Error(BINOCLE_ERR_INVALID_ARGUMENT, "replay: " + what + " " + inQuotes(path) + " holds " +
                                                      std::to_string(size) + " bytes; expected at most " +
                                                      std::to_string(kMaxMetadataBytes));
    std::ifstream in(path, std::ios::binary);
    if (!in) throw sdk::Error(BINOCLE_ERR_IO, "replay: cannot read " + what + " " + inQuotes(path) + ": " + std::strerror(errno));
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

// An image file's size from its header when the format is one input::inspectImage
// reads, else from decoding it.
cv::Size imageSizeOf(const std::filesystem::path &path) {
    try {
        const auto bytes = input::readImageFileBytes(path.string(), "image");
        input::ImageInfo info;
        std::string problem;
        if (!input::inspectImage(bytes.data(), bytes.size(), info, problem))
            throw sdk::Error(BINOCLE_ERR_INVALID_ARGUMENT, "replay: image " + inQuotes(path) + ": " + problem);
        if (!info.format.empty()) return cv::Size(static_cast<int>(info.width), static_cast<int>(info.height));
        return input::readImage(path.string(), cv::IMREAD_UNCHANGED).size();
    } catch (const input::ImageFileError &e) {
        throw sdk::Error(e.notFound() ? BINOCLE_ERR_NOT_FOUND : BINOCLE_ERR_IO, std::string("replay: ") + e.what());
    }
}

bool isImageFile(const std::filesystem::path &p) {
    std::string ext = p.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    static const std::vector<std::string> known{".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".pgm", ".ppm", ".pfm", ".webp"};
    return std::find(known.begin(), known.end(), ext) != known.end();
}

} // namespace binocle::replay
