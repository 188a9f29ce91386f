// SPDX-License-Identifier: MIT
// Whole-file reads and crash-safe writes: a result file is either complete or absent.
#pragma once

#include <cstdint>
#include <string>

namespace binocle {

// Throws binocle::Error naming the path when it cannot be read, is not a regular file or
// holds more than maxBytes.
std::string readTextFile(const std::string &path, uintmax_t maxBytes = uintmax_t{64} << 20);

// Writes to a new temporary file beside path (a random name, created with O_EXCL |
// O_NOFOLLOW: nothing planted in the folder is opened or followed), flushes, then renames
// over path (a symbolic link there is replaced, not followed). On failure the old file
// (if any) is untouched and the temporary is removed.
void writeFileAtomic(const std::string &path, const std::string &bytes);

} // namespace binocle
