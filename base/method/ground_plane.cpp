// SPDX-License-Identifier: MIT
// Ground plane fit (RANSAC + total least squares) and object offsets: the E2 indicators.
#include "method/ground_plane.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

namespace binocle::method {

namespace {
constexpr double kPi = 3.14159265358979323846;
double deg(double rad) { return rad * 180.0 / kPi; }

struct Plane {
    Eigen::Vector3d n; // unit, n.z() > 0
    double d;          // n . p + d = 0
    double distance(const Eigen::Vector3d &p) const { return std::fabs(n.dot(p) + d); }
};

// Total least squares: the plane through the mean, normal along the smallest axis.
bool fitTls(const std::vector<Eigen::Vector3d> &pts, Plane &out) {
    if (pts.size() < 3) return false;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const auto &p : pts) mean += p;
    mean /= static_cast<double>(pts.size());
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (const auto &p : pts) cov += (p - mean) * (p - mean).transpose();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
    Eigen::Vector3d n = eig.eigenvectors().col(0); // eigenvalues in increasing order
    if (n.z() < 0) n = -n;
    out.n = n.normalized();
    out.d = -out.n.dot(mean);
    return std::isfinite(out.d);
}
} // namespace

double GroundPlane::heightAt(double x_mm, double y_mm) const {
    // n.x X + n.y Y + n.z Z + d = 0, with offset_mm = -d / n.z.
    return offset_mm - (normal[0] * x_mm + normal[1] * y_mm) / normal[2];
}

GroundPlane fitGroundPlane(const CloudView &cloud, const GroundPlaneOptions &o) {
    GroundPlane result;
    std::vector<Eigen::Vector3d> candidates;
    candidates.reserve(cloud.count);
    for (size_t i = 0; i < cloud.count; ++i) {
        if (!cloud.finite(i)) continue;
        if (o.x.valid() && !o.x.contains(cloud.x(i))) continue;
        if (o.y.valid() && !o.y.contains(cloud.y(i))) continue;
        if (cloud.z(i) >= o.max_height_mm) continue;
        candidates.emplace_back(cloud.x(i), cloud.y(i), cloud.z(i));
    }
    result.candidates = static_cast<int64_t>(candidates.size());
    if (candidates.size() < 3) return result;

    std::mt19937 rng(o.seed);
    std::vector<Eigen::Vector3d> sample = candidates;
    if (sample.size() > o.max_points) {
        std::shuffle(sample.begin(), sample.end(), rng);
        sample.resize(o.max_points);
    }
    const double minNz = std::cos(o.max_tilt_deg * kPi / 180.0);
    std::uniform_int_distribution<size_t> pick(0, sample.size() - 1);
    Plane best{};
    int64_t bestScore = -1;
    for (int it = 0; it < o.iterations; ++it) {
        const Eigen::Vector3d &a = sample[pick(rng)], &b = sample[pick(rng)], &c = sample[pick(rng)];
        Eigen::Vector3d n = (b - a).cross(c - a);
        const double len = n.norm();
        if (len < 1e-9) continue;
        n /= len;
        if (n.z() < 0) n = -n;
        if (n.z() < minNz) continue; // too steep for ground: a wall, the panel's face
        const Plane p{n, -n.dot(a)};
        int64_t score = 0;
        for (const auto &q : sample)
            if (p.distance(q) < o.inlier_mm) ++score;
        if (score > bestScore) {
            bestScore = score;
            best = p;
        }
    }
    if (bestScore < 3) return result;

    // Least-squares refinement on the inliers among all candidates, twice.
    Plane plane = best;
    std::vector<Eigen::Vector3d> inliers;
    for (int pass = 0; pass < 3; ++pass) {
        inliers.clear();
        for (const auto &q : candidates)
            if (plane.distance(q) < o.inlier_mm) inliers.push_back(q);
        Plane refined;
        if (!fitTls(inliers, refined)) break;
        plane = refined;
    }
    inliers.clear();
    double sq = 0;
    for (const auto &q : candidates) {
        const double dist = plane.distance(q);
        if (dist < o.inlier_mm) {
            inliers.push_back(q);
            sq += dist * dist;
        }
    }
    if (inliers.size() < 3) return result;
    result.found = true;
    for (int k = 0; k < 3; ++k) result.normal[k] = plane.n[k];
    result.offset_mm = -plane.d / plane.n.z();
    result.pitch_deg = deg(std::atan2(-plane.n.y(), plane.n.z()));
    result.roll_deg = deg(std::atan2(-plane.n.x(), plane.n.z()));
    result.inliers = static_cast<int64_t>(inliers.size());
    result.rms_mm = std::sqrt(sq / static_cast<double>(inliers.size()));
    return result;
}

double recoveredInclinationDeg(double applied_inclination_deg, const GroundPlane &plane) {
    if (!plane.found) return std::numeric_limits<double>::quiet_NaN();
    return applied_inclination_deg + plane.pitch_deg;
}

ObjectOffset objectOffset(const std::vector<LocalisedObject> &objects, const KnownObject &truth,
                          double max_distance_mm) {
    ObjectOffset best;
    best.true_x_mm = truth.center_mm[0];
    best.true_range_mm = truth.nearFaceRangeMm();
    double bestDistance = max_distance_mm;
    for (const LocalisedObject &o : objects) {
        const double lateral = o.center_x_mm - best.true_x_mm, range = o.range_mm - best.true_range_mm;
        const double distance = std::hypot(lateral, range);
        if (distance > bestDistance) continue;
        bestDistance = distance;
        best.found = true;
        best.object_id = o.id;
        best.lateral_mm = lateral;
        best.range_mm = range;
        best.distance_mm = distance;
        best.measured_x_mm = o.center_x_mm;
        best.measured_range_mm = o.range_mm;
    }
    return best;
}

ObjectOffset locateKnownObject(const CloudView &cloud, const KnownObject &truth, PanelReadingOptions options,
                               double lateral_margin_mm) {
    ObjectOffset off;
    off.true_x_mm = truth.center_mm[0];
    off.true_range_mm = truth.nearFaceRangeMm();
    const double half = truth.size_mm[0] / 2 + lateral_margin_mm;
    options.lateral = {off.true_x_mm - half, off.true_x_mm + half};
    // Heights too: only up to the object's top + the margin. Without this a larger,
    // denser object within the lateral window and the range search (E2: the tree's
    // crown, 2-5 m up, 1-3 m behind or in front of the marker) wins the band search and
    // the object is "found" metres off.
    const double top = truth.center_mm[2] + truth.size_mm[2] / 2 + lateral_margin_mm;
    if (top < options.grid.z.max_mm) options.grid.z.max_mm = std::max(top, options.grid.z.min_mm + options.grid.cell_mm);
    options.expected_range_mm = off.true_range_mm;
    options.expected_x_mm = off.true_x_mm;
    options.expected_width_mm = truth.size_mm[0];
    const PanelReading r = readPanel(cloud, options);
    if (!r.registered) return off;
    off.found = true;
    off.reading = r;
    off.measured_x_mm = (r.x_min_mm + r.x_max_mm) / 2;
    off.measured_range_mm = r.range_mm;
    off.lateral_mm = off.measured_x_mm - off.true_x_mm;
    off.range_mm = off.measured_range_mm - off.true_range_mm;
    off.distance_mm = std::hypot(off.lateral_mm, off.range_mm);
    return off;
}

} // namespace binocle::method
