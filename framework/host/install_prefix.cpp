// SPDX-License-Identifier: MIT
// The install prefix: named by the program that carries the framework, else bin/.. .
#include "host/install_prefix.hpp"

#include "core/error.hpp"

#include <boost/dll/runtime_symbol_info.hpp>
#include <filesystem>
#include <mutex>

namespace fs = std::filesystem;

namespace binocle {

namespace {

std::mutex prefixMutex;
std::string namedPrefix; // guarded by prefixMutex

} // namespace

void setInstallPrefix(const std::string &prefix) {
    if (!prefix.empty() && fs::path(prefix).is_relative())
        throw Error("install prefix '" + prefix + "': expected an absolute path");
    std::lock_guard<std::mutex> lock(prefixMutex);
    namedPrefix = prefix.empty() ? "" : fs::path(prefix).lexically_normal().string();
}

bool installPrefixIsSet() {
    std::lock_guard<std::mutex> lock(prefixMutex);
    return !namedPrefix.empty();
}

std::string installPrefix() {
    {
        std::lock_guard<std::mutex> lock(prefixMutex);
        if (!namedPrefix.empty()) return namedPrefix;
    }
    try {
        const fs::path exe = boost::dll::program_location().string();
        return exe.parent_path().parent_path().lexically_normal().string();
    } catch (...) {
        return ""; // no program location (unusual): only $BINOCLE_PLUGIN_PATH applies
    }
}

} // namespace binocle
