// SPDX-License-Identifier: MIT
// The truth the `sim` source attaches to a frame: rig parameters and the positions and
// sizes of the scene's objects in the ground frame of that frame (YAML text).
#include "metadata.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>

namespace binocle::sim {

namespace {

// Millimetre values rounded to a micrometre: exact enough, and readable.
double mm(double v) { return std::round(v * 1000.0) / 1000.0; }

void emitVec(YAML::Emitter &e, const Vec3 &v) {
    e << YAML::Flow << YAML::BeginSeq << mm(v.x()) << mm(v.y()) << mm(v.z()) << YAML::EndSeq;
}

} // namespace

std::string frameMetadata(const Scene &scene, const StereoRig &rig, const RigPose &pose, uint64_t frame) {
    const RigSettings &s = rig.settings();
    const Vec3 shift(pose.lateral_mm, pose.forward_mm, 0); // scene frame -> this frame's ground frame
    YAML::Emitter e;
    e.SetDoublePrecision(12);
    e << YAML::BeginMap;
    e << YAML::Key << "frame" << YAML::Value << frame;
    e << YAML::Key << "scene" << YAML::Value << scene.name;
    e << YAML::Key << "rig" << YAML::Value << YAML::BeginMap;
    e << YAML::Key << "baseline_mm" << YAML::Value << s.baseline_mm;
    e << YAML::Key << "focal_length_mm" << YAML::Value << s.focal_length_mm;
    e << YAML::Key << "pixel_pitch_um" << YAML::Value << s.pixel_pitch_um;
    e << YAML::Key << "focal_length_px" << YAML::Value << s.focalLengthPx();
    e << YAML::Key << "camera_height_mm" << YAML::Value << s.camera_height_mm;
    e << YAML::Key << "inclination_deg" << YAML::Value << s.inclination_deg;
    e << YAML::Key << "image_width" << YAML::Value << s.image_width;
    e << YAML::Key << "image_height" << YAML::Value << s.image_height;
    e << YAML::Key << "position_mm" << YAML::Value << YAML::Comment("rig displacement in the scene: lateral, forward");
    e << YAML::Flow << YAML::BeginSeq << mm(pose.lateral_mm) << mm(pose.forward_mm) << YAML::EndSeq;
    e << YAML::EndMap;
    e << YAML::Key << "object_ids" << YAML::Value << YAML::Comment("values of the gt_object_id plane");
    e << YAML::Flow << YAML::BeginMap << YAML::Key << "sky" << YAML::Value << Scene::kSkyId << YAML::Key << "ground"
      << YAML::Value << Scene::kGroundId << YAML::EndMap;
    if (scene.mainObject >= 0)
        e << YAML::Key << "main_object" << YAML::Value << scene.objects[static_cast<size_t>(scene.mainObject)].name;

    // The E1 test panel (METHOD.md): true width X, range Y and height Z for Eq. 2-4.
    for (const SceneObject &o : scene.objects) {
        if (o.type != "cube_matrix") continue;
        const Vec3 lo = o.boundsMin - shift, hi = o.boundsMax - shift;
        e << YAML::Key << "panel" << YAML::Value << YAML::BeginMap;
        e << YAML::Key << "name" << YAML::Value << o.name;
        e << YAML::Key << "width_mm" << YAML::Value << mm(hi.x() - lo.x());
        e << YAML::Key << "range_mm" << YAML::Value << mm(lo.y());
        e << YAML::Key << "height_mm" << YAML::Value << mm(hi.z() - lo.z());
        e << YAML::Key << "center_mm" << YAML::Value;
        emitVec(e, (lo + hi) / 2);
        e << YAML::EndMap;
        break;
    }

    // Calibration mode: the board's true pose in the left camera frame (OpenCV axes):
    // inner corner (i, j) lies at origin + i * square * x_axis + j * square * y_axis.
    for (const SceneObject &o : scene.objects) {
        if (o.type != "calibration_board") continue;
        const Primitive &p = scene.primitives[static_cast<size_t>(o.firstPrimitive)];
        const Texture &t = scene.textures[static_cast<size_t>(p.texture[3])];
        const Camera left = rig.left(pose);
        // Face -Y of the box: u along its +X, v along its +Z, from the face's corner.
        const Vec3 corner = p.center + p.rotation * Vec3(-p.half.x(), -p.half.y(), -p.half.z());
        const Vec3 ux = p.rotation.col(0), vz = p.rotation.col(2);
        const Vec3 origin = corner + (t.margin_mm + t.square_mm) * (ux + vz);
        auto inCamera = [&](const Vec3 &v) { return Vec3(left.rotation.transpose() * v); };
        e << YAML::Key << "board" << YAML::Value << YAML::BeginMap;
        e << YAML::Key << "cols" << YAML::Value << t.board_squares[0] - 1;
        e << YAML::Key << "rows" << YAML::Value << t.board_squares[1] - 1;
        e << YAML::Key << "square_mm" << YAML::Value << t.square_mm;
        e << YAML::Key << "origin_camera_mm" << YAML::Value;
        emitVec(e, inCamera(origin - left.center));
        e << YAML::Key << "x_axis_camera" << YAML::Value << YAML::Flow << YAML::BeginSeq;
        for (double c : inCamera(ux)) e << c;
        e << YAML::EndSeq;
        e << YAML::Key << "y_axis_camera" << YAML::Value << YAML::Flow << YAML::BeginSeq;
        for (double c : inCamera(vz)) e << c;
        e << YAML::EndSeq;
        e << YAML::EndMap;
    }

    e << YAML::Key << "objects" << YAML::Value << YAML::BeginSeq;
    for (const SceneObject &o : scene.objects) {
        const Vec3 lo = o.boundsMin - shift, hi = o.boundsMax - shift;
        e << YAML::BeginMap;
        e << YAML::Key << "name" << YAML::Value << o.name;
        e << YAML::Key << "type" << YAML::Value << o.type;
        e << YAML::Key << "id" << YAML::Value << o.id;
        e << YAML::Key << "center_mm" << YAML::Value;
        emitVec(e, (lo + hi) / 2);
        e << YAML::Key << "size_mm" << YAML::Value;
        emitVec(e, hi - lo);
        e << YAML::Key << "range_mm" << YAML::Value << mm(lo.y());
        if (!o.parts.empty()) {
            e << YAML::Key << "parts" << YAML::Value << YAML::BeginSeq;
            for (const Part &p : o.parts) {
                e << YAML::Flow << YAML::BeginMap << YAML::Key << "name" << YAML::Value << p.name;
                e << YAML::Key << "center_mm" << YAML::Value;
                emitVec(e, p.center - shift);
                e << YAML::Key << "size_mm" << YAML::Value;
                emitVec(e, p.size);
                e << YAML::EndMap;
            }
            e << YAML::EndSeq;
        }
        e << YAML::EndMap;
    }
    e << YAML::EndSeq;
    e << YAML::EndMap;
    return std::string(e.c_str()) + "\n";
}

} // namespace binocle::sim
