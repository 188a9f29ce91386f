// SPDX-License-Identifier: MIT
// Taking pairs from a rig's source, the same for every loop that does: the pipeline's
// acquire stage (pipeline_stages.cpp) and the recorder (recorder.cpp). Whether the source
// is live is its own word, read here once; a grab waits in slices so that a stop is seen.
#pragma once

#include "host/plugin_host.hpp"

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

namespace binocle {

// Whether the source says its frames come on their own clock (cameras): the `live: true`
// entry of its statistics (sdk/include/binocle/abi/source.h). False when it gives no
// statistics, they are not YAML, or asking fails.
bool sourceIsLive(Source &source);

// One grab from a started source, waited for in slices of at most 250 ms so that
// `stopped` (asked between slices) is seen within a fraction of a second even from a
// silent camera. Returns the pair, or null at the end of the stream. Throws the source's
// PluginError: BINOCLE_ERR_TIMEOUT after `timeoutMs` (< 0: wait for ever) or when stopped
// while waiting, any other code at once.
std::unique_ptr<LentFrame> grabWithin(Source &source, int32_t timeoutMs, const std::function<bool()> &stopped);

} // namespace binocle
