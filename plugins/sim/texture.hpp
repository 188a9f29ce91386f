// SPDX-License-Identifier: MIT
// Textures of the `sim` source: analytic chessboards and baked, tileable raster textures
// (procedural noise or an image file) box-filtered over the footprint of a sample.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace binocle::sim {

// A scene or settings error; what() names the file (or setting), line, key and value.
class SceneError : public std::runtime_error {
public:
    explicit SceneError(const std::string &message) : std::runtime_error(message) {}
};

using Vec3 = Eigen::Vector3d;
using Rgb = Eigen::Vector3f; // linear colour, 0..1, in R, G, B order

// A raster with ripmaps: level (i, j) is level 0 shrunk 2^i times along x and 2^j along
// y, so that footprints stretched along an axis (the ground seen at a grazing angle)
// are filtered along that axis only.
class Ripmap {
public:
    // level0: CV_32FC1 or CV_32FC3. wrap: the raster tiles the plane (else edges clamp).
    Ripmap(const cv::Mat &level0, bool wrap);
    int width() const { return width_; }
    int height() const { return height_; }
    int channels() const { return channels_; }
    // Mean of the raster over a box of wx by wy texels (level-0 units) centred at (x, y)
    // texels (pixel centres at half-integers); writes channels() values.
    void sample(double x, double y, double wx, double wy, float *out) const;

private:
    struct Level {
        cv::Mat pixels;
        const float *data = nullptr;   // pixels' first texel
        size_t stride = 0;             // floats from one row to the next
        int cols = 0, rows = 0;
        float scaleX = 1, scaleY = 1;  // level texels per level-0 texel
    };
    void bilinear(const Level &l, float x, float y, float weight, float *out) const;
    const Level &level(int i, int j) const { return levels_[static_cast<size_t>(j * levelsX_ + i)]; }

    int width_ = 0, height_ = 0, channels_ = 1, levelsX_ = 1, levelsY_ = 1;
    double invWidth_ = 1, invHeight_ = 1;
    bool wrap_ = true;
    std::vector<Level> levels_;
};

// Where a ray met a surface, in the surface's own texture coordinates, with the change
// of those coordinates across the footprint of the sample (its two edges).
struct SurfacePoint {
    bool planar = true;
    double u = 0, v = 0;                   // planar: mm, u right and v up as seen from outside
    double dudx = 0, dvdx = 0, dudy = 0, dvdy = 0;
    Vec3 local{0, 0, 0};                   // curved: 3D texture coordinates, mm
    Vec3 dldx{0, 0, 0}, dldy{0, 0, 0};
    Vec3 normal{0, 0, 1};                  // curved: surface normal, picks the projections
};

enum class TextureKind { Solid, Chessboard, Noise, Image };

// Surface pattern, evaluated in the coordinates of the surface it sits on (so that the
// left and the right imager see the very same pattern, and a moved object keeps it).
struct Texture {
    TextureKind kind = TextureKind::Solid;
    std::string preset;                    // "turf", "leaves" ... when made from a preset
    Rgb color0{0.5f, 0.5f, 0.5f}, color1{0.9f, 0.9f, 0.9f};
    double square_mm = 100;                // chessboard: side of a square
    int board_squares[2] = {0, 0};         // chessboard: > 0, a finite board of that many
    double margin_mm = 0;                  //   squares (u, v) inside a color1 margin
    double scale_mm = 200;                 // noise: size of the largest features
    int octaves = 6;                       // noise: octaves of the fractal sum
    double roughness = 0.6;                // noise: amplitude ratio of successive octaves
    double contrast = 1.0;                 // noise: gain around the mean colour
    double sharpness = 0;                  // noise: > 0 pushes towards two tones
    Vec3 stretch{1, 1, 1};                 // noise on curved shapes: per-axis frequency factor
    uint32_t seed = 1;
    double size_mm[2] = {1000, 1000};      // image: extent of one copy on the surface (u, v)
    // Noise and image: the baked raster (noise: one channel in [-1, 1]; image: RGB 0..1),
    // its texels per mm on the surface (u, v), and (noise) the tile's side in mm.
    std::shared_ptr<const Ripmap> raster;
    double texels_per_mm[2] = {1, 1};
    double period_mm = 1;
};

// Procedural texture presets ("turf", "soil", "leaves", "bark", "noise") with their
// default parameters (not yet baked); throws SceneError for an unknown name.
Texture texturePreset(const std::string &name);

// Bakes a noise texture into its tileable raster (after its parameters are final).
void bakeNoise(Texture &t);
// Makes an image texture from an 8-bit BGR image.
void setImage(Texture &t, const cv::Mat &bgr);

// Colour of texture `t` at `sp` (linear RGB, 0..1), box-filtered over the footprint.
Rgb evalTexture(const Texture &t, const SurfacePoint &sp);

// A chessboard of unit squares box-filtered over wx by wy squares: 0 on squares with
// floor(x) + floor(y) even, 1 on the others, grey where the filter straddles edges.
double filteredChessboard(double x, double y, double wx, double wy);

} // namespace binocle::sim
