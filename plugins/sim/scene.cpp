// SPDX-License-Identifier: MIT
// Reads the scene YAML of the `sim` source (format: plugins/sim/README.md) and builds
// the primitives of boxes, cube matrices, spheres, ellipsoids, cylinders and trees.
#include "scene.hpp"

#include "random.hpp"

#include "input/integer_range.hpp"
#include "input/yaml_file.hpp"

#include <binocle/numbers.hpp>

#include <yaml-cpp/yaml.h>

#include <Eigen/Geometry>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <set>
#include <sstream>

namespace binocle::sim {

namespace {

constexpr double kPi = 3.14159265358979323846;
// Primitives (boxes, spheres, ...) a scene may hold: every ray is tested against them, so
// a 100000 x 100000 cube_matrix would never render; refused when read, with the key.
constexpr int64_t kMaxPrimitives = 10000;

// Reads typed values out of YAML nodes; every error names origin:line:column and the key.
class Reader {
public:
    Reader(std::string origin, std::string baseDir) : origin_(std::move(origin)), baseDir_(std::move(baseDir)) {}

    [[noreturn]] void fail(const YAML::Node &at, const std::string &message) const {
        std::ostringstream s;
        s << origin_;
        if (at.IsDefined() && at.Mark().line >= 0) s << ":" << at.Mark().line + 1 << ":" << at.Mark().column + 1;
        s << ": " << message;
        throw SceneError(s.str());
    }

    // Refuses keys of `map` that are not in `allowed` (a typo must not pass silently).
    void onlyKeys(const YAML::Node &map, const std::string &what, const std::vector<std::string> &allowed) const {
        if (!map.IsMap()) fail(map, what + ": expected a map");
        if (auto unknown = binocle::input::findUnknownKey(map, allowed)) fail(unknown->key, what + ": " + unknown->message);
    }

    double number(const YAML::Node &map, const std::string &key, double def, const std::string &what) const {
        const YAML::Node n = map[key];
        if (!n) return def;
        return scalar(n, what + "." + key);
    }

    double positive(const YAML::Node &map, const std::string &key, double def, const std::string &what) const {
        const double v = number(map, key, def, what);
        if (!(v > 0)) fail(map[key] ? map[key] : map, what + "." + key + " = " + fmt(v) + ": expected a value > 0");
        return v;
    }

    int integer(const YAML::Node &map, const std::string &key, int def, int min, const std::string &what) const {
        const YAML::Node n = map[key];
        if (!n) return def;
        // The one strict reader (the SDK's, with base/input's range check): decimal, within int, no octal "0640".
        int64_t parsed = 0;
        if (!n.IsScalar() || !binocle::input::parseInteger(n.Scalar(), parsed, nullptr, INT32_MIN, INT32_MAX))
            fail(n, what + "." + key + " = '" + text(n) + "': expected a decimal integer");
        const int v = static_cast<int>(parsed);
        if (v < min) fail(n, what + "." + key + " = " + std::to_string(v) + ": expected a value >= " + std::to_string(min));
        return v;
    }

    std::string string(const YAML::Node &map, const std::string &key, const std::string &def, const std::string &what) const {
        const YAML::Node n = map[key];
        if (!n) return def;
        if (!n.IsScalar()) fail(n, what + "." + key + ": expected a string");
        return n.as<std::string>();
    }

    std::vector<double> list(const YAML::Node &n, size_t count, const std::string &what) const {
        if (!n.IsSequence() || n.size() != count)
            fail(n, what + ": expected a list of " + std::to_string(count) + " numbers, got '" + text(n) + "'");
        std::vector<double> v;
        for (size_t i = 0; i < count; ++i) v.push_back(scalar(n[i], what + "[" + std::to_string(i) + "]"));
        return v;
    }

    Vec3 vec3(const YAML::Node &map, const std::string &key, const Vec3 &def, const std::string &what, bool required = false) const {
        const YAML::Node n = map[key];
        if (!n) {
            if (required) fail(map, what + ": key '" + key + "' is required (a list [X, Y, Z] in mm)");
            return def;
        }
        const auto v = list(n, 3, what + "." + key);
        return {v[0], v[1], v[2]};
    }

    Vec3 positiveVec3(const YAML::Node &map, const std::string &key, const Vec3 &def, const std::string &what,
                      bool required = false) const {
        const Vec3 v = vec3(map, key, def, what, required);
        if (!(v.minCoeff() > 0)) fail(map[key] ? map[key] : map, what + "." + key + ": expected three values > 0");
        return v;
    }

    // A grey level (one number) or [R, G, B], 0..255.
    Rgb color(const YAML::Node &n, const std::string &what) const {
        Rgb c;
        if (n.IsScalar()) {
            c.setConstant(static_cast<float>(scalar(n, what)));
        } else {
            const auto v = list(n, 3, what + " (a grey level or [R, G, B], 0..255)");
            c = Rgb(static_cast<float>(v[0]), static_cast<float>(v[1]), static_cast<float>(v[2]));
        }
        if (c.minCoeff() < 0 || c.maxCoeff() > 255) fail(n, what + " = '" + text(n) + "': expected values in 0..255");
        return c / 255.0f;
    }

    std::string resolve(const std::string &path) const {
        if (path.empty() || path[0] == '/' || baseDir_.empty()) return path;
        return baseDir_ + "/" + path;
    }

    static std::string text(const YAML::Node &n) {
        YAML::Emitter e;
        e.SetSeqFormat(YAML::Flow);
        e.SetMapFormat(YAML::Flow);
        e << n;
        return e.c_str();
    }

    static std::string fmt(double v) {
        std::ostringstream s;
        s << v;
        return s.str();
    }

private:
    double scalar(const YAML::Node &n, const std::string &what) const {
        double v = 0;
        if (!n.IsScalar() || !binocle::sdk::parseDecimalReal(n.Scalar(), v))
            fail(n, what + " = '" + text(n) + "': expected a finite decimal number");
        return v;
    }

    std::string origin_, baseDir_;
};

class SceneBuilder {
public:
    SceneBuilder(Scene &scene, const Reader &reader) : scene_(scene), r_(reader) {}

    void build(const YAML::Node &root) {
        r_.onlyKeys(root, "scene", {"name", "description", "main_object", "sky", "light", "ground", "objects"});
        scene_.name = r_.string(root, "name", "unnamed", "scene");
        if (const YAML::Node sky = root["sky"]) {
            r_.onlyKeys(sky, "sky", {"zenith", "horizon"});
            if (sky["zenith"]) scene_.sky.zenith = r_.color(sky["zenith"], "sky.zenith");
            if (sky["horizon"]) scene_.sky.horizon = r_.color(sky["horizon"], "sky.horizon");
        }
        if (const YAML::Node light = root["light"]) {
            r_.onlyKeys(light, "light", {"direction", "ambient"});
            scene_.light.direction = r_.vec3(light, "direction", scene_.light.direction, "light");
            if (scene_.light.direction.norm() <= 0) r_.fail(light["direction"], "light.direction: expected a non-zero vector");
            scene_.light.ambient = r_.number(light, "ambient", scene_.light.ambient, "light");
            if (scene_.light.ambient < 0 || scene_.light.ambient > 1) r_.fail(light["ambient"], "light.ambient: expected 0..1");
        }
        scene_.light.direction.normalize();
        const YAML::Node ground = root["ground"];
        if (!ground) {
            scene_.groundTexture = scene_.addTexture(texturePreset("turf"));
        } else if (ground.IsScalar() && (ground.as<std::string>() == "none" || ground.as<std::string>() == "false")) {
            scene_.groundTexture = -1;
        } else {
            r_.onlyKeys(ground, "ground", {"texture"});
            scene_.groundTexture = texture(ground["texture"], "ground.texture", "turf");
        }
        const YAML::Node objects = root["objects"];
        if (objects) {
            if (!objects.IsSequence()) r_.fail(objects, "objects: expected a list");
            for (size_t i = 0; i < objects.size(); ++i) object(objects[i], "objects[" + std::to_string(i) + "]");
        }
        if (const YAML::Node main = root["main_object"]) {
            if (!main.IsScalar()) r_.fail(main, "main_object: expected the name of one of the objects, not a map or a list");
            const std::string name = main.Scalar();
            scene_.mainObject = scene_.findObject(name);
            if (scene_.mainObject < 0) r_.fail(main, "main_object: no object named '" + name + "'");
        } else if (!scene_.objects.empty()) {
            scene_.mainObject = 0;
        }
    }

private:
    // A texture given as a preset name or a map; absent: the preset `fallback`.
    int texture(const YAML::Node &n, const std::string &what, const std::string &fallback) {
        if (!n) return scene_.addTexture(texturePreset(fallback));
        if (n.IsScalar()) return scene_.addTexture(preset(n, n.as<std::string>(), what));
        r_.onlyKeys(n, what, {"type", "color", "colors", "square_mm", "scale_mm", "octaves", "roughness", "contrast",
                              "sharpness", "stretch", "seed", "file", "size_mm"});
        if (!n["type"]) r_.fail(n, what + ": key 'type' is required (chessboard, noise, solid, image, or a preset)");
        const std::string type = r_.string(n, "type", "", what);
        Texture t;
        if (type == "chessboard") {
            t.kind = TextureKind::Chessboard;
            t.color0 = Rgb::Constant(25.0f / 255);
            t.color1 = Rgb::Constant(230.0f / 255);
            t.square_mm = r_.positive(n, "square_mm", 100, what);
        } else if (type == "solid") {
            t.kind = TextureKind::Solid;
            t.color0 = n["color"] ? r_.color(n["color"], what + ".color") : Rgb::Constant(0.5f);
            t.color1 = t.color0;
        } else if (type == "image") {
            t.kind = TextureKind::Image;
            const std::string file = r_.resolve(r_.string(n, "file", "", what));
            if (file.empty()) r_.fail(n, what + ": key 'file' is required for an image texture");
            const cv::Mat im = cv::imread(file, cv::IMREAD_COLOR);
            if (im.empty()) r_.fail(n["file"], what + ".file: cannot read image '" + file + "'");
            const auto size = n["size_mm"] ? r_.list(n["size_mm"], 2, what + ".size_mm") : std::vector<double>{1000, 1000};
            if (size[0] <= 0 || size[1] <= 0) r_.fail(n["size_mm"], what + ".size_mm: expected two values > 0");
            t.size_mm[0] = size[0];
            t.size_mm[1] = size[1];
            setImage(t, im);
        } else {
            t = preset(n["type"], type, what);
        }
        if (n["colors"]) {
            const YAML::Node c = n["colors"];
            if (!c.IsSequence() || c.size() != 2) r_.fail(c, what + ".colors: expected a list of two colours");
            t.color0 = r_.color(c[0], what + ".colors[0]");
            t.color1 = r_.color(c[1], what + ".colors[1]");
        }
        if (t.kind == TextureKind::Noise) {
            t.scale_mm = r_.positive(n, "scale_mm", t.scale_mm, what);
            t.octaves = r_.integer(n, "octaves", t.octaves, 1, what);
            t.roughness = r_.positive(n, "roughness", t.roughness, what);
            t.contrast = r_.number(n, "contrast", t.contrast, what);
            t.sharpness = r_.number(n, "sharpness", t.sharpness, what);
            t.stretch = r_.positiveVec3(n, "stretch", t.stretch, what);
        }
        t.seed = static_cast<uint32_t>(r_.integer(n, "seed", static_cast<int>(t.seed), 0, what));
        return scene_.addTexture(std::move(t));
    }

    Texture preset(const YAML::Node &at, const std::string &name, const std::string &what) {
        try {
            return texturePreset(name);
        } catch (const SceneError &e) {
            r_.fail(at, what + ": " + e.what());
        }
    }

    // Refuses, before anything is built, an object of `count` primitives that would take
    // the scene past kMaxPrimitives; `key` names the setting that asked for them.
    void budget(const YAML::Node &at, const std::string &key, int64_t count, const std::string &what) const {
        const auto used = static_cast<int64_t>(scene_.primitives.size());
        if (count > kMaxPrimitives - used)
            r_.fail(at, what + ": " + key + " asks for " + std::to_string(count) + " primitives; a scene holds at most " +
                            std::to_string(kMaxPrimitives) + " (" + std::to_string(used) + " already used)");
    }

    // Per-face textures of a box: `texture` for all, then `faces: {front: ...}` overrides.
    std::array<int, 6> boxTextures(const YAML::Node &n, const std::string &what) {
        const int all = texture(n["texture"], what + ".texture", "noise");
        std::array<int, 6> t{{all, all, all, all, all, all}};
        if (const YAML::Node faces = n["faces"]) {
            static const char *names[6] = {"right", "left", "back", "front", "top", "bottom"}; // +X -X +Y -Y +Z -Z
            r_.onlyKeys(faces, what + ".faces", {"right", "left", "back", "front", "top", "bottom"});
            for (int i = 0; i < 6; ++i)
                if (faces[names[i]]) t[static_cast<size_t>(i)] = texture(faces[names[i]], what + ".faces." + names[i], "noise");
        }
        return t;
    }

    static Primitive box(const Vec3 &center, const Vec3 &size, double yaw_deg, const std::array<int, 6> &textures) {
        Primitive p;
        p.shape = Shape::Box;
        p.center = center;
        p.half = size / 2;
        p.rotation = Eigen::AngleAxisd(yaw_deg * kPi / 180, Vec3::UnitZ()).toRotationMatrix();
        p.axisAligned = yaw_deg == 0;
        p.texture = textures;
        return p;
    }

    void object(const YAML::Node &n, const std::string &at) {
        if (!n.IsMap()) r_.fail(n, at + ": expected a map with 'name' and 'type'");
        const std::string type = r_.string(n, "type", "", at);
        const std::string name = r_.string(n, "name", type + "_" + std::to_string(scene_.objects.size()), at);
        if (scene_.findObject(name) >= 0) r_.fail(n["name"], at + ": a second object named '" + name + "'");
        const std::string what = "object '" + name + "'";
        if (type == "box") {
            r_.onlyKeys(n, what, {"name", "type", "center_mm", "size_mm", "yaw_deg", "texture", "faces"});
            const Vec3 size = r_.positiveVec3(n, "size_mm", Vec3::Zero(), what, true);
            scene_.addObject(name, type,
                             {box(r_.vec3(n, "center_mm", Vec3::Zero(), what, true), size, r_.number(n, "yaw_deg", 0, what),
                                  boxTextures(n, what))});
        } else if (type == "cube_matrix") {
            cubeMatrix(n, name, what);
        } else if (type == "sphere" || type == "ellipsoid") {
            const bool sphere = type == "sphere";
            r_.onlyKeys(n, what, {"name", "type", "center_mm", sphere ? "radius_mm" : "radii_mm", "texture"});
            Primitive p;
            p.shape = Shape::Ellipsoid;
            p.center = r_.vec3(n, "center_mm", Vec3::Zero(), what, true);
            p.half = sphere ? Vec3::Constant(r_.positive(n, "radius_mm", 250, what))
                            : r_.positiveVec3(n, "radii_mm", Vec3::Zero(), what, true);
            p.textureOrigin = p.center;
            p.texture.fill(texture(n["texture"], what + ".texture", "noise"));
            scene_.addObject(name, type, {p});
        } else if (type == "cylinder") {
            r_.onlyKeys(n, what, {"name", "type", "base_mm", "radius_mm", "height_mm", "texture"});
            Primitive p;
            p.shape = Shape::Cylinder;
            p.center = r_.vec3(n, "base_mm", Vec3::Zero(), what, true);
            const double radius = r_.positive(n, "radius_mm", 100, what);
            p.half = Vec3(radius, radius, r_.positive(n, "height_mm", 1000, what));
            p.textureOrigin = p.center;
            p.texture.fill(texture(n["texture"], what + ".texture", "bark"));
            scene_.addObject(name, type, {p});
        } else if (type == "tree") {
            tree(n, name, what);
        } else {
            r_.fail(n["type"] ? n["type"] : n,
                    at + ": type '" + type + "': expected box, cube_matrix, sphere, ellipsoid, cylinder or tree");
        }
    }

    // METHOD.md's E1 panel: cols x rows cubes in a vertical plane facing the rig.
    void cubeMatrix(const YAML::Node &n, const std::string &name, const std::string &what) {
        r_.onlyKeys(n, what, {"name", "type", "cols", "rows", "cube_mm", "column_gap_mm", "row_gap_mm", "range_mm",
                              "center_x_mm", "base_z_mm", "texture", "faces"});
        const int cols = r_.integer(n, "cols", 3, 1, what), rows = r_.integer(n, "rows", 3, 1, what);
        budget(n, "cols x rows = " + std::to_string(cols) + " x " + std::to_string(rows), int64_t{cols} * rows, what);
        const double cube = r_.positive(n, "cube_mm", 500, what);
        const double colGap = r_.number(n, "column_gap_mm", 500, what), rowGap = r_.number(n, "row_gap_mm", 250, what);
        if (colGap < 0 || rowGap < 0) r_.fail(n, what + ": gaps must be >= 0");
        const double range = r_.positive(n, "range_mm", 6000, what);
        const double cx = r_.number(n, "center_x_mm", 0, what), z0 = r_.number(n, "base_z_mm", 0, what);
        const std::array<int, 6> tex = boxTextures(n, what);
        const double width = cols * cube + (cols - 1) * colGap;
        std::vector<Primitive> prims;
        std::vector<Part> parts;
        for (int row = 0; row < rows; ++row) {
            for (int col = 0; col < cols; ++col) {
                const Vec3 c(cx - width / 2 + cube / 2 + col * (cube + colGap), range + cube / 2,
                             z0 + cube / 2 + row * (cube + rowGap));
                prims.push_back(box(c, Vec3::Constant(cube), 0, tex));
                parts.push_back({"cube_r" + std::to_string(row) + "_c" + std::to_string(col), c, Vec3::Constant(cube)});
            }
        }
        scene_.addObject(name, "cube_matrix", std::move(prims), std::move(parts));
    }

    // A trunk (cylinder) and a crown: a core ellipsoid with spheres scattered in it.
    void tree(const YAML::Node &n, const std::string &name, const std::string &what) {
        r_.onlyKeys(n, what, {"name", "type", "base_mm", "trunk_radius_mm", "trunk_height_mm", "crown_center_height_mm",
                              "crown_radii_mm", "crown_spheres", "crown_sphere_radius_mm", "seed", "bark", "leaves"});
        const Vec3 base = r_.vec3(n, "base_mm", Vec3::Zero(), what, true);
        const double trunkRadius = r_.positive(n, "trunk_radius_mm", 150, what);
        const double crownHeight = r_.positive(n, "crown_center_height_mm", 3500, what);
        const double trunkHeight = r_.positive(n, "trunk_height_mm", crownHeight, what);
        const Vec3 radii = r_.positiveVec3(n, "crown_radii_mm", Vec3(1600, 1600, 1400), what);
        const int spheres = r_.integer(n, "crown_spheres", 40, 0, what);
        budget(n["crown_spheres"] ? n["crown_spheres"] : n, "crown_spheres = " + std::to_string(spheres) + " (+ trunk and core)",
               int64_t{spheres} + 2, what);
        std::vector<double> sr{0.25 * radii.minCoeff(), 0.45 * radii.minCoeff()};
        if (n["crown_sphere_radius_mm"]) sr = r_.list(n["crown_sphere_radius_mm"], 2, what + ".crown_sphere_radius_mm");
        if (!(sr[0] > 0 && sr[1] >= sr[0])) r_.fail(n["crown_sphere_radius_mm"], what + ".crown_sphere_radius_mm: expected [min, max], 0 < min <= max");
        const uint32_t seed = static_cast<uint32_t>(r_.integer(n, "seed", 1, 0, what));
        const int bark = texture(n["bark"], what + ".bark", "bark");
        const int leaves = texture(n["leaves"], what + ".leaves", "leaves");

        std::vector<Primitive> prims;
        Primitive trunk;
        trunk.shape = Shape::Cylinder;
        trunk.center = base;
        trunk.half = Vec3(trunkRadius, trunkRadius, trunkHeight);
        trunk.textureOrigin = base;
        trunk.texture.fill(bark);
        prims.push_back(trunk);
        const Vec3 crownCenter = base + Vec3(0, 0, crownHeight);
        Primitive core;
        core.shape = Shape::Ellipsoid;
        core.center = crownCenter;
        core.half = radii * 0.75;
        core.textureOrigin = base;
        core.texture.fill(leaves);
        prims.push_back(core);
        Random rng(seed);
        for (int i = 0; i < spheres; ++i) {
            // Clumps on the core's surface, bulging out of it up to the crown's ellipsoid
            // (a sphere hidden inside the core would cost rays and show nothing).
            Vec3 d;
            do d = Vec3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
            while (d.squaredNorm() > 1 || d.squaredNorm() < 1e-4);
            d.normalize();
            const double r = rng.uniform(sr[0], sr[1]);
            Primitive s = core;
            s.half = Vec3::Constant(r);
            s.center = crownCenter + d.cwiseProduct((radii - s.half).cwiseMax(0.0)) * rng.uniform(0.8, 1.0);
            prims.push_back(s);
        }
        Vec3 lo = primitiveMin(prims[1]), hi = primitiveMax(prims[1]);
        for (size_t i = 2; i < prims.size(); ++i) {
            lo = lo.cwiseMin(primitiveMin(prims[i]));
            hi = hi.cwiseMax(primitiveMax(prims[i]));
        }
        std::vector<Part> parts{{"trunk", base + Vec3(0, 0, trunkHeight / 2), Vec3(2 * trunkRadius, 2 * trunkRadius, trunkHeight)},
                                {"crown", (lo + hi) / 2, hi - lo}};
        scene_.addObject(name, "tree", std::move(prims), std::move(parts));
    }

    Scene &scene_;
    const Reader &r_;
};

} // namespace

Vec3 primitiveMin(const Primitive &p) {
    switch (p.shape) {
    case Shape::Box: return p.center - p.rotation.cwiseAbs() * p.half;
    case Shape::Ellipsoid: return p.center - p.half;
    case Shape::Cylinder: return p.center - Vec3(p.half.x(), p.half.x(), 0);
    }
    return p.center;
}

Vec3 primitiveMax(const Primitive &p) {
    switch (p.shape) {
    case Shape::Box: return p.center + p.rotation.cwiseAbs() * p.half;
    case Shape::Ellipsoid: return p.center + p.half;
    case Shape::Cylinder: return p.center + Vec3(p.half.x(), p.half.x(), p.half.z());
    }
    return p.center;
}

Scene Scene::fromYaml(const std::string &text, const std::string &origin, const std::string &baseDir) {
    Reader reader(origin, baseDir);
    YAML::Node root;
    try {
        root = binocle::input::parseYaml(text, origin); // duplicate keys, bad UTF-8 refused too
    } catch (const binocle::input::YamlError &e) {
        throw SceneError(e.what());
    }
    if (!root.IsMap()) throw SceneError(origin + ": a scene must be a YAML map (keys name, ground, objects ...)");
    Scene scene;
    try {
        SceneBuilder(scene, reader).build(root);
    } catch (const YAML::Exception &e) {
        throw SceneError(origin + ":" + std::to_string(e.mark.line + 1) + ":" + std::to_string(e.mark.column + 1) + ": " + e.msg);
    }
    return scene;
}

Scene Scene::load(const std::string &path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw SceneError("scene file " + path + ": cannot open it");
    std::ostringstream s;
    s << in.rdbuf();
    const size_t slash = path.find_last_of('/');
    return fromYaml(s.str(), path, slash == std::string::npos ? "." : path.substr(0, slash));
}

Scene Scene::builtIn() { return fromYaml(builtInYaml(), "built-in scene (configs/scenes/e1_panel.yaml)", ""); }

int Scene::findObject(const std::string &name) const {
    for (size_t i = 0; i < objects.size(); ++i)
        if (objects[i].name == name) return static_cast<int>(i);
    return -1;
}

void Scene::moveObject(int index, const Vec3 &delta) {
    SceneObject &o = objects.at(static_cast<size_t>(index));
    for (int i = 0; i < o.primitiveCount; ++i) {
        Primitive &p = primitives[static_cast<size_t>(o.firstPrimitive + i)];
        p.center += delta;
        p.textureOrigin += delta;
    }
    o.boundsMin += delta;
    o.boundsMax += delta;
    for (Part &part : o.parts) part.center += delta;
}

void Scene::placeMainObjectAtRange(double range_mm) {
    if (mainObject < 0) throw SceneError("range_mm: the scene '" + name + "' has no object to place (no main_object)");
    moveObject(mainObject, Vec3(0, range_mm - objects[static_cast<size_t>(mainObject)].boundsMin.y(), 0));
}

int Scene::addObject(const std::string &objectName, const std::string &type, std::vector<Primitive> prims,
                     std::vector<Part> parts) {
    if (prims.empty()) throw SceneError("object '" + objectName + "' has no surface");
    if (objects.size() + 2 > 65535) throw SceneError("too many objects (at most 65533)");
    if (static_cast<int64_t>(primitives.size() + prims.size()) > kMaxPrimitives)
        throw SceneError("object '" + objectName + "': " + std::to_string(prims.size()) +
                         " primitives would take the scene past its limit of " + std::to_string(kMaxPrimitives));
    SceneObject o;
    o.name = objectName;
    o.type = type;
    o.id = static_cast<uint16_t>(objects.size() + 2);
    o.firstPrimitive = static_cast<int>(primitives.size());
    o.primitiveCount = static_cast<int>(prims.size());
    o.boundsMin = primitiveMin(prims.front());
    o.boundsMax = primitiveMax(prims.front());
    for (Primitive &p : prims) {
        p.object = static_cast<int>(objects.size());
        o.boundsMin = o.boundsMin.cwiseMin(primitiveMin(p));
        o.boundsMax = o.boundsMax.cwiseMax(primitiveMax(p));
        primitives.push_back(p);
    }
    o.parts = std::move(parts);
    objects.push_back(std::move(o));
    return static_cast<int>(objects.size()) - 1;
}

int Scene::addTexture(Texture t) {
    if (t.kind == TextureKind::Noise && !t.raster) bakeNoise(t);
    textures.push_back(std::move(t));
    return static_cast<int>(textures.size()) - 1;
}

} // namespace binocle::sim
