// SPDX-License-Identifier: MIT
// Textures of the `sim` source: analytic chessboards and baked, tileable raster textures
// (procedural noise or an image file) box-filtered over the footprint of a sample.
#include "texture.hpp"

#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <mutex>
#include <tuple>

namespace binocle::sim {

namespace {

inline uint32_t hashLattice(int32_t x, int32_t y, uint32_t seed) {
    uint32_t h = seed * 0x9E3779B1u;
    h ^= static_cast<uint32_t>(x) * 0x85EBCA77u;
    h = (h << 13) | (h >> 19);
    h ^= static_cast<uint32_t>(y) * 0xC2B2AE3Du;
    h ^= h >> 15;
    h *= 0x2C1B3C6Du;
    h ^= h >> 12;
    h *= 0x297A2D39u;
    h ^= h >> 15;
    return h;
}

// Lattice value in [-1, 1].
inline double latticeValue(int32_t x, int32_t y, uint32_t seed) {
    return static_cast<double>(hashLattice(x, y, seed) >> 8) * (2.0 / 16777215.0) - 1.0;
}

inline double fade(double t) { return t * t * t * (t * (t * 6 - 15) + 10); }
inline double lerp(double a, double b, double t) { return a + (b - a) * t; }
inline double clamp01(double v) { return v < 0 ? 0 : (v > 1 ? 1 : v); }

// floor() without a libm call (the baseline x86-64 target has no rounding instruction).
inline double fastFloor(double v) {
    if (!(std::abs(v) < 9e15)) return std::floor(v);
    const double t = static_cast<double>(static_cast<long long>(v));
    return t > v ? t - 1.0 : t;
}

// log2 within 0.01, continuous (it picks and blends ripmap levels), for x >= 1.
inline double fastLog2(double x) {
    const float f = static_cast<float>(x);
    uint32_t bits;
    std::memcpy(&bits, &f, sizeof bits);
    const float exponent = static_cast<float>(static_cast<int>((bits >> 23) & 255u) - 127);
    bits = (bits & 0x7FFFFFu) | 0x3F800000u; // mantissa m in [1, 2)
    float m;
    std::memcpy(&m, &bits, sizeof m);
    const float y = m - 1.0f;
    return exponent + y * (1.3465f - 0.3465f * y);
}

Rgb mix(const Rgb &a, const Rgb &b, double t) { return a + (b - a) * static_cast<float>(t); }

// Noise texture value (about [-1, 1]) at (u, v) mm, box-filtered over wu by wv mm.
// Averaged over more than one tile, a tile keeps its column (row) means, where an endless
// texture would average out like 1 / sqrt(length): the excess is taken away, or the
// ground near the horizon would show the tile's columns as streaks.
inline double noiseAt(const Texture &t, double u, double v, double wu, double wv) {
    float n = 0;
    const double ku = t.texels_per_mm[0], kv = t.texels_per_mm[1];
    t.raster->sample(u * ku, v * kv, wu * ku, wv * kv, &n);
    double gain = 1;
    if (wu > t.period_mm) gain *= std::sqrt(t.period_mm / wu);
    if (wv > t.period_mm) gain *= std::sqrt(t.period_mm / wv);
    return gain * n;
}

// Planar noise: the tile read through a slow, smooth warp of its coordinates (waves
// whose periods are incommensurate with the tile's): between one period and the next the
// lookup drifts by more than a feature, so the texture never repeats and a matcher finds
// no period. The warp stretches the pattern by at most 10 %, which the footprint ignores.
double planarNoise(const Texture &t, const SurfacePoint &sp) {
    const double period = t.period_mm;
    // A periodic wave in [-0.5, 0.5] with continuous slope (two smoothsteps), slope <= 3.
    auto wave = [](double q) {
        double f = q - fastFloor(q);
        f = f < 0.5 ? 2 * f : 2 - 2 * f;
        return f * f * (3 - 2 * f) - 0.5;
    };
    const double a = 0.138 * period, ku = 1.0 / (4.13 * period), kv = 1.0 / (9.71 * period);
    const double u = sp.u + a * wave(ku * sp.u + kv * sp.v), v = sp.v + a * wave(ku * sp.v - kv * sp.u + 0.37);
    return noiseAt(t, u, v, std::abs(sp.dudx) + std::abs(sp.dudy), std::abs(sp.dvdx) + std::abs(sp.dvdy));
}

// Curved surfaces: the tile projected along the three axes, blended by the normal, and
// filtered isotropically (one mip level per projection).
double curvedNoise(const Texture &t, const SurfacePoint &sp) {
    const Vec3 p = sp.local.cwiseProduct(t.stretch), dx = sp.dldx.cwiseProduct(t.stretch),
               dy = sp.dldy.cwiseProduct(t.stretch);
    Vec3 w = sp.normal.cwiseAbs().array().square().square();
    w /= w.sum();
    double n = 0;
    static const int other[3][2] = {{1, 2}, {0, 2}, {0, 1}};
    for (int a = 0; a < 3; ++a) {
        if (w[a] < 0.02) continue;
        const int i = other[a][0], j = other[a][1];
        const double width = std::max(std::abs(dx[i]) + std::abs(dy[i]), std::abs(dx[j]) + std::abs(dy[j]));
        n += w[a] * noiseAt(t, p[i] + 0.37 * a * t.period_mm, p[j], width, width); // offset: other patterns
    }
    return n;
}

} // namespace

// ---- Ripmap ---------------------------------------------------------------------------

Ripmap::Ripmap(const cv::Mat &level0, bool wrap)
    : width_(level0.cols), height_(level0.rows), channels_(level0.channels()), wrap_(wrap) {
    CV_Assert(level0.depth() == CV_32F && (channels_ == 1 || channels_ == 3) && !level0.empty());
    invWidth_ = 1.0 / width_;
    invHeight_ = 1.0 / height_;
    while ((width_ >> levelsX_) >= 1) ++levelsX_;
    while ((height_ >> levelsY_) >= 1) ++levelsY_;
    levels_.resize(static_cast<size_t>(levelsX_ * levelsY_));
    for (int j = 0; j < levelsY_; ++j) {
        for (int i = 0; i < levelsX_; ++i) {
            Level &dst = levels_[static_cast<size_t>(j * levelsX_ + i)];
            const cv::Size size(std::max(1, width_ >> i), std::max(1, height_ >> j));
            if (i == 0 && j == 0)
                dst.pixels = level0.clone();
            else // halve the neighbour level along one axis (box average)
                cv::resize(i > 0 ? level(i - 1, j).pixels : level(i, j - 1).pixels, dst.pixels, size, 0, 0, cv::INTER_AREA);
            dst.data = dst.pixels.ptr<float>(0);
            dst.stride = dst.pixels.step1();
            dst.cols = size.width;
            dst.rows = size.height;
            dst.scaleX = static_cast<float>(size.width) / static_cast<float>(width_);
            dst.scaleY = static_cast<float>(size.height) / static_cast<float>(height_);
        }
    }
}

void Ripmap::bilinear(const Level &l, float x, float y, float weight, float *out) const {
    const float lx = x * l.scaleX - 0.5f, ly = y * l.scaleY - 0.5f;
    int x0, y0, x1, y1;
    float ax, ay;
    if (wrap_) {
        // x, y lie in [0, size) (see sample()): lx, ly in [-0.5, cols - 0.5).
        const int ix = static_cast<int>(lx + 1.0f) - 1, iy = static_cast<int>(ly + 1.0f) - 1;
        ax = lx - static_cast<float>(ix);
        ay = ly - static_cast<float>(iy);
        x0 = ix < 0 ? l.cols - 1 : ix;
        y0 = iy < 0 ? l.rows - 1 : iy;
        x1 = ix + 1 >= l.cols ? 0 : ix + 1;
        y1 = iy + 1 >= l.rows ? 0 : iy + 1;
    } else {
        const float cx = std::clamp(lx, 0.0f, static_cast<float>(l.cols - 1)), cy = std::clamp(ly, 0.0f, static_cast<float>(l.rows - 1));
        x0 = static_cast<int>(cx);
        y0 = static_cast<int>(cy);
        ax = cx - static_cast<float>(x0);
        ay = cy - static_cast<float>(y0);
        x1 = std::min(x0 + 1, l.cols - 1);
        y1 = std::min(y0 + 1, l.rows - 1);
    }
    const float *r0 = l.data + static_cast<size_t>(y0) * l.stride, *r1 = l.data + static_cast<size_t>(y1) * l.stride;
    const float w00 = weight * (1 - ax) * (1 - ay), w10 = weight * ax * (1 - ay), w01 = weight * (1 - ax) * ay,
                w11 = weight * ax * ay;
    if (channels_ == 1) {
        out[0] += w00 * r0[x0] + w10 * r0[x1] + w01 * r1[x0] + w11 * r1[x1];
        return;
    }
    for (int c = 0; c < 3; ++c)
        out[c] += w00 * r0[x0 * 3 + c] + w10 * r0[x1 * 3 + c] + w01 * r1[x0 * 3 + c] + w11 * r1[x1 * 3 + c];
}

void Ripmap::sample(double x, double y, double wx, double wy, float *out) const {
    for (int c = 0; c < channels_; ++c) out[c] = 0;
    // Level along each axis: the one whose texels are as wide as the footprint; blend the
    // two nearest levels on each axis (up to four bilinear lookups).
    const double lx = wx > 1 ? std::min(fastLog2(wx), levelsX_ - 1.0) : 0.0;
    const double ly = wy > 1 ? std::min(fastLog2(wy), levelsY_ - 1.0) : 0.0;
    const int i0 = static_cast<int>(lx), j0 = static_cast<int>(ly);
    const float ax = static_cast<float>(lx - i0), ay = static_cast<float>(ly - j0);
    // Single precision from here: bring a tiling raster's coordinates into [0, size).
    if (wrap_) {
        x -= fastFloor(x * invWidth_) * width_;
        y -= fastFloor(y * invHeight_) * height_;
        if (!(x < width_)) x = 0; // rounding, or coordinates beyond any sensible range
        if (!(y < height_)) y = 0;
    }
    const float fx = static_cast<float>(x), fy = static_cast<float>(y);
    if (i0 == j0 && ax == ay) { // isotropic: an ordinary mip-map, two lookups
        bilinear(level(i0, i0), fx, fy, 1 - ax, out);
        if (ax > 0) bilinear(level(i0 + 1, i0 + 1), fx, fy, ax, out);
        return;
    }
    bilinear(level(i0, j0), fx, fy, (1 - ax) * (1 - ay), out);
    if (ax > 0) bilinear(level(i0 + 1, j0), fx, fy, ax * (1 - ay), out);
    if (ay > 0) bilinear(level(i0, j0 + 1), fx, fy, (1 - ax) * ay, out);
    if (ax > 0 && ay > 0) bilinear(level(i0 + 1, j0 + 1), fx, fy, ax * ay, out);
}

// ---- Procedural patterns ----------------------------------------------------------------

double filteredChessboard(double x, double y, double wx, double wy) {
    // Per axis: the mean of the +-1 square wave (+1 where floor(p) is even) over
    // [p - w/2, p + w/2] (Inigo Quilez's analytic form); the board is their product.
    auto axis = [](double p, double w) {
        if (w < 1e-4) return (static_cast<long>(fastFloor(p)) & 1L) ? -1.0 : 1.0;
        w = std::min(w, 8.0);
        auto tri = [](double q) { const double f = q * 0.5 - fastFloor(q * 0.5); return std::abs(f - 0.5); };
        return 2.0 * (tri(p - 0.5 * w) - tri(p + 0.5 * w)) / w;
    };
    return 0.5 - 0.5 * axis(x, wx) * axis(y, wy);
}

// ---- Textures ---------------------------------------------------------------------------

Texture texturePreset(const std::string &name) {
    struct Preset {
        const char *name;
        float color0[3], color1[3]; // RGB 0..255
        double scale_mm;
        int octaves;
        double roughness, contrast, sharpness, stretchZ;
        uint32_t seed;
    };
    static const Preset presets[] = {
        {"noise", {40, 40, 40}, {220, 220, 220}, 200, 6, 0.65, 1.6, 0, 1, 1},
        // Grass: busy detail down to a few millimetres, patches of lighter green.
        {"turf", {45, 70, 25}, {150, 185, 80}, 250, 7, 0.85, 2.2, 0, 1, 11},
        {"soil", {70, 50, 35}, {165, 130, 95}, 300, 8, 0.7, 1.6, 0, 1, 13},
        // Foliage: two-tone clumps of leaves with dark gaps.
        {"leaves", {20, 45, 15}, {110, 160, 60}, 250, 6, 0.7, 2.0, 1.0, 1, 17},
        // Vertical furrows: the pattern is stretched along the trunk.
        {"bark", {45, 35, 25}, {120, 100, 80}, 120, 6, 0.6, 1.6, 0, 0.2, 19},
    };
    for (const Preset &p : presets) {
        if (name != p.name) continue;
        Texture t;
        t.kind = TextureKind::Noise;
        t.preset = name;
        t.color0 = Rgb(p.color0[0], p.color0[1], p.color0[2]) / 255.0f;
        t.color1 = Rgb(p.color1[0], p.color1[1], p.color1[2]) / 255.0f;
        t.scale_mm = p.scale_mm;
        t.octaves = p.octaves;
        t.roughness = p.roughness;
        t.contrast = p.contrast;
        t.sharpness = p.sharpness;
        t.stretch = Vec3(1, 1, p.stretchZ);
        t.seed = p.seed;
        return t;
    }
    throw SceneError("unknown texture '" + name + "' (expected chessboard, noise, solid, image, turf, soil, leaves or bark)");
}

void bakeNoise(Texture &t) {
    // Tiles are kept while a scene uses them: loading the same scene again (every source
    // of an experiment) bakes nothing.
    using Key = std::tuple<double, int, double, uint32_t>;
    static std::mutex mutex;
    static std::map<Key, std::weak_ptr<const Ripmap>> cache;
    const Key key{t.scale_mm, t.octaves, t.roughness, t.seed};
    std::lock_guard<std::mutex> lock(mutex);
    // One tile spans sixteen of the largest features (a smaller tile shows its period on a
    // ground seen at a grazing angle).
    t.period_mm = 16.0 * t.scale_mm;
    auto &cached = cache[key];
    if (auto raster = cached.lock()) {
        t.raster = raster;
        t.texels_per_mm[0] = t.texels_per_mm[1] = raster->width() / t.period_mm;
        return;
    }

    // Texels resolve the finest octave, or as many octaves as 1024 texels allow. Sizes are
    // powers of two, so each octave's lattice cell is a whole number of texels.
    const double period = t.period_mm;
    const double finest = t.scale_mm / std::pow(2.0, t.octaves - 1);
    int n = 64;
    while (n < 1024 && period / n > finest / 2) n *= 2;
    double norm = 0, amplitude = 1;
    for (int i = 0; i < t.octaves; ++i, amplitude *= t.roughness) norm += amplitude;
    cv::Mat tile(n, n, CV_32F, cv::Scalar(0));
    amplitude = 1;
    for (int i = 0; i < t.octaves; ++i, amplitude *= t.roughness) {
        const int cells = 16 << i; // lattice cells per tile
        if (cells * 2 > n) break; // finer than two texels: its filtered mean, zero, is what remains
        const int per = n / cells; // texels per cell
        const uint32_t seed = t.seed + 7919u * static_cast<uint32_t>(i);
        std::vector<float> lattice(static_cast<size_t>(cells * cells)), weight(static_cast<size_t>(per));
        for (int y = 0; y < cells; ++y)
            for (int x = 0; x < cells; ++x) lattice[static_cast<size_t>(y * cells + x)] = static_cast<float>(latticeValue(x, y, seed));
        for (int k = 0; k < per; ++k) weight[static_cast<size_t>(k)] = static_cast<float>(fade((k + 0.5) / per));
        const float a = static_cast<float>(amplitude / norm);
        cv::parallel_for_(cv::Range(0, n), [&](const cv::Range &rows) {
            for (int y = rows.start; y < rows.end; ++y) {
                const int iy = y / per, jy = (iy + 1) % cells;
                const float sy = weight[static_cast<size_t>(y % per)];
                const float *l0 = &lattice[static_cast<size_t>(iy * cells)], *l1 = &lattice[static_cast<size_t>(jy * cells)];
                float *row = tile.ptr<float>(y);
                for (int x = 0; x < n; ++x) {
                    const int ix = x / per, jx = (ix + 1) % cells;
                    const float sx = weight[static_cast<size_t>(x % per)];
                    const float top = l0[ix] + (l0[jx] - l0[ix]) * sx, bottom = l1[ix] + (l1[jx] - l1[ix]) * sx;
                    row[x] += a * (top + (bottom - top) * sy);
                }
            }
        });
    }
    t.raster = std::make_shared<const Ripmap>(tile, true);
    t.texels_per_mm[0] = t.texels_per_mm[1] = n / period;
    cached = t.raster;
}

void setImage(Texture &t, const cv::Mat &bgr) {
    cv::Mat rgb;
    cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
    rgb.convertTo(rgb, CV_32FC3, 1.0 / 255);
    t.kind = TextureKind::Image;
    t.raster = std::make_shared<const Ripmap>(rgb, true);
    t.texels_per_mm[0] = rgb.cols / t.size_mm[0];
    t.texels_per_mm[1] = rgb.rows / t.size_mm[1];
}

Rgb evalTexture(const Texture &t, const SurfacePoint &sp) {
    switch (t.kind) {
    case TextureKind::Solid: return t.color0;
    case TextureKind::Chessboard: {
        const double x = (sp.u - t.margin_mm) / t.square_mm, y = (sp.v - t.margin_mm) / t.square_mm;
        if (t.board_squares[0] > 0 && (x < 0 || y < 0 || x >= t.board_squares[0] || y >= t.board_squares[1]))
            return t.color1;
        const double s = filteredChessboard(x, y, (std::abs(sp.dudx) + std::abs(sp.dudy)) / t.square_mm,
                                            (std::abs(sp.dvdx) + std::abs(sp.dvdy)) / t.square_mm);
        return mix(t.color0, t.color1, s);
    }
    case TextureKind::Noise: {
        const double n = sp.planar ? planarNoise(t, sp) : curvedNoise(t, sp);
        double k = 0.5 + t.contrast * n;
        if (t.sharpness > 0) k = 0.5 + (k - 0.5) * (1.0 + t.sharpness);
        return mix(t.color0, t.color1, clamp01(k));
    }
    case TextureKind::Image: {
        // u to the right, v upwards; the image's first row is its top.
        float c[3];
        const double ku = t.texels_per_mm[0], kv = t.texels_per_mm[1];
        t.raster->sample(sp.u * ku, (t.size_mm[1] - sp.v) * kv, (std::abs(sp.dudx) + std::abs(sp.dudy)) * ku,
                         (std::abs(sp.dvdx) + std::abs(sp.dvdy)) * kv, c);
        return Rgb(c[0], c[1], c[2]);
    }
    }
    return t.color0;
}

} // namespace binocle::sim
