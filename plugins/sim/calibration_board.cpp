// SPDX-License-Identifier: MIT
// Calibration mode of the `sim` source: a chessboard held in varied poses in front of
// the rig, one pose per frame, for `binocle calibrate` and its tests.
#include "calibration_board.hpp"

#include "random.hpp"

#include "input/integer_range.hpp"
#include "input/yaml_file.hpp"

#include <binocle/numbers.hpp>
#include <binocle/text.hpp>

#include <yaml-cpp/yaml.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <type_traits>

namespace binocle::sim {

namespace {

constexpr double kDegToRad = 3.14159265358979323846 / 180.0;

} // namespace

BoardSettings BoardSettings::fromYaml(const std::string &text) {
    const std::string origin = "calibration_board";
    BoardSettings b;
    try {
        // The framework's strict readers: duplicate keys, unknown keys and octal-looking
        // or out-of-range numbers are refused with their position.
        const YAML::Node n = input::parseYaml(text, origin);
        input::checkKeys(n, {"cols", "rows", "square_mm", "poses", "max_tilt_deg", "seed"}, origin, origin);
        auto integer = [&](const char *key, int64_t min, int64_t max, auto &out) {
            const YAML::Node v = n[key];
            if (!v) return;
            int64_t parsed = 0;
            std::string why;
            if (!v.IsScalar() || !input::parseInteger(v.Scalar(), parsed, &why, min, max))
                throw SceneError(input::located(v, origin) + ": " + origin + "." + key + " = '" +
                                 (v.IsScalar() ? sdk::printable(v.Scalar(), 40) : std::string("(not a scalar)")) + "': " +
                                 (why.empty() ? "expected a decimal integer" : why));
            out = static_cast<std::remove_reference_t<decltype(out)>>(parsed);
        };
        auto real = [&](const char *key, double &out) {
            const YAML::Node v = n[key];
            if (!v) return;
            std::string why;
            if (!v.IsScalar() || !sdk::parseDecimalReal(v.Scalar(), out, &why))
                throw SceneError(input::located(v, origin) + ": " + origin + "." + key + " = '" +
                                 (v.IsScalar() ? sdk::printable(v.Scalar(), 40) : std::string("(not a scalar)")) + "': " +
                                 (why.empty() ? "expected a number" : why));
        };
        integer("cols", 2, 1000, b.cols);
        integer("rows", 2, 1000, b.rows);
        integer("poses", 0, INT32_MAX, b.poses);
        integer("seed", 0, UINT32_MAX, b.seed);
        real("square_mm", b.square_mm);
        real("max_tilt_deg", b.max_tilt_deg);
    } catch (const input::YamlError &e) {
        throw SceneError(e.what());
    }
    if (b.cols < 2 || b.rows < 2) throw SceneError("calibration_board: cols and rows must be >= 2 (inner corners)");
    if (!(b.square_mm > 0)) throw SceneError("calibration_board.square_mm: expected a value > 0");
    if (b.poses < 0) throw SceneError("calibration_board.poses: expected a value >= 0 (0: a new pose every frame, endless)");
    if (b.max_tilt_deg < 0 || b.max_tilt_deg > 60) throw SceneError("calibration_board.max_tilt_deg: expected 0..60");
    return b;
}

Scene boardScene(const BoardSettings &b, const StereoRig &rig, int index) {
    const RigSettings &s = rig.settings();
    Scene scene;
    scene.name = "calibration_board";
    scene.groundTexture = -1;
    scene.sky.zenith = scene.sky.horizon = Rgb::Constant(0.5f);
    scene.light.direction = Vec3(0, -1, 0.3).normalized();
    scene.light.ambient = 0.7;

    Texture t;
    t.kind = TextureKind::Chessboard;
    t.color0 = Rgb::Constant(0.08f);
    t.color1 = Rgb::Constant(0.92f);
    t.square_mm = b.square_mm;
    t.board_squares[0] = b.cols + 1;
    t.board_squares[1] = b.rows + 1;
    t.margin_mm = b.square_mm;
    const int board = scene.addTexture(t);
    const int plain = scene.addTexture(Texture{}); // edges and back: grey
    const double width = (b.cols + 3) * b.square_mm, height = (b.rows + 3) * b.square_mm;

    // Distance and offsets such that the whole board (tilted, margin included) stays
    // inside both images.
    Random rng({b.seed, static_cast<uint32_t>(index), 0x0b0a4du});
    const double f = s.focalLengthPx();
    const double fraction = rng.uniform(0.35, 0.6);
    double distance = f * width / (fraction * s.image_width);
    const double slack = 1.25; // perspective of a tilted board
    distance = std::max(distance, f * (width * slack + s.baseline_mm) / (s.image_width - 16.0));
    distance = std::max(distance, f * height * slack / (s.image_height - 16.0));
    const double freeU = std::max(0.0, (s.image_width - f * (width * slack + s.baseline_mm) / distance) / 2 - 8);
    const double freeV = std::max(0.0, (s.image_height - f * height * slack / distance) / 2 - 8);
    const Vec3 centreInCamera(s.baseline_mm / 2 + rng.uniform(-1, 1) * freeU * distance / f,
                              rng.uniform(-1, 1) * freeV * distance / f, distance);
    const double tiltX = rng.uniform(-1, 1) * b.max_tilt_deg * kDegToRad;
    const double tiltY = rng.uniform(-1, 1) * b.max_tilt_deg * kDegToRad;
    const double roll = rng.uniform(-1, 1) * 15 * kDegToRad;
    // Board axes in the camera frame: X right, Y away from the rig (its normal), Z up.
    Mat3 facing;
    facing << 1, 0, 0, 0, 0, -1, 0, 1, 0;
    const Mat3 tilt = (Eigen::AngleAxisd(roll, Vec3::UnitZ()) * Eigen::AngleAxisd(tiltY, Vec3::UnitY()) *
                       Eigen::AngleAxisd(tiltX, Vec3::UnitX()))
                          .toRotationMatrix();
    const Camera left = rig.left(RigPose{});
    Primitive p;
    p.shape = Shape::Box;
    p.half = Vec3(width / 2, 2.0, height / 2);
    p.rotation = left.rotation * tilt * facing;
    p.axisAligned = false;
    p.center = left.center + left.rotation * centreInCamera;
    p.texture.fill(plain);
    p.texture[3] = board; // -Y: the face towards the rig
    scene.addObject("board", "calibration_board", {p});
    scene.mainObject = -1;
    return scene;
}

} // namespace binocle::sim
