// SPDX-License-Identifier: MIT
// The files Binocle ships (configs/...), found the same way from the CLI and from Python.
#pragma once

#include <string>

namespace binocle::app {

// A file shipped with Binocle (e.g. "configs/rigs/sim-e1.yaml"): under the install prefix
// (host/install_prefix.hpp: next to the executable, or the Python module's), else from the
// source tree it was built from.
std::string dataFile(const std::string &relative);

} // namespace binocle::app
