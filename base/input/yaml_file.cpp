// SPDX-License-Identifier: MIT
// One YAML loader: UTF-8, syntax and duplicate keys checked, size bounded.
#include "input/yaml_file.hpp"

#include "input/names.hpp"
#include "input/utf8.hpp"

#include <binocle/text.hpp>

#include <yaml-cpp/depthguard.h>
#include <yaml-cpp/eventhandler.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <vector>

namespace fs = std::filesystem;

namespace binocle::input {

namespace {

std::string at(const std::string &origin, const YAML::Mark &m) {
    if (m.is_null()) return origin;
    return origin + ":" + std::to_string(m.line + 1) + ":" + std::to_string(m.column + 1);
}

std::string lineColumn(const YAML::Mark &m) { return std::to_string(m.line + 1) + ":" + std::to_string(m.column + 1); }

} // namespace

void checkDuplicateKeys(const YAML::Node &root, const std::string &origin) {
    std::vector<YAML::Node> todo{root};
    std::set<int> seen; // marks (byte offsets) of the collections already checked
    while (!todo.empty()) {
        const YAML::Node n = todo.back();
        todo.pop_back();
        if (!n.IsMap() && !n.IsSequence()) continue;
        const YAML::Mark m = n.Mark();
        if (!m.is_null() && !seen.insert(m.pos).second) continue; // an alias of a node already checked
        if (n.IsSequence()) {
            for (const auto &e : n) todo.push_back(e);
            continue;
        }
        std::map<std::string, YAML::Mark> keys;
        for (const auto &kv : n) {
            if (kv.first.IsScalar()) {
                auto [it, fresh] = keys.emplace(kv.first.Scalar(), kv.first.Mark());
                if (!fresh)
                    throw YamlError(at(origin, kv.first.Mark()) + ": key '" + sdk::printable(kv.first.Scalar()) +
                                    "' given twice in one map: first at " + lineColumn(it->second) + ", again at " +
                                    lineColumn(kv.first.Mark()) + "; remove one of them");
            }
            todo.push_back(kv.second);
        }
    }
}

namespace {

// Where a second document begins, if the text holds one (or anything after the first).
// The parser is asked for two documents at most: it is its own loop that never ends.
std::optional<YAML::Mark> secondDocument(const std::string &text) {
    struct Events : YAML::EventHandler {
        int documents = 0;
        YAML::Mark second;
        void OnDocumentStart(const YAML::Mark &mark) override {
            if (++documents == 2) second = mark;
        }
        void OnDocumentEnd() override {}
        void OnNull(const YAML::Mark &, YAML::anchor_t) override {}
        void OnAlias(const YAML::Mark &, YAML::anchor_t) override {}
        void OnScalar(const YAML::Mark &, const std::string &, YAML::anchor_t, const std::string &) override {}
        void OnSequenceStart(const YAML::Mark &, const std::string &, YAML::anchor_t, YAML::EmitterStyle::value) override {}
        void OnSequenceEnd() override {}
        void OnMapStart(const YAML::Mark &, const std::string &, YAML::anchor_t, YAML::EmitterStyle::value) override {}
        void OnMapEnd() override {}
    } events;
    std::istringstream in(text);
    YAML::Parser parser(in);
    if (!parser.HandleNextDocument(events) || !parser.HandleNextDocument(events)) return std::nullopt;
    return events.second;
}

} // namespace

YAML::Node parseYaml(const std::string &text, const std::string &origin) {
    size_t bad = 0;
    if (!isValidUtf8(text, &bad)) {
        const size_t lineStart = text.rfind('\n', bad == 0 ? 0 : bad - 1);
        const size_t line = static_cast<size_t>(std::count(text.begin(), text.begin() + static_cast<long>(bad), '\n')) + 1;
        const size_t column = bad - (lineStart == std::string::npos || bad == 0 ? 0 : lineStart + 1) + 1;
        char byte[8];
        std::snprintf(byte, sizeof byte, "0x%02X", static_cast<unsigned char>(text[bad]));
        throw YamlError(origin + ":" + std::to_string(line) + ":" + std::to_string(column) + ": byte " + byte +
                        " is not valid UTF-8; expected a UTF-8 text (YAML files are UTF-8)");
    }
    YAML::Node root;
    try {
        root = YAML::Load(text);
        // YAML::Load stops after the first document and ignores whatever follows, broken
        // or not (a rig with a second `---` block; a mangled calibration). So the text is
        // parsed again, events only, for one more document. Not with YAML::LoadAll: on
        // stray tokens after a document it loops for ever, allocating (found by fuzzing).
        if (const auto second = secondDocument(text))
            throw YamlError(at(origin, *second) + ": more follows the first YAML document here; expected one document");
    } catch (const YAML::DeepRecursion &e) {
        // yaml-cpp's own guard (500 levels), which it words "bad file".
        throw YamlError(at(origin, e.mark) + ": lists or maps nested more than " + std::to_string(e.depth()) +
                        " deep; expected a YAML file nested a few levels (no Binocle file needs more than ten)");
    } catch (const YAML::ParserException &e) {
        throw YamlError(at(origin, e.mark) + ": YAML syntax error: " + e.msg);
    } catch (const YAML::Exception &e) {
        throw YamlError(origin + ": cannot read YAML: " + e.msg);
    }
    checkDuplicateKeys(root, origin);
    return root;
}

YAML::Node loadYamlFile(const std::string &path, uint64_t maxBytes) {
    std::error_code ec;
    const auto status = fs::status(path, ec);
    if (ec || !fs::exists(status)) throw YamlError(path + ": no such file");
    if (!fs::is_regular_file(status)) throw YamlError(path + ": not a regular file; expected a YAML file");
    const uint64_t size = fs::file_size(path, ec);
    if (ec) throw YamlError(path + ": cannot read its size: " + ec.message());
    if (size > maxBytes)
        throw YamlError(path + ": the file holds " + std::to_string(size) + " bytes; expected a YAML file of at most " +
                        std::to_string(maxBytes) + " bytes");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw YamlError(path + ": cannot open: " + std::strerror(errno));
    std::ostringstream text;
    text << in.rdbuf();
    return parseYaml(text.str(), path);
}

std::optional<UnknownKey> findUnknownKey(const YAML::Node &map, const std::vector<std::string> &valid,
                                         const std::string &owner) {
    if (!map.IsMap()) return std::nullopt;
    for (const auto &kv : map) {
        const std::string name = kv.first.IsScalar() ? kv.first.Scalar() : "(a non-scalar key)";
        if (std::find(valid.begin(), valid.end(), name) != valid.end()) continue;
        const std::string hint = kv.first.IsScalar() ? nearestWord(name, valid) : "";
        std::string list;
        for (const auto &v : valid) list += (list.empty() ? "" : ", ") + v;
        return UnknownKey{kv.first, name,
                          "unknown key '" + sdk::printable(name, 60) + "'" + (owner.empty() ? "" : " " + owner) + (hint.empty() ? "" : "; did you mean '" + hint + "'?") +
                              " (valid keys: " + (list.empty() ? "none" : list) + ")"};
    }
    return std::nullopt;
}

void checkKeys(const YAML::Node &map, const std::vector<std::string> &valid, const std::string &what,
               const std::string &origin) {
    if (!map.IsMap()) throw YamlError(located(map, origin) + ": " + what + ": expected a map");
    if (auto unknown = findUnknownKey(map, valid)) throw YamlError(located(unknown->key, origin) + ": " + what + ": " + unknown->message);
}

std::string located(const YAML::Node &node, const std::string &origin) {
    return node.IsDefined() ? at(origin, node.Mark()) : origin;
}

} // namespace binocle::input
