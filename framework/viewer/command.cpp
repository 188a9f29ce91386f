// SPDX-License-Identifier: MIT
// The page's commands: sizes and nesting checked on the raw text, then one JSON parse,
// then the key's shape (short dotted names) before any rig code sees it.
#include "viewer/command.hpp"

#include <binocle/text.hpp>
#include <nlohmann/json.hpp>

namespace binocle::viewer {

namespace {

using Json = nlohmann::json;

const char *const kOps = "set, pause, resume, step, restart, reset, snapshot";

// Deepest nesting of arrays and objects, outside strings, stopping once past `limit`:
// one pass, no allocation.
size_t nestingDepth(std::string_view text, size_t limit) {
    size_t depth = 0, deepest = 0;
    bool inString = false;
    for (size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (inString) {
            if (c == '\\') ++i;
            else if (c == '"') inString = false;
        } else if (c == '"') {
            inString = true;
        } else if (c == '{' || c == '[') {
            deepest = std::max(deepest, ++depth);
            if (deepest > limit) return deepest;
        } else if ((c == '}' || c == ']') && depth > 0) {
            --depth;
        }
    }
    return deepest;
}

std::string keyProblem(const std::string &key) {
    if (key.empty()) return "is empty";
    if (key.size() > kMaxKeyBytes)
        return "is " + std::to_string(key.size()) + " bytes long; expected at most " + std::to_string(kMaxKeyBytes);
    size_t parts = 1, partLength = 0;
    for (const char c : key) {
        if (c == '.') {
            if (partLength == 0) return "has an empty part; expected names joined by '.' (matcher.num_disparities)";
            if (++parts > kMaxKeyParts)
                return "has more than " + std::to_string(kMaxKeyParts) + " parts; expected BLOCK.SETTING or transforms.N.SETTING";
            partLength = 0;
        } else if ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_') {
            ++partLength;
        } else {
            return "holds a character other than letters, digits, '_' and '.'";
        }
    }
    if (partLength == 0) return "ends with '.'";
    return "";
}

} // namespace

Command parseCommand(std::string_view text) {
    if (text.size() > kMaxCommandBytes)
        throw CommandError("view: a command of " + std::to_string(text.size()) + " bytes; expected at most " +
                           std::to_string(kMaxCommandBytes));
    if (nestingDepth(text, kMaxCommandDepth) > kMaxCommandDepth)
        throw CommandError("view: a command is one flat JSON object (nested deeper than " + std::to_string(kMaxCommandDepth) +
                           " levels)");
    const Json c = Json::parse(text, nullptr, false);
    if (c.is_discarded() || !c.is_object() || !c.contains("op") || !c["op"].is_string())
        throw CommandError("view: a command is a JSON object with \"op\" (" + std::string(kOps) + ")");
    Command out;
    out.name = c["op"].get<std::string>();
    static const std::pair<const char *, Op> ops[] = {{"set", Op::Set},         {"pause", Op::Pause}, {"resume", Op::Resume},
                                                      {"step", Op::Step},       {"restart", Op::Restart},
                                                      {"reset", Op::Reset},     {"snapshot", Op::Snapshot}};
    bool known = false;
    for (const auto &[name, op] : ops)
        if (out.name == name) out.op = op, known = true;
    if (!known) throw CommandError("view: unknown command '" + sdk::printable(out.name, 40) + "' (" + kOps + ")", out.name);
    if (out.op != Op::Set) return out;

    if (!c.contains("key") || !c["key"].is_string() || !c.contains("value") || !c["value"].is_string())
        throw CommandError("view: set needs \"key\" and \"value\" (YAML text), both strings", out.name);
    out.key = c["key"].get<std::string>();
    out.value = c["value"].get<std::string>();
    if (const std::string why = keyProblem(out.key); !why.empty())
        throw CommandError("view: set: the key '" + sdk::printable(out.key, 60) + "' " + why, out.name, sdk::printable(out.key, 60));
    if (out.value.size() > kMaxValueBytes)
        throw CommandError("view: set " + out.key + ": a value of " + std::to_string(out.value.size()) + " bytes; expected at most " +
                               std::to_string(kMaxValueBytes),
                           out.name, out.key);
    if (out.value.find('\0') != std::string::npos)
        throw CommandError("view: set " + out.key + ": the value holds a NUL character", out.name, out.key);
    return out;
}

} // namespace binocle::viewer
