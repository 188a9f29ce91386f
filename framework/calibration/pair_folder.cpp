// SPDX-License-Identifier: MIT
// Chessboard pairs in a folder, matched by the number in their names.
#include "calibration/pair_folder.hpp"

#include "core/error.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <map>
#include <set>

namespace fs = std::filesystem;

namespace binocle {

namespace {

std::string lower(std::string s) {
    for (char &c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

bool isImage(const fs::path &p) {
    static const std::set<std::string> extensions = {".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".pgm", ".ppm"};
    return extensions.count(lower(p.extension().string())) != 0;
}

// The last run of digits in the stem, or "" when there is none.
std::string numberIn(const std::string &stem) {
    const auto end = stem.find_last_of("0123456789");
    if (end == std::string::npos) return "";
    auto begin = end;
    while (begin > 0 && std::isdigit(static_cast<unsigned char>(stem[begin - 1]))) --begin;
    return stem.substr(begin, end - begin + 1);
}

unsigned long long valueOf(const std::string &digits) {
    const auto nz = digits.find_first_not_of('0');
    const std::string d = nz == std::string::npos ? "0" : digits.substr(nz);
    return d.size() > 18 ? ~0ull : std::stoull(d);
}

} // namespace

PairListing listImagePairs(const std::string &dir) {
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) throw Error("--pairs " + dir + ": not a folder");
    struct Side {
        std::map<unsigned long long, std::pair<std::string, std::string>> byNumber; // number -> (digits, file)
    } left, right;
    PairListing out;
    std::vector<fs::path> files;
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec))
        if (it->is_regular_file() && isImage(it->path())) files.push_back(it->path());
    if (ec) throw Error("--pairs " + dir + ": cannot list the folder: " + ec.message());
    std::sort(files.begin(), files.end());
    for (const auto &f : files) {
        const std::string name = f.filename().string(), stem = lower(f.stem().string());
        Side *side = stem.rfind("left", 0) == 0 ? &left : stem.rfind("right", 0) == 0 ? &right : nullptr;
        if (!side) continue;
        const std::string digits = numberIn(stem);
        if (digits.empty()) {
            out.unmatched.push_back(name + ": no number in the name");
            continue;
        }
        const auto [it, fresh] = side->byNumber.emplace(valueOf(digits), std::make_pair(digits, f.string()));
        if (!fresh) out.unmatched.push_back(name + ": number " + digits + " already taken by " + fs::path(it->second.second).filename().string());
    }
    for (const auto &[n, l] : left.byNumber) {
        auto r = right.byNumber.find(n);
        if (r == right.byNumber.end()) {
            out.unmatched.push_back(fs::path(l.second).filename().string() + ": no right image numbered " + l.first);
            continue;
        }
        out.pairs.push_back({l.first, l.second, r->second.second});
    }
    for (const auto &[n, r] : right.byNumber)
        if (!left.byNumber.count(n))
            out.unmatched.push_back(fs::path(r.second).filename().string() + ": no left image numbered " + r.first);
    return out;
}

} // namespace binocle
