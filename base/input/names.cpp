// SPDX-License-Identifier: MIT
// Safe names and the nearest word.
#include "input/names.hpp"

#include <algorithm>
#include <vector>

namespace binocle::input {

bool isSafeName(std::string_view name, std::string *why) {
    auto fail = [&](const char *what) {
        if (why) *why = what;
        return false;
    };
    if (name.empty()) return fail("empty name");
    if (name.size() > 100) return fail("longer than 100 characters");
    for (char c : name) {
        const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' ||
                        c == '_' || c == '-';
        if (!ok) return fail("expected letters, digits, '.', '_' or '-' only");
    }
    if (name.front() == '.') return fail("starts with '.'");
    return true;
}

std::string nearestWord(const std::string &word, const std::vector<std::string> &candidates) {
    auto distance = [](const std::string &a, const std::string &b) {
        std::vector<size_t> prev(b.size() + 1), cur(b.size() + 1);
        for (size_t j = 0; j <= b.size(); ++j) prev[j] = j;
        for (size_t i = 1; i <= a.size(); ++i) {
            cur[0] = i;
            for (size_t j = 1; j <= b.size(); ++j)
                cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
            std::swap(prev, cur);
        }
        return prev[b.size()];
    };
    auto commonPrefix = [](const std::string &a, const std::string &b) {
        size_t n = 0;
        while (n < a.size() && n < b.size() && a[n] == b[n]) ++n;
        return n;
    };
    std::string best;
    size_t bestD = std::max<size_t>(2, word.size() / 3) + 1, bestPrefix = 0;
    for (const auto &c : candidates) {
        const size_t d = distance(word, c), prefix = commonPrefix(word, c);
        // Ties go to the longer common prefix: "num_disparity" -> "num_disparities",
        // not "min_disparity".
        if (d < bestD || (d == bestD && !best.empty() && prefix > bestPrefix)) bestD = d, best = c, bestPrefix = prefix;
    }
    return best;
}

} // namespace binocle::input
