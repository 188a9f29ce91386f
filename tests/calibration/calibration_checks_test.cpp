// SPDX-License-Identifier: MIT
// Calibrations checked at load: finite but absurd values (issue 24) are refused with the
// file, the key, the value and what was expected, before they make clouds of inf or NaN.
#include "core/calibration.hpp"
#include "core/error.hpp"

#include <gtest/gtest.h>

#include <functional>
#include <string>

using namespace binocle;

namespace {

// The message of the error that loading `c`, written and read again, gives ("" if none).
std::string loadError(const std::function<void(StereoCalibration &)> &change) {
    StereoCalibration c = StereoCalibration::ideal({640, 480}, 800, 120);
    change(c);
    c.R1.release(); // not written: derived values would be refused first
    try {
        StereoCalibration::fromYaml(c.toYaml(), "cal.yml");
    } catch (const Error &e) {
        return e.what();
    }
    return "";
}

TEST(CalibrationChecks, AbsurdFocalLengthsAreRefused) {
    EXPECT_EQ(loadError([](StereoCalibration &c) { c.M1.at<double>(0, 0) = 1e-300; }),
              "cal.yml: calibration key 'M1': focal length fx = 1e-300 px; expected 6.4..640000 px (0.01 to 1000 times "
              "the image's larger side, 640 px)");
    EXPECT_EQ(loadError([](StereoCalibration &c) { c.M2.at<double>(1, 1) = 1e300; }),
              "cal.yml: calibration key 'M2': focal length fy = 1e+300 px; expected 6.4..640000 px (0.01 to 1000 times "
              "the image's larger side, 640 px)");
}

TEST(CalibrationChecks, PrincipalPointMustBeOnOrNearTheImage) {
    EXPECT_EQ(loadError([](StereoCalibration &c) { c.M1.at<double>(0, 2) = 1e300; }),
              "cal.yml: calibration key 'M1': principal point cx = 1e+300 px; expected -640..1280 px (on or near the "
              "640x480 image)");
    EXPECT_EQ(loadError([](StereoCalibration &c) { c.M2.at<double>(1, 2) = -481; }),
              "cal.yml: calibration key 'M2': principal point cy = -481 px; expected -480..960 px (on or near the "
              "640x480 image)");
    // Off-centre but near: accepted (rectified pairs, Middlebury's doffs).
    EXPECT_EQ(loadError([](StereoCalibration &c) { c.M2.at<double>(0, 2) = 700; }), "");
}

TEST(CalibrationChecks, BaselineMustBeWithinAStereoRigsRange) {
    EXPECT_EQ(loadError([](StereoCalibration &c) { c.T.at<double>(0) = -1e-300; }),
              "cal.yml: calibration key 'T' gives a baseline of 1e-300 mm; expected 0.1..1e+06 mm");
    EXPECT_EQ(loadError([](StereoCalibration &c) { c.T.at<double>(0) = -2e6; }),
              "cal.yml: calibration key 'T' gives a baseline of 2e+06 mm; expected 0.1..1e+06 mm");
    EXPECT_EQ(loadError([](StereoCalibration &c) { c.T.at<double>(0) = -0.5; }), "");
}

TEST(CalibrationChecks, RotationMustBeOrthonormal) {
    EXPECT_EQ(loadError([](StereoCalibration &c) { c.R.at<double>(0, 0) = 2; }),
              "cal.yml: calibration key 'R' is not a rotation matrix (expected R R^T = I, det R = 1)");
}

TEST(CalibrationChecks, OrdinaryCalibrationsStillLoad) {
    EXPECT_EQ(loadError([](StereoCalibration &) {}), "");
    // A telephoto (f = 100 x side) and a wide lens (f = 0.2 x side).
    EXPECT_EQ(loadError([](StereoCalibration &c) { c.M1.at<double>(0, 0) = c.M1.at<double>(1, 1) = 64000; }), "");
    EXPECT_EQ(loadError([](StereoCalibration &c) { c.M2.at<double>(0, 0) = c.M2.at<double>(1, 1) = 128; }), "");
}

} // namespace
