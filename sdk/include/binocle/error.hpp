// SPDX-License-Identifier: MIT
// binocle::sdk::Error: what a plugin throws to fail a call with a result code and a
// message. The export macros of plugin.hpp catch it at the boundary; the settings
// checker (settings.hpp) throws it for a refused value.
#pragma once

#include <binocle/abi.h>

#include <stdexcept>
#include <string>

namespace binocle::sdk {

// An error with a result code; anything else thrown becomes BINOCLE_ERR_INTERNAL.
class Error : public std::runtime_error {
public:
    Error(binocle_result code, const std::string &message) : std::runtime_error(message), code_(code) {}
    binocle_result code() const noexcept { return code_; }

private:
    binocle_result code_;
};

} // namespace binocle::sdk
