// SPDX-License-Identifier: MIT
// The simulated stereo head: pinhole imagers with Brown-Conrady distortion, the right
// imager's small misalignment, and the exact calibration that follows from them.
#include "rig.hpp"

#include <Eigen/Geometry>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include <cmath>
#include <sstream>

namespace binocle::sim {

namespace {

constexpr double kDegToRad = 3.14159265358979323846 / 180.0;

cv::Mat toMat(const Eigen::MatrixXd &m) {
    cv::Mat out;
    cv::eigen2cv(m, out);
    return out;
}

Mat3 toEigen(const cv::Mat &m) {
    Mat3 out;
    cv::cv2eigen(m, out);
    return out;
}

bool nonZero(const Distortion &d) {
    for (double k : d)
        if (k != 0) return true;
    return false;
}

} // namespace

bool RigSettings::ideal() const {
    return !nonZero(distortion) && !nonZero(distortion_right) && right_rotation_deg.isZero() && right_offset_mm.isZero();
}

Vec2 Camera::distort(const Vec2 &p) const {
    const double k1 = distortion[0], k2 = distortion[1], p1 = distortion[2], p2 = distortion[3], k3 = distortion[4];
    const double x = p.x(), y = p.y(), r2 = x * x + y * y;
    const double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
    return {x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x), y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y};
}

Vec2 Camera::undistort(const Vec2 &target) const {
    const double k1 = distortion[0], k2 = distortion[1], p1 = distortion[2], p2 = distortion[3], k3 = distortion[4];
    Vec2 p = target;
    for (int it = 0; it < 20; ++it) {
        const double x = p.x(), y = p.y(), r2 = x * x + y * y;
        const double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
        const double g = k1 + r2 * (2 * k2 + 3 * k3 * r2); // d radial / d r2
        const Vec2 e = distort(p) - target;
        Eigen::Matrix2d j;
        j(0, 0) = radial + 2 * g * x * x + 2 * p1 * y + 6 * p2 * x;
        j(0, 1) = 2 * g * x * y + 2 * p1 * x + 2 * p2 * y;
        j(1, 0) = j(0, 1);
        j(1, 1) = radial + 2 * g * y * y + 6 * p1 * y + 2 * p2 * x;
        const Vec2 step = j.inverse() * e;
        p -= step;
        if (step.squaredNorm() < 1e-24) break;
    }
    return p;
}

Vec3 Camera::direction(double u, double v) const {
    if (!distorted) return rotation.col(2) + rotation.col(0) * ((u - cx) / fx) + rotation.col(1) * ((v - cy) / fy);
    const Vec2 n = undistort(Vec2((u - cx) / fx, (v - cy) / fy));
    return rotation * Vec3(n.x(), n.y(), 1.0);
}

bool Camera::project(const Vec3 &point, double &u, double &v) const {
    const Vec3 p = rotation.transpose() * (point - center);
    if (p.z() <= 0) return false;
    Vec2 n(p.x() / p.z(), p.y() / p.z());
    if (distorted) n = distort(n);
    u = fx * n.x() + cx;
    v = fy * n.y() + cy;
    return true;
}

StereoRig::StereoRig(const RigSettings &s) : s_(s) {
    const double th = s.inclination_deg * kDegToRad;
    // Columns: the camera axes Xc, Yc, Zc in the ground frame (Eq. 1).
    groundFromCamera_ << 1, 0, 0,             //
        0, -std::sin(th), std::cos(th),       //
        0, -std::cos(th), -std::sin(th);
    const Vec3 a = s.right_rotation_deg * kDegToRad; // roll, pitch, yaw
    rightAxes_ = (Eigen::AngleAxisd(a[0], Vec3::UnitZ()) * Eigen::AngleAxisd(a[2], Vec3::UnitY()) *
                  Eigen::AngleAxisd(a[1], Vec3::UnitX()))
                     .toRotationMatrix();
    rightCentre_ = Vec3(s.baseline_mm, 0, 0) + s.right_offset_mm;

    const double f = s.focalLengthPx();
    const double cx = (s.image_width - 1) / 2.0, cy = (s.image_height - 1) / 2.0;
    M1 = (cv::Mat_<double>(3, 3) << f, 0, cx, 0, f, cy, 0, 0, 1);
    M2 = M1.clone();
    D1 = cv::Mat(1, 5, CV_64F, const_cast<double *>(s.distortion.data())).clone();
    D2 = cv::Mat(1, 5, CV_64F, const_cast<double *>(s.distortion_right.data())).clone();
    // x_r = R x_l + T with x_l = rightAxes x_r + rightCentre.
    R = toMat(rightAxes_.transpose());
    T = toMat(-rightAxes_.transpose() * rightCentre_);
    const cv::Size size(s.image_width, s.image_height);
    if (s.ideal()) {
        // What framework/core/calibration.cpp derives for a rectified pair.
        R1 = cv::Mat::eye(3, 3, CV_64F);
        R2 = cv::Mat::eye(3, 3, CV_64F);
        P1 = cv::Mat::zeros(3, 4, CV_64F);
        M1.copyTo(P1(cv::Rect(0, 0, 3, 3)));
        P2 = P1.clone();
        P2.at<double>(0, 3) = -s.baseline_mm * f;
        Q = (cv::Mat_<double>(4, 4) << 1, 0, 0, -cx, 0, 1, 0, -cy, 0, 0, 0, f, 0, 0, 1.0 / s.baseline_mm, 0);
    } else {
        cv::stereoRectify(M1, D1, M2, D2, size, R, T, R1, R2, P1, P2, Q, cv::CALIB_ZERO_DISPARITY, 0, size);
    }
    rectifiedFocalPx_ = P1.at<double>(0, 0);
    rectifiedBaselineMm_ = -P2.at<double>(0, 3) / P2.at<double>(0, 0);
    principalOffsetPx_ = P1.at<double>(0, 2) - P2.at<double>(0, 2);
}

Camera StereoRig::camera(const RigPose &pose, const Mat3 &axesInLeft, const Vec3 &centreInLeft, const Distortion &d) const {
    Camera c;
    c.width = s_.image_width;
    c.height = s_.image_height;
    c.fx = c.fy = s_.focalLengthPx();
    c.cx = (s_.image_width - 1) / 2.0;
    c.cy = (s_.image_height - 1) / 2.0;
    c.distortion = d;
    c.distorted = nonZero(d);
    c.rotation = groundFromCamera_ * axesInLeft;
    c.center = Vec3(pose.lateral_mm, pose.forward_mm, s_.camera_height_mm) + groundFromCamera_ * centreInLeft;
    return c;
}

Camera StereoRig::left(const RigPose &pose) const { return camera(pose, Mat3::Identity(), Vec3::Zero(), s_.distortion); }

Camera StereoRig::right(const RigPose &pose) const { return camera(pose, rightAxes_, rightCentre_, s_.distortion_right); }

Camera StereoRig::rectifiedLeft(const RigPose &pose) const {
    // x_rect = R1 x_l: the rectified axes in the left frame are the rows of R1.
    Camera c = camera(pose, toEigen(R1).transpose(), Vec3::Zero(), Distortion{});
    c.fx = P1.at<double>(0, 0);
    c.fy = P1.at<double>(1, 1);
    c.cx = P1.at<double>(0, 2);
    c.cy = P1.at<double>(1, 2);
    return c;
}

Camera StereoRig::rectifiedRight(const RigPose &pose) const {
    // x_rect = R2 x_r: the rectified axes in the left frame are rightAxes_ R2^T.
    Camera c = camera(pose, rightAxes_ * toEigen(R2).transpose(), rightCentre_, Distortion{});
    c.fx = P2.at<double>(0, 0);
    c.fy = P2.at<double>(1, 1);
    c.cx = P2.at<double>(0, 2);
    c.cy = P2.at<double>(1, 2);
    return c;
}

std::string StereoRig::calibrationYaml() const {
    cv::FileStorage fs(".yml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
    std::ostringstream configuration;
    configuration << "sim_B" << s_.baseline_mm << "_f" << s_.focal_length_mm;
    fs << "image_width" << s_.image_width << "image_height" << s_.image_height;
    fs << "configuration" << configuration.str();
    fs << "rectified" << (s_.ideal() ? 1 : 0);
    fs << "M1" << M1 << "D1" << D1 << "M2" << M2 << "D2" << D2 << "R" << R << "T" << T;
    fs << "R1" << R1 << "R2" << R2 << "P1" << P1 << "P2" << P2 << "Q" << Q;
    fs << "baseline_mm" << cv::norm(T) << "focal_length_px" << P1.at<double>(0, 0);
    fs << "rms_px" << 0.0; // exact by construction
    return fs.releaseAndGetString();
}

} // namespace binocle::sim
