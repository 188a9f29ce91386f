// SPDX-License-Identifier: MIT
// dataFile: <prefix>/share/binocle/<relative>, else the source tree's file.
#include "app/data_file.hpp"

#include "host/install_prefix.hpp"

#include <filesystem>

namespace binocle::app {

std::string dataFile(const std::string &relative) {
    const std::string prefix = installPrefix();
    std::error_code ec;
    if (!prefix.empty()) {
        const auto installed = std::filesystem::path(prefix) / BINOCLE_DATA_INSTALL_DIR / relative;
        if (std::filesystem::exists(installed, ec)) return installed.string();
    }
    return (std::filesystem::path(BINOCLE_SOURCE_DIR) / relative).string();
}

} // namespace binocle::app
