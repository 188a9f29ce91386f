// SPDX-License-Identifier: MIT
// A plugin file the host accepted (PluginRecord), and the names of the ABI's numbers.
// What every other header of the host builds on.
#pragma once

#include <binocle/abi.h>
#include <binocle/plugin.hpp>

#include <memory>
#include <string>
#include <vector>

namespace boost::dll {
class shared_library;
}

namespace binocle {

const char *kindName(int32_t kind);    // "source", "matcher", "transform", "evaluator"
const char *resultName(int32_t code);  // "BINOCLE_ERR_TIMEOUT" ...
using sdk::bytesPerPixel; // of a BINOCLE_PIXEL_* format, 0 when unknown: the SDK's (binocle/plugin.hpp)

// A plugin file that was accepted.
struct PluginRecord {
    std::string path;
    std::string name, version, description;
    int32_t kind = 0;
    uint32_t abi_version = 0, api_version = 0;
    // The host's own full-size copy of the plugin's table: the bytes the plugin declared
    // (header.struct_size), zeros after them, so that an entry a plugin built against an
    // older API lacks reads as NULL (absent) and one a newer plugin appended is never read.
    const binocle_plugin_header *table = nullptr;
    std::shared_ptr<const void> tableStorage;
    std::shared_ptr<boost::dll::shared_library> library; // keeps the code loaded
    // Read by a helper process (PluginHost::describe): header and settings table only, no
    // library and no entry points here; instances of it run in helper processes only.
    bool described = false;
    std::vector<binocle_param_desc> params() const;
};

} // namespace binocle
