// SPDX-License-Identifier: MIT
// The rule for names of plugins and of their settings: [a-z0-9_]+. Internal to host/.
#pragma once

namespace binocle {

// True for a non-empty name of lowercase letters, digits and underscores ("window_px").
bool validName(const char *name);

} // namespace binocle
