// SPDX-License-Identifier: MIT
// binocle.experiment(): an experiment file run as `binocle experiment` runs it.
#pragma once

#include <pybind11/pybind11.h>

namespace binocle::python {

namespace py = pybind11;

// Runs the experiment (its tests on a thread of their own, Ctrl-C seen here) and returns
// its results.json as a dict, plus "out", "failed" and "seconds".
py::dict experiment(const py::object &file, const py::object &set, const py::object &out, const py::object &tests,
                    const py::object &force, const py::object &progress);

} // namespace binocle::python
