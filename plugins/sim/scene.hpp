// SPDX-License-Identifier: MIT
// The simulated world of the `sim` source: textures, primitives and named objects in the
// ground frame of METHOD.md (mm; X lateral right, Y range forward, Z height up).
#pragma once

#include "texture.hpp"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace binocle::sim {

using Mat3 = Eigen::Matrix3d;

enum class Shape { Box, Ellipsoid, Cylinder };

// One analytic surface. Boxes carry a texture per face (+X, -X, +Y, -Y, +Z, -Z in the
// box's own axes); the other shapes use texture[0].
struct Primitive {
    Shape shape = Shape::Box;
    Vec3 center{0, 0, 0};      // box, ellipsoid: centre; cylinder: centre of the bottom disc
    Vec3 half{1, 1, 1};        // box: half sizes; ellipsoid: radii; cylinder: (radius, radius, height)
    Mat3 rotation = Mat3::Identity(); // box: box axes -> ground axes
    bool axisAligned = true;   // box: rotation is the identity
    Vec3 textureOrigin{0, 0, 0}; // curved shapes: 3D texture coordinates are p - textureOrigin
    std::array<int, 6> texture{{0, 0, 0, 0, 0, 0}};
    int object = 0;            // index in Scene::objects
};

// Axis-aligned bounds of a primitive in the ground frame.
Vec3 primitiveMin(const Primitive &p);
Vec3 primitiveMax(const Primitive &p);

// A named part whose truth goes into the metadata (a cube of the panel, a trunk ...).
struct Part {
    std::string name;
    Vec3 center, size; // mm, ground frame; size = width (X), depth (Y), height (Z)
};

// A thing a YAML entry describes: one or more primitives, listed with its truth.
struct SceneObject {
    std::string name, type;
    int firstPrimitive = 0, primitiveCount = 0;
    Vec3 boundsMin{0, 0, 0}, boundsMax{0, 0, 0}; // axis-aligned bounds in the ground frame
    std::vector<Part> parts;
    uint16_t id = 0; // value in the gt_object_id plane (set by Scene::addObject)
};

struct Sky {
    Rgb zenith{0.45f, 0.6f, 0.85f}, horizon{0.8f, 0.85f, 0.9f};
};

struct Light {
    Vec3 direction{0.3, -0.6, 0.75}; // towards the light, ground frame (normalised on load)
    double ambient = 0.45;            // share of light that does not depend on the normal
};

struct Scene {
    std::string name;
    std::vector<Texture> textures;
    std::vector<Primitive> primitives;
    std::vector<SceneObject> objects;
    int groundTexture = -1; // -1: no ground plane
    Sky sky;
    Light light;
    int mainObject = -1;    // what range_mm moves; -1: none

    // Ids in the gt_object_id plane: 0 = nothing (sky), 1 = ground, 2 + i = objects[i].
    static constexpr uint16_t kSkyId = 0, kGroundId = 1;

    // Parses a scene. `origin` names the text in errors (the file path); relative image
    // paths are resolved against `baseDir`.
    static Scene fromYaml(const std::string &text, const std::string &origin, const std::string &baseDir);
    static Scene load(const std::string &path);
    // configs/scenes/e1_panel.yaml, compiled in.
    static Scene builtIn();
    static const char *builtInYaml();

    int findObject(const std::string &name) const; // -1 if absent
    void moveObject(int index, const Vec3 &delta);
    // Moves the main object along Y so that its face nearest to the rig is at range_mm.
    void placeMainObjectAtRange(double range_mm);

    // Appends primitives as a new object and returns its index (builders and tests).
    int addObject(const std::string &name, const std::string &type, std::vector<Primitive> prims,
                  std::vector<Part> parts = {});
    int addTexture(Texture t);
};

} // namespace binocle::sim
