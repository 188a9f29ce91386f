// SPDX-License-Identifier: MIT
// Ground-frame clouds with known geometry for the tests of the paper's method: the E1
// panel (front faces of 3 x 3 cubes), a flat ground, boxes, outliers, and distortions.
#pragma once

#include "method/ground_frame.hpp"

#include <cmath>
#include <random>
#include <vector>

namespace binocle::test {

struct SyntheticScene {
    double range_mm = 6000;    // the panel's face
    bool panel = true;
    bool ground = true;
    double step_mm = 10;       // spacing of the panel's points
    double ground_step_mm = 100;
    double noise_mm = 5;       // Gaussian, each axis
    double range_noise_mm = 0; // extra Gaussian noise in range only
    int outliers = 40;         // uniform in the scene's box
    unsigned seed = 7;
};

class CloudBuilder {
public:
    explicit CloudBuilder(unsigned seed) : rng_(seed) {}

    void point(double x, double y, double z) {
        xyz.push_back(static_cast<float>(x));
        xyz.push_back(static_cast<float>(y));
        xyz.push_back(static_cast<float>(z));
    }
    // A rectangle of the plane Y = y (a face looking at the camera), points on a jittered
    // lattice of `step`, with Gaussian noise.
    void frontFace(double x0, double x1, double z0, double z1, double y, double step, double noise, double rangeNoise = 0) {
        std::uniform_real_distribution<double> jitter(0, step);
        std::normal_distribution<double> n(0, noise > 0 ? noise : 1e-9), nr(0, rangeNoise > 0 ? rangeNoise : 1e-9);
        for (double x = x0; x < x1; x += step)
            for (double z = z0; z < z1; z += step) {
                const double px = x + jitter(rng_), pz = z + jitter(rng_);
                if (px >= x1 || pz >= z1) continue; // uniform density up to the edges
                point(px + n(rng_), y + n(rng_) + nr(rng_), pz + n(rng_));
            }
    }
    // The top of a box (Z = z), from range y0 to y1.
    void topFace(double x0, double x1, double y0, double y1, double z, double step, double noise) {
        std::uniform_real_distribution<double> jitter(0, step);
        std::normal_distribution<double> n(0, noise > 0 ? noise : 1e-9);
        for (double x = x0; x < x1; x += step)
            for (double y = y0; y < y1; y += step) point(x + jitter(rng_) + n(rng_), y + jitter(rng_) + n(rng_), z + n(rng_));
    }
    void ground(double x0, double x1, double y0, double y1, double step, double noise) { topFace(x0, x1, y0, y1, 0, step, noise); }
    void outliers(int count) {
        std::uniform_real_distribution<double> ux(-5000, 5000), uy(1000, 20000), uz(0, 4000);
        for (int i = 0; i < count; ++i) point(ux(rng_), uy(rng_), uz(rng_));
    }
    std::mt19937 &rng() { return rng_; }

    std::vector<float> xyz;

private:
    std::mt19937 rng_;
};

// The E1 panel of METHOD.md: 0.5 m cubes, 0.5 m column gaps, 0.25 m row gaps, bottom row
// on the ground, centred on X = 0: 2.5 m wide, 2.0 m tall, face at range_mm.
inline std::vector<float> panelScene(const SyntheticScene &s = {}) {
    CloudBuilder b(s.seed);
    if (s.panel)
        for (int col = 0; col < 3; ++col)
            for (int row = 0; row < 3; ++row) {
                const double x0 = -1250 + col * 1000.0, z0 = row * 750.0;
                b.frontFace(x0, x0 + 500, z0, z0 + 500, s.range_mm, s.step_mm, s.noise_mm, s.range_noise_mm);
            }
    if (s.ground) b.ground(-5000, 5000, 1000, 20000, s.ground_step_mm, s.noise_mm);
    b.outliers(s.outliers);
    return b.xyz;
}

inline void stretchX(std::vector<float> &xyz, double factor) {
    for (size_t i = 0; i < xyz.size(); i += 3) xyz[i] = static_cast<float>(xyz[i] * factor);
}
inline void shiftY(std::vector<float> &xyz, double mm) {
    for (size_t i = 1; i < xyz.size(); i += 3) xyz[i] = static_cast<float>(xyz[i] + mm);
}

// A level ground seen by a camera at height hc pitched down by trueDeg, moved into the
// ground frame with Eq. 1 at appliedDeg (the ground plugin's own code): the ground comes
// out tilted by trueDeg - appliedDeg.
inline std::vector<float> groundSeenWithInclination(double hc, double trueDeg, double appliedDeg, double noise,
                                                    unsigned seed = 3) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> n(0, noise > 0 ? noise : 1e-9);
    const double t = trueDeg * 3.14159265358979323846 / 180, c = std::cos(t), sn = std::sin(t);
    const method::GroundFrame applied(hc, appliedDeg);
    std::vector<float> xyz;
    for (double x = -4000; x <= 4000; x += 100)
        for (double y = 2000; y <= 15000; y += 100) {
            // Inverse of Eq. 1 at the true inclination: Zc = Y cos + (hc - Z) sin, Yc = -Y sin + (hc - Z) cos.
            const double z = n(rng);
            const double zc = y * c + (hc - z) * sn, yc = -y * sn + (hc - z) * c;
            const auto g = applied.toGround(x + n(rng), yc, zc);
            xyz.push_back(static_cast<float>(g[0]));
            xyz.push_back(static_cast<float>(g[1]));
            xyz.push_back(static_cast<float>(g[2]));
        }
    return xyz;
}

} // namespace binocle::test
