// SPDX-License-Identifier: MIT
// binocle.design(): the ranking of `binocle design`, as Python objects.
#pragma once

#include <pybind11/pybind11.h>

namespace binocle::python {

namespace py = pybind11;

// Defines binocle.design() in `m`.
void defineDesign(py::module_ &m);

} // namespace binocle::python
