// SPDX-License-Identifier: MIT
// Eq. 1 of METHOD.md: a point of the camera frame into the ground frame (both in mm).
#pragma once

#include <array>
#include <cmath>

namespace binocle::method {

// Camera frame: origin at the left optical centre, Xc right, Yc down, Zc forward.
// Ground frame: origin on the ground below it, X lateral (right), Y range, Z height.
class GroundFrame {
public:
    // cameraHeightMm: hc; inclinationDeg: theta, the downward pitch of the optical axis.
    GroundFrame(double cameraHeightMm, double inclinationDeg)
        : heightMm_(cameraHeightMm), sin_(std::sin(inclinationDeg * kPi / 180.0)),
          cos_(std::cos(inclinationDeg * kPi / 180.0)) {}

    // Eq. 1:  X = Xc
    //         Y = Zc cos(theta) - Yc sin(theta)
    //         Z = hc - Zc sin(theta) - Yc cos(theta)
    std::array<double, 3> toGround(double xc, double yc, double zc) const {
        return {xc, zc * cos_ - yc * sin_, heightMm_ - zc * sin_ - yc * cos_};
    }

private:
    static constexpr double kPi = 3.14159265358979323846;
    double heightMm_, sin_, cos_;
};

} // namespace binocle::method
