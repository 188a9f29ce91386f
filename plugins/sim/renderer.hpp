// SPDX-License-Identifier: MIT
// Ray caster of the `sim` source: renders a scene as the two imagers of a StereoRig see
// it (Lambert-shaded, textures filtered over each pixel's footprint, edges supersampled,
// sensor noise) and the exact ground truth.
#pragma once

#include "rig.hpp"
#include "scene.hpp"

#include <opencv2/core.hpp>

#include <cstdint>
#include <vector>

namespace binocle::sim {

struct RenderSettings {
    int antialias = 2;        // samples per axis per sensor pixel where a pixel straddles an edge
    int binning = 1;          // sensor pixels per axis averaged into an output pixel
    double noise_sigma = 2;   // grey levels, per sensor pixel (an output pixel gets sigma / binning)
    double gain_right = 1;    // right imager's response relative to the left
    double offset_right = 0;  // grey levels added to the right image
    bool color = false;       // BGR8 rather than GRAY8
    uint32_t seed = 1;
};

struct RenderedFrame {
    cv::Mat left, right;            // CV_8UC1, or CV_8UC3 (BGR)
    cv::Mat gt_disparity;           // CV_32F px, rectified left grid; -1 where nothing was hit
    cv::Mat gt_depth;               // CV_32F mm, depth along the rectified optical axis; 0 where nothing
    cv::Mat gt_valid;               // CV_8U, 255 where a surface was hit
    cv::Mat gt_object_id;           // CV_16U: Scene::kSkyId, kGroundId or SceneObject::id
    cv::Mat gt_nonocc;              // CV_8U, 255 where the surface hit is also seen by the right imager
};

// Nearest-surface queries on a scene (ground plane, object bounds, analytic shapes).
class Tracer {
public:
    struct Hit {
        double t = 0;        // distance along the unit ray, mm
        int primitive = -1;  // index in Scene::primitives, -1 = ground plane
        int face = 0;        // box face +X, -X, +Y, -Y, +Z, -Z; cylinder 0 side, 4 top, 5 bottom
    };

    explicit Tracer(const Scene &scene); // builds a bounding volume hierarchy of the primitives
    // Nearest surface along origin + t * direction (direction of unit length).
    bool trace(const Vec3 &origin, const Vec3 &direction, Hit &hit) const;
    // Whether any surface lies along origin + t * direction with t < tMax (a shadow ray:
    // the first one found ends the search, nothing beyond tMax is visited).
    bool blocked(const Vec3 &origin, const Vec3 &direction, double tMax) const;
    // Light leaving the surface of `hit` towards the origin. dir: the ray's direction
    // with any length; dirDx, dirDy: its change across the sample's footprint (both
    // edges), which sets how much texture detail is filtered out.
    Rgb shade(const Vec3 &origin, const Vec3 &unitDir, const Hit &hit, const Vec3 &dir, const Vec3 &dirDx,
              const Vec3 &dirDy) const;
    Rgb sky(const Vec3 &unitDir) const;
    uint16_t objectId(const Hit &hit) const;
    // What an edge separates: the object and, for boxes and cylinders, the face.
    float edgeId(const Hit &hit) const;

private:
    struct Node {
        Vec3 lo, hi;      // bounds of everything below
        int first = 0;    // leaf: first index in order_; inner: index of the second child
        int count = 0;    // leaf: number of primitives; inner: 0 (first child follows the node)
        int axis = 0;     // inner: the split axis, to visit the nearer child first
    };
    int build(int begin, int end);
    // Walks the hierarchy for hits nearer than `best`: the nearest (best and hit updated),
    // or with AnyHit the first found.
    template <bool AnyHit>
    bool traverse(const Vec3 &o, const Vec3 &d, double &best, Hit &hit) const;
    bool hitPrimitive(int index, const Vec3 &o, const Vec3 &d, const Vec3 &inv, double best, double &t, int &face) const;

    const Scene &scene_;
    std::vector<Node> nodes_;
    std::vector<int> order_; // primitive indices, leaves' ranges
    Vec3 rootCentre_{0, 0, 0}; // bounding sphere of the root's bounds
    double rootRadius2_ = 0;
};

// Whether scene point p (met by a ray of the rectified left imager; onGround: on the
// ground plane) is seen by `right`, an undistorted imager (the rectified right one): it
// lands inside its image, and the ray from its optical centre towards p meets no surface
// before p. A point on the back of a solid is hidden by its front. What gt_nonocc holds.
bool seenBy(const Camera &right, const Tracer &tracer, const Vec3 &p, bool onGround);

class Renderer {
public:
    Renderer(const StereoRig &rig, RenderSettings settings) : rig_(rig), settings_(settings) {}

    // One stereo pair of `scene` with the rig at `pose`; `frame` varies the noise.
    RenderedFrame render(const Scene &scene, const RigPose &pose, uint64_t frame) const;

    // Linear radiance (CV_32FC3, RGB, 0..1) of one imager. When `truth` is given the
    // camera must be the rectified left one, `rectifiedRight` its partner (for the
    // occlusion mask), and the ground truth planes are filled from the same rays.
    cv::Mat renderRadiance(const Scene &scene, const Camera &camera, RenderedFrame *truth = nullptr,
                           const Camera *rectifiedRight = nullptr) const;
    // Ground truth alone, in the grid of the rectified left imager.
    void renderGroundTruth(const Scene &scene, const Camera &rectifiedLeft, const Camera &rectifiedRight,
                           RenderedFrame &out) const;

    const RenderSettings &settings() const { return settings_; }

private:
    // Radiance -> 8-bit image with the imager's gain, offset and seeded noise.
    cv::Mat expose(const cv::Mat &radiance, int imager, uint64_t frame) const;

    const StereoRig &rig_;
    RenderSettings settings_;
};

} // namespace binocle::sim
