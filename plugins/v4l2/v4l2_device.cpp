// SPDX-License-Identifier: MIT
// v4l2: the parts of the device layer that every implementation shares.
#include "v4l2_device.hpp"

#include <cstring>

namespace binocle::v4l2 {

DeviceError::DeviceError(int err, const std::string &call)
    : std::runtime_error(call + ": " + std::strerror(err)), err_(err), call_(call) {}

std::string fourccText(uint32_t fourcc) {
    std::string s;
    for (int i = 0; i < 4; ++i) {
        const char c = static_cast<char>((fourcc >> (8 * i)) & 0xff);
        if (c != ' ' && c != '\0') s += (c >= 32 && c < 127) ? c : '?';
    }
    return s;
}

} // namespace binocle::v4l2
