// SPDX-License-Identifier: MIT
// Seeded random numbers of the `sim` source, the same on every platform: std::mt19937
// is specified to the bit, the distributions of the standard library are not.
#pragma once

#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <random>
#include <vector>

namespace binocle::sim {

class Random {
public:
    explicit Random(uint32_t seed) : engine_(seed) {}
    // Seeded from several numbers (seed, frame, imager, row ...), mixed into one: cheaper
    // than std::seed_seq, which matters with one generator per image row.
    Random(std::initializer_list<uint32_t> seeds) : engine_(mix(seeds)) {}

    // Uniform in [0, 1).
    double uniform() { return static_cast<double>(engine_() >> 8) * (1.0 / 16777216.0); }
    double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }

    // Standard normal drawn from a fixed table of 65536 Box-Muller values: one engine
    // call per value, for sensor noise on every pixel.
    float tableNormal() { return normalTable()[engine_() & 0xFFFFu]; }
    static const float *normalTable() {
        static const std::vector<float> table = [] {
            Random r(0x5eed);
            std::vector<float> t(65536);
            for (float &v : t) v = static_cast<float>(r.normal());
            return t;
        }();
        return table.data();
    }
    // The engine's next 32 bits.
    uint32_t bits() { return static_cast<uint32_t>(engine_()); }

    // Standard normal (Box-Muller; the second value of each pair is kept for the next call).
    double normal() {
        if (hasSpare_) {
            hasSpare_ = false;
            return spare_;
        }
        const double u1 = 1.0 - uniform(); // (0, 1]: log is finite
        const double u2 = uniform();
        const double r = std::sqrt(-2.0 * std::log(u1));
        const double a = 6.283185307179586 * u2;
        spare_ = r * std::sin(a);
        hasSpare_ = true;
        return r * std::cos(a);
    }

private:
    static uint32_t mix(std::initializer_list<uint32_t> seeds) {
        uint64_t h = 0x9E3779B97F4A7C15ull;
        for (uint32_t s : seeds) { // splitmix64 steps
            h += s + 0x9E3779B97F4A7C15ull;
            h = (h ^ (h >> 30)) * 0xBF58476D1CE4E5B9ull;
            h = (h ^ (h >> 27)) * 0x94D049BB133111EBull;
            h ^= h >> 31;
        }
        return static_cast<uint32_t>(h ^ (h >> 32));
    }

    std::mt19937 engine_;
    double spare_ = 0;
    bool hasSpare_ = false;
};

} // namespace binocle::sim
