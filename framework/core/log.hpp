// SPDX-License-Identifier: MIT
// Logging set-up (spdlog): the level, the console format, an optional log file, and how
// plugins' messages (binocle_host.log) reach the log, tagged with the plugin's name.
#pragma once

#include <optional>
#include <spdlog/common.h>
#include <string>

namespace binocle {

// "trace", "debug", "info", "warn"/"warning", "error", "critical", "off"; throws
// binocle::Error naming `what` (e.g. "--log-level") and the accepted values otherwise.
spdlog::level::level_enum parseLogLevel(const std::string &text, const std::string &what);

struct LogOptions {
    std::string program = "binocle";  // prefix of warnings and errors: "binocle run: error: ..."
    spdlog::level::level_enum level = spdlog::level::info;
    std::string file;                  // also log here (every level from `level` up), with times
};

// Replaces the default logger: stderr in the command's words (info lines as they are,
// "<program>: <level>: <message>" otherwise) and, with `file`, a timestamped copy.
// Throws binocle::Error when the log file cannot be opened.
void setupLogging(const LogOptions &options);

// A plugin's message (BINOCLE_LOG_* level) into the log, as "[plugin] message".
void logFromPlugin(const std::string &plugin, int32_t level, const std::string &message);

} // namespace binocle
