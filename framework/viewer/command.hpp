// SPDX-License-Identifier: MIT
// What a page may send: one command as JSON text, its sizes checked before it is parsed.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <string_view>

namespace binocle::viewer {

// Caps checked before anything is parsed or allocated for a command. The server also
// stops reading a WebSocket message or a POST body at kMaxCommandBytes.
inline constexpr size_t kMaxCommandBytes = 64 * 1024;
// A command is one flat object: nesting deeper than this is refused before parsing.
inline constexpr size_t kMaxCommandDepth = 2;
// The longest key a rig has is "transforms.N.setting" (3 parts).
inline constexpr size_t kMaxKeyBytes = 160;
inline constexpr size_t kMaxKeyParts = 3;
// A value is YAML text (a number, a path, a small YAML tree): it is copied into the state
// every page receives, so it is kept small.
inline constexpr size_t kMaxValueBytes = 4 * 1024;

enum class Op { Set, Pause, Resume, Step, Restart, Reset, Snapshot };

struct Command {
    Op op = Op::Pause;
    std::string name;       // the op as sent ("set")
    std::string key, value; // set only
};

// A command refused before it reaches the rig: `message` is for the page and the log
// (excerpts of what was sent, never all of it); `op` and `key` when they were read.
class CommandError : public std::runtime_error {
public:
    CommandError(const std::string &message, std::string op = "", std::string key = "")
        : std::runtime_error(message), op(std::move(op)), key(std::move(key)) {}
    std::string op, key;
};

// Parses one command: {"op": "set", "key": "matcher.num_disparities", "value": "128"},
// {"op": "pause"}, ... Throws CommandError naming the limit or the field. The cost is
// linear in the text, and nothing is allocated for a text over kMaxCommandBytes.
Command parseCommand(std::string_view text);

} // namespace binocle::viewer
