// SPDX-License-Identifier: MIT
// The cloud stage (CloudProjector) gives the points of the former triangulation — Q times
// (u, v, d, 1) per pixel in double precision, then R1^T — within float tolerance, for a
// calibration with a real rectifying rotation, and keeps its arrays from frame to frame.
#include "core/calibration.hpp"
#include "core/cloud.hpp"

#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>

namespace binocle {
namespace {

// The triangulation the pipeline used before the cloud stage: kept here as the reference.
Cloud referenceCloud(const cv::Mat &disparity, const StereoCalibration &cal, const cv::Mat &left, double max_range_mm) {
    Cloud cloud;
    cloud.image_width = disparity.cols;
    cloud.image_height = disparity.rows;
    const bool color = !left.empty() && left.size() == disparity.size();
    cv::Mat q64, r64;
    cal.Q.convertTo(q64, CV_64F);
    const cv::Matx44d Q(q64.reshape(1, 1).ptr<double>());
    cal.R1.convertTo(r64, CV_64F);
    const cv::Matx33d R1t = cv::Matx33d(r64.reshape(1, 1).ptr<double>()).t();
    for (int v = 0; v < disparity.rows; ++v) {
        const float *d = disparity.ptr<float>(v);
        for (int u = 0; u < disparity.cols; ++u) {
            if (!(d[u] > 0)) continue;
            const cv::Vec4d h = Q * cv::Vec4d(u, v, d[u], 1.0);
            if (!(h[3] > 0)) continue;
            const cv::Vec3d pr(h[0] / h[3], h[1] / h[3], h[2] / h[3]);
            if (!(pr[2] > 0) || pr[2] > max_range_mm) continue;
            const cv::Vec3d p = R1t * pr;
            cloud.xyz.insert(cloud.xyz.end(), {static_cast<float>(p[0]), static_cast<float>(p[1]), static_cast<float>(p[2])});
            cloud.pixel.push_back(v * disparity.cols + u);
            if (color) {
                const cv::Vec3b &bgr = left.at<cv::Vec3b>(v, u);
                cloud.rgb.insert(cloud.rgb.end(), {bgr[2], bgr[1], bgr[0]});
            }
        }
    }
    return cloud;
}

StereoCalibration tiltedRig() {
    StereoCalibration c;
    c.image_size = cv::Size(640, 480);
    c.M1 = (cv::Mat_<double>(3, 3) << 520, 0, 318, 0, 521, 243, 0, 0, 1);
    c.M2 = (cv::Mat_<double>(3, 3) << 518, 0, 325, 0, 519, 238, 0, 0, 1);
    c.D1 = cv::Mat::zeros(1, 5, CV_64F);
    c.D2 = cv::Mat::zeros(1, 5, CV_64F);
    cv::Rodrigues(cv::Vec3d(0.01, 0.03, -0.004), c.R);
    c.T = (cv::Mat_<double>(3, 1) << -150, 1.5, 2);
    c.computeRectification();
    return c;
}

TEST(CloudStage, SamePointsAsTheFormerTriangulation) {
    const StereoCalibration cal = tiltedRig();
    cv::Mat disparity(480, 640, CV_32F), left(480, 640, CV_8UC3);
    cv::RNG rng(7);
    rng.fill(disparity, cv::RNG::UNIFORM, 1.0, 90.0);
    rng.fill(left, cv::RNG::UNIFORM, 0, 256);
    // Holes: invalid (-1) and zero disparities, as matchers leave them.
    for (int i = 0; i < 60000; ++i) disparity.at<float>(rng.uniform(0, 480), rng.uniform(0, 640)) = i % 2 ? -1.f : 0.f;
    const double maxRange = 30000; // some small disparities fall beyond it
    const Cloud expected = referenceCloud(disparity, cal, left, maxRange);
    Cloud got;
    const size_t valid = CloudProjector(cal, maxRange).project(disparity, left, got);
    EXPECT_EQ(valid, static_cast<size_t>(cv::countNonZero(disparity > 0)));
    ASSERT_GT(expected.size(), 200000u);
    ASSERT_LT(expected.size(), valid); // the range test dropped some
    ASSERT_EQ(got.size(), expected.size());
    EXPECT_EQ(got.pixel, expected.pixel);
    EXPECT_EQ(got.rgb, expected.rgb);
    for (size_t i = 0; i < got.size(); ++i) {
        const cv::Vec3f e(&expected.xyz[3 * i]), g(&got.xyz[3 * i]);
        // Float rounding of the stored coordinates, relative to the point's distance.
        ASSERT_LE(cv::norm(g - e), 1e-6 * cv::norm(e)) << "pixel " << got.pixel[i] << ": " << g << " vs " << e;
    }
    EXPECT_EQ(got.frame, BINOCLE_FRAME_CAMERA);
    EXPECT_EQ(got.image_width, 640);
    // cloudFromDisparity is the same computation.
    const Cloud again = cloudFromDisparity(disparity, cal, left, maxRange);
    EXPECT_EQ(again.xyz, got.xyz);
}

TEST(CloudStage, GrayColoursAndReusedStorage) {
    const StereoCalibration cal = StereoCalibration::ideal(cv::Size(64, 48), 100, 100);
    cv::Mat disparity(48, 64, CV_32F, cv::Scalar(4)), gray(48, 64, CV_8U, cv::Scalar(77));
    CloudProjector projector(cal, 50000);
    Cloud cloud;
    projector.project(disparity, gray, cloud);
    ASSERT_EQ(cloud.size(), 64u * 48u);
    EXPECT_NEAR(cloud.xyz[2], 100.0 * 100.0 / 4.0, 1e-2); // Z = f B / d
    EXPECT_EQ(cloud.rgb[0], 77);
    const float *storage = cloud.xyz.data();
    disparity.colRange(0, 32).setTo(-1);
    projector.project(disparity, cv::Mat(), cloud);
    EXPECT_EQ(cloud.size(), 32u * 48u);
    EXPECT_TRUE(cloud.rgb.empty());
    EXPECT_EQ(cloud.xyz.data(), storage); // shrinking keeps the arrays
}

} // namespace
} // namespace binocle
