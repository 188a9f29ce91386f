// SPDX-License-Identifier: MIT
// JSON and frames between the framework and Python.
#include "python/convert.hpp"

namespace binocle::python {

py::object toPython(const nlohmann::ordered_json &j) {
    switch (j.type()) {
    case nlohmann::ordered_json::value_t::null: return py::none();
    case nlohmann::ordered_json::value_t::boolean: return py::bool_(j.get<bool>());
    case nlohmann::ordered_json::value_t::number_integer: return py::int_(j.get<int64_t>());
    case nlohmann::ordered_json::value_t::number_unsigned: return py::int_(j.get<uint64_t>());
    case nlohmann::ordered_json::value_t::number_float: return py::float_(j.get<double>());
    case nlohmann::ordered_json::value_t::string: return py::str(j.get_ref<const std::string &>());
    case nlohmann::ordered_json::value_t::array: {
        py::list out;
        for (const auto &v : j) out.append(toPython(v));
        return std::move(out);
    }
    case nlohmann::ordered_json::value_t::object: {
        py::dict out;
        for (const auto &[k, v] : j.items()) out[py::str(k)] = toPython(v);
        return std::move(out);
    }
    default: return py::none();
    }
}

namespace {

// A view of an image of the frame: H x W (one channel) or H x W x C, strides from the Mat.
py::array imageArray(const cv::Mat &m, const py::handle &owner) {
    if (m.empty()) return py::array(py::dtype::of<uint8_t>(), std::vector<py::ssize_t>{0, 0});
    const py::dtype type = m.depth() == CV_32F ? py::dtype::of<float>() : m.depth() == CV_16U ? py::dtype::of<uint16_t>()
                                                                                              : py::dtype::of<uint8_t>();
    const auto rows = static_cast<py::ssize_t>(m.rows), cols = static_cast<py::ssize_t>(m.cols);
    const auto step = static_cast<py::ssize_t>(m.step[0]), elem = static_cast<py::ssize_t>(m.elemSize1());
    if (m.channels() == 1) return py::array(type, {rows, cols}, {step, elem}, m.data, owner);
    const auto channels = static_cast<py::ssize_t>(m.channels());
    return py::array(type, {rows, cols, channels}, {step, elem * channels, elem}, m.data, owner);
}

template <class T>
py::array pointArray(const std::vector<T> &values, const py::handle &owner) {
    const auto n = static_cast<py::ssize_t>(values.size() / 3);
    return py::array(py::dtype::of<T>(), {n, py::ssize_t{3}}, {static_cast<py::ssize_t>(3 * sizeof(T)), static_cast<py::ssize_t>(sizeof(T))},
                     values.empty() ? nullptr : values.data(), owner);
}

} // namespace

Frame toFrame(std::shared_ptr<OwnedFrame> f) {
    // One owner for every array of the frame: the buffers go when the last array does.
    py::capsule owner(new std::shared_ptr<OwnedFrame>(f), [](void *p) { delete static_cast<std::shared_ptr<OwnedFrame> *>(p); });
    Frame out;
    out.index = f->index;
    out.sequence = f->sequence;
    out.left = imageArray(f->left, owner);
    out.right = imageArray(f->right, owner);
    out.disparity = imageArray(f->disparity, owner);
    out.cloud = pointArray(f->xyz, owner);
    out.colors = pointArray(f->rgb, owner);
    out.cloud_frame = f->cloud_frame == BINOCLE_FRAME_GROUND ? "ground" : "camera";
    for (const auto &[name, value] : f->figures) out.figures[py::str(name)] = value;
    out.metrics = toPython(f->metrics);
    out.valid_pixel_ratio = f->valid_pixel_ratio;
    out.seconds = f->seconds;
    out.latency_s = f->latency_s;
    return out;
}

} // namespace binocle::python
