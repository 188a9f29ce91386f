// SPDX-License-Identifier: MIT
// From the framework's types to Python's: JSON to dicts and lists, owned images and
// clouds to numpy arrays that keep their owner alive (no copy).
#pragma once

#include "python/run_stream.hpp"

#include <nlohmann/json.hpp>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

namespace binocle::python {

namespace py = pybind11;

// null -> None, bool, numbers, strings, arrays -> list, objects -> dict (in order).
py::object toPython(const nlohmann::ordered_json &j);

// A frame as Python sees it; the arrays are views of the OwnedFrame's buffers.
struct Frame {
    uint64_t index = 0, sequence = 0;
    py::array left, right, disparity, cloud, colors;
    std::string cloud_frame; // "camera" or "ground"
    py::dict figures;        // "evaluator.metric" -> value
    py::object metrics;      // {evaluator: {metric: value}}
    double valid_pixel_ratio = 0, seconds = 0, latency_s = 0;
};

Frame toFrame(std::shared_ptr<OwnedFrame> frame);

} // namespace binocle::python
