// SPDX-License-Identifier: MIT
// binocle::Error, the error a user can fix: thrown by the base layer (the atomic file
// writer) and by the framework; the CLI prints what() and exits non-zero, the Python
// module raises binocle.Error.
#pragma once

#include <stdexcept>
#include <string>

namespace binocle {

// Something the user can fix: a file, a key, a value, a device. what() names them.
class Error : public std::runtime_error {
public:
    explicit Error(const std::string &message) : std::runtime_error(message) {}
};

} // namespace binocle
