// SPDX-License-Identifier: MIT
// Errors the framework throws; the CLI prints what() and exits non-zero.
#pragma once

#include <stdexcept>
#include <string>

namespace binocle {

// Something the user can fix: a file, a key, a value, a device. what() names them.
class Error : public std::runtime_error {
public:
    explicit Error(const std::string &message) : std::runtime_error(message) {}
};

// A plugin refused a call or misbehaved; what() names the plugin and carries its message.
class PluginError : public Error {
public:
    PluginError(const std::string &message, int code) : Error(message), code_(code) {}
    int code() const noexcept { return code_; }

private:
    int code_;
};

} // namespace binocle
