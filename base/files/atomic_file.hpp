// SPDX-License-Identifier: MIT
// Whole-file reads and crash-safe writes: a result file is either complete or absent.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

namespace binocle {

// Throws binocle::Error naming the path when it cannot be read, is not a regular file or
// holds more than maxBytes.
std::string readTextFile(const std::string &path, uintmax_t maxBytes = uintmax_t{64} << 20);

// Writes to a new temporary beside path (".tmp-<pid>-<random>-<name>", created with
// O_EXCL | O_NOFOLLOW: a planted symlink is never followed), fsyncs, then renames over
// path. On failure the old file (if any) is untouched and the temporary is removed.
void writeFileAtomic(const std::string &path, const std::string &bytes);

// Same, for writers that need a file name (cv::imwrite): `write` receives the temporary
// path, which keeps the extension of `path` so that the format is chosen right.
void writeFileAtomicWith(const std::string &path, const std::function<void(const std::string &tmp)> &write);

} // namespace binocle
