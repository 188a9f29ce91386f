// SPDX-License-Identifier: MIT
// Errors the framework throws; the CLI prints what() and exits non-zero. binocle::Error
// itself lives in the base layer (base/error/error.hpp), which throws it too.
#pragma once

#include "error/error.hpp"

#include <string>

namespace binocle {

// A plugin refused a call or misbehaved; what() names the plugin and carries its message.
class PluginError : public Error {
public:
    PluginError(const std::string &message, int code) : Error(message), code_(code) {}
    int code() const noexcept { return code_; }

private:
    int code_;
};

} // namespace binocle
