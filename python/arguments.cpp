// SPDX-License-Identifier: MIT
// The module's arguments, checked: each refusal names the argument, the value and what
// was expected.
#include "python/arguments.hpp"

namespace binocle::python {

namespace {

// A value as Python writes it (repr), cut when long.
std::string shown(const py::handle &value) {
    std::string text;
    try {
        text = py::repr(value).cast<std::string>();
    } catch (const py::error_already_set &) {
        text = "<" + std::string(Py_TYPE(value.ptr())->tp_name) + ">";
    }
    return text.size() > 80 ? text.substr(0, 77) + "..." : text;
}

std::string typeName(const py::handle &value) { return Py_TYPE(value.ptr())->tp_name; }

[[noreturn]] void refuse(const std::string &name, const py::handle &value, const std::string &expected) {
    throw ArgumentError(name + "=" + shown(value) + ": " + expected);
}

bool isNumpy(const py::handle &value, const char *type) {
    return py::isinstance(value, py::module_::import("numpy").attr(type));
}

// A setting value as YAML text: JSON (YAML's flow subset), numpy values as Python's.
std::string yamlText(const std::string &key, const py::handle &value) {
    if (py::isinstance<py::str>(value)) return value.cast<std::string>();
    const py::cpp_function plain([](const py::handle &o) -> py::object {
        if (isNumpy(o, "generic") || isNumpy(o, "ndarray")) return o.attr("tolist")();
        throw py::type_error("not a setting value");
    });
    try {
        return py::module_::import("json").attr("dumps")(value, py::arg("default") = plain).cast<std::string>();
    } catch (const py::error_already_set &e) {
        if (!e.matches(PyExc_TypeError) && !e.matches(PyExc_ValueError)) throw;
        refuse("set['" + key + "']", value, "a " + typeName(value) + " is not a setting value; expected a str, int, float, "
                                            "bool, None, or a list or dict of them");
    }
}

} // namespace

std::optional<int64_t> wholeNumber(const py::handle &value, const std::string &name, int64_t least, int64_t most,
                                   const std::string &none) {
    const std::string top = most == std::numeric_limits<int64_t>::max() ? "2**63-1" : std::to_string(most);
    const std::string expected = "expected a whole number from " + std::to_string(least) + " to " + top +
                                 (none.empty() ? "" : " (or None: " + none + ")");
    if (value.is_none()) {
        if (!none.empty()) return std::nullopt;
        refuse(name, value, expected);
    }
    if (PyBool_Check(value.ptr()) || !PyIndex_Check(value.ptr())) refuse(name, value, expected + ", not a " + typeName(value));
    const auto index = py::reinterpret_steal<py::object>(PyNumber_Index(value.ptr()));
    if (!index) throw py::error_already_set();
    int overflow = 0;
    const long long v = PyLong_AsLongLongAndOverflow(index.ptr(), &overflow);
    if (overflow == 0 && v == -1 && PyErr_Occurred()) throw py::error_already_set();
    if (overflow != 0 || v < least || v > most) refuse(name, value, expected);
    return static_cast<int64_t>(v);
}

double realNumber(const py::handle &value, const std::string &name) {
    const bool number = PyFloat_Check(value.ptr()) || PyLong_Check(value.ptr()) || isNumpy(value, "number");
    if (PyBool_Check(value.ptr()) || !number) refuse(name, value, "expected a number, not a " + typeName(value));
    return value.cast<double>();
}

std::optional<std::string> text(const py::handle &value, const std::string &name, const std::string &none) {
    const std::string expected = "expected a str" + (none.empty() ? "" : " or None (" + none + ")");
    if (value.is_none() && !none.empty()) return std::nullopt;
    if (!py::isinstance<py::str>(value)) refuse(name, value, expected + ", not a " + typeName(value));
    return value.cast<std::string>();
}

bool flag(const py::handle &value, const std::string &name) {
    if (PyBool_Check(value.ptr())) return value.ptr() == Py_True;
    if (isNumpy(value, "bool_")) return value.attr("item")().ptr() == Py_True;
    refuse(name, value, "expected True or False, not a " + typeName(value));
}

std::optional<std::string> pathText(const py::handle &value, const std::string &name, const std::string &none) {
    const std::string expected = "expected a path (a str or an os.PathLike)" + (none.empty() ? "" : " or None (" + none + ")");
    if (value.is_none()) {
        if (!none.empty()) return std::nullopt;
        refuse(name, value, expected);
    }
    py::object path = py::reinterpret_borrow<py::object>(value);
    if (!py::isinstance<py::str>(path) && py::hasattr(path, "__fspath__")) path = py::module_::import("os").attr("fspath")(path);
    if (py::isinstance<py::bytes>(path))
        refuse(name, value, "a bytes path; " + expected + " (os.fsdecode() makes one of bytes)");
    if (!py::isinstance<py::str>(path)) refuse(name, value, expected + ", not a " + typeName(value));
    // As the file system's bytes (os.fsencode): a name os.listdir gave back keeps its
    // undecodable bytes.
    const std::string text = py::module_::import("os").attr("fsencode")(path).cast<std::string>();
    if (text.empty()) refuse(name, value, expected + ", not an empty text");
    if (text.find('\0') != std::string::npos) refuse(name, value, expected + " without a NUL character");
    return text;
}

std::vector<std::string> textList(const py::handle &value, const std::string &name) {
    const std::string expected = "expected a list of str";
    if (!py::isinstance<py::list>(value) && !py::isinstance<py::tuple>(value)) refuse(name, value, expected + ", not a " + typeName(value));
    std::vector<std::string> texts;
    for (const py::handle item : value) {
        if (!py::isinstance<py::str>(item)) refuse(name, value, expected + ", not a list holding a " + typeName(item));
        texts.push_back(item.cast<std::string>());
    }
    return texts;
}

std::vector<std::string> setTexts(const py::handle &set) {
    std::vector<std::string> texts;
    if (set.is_none()) return texts;
    if (py::isinstance<py::dict>(set)) {
        for (const auto &[key, value] : set.cast<py::dict>()) {
            if (!py::isinstance<py::str>(key)) refuse("set", set, "the key " + shown(key) + " is a " + typeName(key) + "; expected str keys such as 'matcher.num_disparities'");
            const std::string k = key.cast<std::string>();
            if (k.empty() || k.find('=') != std::string::npos) refuse("set", set, "the key " + shown(key) + " is not a setting's key (expected a key such as 'matcher.num_disparities')");
            texts.push_back(k + "=" + yamlText(k, value));
        }
        return texts;
    }
    if (py::isinstance<py::str>(set)) return {set.cast<std::string>()};
    if (!py::isinstance<py::list>(set) && !py::isinstance<py::tuple>(set))
        refuse("set", set, "expected a dict {'key': value} or a list of 'key=value' texts, not a " + typeName(set));
    return textList(set, "set");
}

} // namespace binocle::python
