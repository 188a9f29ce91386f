// SPDX-License-Identifier: MIT
// A small JSON value for result files (summary.json, results.json): build and dump.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <variant>
#include <vector>

namespace binocle {

class Json {
public:
    using Array = std::vector<Json>;
    using Object = std::vector<std::pair<std::string, Json>>; // keeps insertion order

    Json() : v_(nullptr) {}
    Json(std::nullptr_t) : v_(nullptr) {}
    Json(bool b) : v_(b) {}
    Json(int v) : v_(static_cast<double>(v)) {}
    Json(int64_t v) : v_(static_cast<double>(v)) {}
    Json(uint64_t v) : v_(static_cast<double>(v)) {}
    Json(double v) : v_(v) {}
    Json(const char *s) : v_(std::string(s)) {}
    Json(std::string s) : v_(std::move(s)) {}
    Json(Array a) : v_(std::move(a)) {}
    Json(Object o) : v_(std::move(o)) {}

    static Json object() { return Json(Object{}); }
    static Json array() { return Json(Array{}); }

    // Object: sets (or replaces) a member. Array: appends.
    Json &set(const std::string &key, Json value);
    Json &push(Json value);
    // nullptr when absent / not an object.
    const Json *get(const std::string &key) const;
    bool isNumber() const { return std::holds_alternative<double>(v_); }
    double number() const { return std::get<double>(v_); }

    // Non-finite numbers become null (JSON has no NaN).
    std::string dump(int indent = 2) const;

private:
    void dumpTo(std::string &out, int indent, int depth) const;
    std::variant<std::nullptr_t, bool, double, std::string, Array, Object> v_;
};

std::string jsonEscape(const std::string &s);

} // namespace binocle
