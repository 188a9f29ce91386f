// SPDX-License-Identifier: MIT
// A small JSON value: build and dump.
#include "core/json.hpp"

#include "input/text.hpp"

#include <cmath>
#include <cstdio>

namespace binocle {

Json &Json::set(const std::string &key, Json value) {
    if (!std::holds_alternative<Object>(v_)) v_ = Object{};
    auto &o = std::get<Object>(v_);
    for (auto &kv : o)
        if (kv.first == key) {
            kv.second = std::move(value);
            return *this;
        }
    o.emplace_back(key, std::move(value));
    return *this;
}

Json &Json::push(Json value) {
    if (!std::holds_alternative<Array>(v_)) v_ = Array{};
    std::get<Array>(v_).push_back(std::move(value));
    return *this;
}

const Json *Json::get(const std::string &key) const {
    if (!std::holds_alternative<Object>(v_)) return nullptr;
    for (const auto &kv : std::get<Object>(v_))
        if (kv.first == key) return &kv.second;
    return nullptr;
}

std::string jsonEscape(const std::string &text) {
    // JSON is UTF-8: a name or path with ill-formed bytes (a non-UTF-8 file name, a
    // plugin's message) is written with U+FFFD in their place, never as invalid JSON.
    const std::string s = input::sanitizeUtf8(text);
    std::string out = "\"";
    for (unsigned char c : s) {
        switch (c) {
        case '"': out += "\\\""; break;
        case '\\': out += "\\\\"; break;
        case '\n': out += "\\n"; break;
        case '\r': out += "\\r"; break;
        case '\t': out += "\\t"; break;
        default:
            if (c < 0x20) {
                char buf[8];
                std::snprintf(buf, sizeof buf, "\\u%04x", c);
                out += buf;
            } else {
                out += static_cast<char>(c);
            }
        }
    }
    return out + "\"";
}

std::string Json::dump(int indent) const {
    std::string out;
    dumpTo(out, indent, 0);
    return out + "\n";
}

void Json::dumpTo(std::string &out, int indent, int depth) const {
    const std::string pad = indent > 0 ? "\n" + std::string(static_cast<size_t>(indent * (depth + 1)), ' ') : "";
    const std::string padEnd = indent > 0 ? "\n" + std::string(static_cast<size_t>(indent * depth), ' ') : "";
    if (std::holds_alternative<std::nullptr_t>(v_)) {
        out += "null";
    } else if (auto b = std::get_if<bool>(&v_)) {
        out += *b ? "true" : "false";
    } else if (auto d = std::get_if<double>(&v_)) {
        if (!std::isfinite(*d)) {
            out += "null";
        } else if (*d == std::floor(*d) && std::fabs(*d) < 1e15) {
            out += std::to_string(static_cast<int64_t>(*d));
        } else {
            char buf[32];
            std::snprintf(buf, sizeof buf, "%.10g", *d);
            out += buf;
        }
    } else if (auto s = std::get_if<std::string>(&v_)) {
        out += jsonEscape(*s);
    } else if (auto a = std::get_if<Array>(&v_)) {
        if (a->empty()) {
            out += "[]";
            return;
        }
        out += "[";
        for (size_t i = 0; i < a->size(); ++i) {
            out += (i ? "," : "") + pad;
            (*a)[i].dumpTo(out, indent, depth + 1);
        }
        out += padEnd + "]";
    } else if (auto o = std::get_if<Object>(&v_)) {
        if (o->empty()) {
            out += "{}";
            return;
        }
        out += "{";
        for (size_t i = 0; i < o->size(); ++i) {
            out += (i ? "," : "") + pad + jsonEscape((*o)[i].first) + (indent > 0 ? ": " : ":");
            (*o)[i].second.dumpTo(out, indent, depth + 1);
        }
        out += padEnd + "}";
    }
}

} // namespace binocle
