// SPDX-License-Identifier: MIT
// The report's template (framework/report/web/), embedded at build time.
#pragma once

#include "core/embedded_file.hpp"

#include <string_view>

namespace binocle::report {

// nullptr when no such file was embedded.
const EmbeddedFile *webFile(std::string_view name);

} // namespace binocle::report
