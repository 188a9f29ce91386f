// SPDX-License-Identifier: MIT
// The viewer's page (framework/viewer/web/), embedded at build time.
#pragma once

#include "core/embedded_file.hpp"

#include <string_view>

namespace binocle::viewer {

// nullptr when no such file was embedded.
const EmbeddedFile *webFile(std::string_view name);

} // namespace binocle::viewer
