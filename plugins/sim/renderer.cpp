// SPDX-License-Identifier: MIT
// Ray caster of the `sim` source: renders a scene as the two imagers of a StereoRig see
// it (supersampled, Lambert-shaded, with sensor noise) and the exact ground truth.
#include "renderer.hpp"

#include "random.hpp"

#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace binocle::sim {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kEpsilon = 1e-6; // mm: hits closer than this to the origin are ignored

// Slab test against axis-aligned bounds lo..hi; true when the ray enters them before
// tMax. Written out per axis: the hottest few lines of the renderer.
inline bool hitBounds(const Vec3 &o, const Vec3 &inv, const Vec3 &lo, const Vec3 &hi, double tMax) {
    // NaN (0 * inf, a ray in a slab's plane) loses every comparison: it leaves tn / tf as they are.
    const double x1 = (lo.x() - o.x()) * inv.x(), x2 = (hi.x() - o.x()) * inv.x();
    const double y1 = (lo.y() - o.y()) * inv.y(), y2 = (hi.y() - o.y()) * inv.y();
    const double z1 = (lo.z() - o.z()) * inv.z(), z2 = (hi.z() - o.z()) * inv.z();
    double tn = 0, tf = tMax;
    auto grow = [&](double a, double b) {
        const double near = a < b ? a : b, far = a < b ? b : a;
        if (near > tn) tn = near;
        if (far < tf) tf = far;
    };
    grow(x1, x2);
    grow(y1, y2);
    grow(z1, z2);
    return tn <= tf;
}

// Box in its own axes (centred at 0, half sizes h), inv = 1 / d per axis; seen from
// outside only.
inline bool hitBox(const Vec3 &o, const Vec3 &d, const Vec3 &inv, const Vec3 &h, double tMax, double &t, int &face) {
    double tn = -kInf, tf = kInf;
    int axis = 0;
    for (int a = 0; a < 3; ++a) {
        if (d[a] == 0) {
            if (std::abs(o[a]) > h[a]) return false;
            continue;
        }
        double t1 = (-h[a] - o[a]) * inv[a], t2 = (h[a] - o[a]) * inv[a];
        if (t1 > t2) std::swap(t1, t2);
        if (t1 > tn) {
            tn = t1;
            axis = a;
        }
        tf = std::min(tf, t2);
        if (tn > tf) return false;
    }
    if (tn <= kEpsilon || tn >= tMax) return false;
    t = tn;
    face = 2 * axis + (d[axis] > 0 ? 1 : 0); // entering a +axis face when moving towards -axis
    return true;
}

inline bool hitEllipsoid(const Primitive &p, const Vec3 &o, const Vec3 &d, double tMax, double &t) {
    double tt;
    if (p.half.x() == p.half.y() && p.half.x() == p.half.z()) { // sphere: no division
        const Vec3 oc = o - p.center;
        const double b = oc.dot(d), c = oc.squaredNorm() - p.half.x() * p.half.x();
        const double disc = b * b - c;
        if (disc < 0) return false;
        tt = -b - std::sqrt(disc);
    } else {
        const Vec3 q = (o - p.center).cwiseQuotient(p.half), e = d.cwiseQuotient(p.half);
        const double a = e.squaredNorm(), b = q.dot(e), c = q.squaredNorm() - 1.0;
        const double disc = b * b - a * c;
        if (disc < 0) return false;
        tt = (-b - std::sqrt(disc)) / a;
    }
    if (tt <= kEpsilon || tt >= tMax) return false;
    t = tt;
    return true;
}

// Vertical cylinder, base disc centred at p.center, radius half.x, height half.z.
inline bool hitCylinder(const Primitive &p, const Vec3 &o, const Vec3 &d, double tMax, double &t, int &face) {
    const Vec3 q = o - p.center;
    const double r = p.half.x(), h = p.half.z();
    bool found = false;
    const double a = d.x() * d.x() + d.y() * d.y();
    if (a > 0) {
        const double b = q.x() * d.x() + q.y() * d.y(), c = q.x() * q.x() + q.y() * q.y() - r * r;
        const double disc = b * b - a * c;
        if (disc >= 0) {
            const double tt = (-b - std::sqrt(disc)) / a;
            const double z = q.z() + tt * d.z();
            if (tt > kEpsilon && tt < tMax && z >= 0 && z <= h) {
                t = tMax = tt;
                face = 0;
                found = true;
            }
        }
    }
    if (d.z() != 0) {
        const double capZ = d.z() < 0 ? h : 0.0;
        const double tt = (capZ - q.z()) / d.z();
        const double x = q.x() + tt * d.x(), y = q.y() + tt * d.y();
        if (tt > kEpsilon && tt < tMax && x * x + y * y <= r * r) {
            t = tt;
            face = d.z() < 0 ? 4 : 5;
            found = true;
        }
    }
    return found;
}

inline Vec3 boxAxis(int face) {
    Vec3 n = Vec3::Zero();
    n[face / 2] = (face % 2 == 0) ? 1.0 : -1.0;
    return n;
}

inline double clamp01(double v) { return v < 0 ? 0 : (v > 1 ? 1 : v); }

inline Vec3 unit(const Vec3 &v) { return v * (1.0 / v.norm()); } // one division, not three

// Surface coordinates (u, v) of point p on a face of a box: right and up as seen from
// outside the face, origin at its corner.
inline void boxFaceUv(const Primitive &prim, int face, const Vec3 &p, double &u, double &v) {
    const Vec3 q = prim.axisAligned ? Vec3(p - prim.center) : Vec3(prim.rotation.transpose() * (p - prim.center));
    const Vec3 &h = prim.half;
    switch (face) {
    case 0: u = q.y() + h.y(); v = q.z() + h.z(); break; // +X
    case 1: u = h.y() - q.y(); v = q.z() + h.z(); break; // -X
    case 2: u = h.x() - q.x(); v = q.z() + h.z(); break; // +Y
    case 3: u = q.x() + h.x(); v = q.z() + h.z(); break; // -Y (faces the rig)
    case 4: u = q.x() + h.x(); v = q.y() + h.y(); break; // +Z
    default: u = q.x() + h.x(); v = h.y() - q.y(); break; // -Z
    }
}

// Where the ray origin + s * dir meets the plane through p with normal n (tangent plane);
// far away when it runs parallel to it or away from it. nDistance = n . (p - origin).
inline Vec3 onTangentPlane(const Vec3 &o, const Vec3 &dir, const Vec3 &n, double nDistance) {
    const double s = nDistance / n.dot(dir);
    return o + (s > 0 && s < 1e12 ? s : 1e12) * dir;
}

// Relative tolerance of the occlusion test: a surface met by the right imager's ray less
// than this fraction of the distance before the point does not hide it (0.006 mm at 6 m:
// far below any surface's thickness, far above rounding).
constexpr double kOcclusionTolerance = 1e-6;

// What the truth of one pixel is made from besides its ray.
struct TruthContext {
    const StereoRig &rig;
    const Tracer &tracer;
    const Camera &right; // rectified right imager
    Vec3 axis;           // rectified optical axis, scene frame
};

// One pixel's worth of ground truth from the ray through its centre.
struct TruthRow {
    float *disparity, *depth;
    uint8_t *valid, *nonocc;
    uint16_t *id;
    void set(int u, const TruthContext &c, const Vec3 &origin, const Vec3 &d, bool hit, const Tracer::Hit &h) {
        const double z = hit ? h.t * d.dot(c.axis) : 0.0;
        if (z > 0 && std::isfinite(z)) {
            depth[u] = static_cast<float>(z);
            disparity[u] = static_cast<float>(c.rig.rectifiedDisparity(z));
            valid[u] = 255;
            id[u] = c.tracer.objectId(h);
            nonocc[u] = seenBy(c.right, c.tracer, origin + h.t * d, h.primitive < 0) ? 255 : 0;
        } else {
            depth[u] = 0;
            disparity[u] = -1.0f;
            valid[u] = 0;
            nonocc[u] = 0;
            id[u] = Scene::kSkyId;
        }
    }
};

void allocateTruth(RenderedFrame &out, int width, int height) {
    out.gt_disparity.create(height, width, CV_32F);
    out.gt_depth.create(height, width, CV_32F);
    out.gt_valid.create(height, width, CV_8U);
    out.gt_nonocc.create(height, width, CV_8U);
    out.gt_object_id.create(height, width, CV_16U);
}

TruthRow truthRow(RenderedFrame &out, int v) {
    return {out.gt_disparity.ptr<float>(v), out.gt_depth.ptr<float>(v), out.gt_valid.ptr<uint8_t>(v),
            out.gt_nonocc.ptr<uint8_t>(v), out.gt_object_id.ptr<uint16_t>(v)};
}

} // namespace

Tracer::Tracer(const Scene &scene) : scene_(scene) {
    order_.resize(scene.primitives.size());
    for (size_t i = 0; i < order_.size(); ++i) order_[i] = static_cast<int>(i);
    if (order_.empty()) return;
    build(0, static_cast<int>(order_.size()));
    rootCentre_ = (nodes_[0].lo + nodes_[0].hi) / 2;
    rootRadius2_ = (nodes_[0].hi - nodes_[0].lo).squaredNorm() / 4 * (1 + 1e-9);
}

// Median split along the longest axis of the primitives' centres; leaves of up to two.
// Splits where the surface area heuristic is lowest (each axis, primitives sorted by
// centre); leaves of up to two primitives.
int Tracer::build(int begin, int end) {
    const int index = static_cast<int>(nodes_.size());
    nodes_.emplace_back();
    auto boundsOf = [&](int k, Vec3 &lo, Vec3 &hi) {
        const Primitive &p = scene_.primitives[static_cast<size_t>(order_[static_cast<size_t>(k)])];
        lo = lo.cwiseMin(primitiveMin(p));
        hi = hi.cwiseMax(primitiveMax(p));
    };
    Vec3 lo = Vec3::Constant(kInf), hi = Vec3::Constant(-kInf);
    for (int k = begin; k < end; ++k) boundsOf(k, lo, hi);
    nodes_[static_cast<size_t>(index)].lo = lo;
    nodes_[static_cast<size_t>(index)].hi = hi;
    const int n = end - begin;
    if (n <= 2) {
        nodes_[static_cast<size_t>(index)].first = begin;
        nodes_[static_cast<size_t>(index)].count = n;
        return index;
    }
    auto area = [](const Vec3 &a, const Vec3 &b) {
        const Vec3 e = (b - a).cwiseMax(0.0);
        return e.x() * e.y() + e.y() * e.z() + e.z() * e.x();
    };
    double bestCost = kInf;
    int bestAxis = 0, bestSplit = begin + n / 2;
    std::vector<double> leftArea(static_cast<size_t>(n));
    for (int axis = 0; axis < 3; ++axis) {
        std::sort(order_.begin() + begin, order_.begin() + end, [&](int a, int b) {
            return scene_.primitives[static_cast<size_t>(a)].center[axis] < scene_.primitives[static_cast<size_t>(b)].center[axis];
        });
        Vec3 l = Vec3::Constant(kInf), h = Vec3::Constant(-kInf);
        for (int k = 0; k < n; ++k) {
            boundsOf(begin + k, l, h);
            leftArea[static_cast<size_t>(k)] = area(l, h); // of the first k + 1
        }
        l = Vec3::Constant(kInf);
        h = Vec3::Constant(-kInf);
        for (int k = n - 1; k >= 1; --k) {
            boundsOf(begin + k, l, h); // right part: k .. n - 1
            const double cost = leftArea[static_cast<size_t>(k - 1)] * k + area(l, h) * (n - k);
            if (cost < bestCost) {
                bestCost = cost;
                bestAxis = axis;
                bestSplit = begin + k;
            }
        }
    }
    std::sort(order_.begin() + begin, order_.begin() + end, [&](int a, int b) {
        return scene_.primitives[static_cast<size_t>(a)].center[bestAxis] < scene_.primitives[static_cast<size_t>(b)].center[bestAxis];
    });
    build(begin, bestSplit);
    const int second = build(bestSplit, end);
    nodes_[static_cast<size_t>(index)].first = second;
    nodes_[static_cast<size_t>(index)].axis = bestAxis;
    return index;
}

bool Tracer::hitPrimitive(int i, const Vec3 &o, const Vec3 &d, const Vec3 &inv, double best, double &t, int &face) const {
    const Primitive &p = scene_.primitives[static_cast<size_t>(i)];
    switch (p.shape) {
    case Shape::Box:
        if (p.axisAligned) return hitBox(o - p.center, d, inv, p.half, best, t, face);
        {
            const Vec3 dl = p.rotation.transpose() * d;
            return hitBox(p.rotation.transpose() * (o - p.center), dl, dl.cwiseInverse(), p.half, best, t, face);
        }
    case Shape::Ellipsoid: face = 0; return hitEllipsoid(p, o, d, best, t);
    case Shape::Cylinder: return hitCylinder(p, o, d, best, t, face);
    }
    return false;
}

bool Tracer::trace(const Vec3 &o, const Vec3 &d, Hit &hit) const {
    double best = kInf;
    bool found = false;
    if (scene_.groundTexture >= 0 && d.z() < 0 && o.z() > 0) {
        best = -o.z() / d.z();
        hit.primitive = -1;
        hit.face = 4;
        found = true;
    }
    found = traverse<false>(o, d, best, hit) || found;
    hit.t = best;
    return found;
}

bool Tracer::blocked(const Vec3 &o, const Vec3 &d, double tMax) const {
    if (scene_.groundTexture >= 0 && d.z() < 0 && o.z() > 0 && -o.z() / d.z() < tMax) return true;
    Hit hit;
    return traverse<true>(o, d, tMax, hit);
}

template <bool AnyHit>
bool Tracer::traverse(const Vec3 &o, const Vec3 &d, double &best, Hit &hit) const {
    if (nodes_.empty()) return false;
    // Bounding sphere of everything first: most rays (sky, near ground) end here, before
    // the divisions of the slab tests.
    const Vec3 oc = rootCentre_ - o;
    const double b = oc.dot(d), c2 = oc.squaredNorm() - b * b;
    if (c2 > rootRadius2_) return false;
    const double half = std::sqrt(rootRadius2_ - c2);
    if (b + half < 0 || b - half > best) return false;
    const Vec3 inv = d.cwiseInverse();
    bool found = false;
    int stack[64];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const int index = stack[--top];
        const Node &node = nodes_[static_cast<size_t>(index)];
        if (!hitBounds(o, inv, node.lo, node.hi, best)) continue;
        if (node.count > 0) {
            for (int k = node.first; k < node.first + node.count; ++k) {
                const int i = order_[static_cast<size_t>(k)];
                double t = 0;
                int face = 0;
                if (hitPrimitive(i, o, d, inv, best, t, face)) {
                    if (AnyHit) return true;
                    best = t;
                    hit.primitive = i;
                    hit.face = face;
                    found = true;
                }
            }
            continue;
        }
        // Visit first (stack last) the child on the side the ray comes from along the
        // split axis: its hits prune the other's bounds.
        const int first = index + 1, second = node.first;
        if (d[node.axis] > 0) {
            stack[top++] = second;
            stack[top++] = first;
        } else {
            stack[top++] = first;
            stack[top++] = second;
        }
    }
    return found;
}

float Tracer::edgeId(const Hit &hit) const {
    if (hit.primitive < 0) return 12.0f;
    const Primitive &p = scene_.primitives[static_cast<size_t>(hit.primitive)];
    return static_cast<float>((p.object + 2) * 8 + (p.shape == Shape::Ellipsoid ? 0 : hit.face));
}

uint16_t Tracer::objectId(const Hit &hit) const {
    if (hit.primitive < 0) return Scene::kGroundId;
    return scene_.objects[static_cast<size_t>(scene_.primitives[static_cast<size_t>(hit.primitive)].object)].id;
}

Rgb Tracer::sky(const Vec3 &d) const {
    const double k = clamp01(d.z() * 2.5);
    return scene_.sky.horizon + (scene_.sky.zenith - scene_.sky.horizon) * static_cast<float>(k);
}

Rgb Tracer::shade(const Vec3 &o, const Vec3 &d, const Hit &hit, const Vec3 &dir, const Vec3 &dirDx,
                  const Vec3 &dirDy) const {
    const Vec3 p = o + hit.t * d;
    SurfacePoint sp;
    Vec3 n = Vec3::UnitZ();
    int texture = scene_.groundTexture;
    const Primitive *prim = hit.primitive >= 0 ? &scene_.primitives[static_cast<size_t>(hit.primitive)] : nullptr;
    if (prim) {
        texture = prim->texture[static_cast<size_t>(hit.face)];
        switch (prim->shape) {
        case Shape::Box: n = prim->axisAligned ? boxAxis(hit.face) : Vec3(prim->rotation * boxAxis(hit.face)); break;
        case Shape::Ellipsoid:
            n = (p - prim->center).cwiseQuotient(prim->half.cwiseProduct(prim->half)).normalized();
            break;
        case Shape::Cylinder:
            if (hit.face == 0)
                n = Vec3(p.x() - prim->center.x(), p.y() - prim->center.y(), 0).normalized();
            else
                n = hit.face == 4 ? Vec3::UnitZ() : Vec3(-Vec3::UnitZ());
            break;
        }
    }
    // Ray differentials: where the footprint's edges meet the tangent plane.
    const double nDistance = hit.t * n.dot(d);
    const Vec3 px = onTangentPlane(o, dir + dirDx, n, nDistance), py = onTangentPlane(o, dir + dirDy, n, nDistance);
    if (!prim || prim->shape == Shape::Box) {
        double u0, v0, ux, vx, uy, vy;
        if (!prim) {
            u0 = p.x(), v0 = p.y(), ux = px.x(), vx = px.y(), uy = py.x(), vy = py.y();
        } else {
            boxFaceUv(*prim, hit.face, p, u0, v0);
            boxFaceUv(*prim, hit.face, px, ux, vx);
            boxFaceUv(*prim, hit.face, py, uy, vy);
        }
        sp.u = u0;
        sp.v = v0;
        sp.dudx = ux - u0;
        sp.dvdx = vx - v0;
        sp.dudy = uy - u0;
        sp.dvdy = vy - v0;
    } else {
        sp.planar = false;
        sp.local = p - prim->textureOrigin;
        sp.dldx = px - p;
        sp.dldy = py - p;
        sp.normal = n;
    }
    const Rgb albedo = evalTexture(scene_.textures[static_cast<size_t>(texture)], sp);
    const double lambert = std::max(0.0, n.dot(scene_.light.direction));
    const double light = scene_.light.ambient + (1.0 - scene_.light.ambient) * lambert;
    return albedo * static_cast<float>(light);
}

bool seenBy(const Camera &right, const Tracer &tracer, const Vec3 &p, bool onGround) {
    double u = 0, v = 0;
    if (!right.project(p, u, v)) return false;
    if (u < -0.5 || u > right.width - 0.5 || v < -0.5 || v > right.height - 0.5) return false;
    if (onGround && right.center.z() <= 0) return false; // the ground is seen from above only
    const Vec3 toPoint = p - right.center;
    const double distance = toPoint.norm();
    return !tracer.blocked(right.center, toPoint / distance, distance * (1 - kOcclusionTolerance));
}

cv::Mat Renderer::renderRadiance(const Scene &scene, const Camera &cam, RenderedFrame *truth,
                                 const Camera *rectifiedRight) const {
    const Tracer tracer(scene);
    if (truth && !rectifiedRight) throw std::logic_error("Renderer::renderRadiance: truth asked without the rectified right imager");
    const int n = std::max(1, settings_.antialias * settings_.binning); // samples per axis on edges
    const Vec3 axis = cam.rotation.col(2);
    // Change of the (unnormalised) ray direction from one pixel to the next.
    const Vec3 stepX = cam.rotation.col(0) / cam.fx, stepY = cam.rotation.col(1) / cam.fy;
    cv::Mat out(cam.height, cam.width, CV_32FC3);
    // What each centre ray met, for finding edges: (object + 2) * 8 + face (faces of boxes
    // and cylinders only), 12 the ground, 0 the sky.
    cv::Mat surface(cam.height, cam.width, CV_32F);
    if (truth) allocateTruth(*truth, cam.width, cam.height);
    const TruthContext context{rig_, tracer, truth ? *rectifiedRight : cam, axis};

    // Pass 1: one ray through each pixel centre, texture filtered over the whole pixel.
    cv::parallel_for_(cv::Range(0, cam.height), [&](const cv::Range &rows) {
        for (int v = rows.start; v < rows.end; ++v) {
            cv::Vec3f *row = out.ptr<cv::Vec3f>(v);
            float *ids = surface.ptr<float>(v);
            TruthRow gt{};
            if (truth) gt = truthRow(*truth, v);
            const Vec3 rowStart = cam.direction(0, v);
            for (int u = 0; u < cam.width; ++u) {
                // Undistorted imagers: the direction grows by stepX from pixel to pixel.
                const Vec3 dir = cam.distorted ? cam.direction(u, v) : Vec3(rowStart + u * stepX), d = unit(dir);
                Tracer::Hit hit;
                const bool found = tracer.trace(cam.center, d, hit);
                const Rgb c = found ? tracer.shade(cam.center, d, hit, dir, stepX, stepY) : tracer.sky(d);
                row[u] = cv::Vec3f(c.x(), c.y(), c.z());
                ids[u] = found ? tracer.edgeId(hit) : 0.0f;
                if (truth) gt.set(u, context, cam.center, d, found, hit);
            }
        }
    });
    if (n == 1) return out;

    // Pass 2: pixels that straddle an edge (a centre ray of their 3 x 3 neighbourhood met
    // another object or face: the neighbourhood's max and min differ) are supersampled.
    // Creases between the spheres of a crown are not edges: the shading is continuous
    // enough there.
    cv::Mat highest, lowest;
    cv::dilate(surface, highest, cv::Mat());
    cv::erode(surface, lowest, cv::Mat());
    const cv::Mat edges = highest != lowest;
    const Vec3 subX = stepX / n, subY = stepY / n;
    cv::parallel_for_(cv::Range(0, cam.height), [&](const cv::Range &rows) {
        for (int v = rows.start; v < rows.end; ++v) {
            cv::Vec3f *row = out.ptr<cv::Vec3f>(v);
            const uint8_t *edge = edges.ptr<uint8_t>(v);
            for (int u = 0; u < cam.width; ++u) {
                if (!edge[u]) continue;
                Rgb sum = Rgb::Zero();
                for (int j = 0; j < n; ++j) {
                    for (int i = 0; i < n; ++i) {
                        // One sample per cell of an n x n grid, placed so that the n^2
                        // samples take n^2 distinct columns and rows ("n-rooks"): edges
                        // along the image axes are resolved to 1/n^2 of a pixel, not 1/n.
                        const double x = (i + (j + 0.5) / n) / n, y = (j + (i + 0.5) / n) / n;
                        const Vec3 dir = cam.direction(u - 0.5 + x, v - 0.5 + y), d = unit(dir);
                        Tracer::Hit hit;
                        sum += tracer.trace(cam.center, d, hit) ? tracer.shade(cam.center, d, hit, dir, subX, subY)
                                                                 : tracer.sky(d);
                    }
                }
                sum /= static_cast<float>(n * n);
                row[u] = cv::Vec3f(sum.x(), sum.y(), sum.z());
            }
        }
    });
    return out;
}

cv::Mat Renderer::expose(const cv::Mat &radiance, int imager, uint64_t frame) const {
    const bool right = imager == 1;
    const float gain = static_cast<float>(255.0 * (right ? settings_.gain_right : 1.0));
    const float offset = static_cast<float>(right ? settings_.offset_right : 0.0) + 0.5f; // + 0.5: rounding
    const float sigma = static_cast<float>(settings_.noise_sigma / std::max(1, settings_.binning));
    const float *normal = Random::normalTable();
    auto quantise = [](float v) { return v <= 0.0f ? uint8_t{0} : (v >= 255.0f ? uint8_t{255} : static_cast<uint8_t>(v)); };
    cv::Mat out(radiance.size(), settings_.color ? CV_8UC3 : CV_8UC1);
    cv::parallel_for_(cv::Range(0, radiance.rows), [&](const cv::Range &rows) {
        for (int v = rows.start; v < rows.end; ++v) {
            // One generator per row: the same bytes whatever the number of threads.
            Random rng({settings_.seed, static_cast<uint32_t>(frame), static_cast<uint32_t>(frame >> 32),
                        static_cast<uint32_t>(imager), static_cast<uint32_t>(v)});
            // Two table indices per engine draw.
            uint32_t bits = 0;
            bool spare = false;
            auto noise = [&] {
                if (sigma <= 0) return 0.0f;
                if (!spare) bits = rng.bits();
                spare = !spare;
                return sigma * normal[spare ? (bits & 0xFFFFu) : (bits >> 16)];
            };
            const cv::Vec3f *in = radiance.ptr<cv::Vec3f>(v);
            uint8_t *dst = out.ptr<uint8_t>(v);
            for (int u = 0; u < radiance.cols; ++u) {
                const cv::Vec3f &c = in[u]; // R, G, B
                if (!settings_.color) {
                    const float grey = 0.299f * c[0] + 0.587f * c[1] + 0.114f * c[2];
                    dst[u] = quantise(grey * gain + offset + noise());
                } else {
                    for (int k = 0; k < 3; ++k) dst[3 * u + k] = quantise(c[2 - k] * gain + offset + noise()); // BGR
                }
            }
        }
    });
    return out;
}

void Renderer::renderGroundTruth(const Scene &scene, const Camera &cam, const Camera &rectifiedRight,
                                 RenderedFrame &out) const {
    const Tracer tracer(scene);
    allocateTruth(out, cam.width, cam.height);
    const TruthContext context{rig_, tracer, rectifiedRight, cam.rotation.col(2)};
    cv::parallel_for_(cv::Range(0, cam.height), [&](const cv::Range &rows) {
        for (int v = rows.start; v < rows.end; ++v) {
            TruthRow gt = truthRow(out, v);
            for (int u = 0; u < cam.width; ++u) {
                const Vec3 d = cam.ray(u, v);
                Tracer::Hit hit;
                const bool found = tracer.trace(cam.center, d, hit);
                gt.set(u, context, cam.center, d, found, hit);
            }
        }
    });
}

RenderedFrame Renderer::render(const Scene &scene, const RigPose &pose, uint64_t frame) const {
    RenderedFrame out;
    if (rig_.settings().ideal()) {
        // The left imager is its own rectified image: its centre rays give the truth.
        const Camera right = rig_.rectifiedRight(pose);
        out.left = expose(renderRadiance(scene, rig_.left(pose), &out, &right), 0, frame);
    } else {
        out.left = expose(renderRadiance(scene, rig_.left(pose)), 0, frame);
        renderGroundTruth(scene, rig_.rectifiedLeft(pose), rig_.rectifiedRight(pose), out);
    }
    out.right = expose(renderRadiance(scene, rig_.right(pose)), 1, frame);
    return out;
}

} // namespace binocle::sim
