// SPDX-License-Identifier: MIT
// Geometry check of a calibration against the rig and the images its source delivers.
#include "calibration/geometry_check.hpp"

#include "core/error.hpp"

#include <cmath>
#include <cstdio>

namespace binocle {

namespace {

std::string number(double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.1f", v);
    std::string s = buf;
    if (s.size() > 2 && s.compare(s.size() - 2, 2, ".0") == 0) s.resize(s.size() - 2);
    return s;
}

std::optional<double> numericSetting(const PluginBlock &block, const char *name) {
    const binocle_param *p = block.params.find(name);
    if (!p) return std::nullopt;
    if (p->type == BINOCLE_PARAM_DOUBLE) return p->d;
    if (p->type == BINOCLE_PARAM_INT) return static_cast<double>(p->i);
    return std::nullopt;
}

} // namespace

std::vector<std::string> geometryDisagreements(const StereoCalibration &c, const GeometryExpectation &e,
                                               const std::string &origin) {
    std::vector<std::string> problems;
    if (c.image_size != e.image_size)
        problems.push_back(origin + " is for " + sizeText(c.image_size) + " images but source '" + e.source + "' delivers " +
                           sizeText(e.image_size));
    const double tx = c.T.empty() ? 0.0 : c.T.at<double>(0);
    if (tx > 0)
        problems.push_back(origin + ": T.x > 0 (T.x = " + number(tx) +
                           " mm): left and right are swapped (the right camera must be to the right of the left one: "
                           "T.x < 0 with x_r = R x_l + T)");
    else if (!(tx < 0))
        problems.push_back(origin + ": T.x = 0: the cameras are not side by side (expected T.x < 0, the right camera "
                           "to the right of the left one)");
    if (e.baseline_mm && *e.baseline_mm > 0) {
        const double b = c.baselineMm();
        if (std::abs(b - *e.baseline_mm) > e.baseline_tolerance * *e.baseline_mm)
            problems.push_back(origin + ": baseline " + number(b) + " mm but the rig says baseline_mm: " +
                               number(*e.baseline_mm) + " (more than " + number(100 * e.baseline_tolerance) +
                               " % apart; recalibrate for this configuration, or check the square size)");
    }
    return problems;
}

void checkGeometry(const StereoCalibration &c, const GeometryExpectation &e, const std::string &origin) {
    const std::vector<std::string> problems = geometryDisagreements(c, e, origin);
    if (problems.empty()) return;
    std::string text;
    for (const auto &p : problems) text += (text.empty() ? "" : "; ") + p;
    throw Error(text);
}

StatedGeometry statedGeometry(const PluginBlock &source) {
    StatedGeometry g;
    g.baseline_mm = numericSetting(source, "baseline_mm");
    g.focal_length_mm = numericSetting(source, "focal_length_mm");
    g.pixel_pitch_um = numericSetting(source, "pixel_pitch_um");
    return g;
}

} // namespace binocle
