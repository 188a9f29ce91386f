// SPDX-License-Identifier: MIT
// Where Binocle's own files lie at run time: <prefix>/lib/binocle/plugins (the plugins)
// and <prefix>/libexec/binocle/binocle-plugin-helper (the helper of `isolation: process`).
#pragma once

#include <string>

namespace binocle {

// The prefix named by setInstallPrefix, else the folder above the running executable's
// (<prefix>/bin/binocle; the build tree mirrors that layout). "" when neither is known.
std::string installPrefix();

// For a program that is not one of Binocle's executables but carries the framework (the
// Python module, inside python3): the prefix it was installed or built under, found from
// where its own file lies. An absolute path; "" goes back to the executable's. Set it
// before the first PluginHost is made.
void setInstallPrefix(const std::string &prefix);

// True once setInstallPrefix named a prefix.
bool installPrefixIsSet();

} // namespace binocle
