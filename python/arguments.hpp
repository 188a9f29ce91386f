// SPDX-License-Identifier: MIT
// The arguments of the module's calls, read strictly: a value of the wrong type or out of
// range is a binocle.UsageError that names the argument, the value (as Python writes it)
// and what was expected, never pybind11's cast error or a silent conversion.
#pragma once

#include "app/request.hpp"

#include <pybind11/pybind11.h>

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace binocle::python {

namespace py = pybind11;

// A mistake in the call's arguments: the application layer's mistake in a request, raised
// as binocle.UsageError (a ValueError), as the CLI's UsageError is the same type.
using ArgumentError = app::RequestError;

// A whole number from `least` to `most`: a Python int or an integer numpy scalar
// (anything with __index__), not a bool, a float or a text. `none`, when not empty, says
// what None means (then None is accepted and returns nullopt).
std::optional<int64_t> wholeNumber(const py::handle &value, const std::string &name, int64_t least,
                                   int64_t most = std::numeric_limits<int64_t>::max(), const std::string &none = {});

// A real number: a Python int or float, or a numpy number; not a bool or a text.
double realNumber(const py::handle &value, const std::string &name);

// A str; `none`, when not empty, says what None means (then None returns nullopt).
std::optional<std::string> text(const py::handle &value, const std::string &name, const std::string &none = {});

// True or False (numpy.bool_ too); not 0, 1, None or a text.
bool flag(const py::handle &value, const std::string &name);

// A path: a str or an os.PathLike whose path is a str. Bytes are refused (a folder named
// "b'dir'" is not what anyone meant); `none`, when not empty, says what None means.
std::optional<std::string> pathText(const py::handle &value, const std::string &name, const std::string &none = {});

// A list (or tuple) of str.
std::vector<std::string> textList(const py::handle &value, const std::string &name);

// `set`: a dict {"key": value} or a list of "key=value" texts, as --set texts. Strings as
// they are; other values as YAML (JSON) text: True -> true, [1, 2] -> [1, 2], None ->
// null (which the settings checker answers as it answers `--set key=null`); numpy scalars
// and arrays as their Python values.
std::vector<std::string> setTexts(const py::handle &set);

} // namespace binocle::python
