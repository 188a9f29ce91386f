// SPDX-License-Identifier: MIT
// A read-only view on a ground-frame point cloud (mm), and an interval type, shared by
// every part of the paper's method.
#pragma once

#include <binocle/abi/cloud_transform.h>

#include <cmath>
#include <cstddef>
#include <vector>

namespace binocle::method {

// Points as three floats each (X, Y, Z), millimetres, in the ground frame of METHOD.md:
// X lateral (right), Y range (forward), Z height (up). Owns nothing.
struct CloudView {
    const float *xyz = nullptr;
    size_t count = 0;

    CloudView() = default;
    CloudView(const float *points, size_t n) : xyz(points), count(n) {}
    explicit CloudView(const std::vector<float> &points) : xyz(points.data()), count(points.size() / 3) {}
    explicit CloudView(const binocle_cloud &c)
        : xyz(c.xyz), count(c.count > 0 && c.xyz ? static_cast<size_t>(c.count) : 0) {}

    float x(size_t i) const { return xyz[3 * i]; }
    float y(size_t i) const { return xyz[3 * i + 1]; }
    float z(size_t i) const { return xyz[3 * i + 2]; }
    // Non-finite points (a matcher's stray value) are skipped by every function of the method.
    bool finite(size_t i) const { return std::isfinite(x(i)) && std::isfinite(y(i)) && std::isfinite(z(i)); }
};

// A closed-open interval [min_mm, max_mm) of one axis.
struct Extent {
    double min_mm = 0, max_mm = 0;
    double size() const { return max_mm - min_mm; }
    bool contains(double v) const { return v >= min_mm && v < max_mm; }
    bool valid() const { return std::isfinite(min_mm) && std::isfinite(max_mm) && max_mm > min_mm; }
};

} // namespace binocle::method
