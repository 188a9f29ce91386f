// SPDX-License-Identifier: MIT
// Names from untrusted input: names that become file names, and the "did you mean" of
// every message about a name. (Printable excerpts and confined relative paths are the
// SDK's: binocle/text.hpp.)
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace binocle::input {

// A name usable as one file-name component: 1..100 characters of [A-Za-z0-9._-], not
// starting with '.' ("1", "e1-b150_f8" yes; "../x", "/x", ".", "a b" no).
bool isSafeName(std::string_view name, std::string *why = nullptr);

// The candidate closest to `word` by edit distance (ties: the longer common prefix),
// or "" when none is close: the "did you mean" of every message about a name.
std::string nearestWord(const std::string &word, const std::vector<std::string> &candidates);

} // namespace binocle::input
