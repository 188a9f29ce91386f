// SPDX-License-Identifier: MIT
// Stereo calibration file: read, write, rectify.
#include "core/calibration.hpp"

#include "core/error.hpp"
#include "files/atomic_file.hpp"
#include "input/image_file.hpp"
#include "input/integer_range.hpp"
#include "input/yaml_file.hpp"

#include <binocle/numbers.hpp>
#include <binocle/text.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <tuple>
#include <opencv2/calib3d.hpp>
#include <sstream>

namespace binocle {

double StereoCalibration::baselineMm() const {
    // hypot, not cv::norm: |T| of T = (-1e308, 0, 0) is 1e308, not inf.
    if (T.total() != 3 || T.depth() != CV_64F) return T.empty() ? 0.0 : cv::norm(T);
    const double *t = T.ptr<double>();
    return std::hypot(std::hypot(t[0], t[1]), t[2]);
}

double StereoCalibration::focalLengthPx() const {
    if (!P1.empty()) return P1.at<double>(0, 0);
    return M1.empty() ? 0.0 : M1.at<double>(0, 0);
}

void StereoCalibration::computeRectification() {
    if (rectified) {
        // Already rectified: rows correspond; the reprojection matrix comes from M1 and
        // the baseline. A horizontal offset of the principal points (Middlebury's doffs)
        // is kept in Q(3,3).
        R1 = cv::Mat::eye(3, 3, CV_64F);
        R2 = cv::Mat::eye(3, 3, CV_64F);
        P1 = cv::Mat::zeros(3, 4, CV_64F);
        M1.copyTo(P1(cv::Rect(0, 0, 3, 3)));
        P2 = cv::Mat::zeros(3, 4, CV_64F);
        M2.copyTo(P2(cv::Rect(0, 0, 3, 3)));
        const double tx = T.at<double>(0);
        P2.at<double>(0, 3) = tx * M2.at<double>(0, 0);
        const double f = M1.at<double>(0, 0), cx = M1.at<double>(0, 2), cy = M1.at<double>(1, 2);
        const double cx2 = M2.at<double>(0, 2);
        Q = (cv::Mat_<double>(4, 4) << 1, 0, 0, -cx, 0, 1, 0, -cy, 0, 0, 0, f, 0, 0, -1.0 / tx, (cx - cx2) / tx);
        return;
    }
    cv::stereoRectify(M1, D1, M2, D2, image_size, R, T, R1, R2, P1, P2, Q, cv::CALIB_ZERO_DISPARITY, 0, image_size);
}


namespace {

// What validate() accepts beyond finiteness (calibration.hpp): a focal length of 0.01
// (a field of view far beyond 180 degrees) to 1000 (0.06 degrees) times the image's larger
// side; a baseline of 0.1 mm (below any stereo rig: a unit mistake or garbage) to
// kMaxBaselineMm; a principal point within one image size of the image.
constexpr double kFocalPerSide[2] = {0.01, 1000};
constexpr double kMinBaselineMm = 0.1;

std::string number(double v) {
    if (std::isnan(v)) return "nan"; // not "-nan": the sign of a NaN means nothing here
    std::ostringstream s;
    s << v;
    return s.str();
}

// A calibration's text is read with the strict YAML loader and these readers, not with
// OpenCV's FileStorage: FileStorage trusts its input, and on some mangled files (well-formed
// YAML included) it never returns; found by fuzzing, tests/data/bad_calibration/. Numbers
// go through the one strict reader (sdk::parseDecimalReal), sizes are checked before anything
// is allocated, and the messages say where ("file:line:column").

// One value of a calibration as a real number; .nan and .inf are read (and refused where
// they matter, with the key and the position in the matrix).
double readReal(const YAML::Node &n, const std::string &what, const std::string &origin) {
    double v = 0;
    std::string why;
    if (!n.IsScalar() || !sdk::parseDecimalReal(n.Scalar(), v, &why, true))
        throw Error(input::located(n, origin) + ": calibration key " + what +
                    (n.IsScalar() ? " = '" + sdk::printable(n.Scalar(), 40) + "': " + why : ": expected a number"));
    return v;
}

// image_width / image_height: whole, positive, within the image limits; read as real
// numbers first so that 1e300 or 640.5 are refused instead of cast.
int imageSide(const YAML::Node &root, const char *key, const std::string &origin) {
    const YAML::Node n = root[key];
    if (!n) throw Error(origin + ": calibration key '" + key + "' is missing (expected the image size in pixels)");
    const double v = readReal(n, std::string("'") + key + "'", origin);
    if (!(v >= 1 && v <= static_cast<double>(input::kMaxImageSide)) || v != std::floor(v))
        throw Error(origin + ": calibration key '" + key + "' = " + number(v) + ": expected a whole number of pixels 1.." +
                    std::to_string(input::kMaxImageSide));
    return static_cast<int>(v);
}

// An OpenCV matrix as FileStorage writes it: !!opencv-matrix {rows, cols, dt, data}. At
// most 16 values; the declared size is checked before anything is read or allocated.
cv::Mat readMatrix(const YAML::Node &root, const char *key, int rows, int cols, const std::string &origin,
                   bool required = true) {
    const YAML::Node n = root[key];
    const std::string shape = rows > 0 ? std::to_string(rows) + "x" + std::to_string(cols) : std::string("at most 16 values");
    if (!n) {
        if (required) throw Error(origin + ": calibration key '" + key + "' is missing (expected a " + shape + " matrix)");
        return {};
    }
    const std::string name = std::string("'") + key + "'";
    const std::string notMatrix = origin + ": calibration key " + name + " is not a small OpenCV matrix (expected !!opencv-matrix with " + shape + ")";
    if (!n.IsMap()) throw Error(notMatrix);
    if (const auto unknown = input::findUnknownKey(n, {"rows", "cols", "dt", "data"}))
        throw Error(input::located(unknown->key, origin) + ": calibration key " + name + ": " + unknown->message);
    int64_t size[2] = {0, 0};
    for (int i = 0; i < 2; ++i) {
        const YAML::Node d = n[i == 0 ? "rows" : "cols"];
        if (!d || !d.IsScalar() || !input::parseInteger(d.Scalar(), size[i], nullptr, 1, 16)) throw Error(notMatrix);
    }
    if (size[0] * size[1] > 16) throw Error(notMatrix);
    if (const YAML::Node dt = n["dt"]; dt && !(dt.IsScalar() && (dt.Scalar() == "d" || dt.Scalar() == "f")))
        throw Error(input::located(dt, origin) + ": calibration key " + name + ": dt '" +
                    sdk::printable(dt.IsScalar() ? dt.Scalar() : std::string("(not a scalar)"), 20) +
                    "': expected d (double) or f (float)");
    const YAML::Node data = n["data"];
    const auto total = static_cast<size_t>(size[0] * size[1]);
    if (!data || !data.IsSequence() || data.size() != total)
        throw Error(input::located(data ? data : n, origin) + ": calibration key " + name + ": expected 'data' to hold " +
                    std::to_string(total) + " numbers (rows x cols)" +
                    (data && data.IsSequence() ? ", it holds " + std::to_string(data.size()) : std::string()));
    cv::Mat m(static_cast<int>(size[0]), static_cast<int>(size[1]), CV_64F);
    for (size_t i = 0; i < total; ++i) m.at<double>(static_cast<int>(i)) = readReal(data[i], name, origin);
    if (rows > 0 && cols > 0 && m.total() == static_cast<size_t>(rows * cols)) m = m.reshape(1, rows);
    if ((rows > 0 && m.rows != rows) || (cols > 0 && m.cols != cols))
        throw Error(origin + ": calibration key " + name + " is " + std::to_string(m.rows) + "x" + std::to_string(m.cols) +
                    ", expected " + std::to_string(rows) + "x" + std::to_string(cols));
    return m;
}

void requireFinite(const cv::Mat &m, const char *key, const std::string &origin) {
    for (int r = 0; r < m.rows; ++r)
        for (int c = 0; c < m.cols; ++c)
            if (!std::isfinite(m.at<double>(r, c)))
                throw Error(origin + ": calibration key '" + key + "' holds " + number(m.at<double>(r, c)) + " at (" +
                            std::to_string(r) + ", " + std::to_string(c) + "); expected finite numbers");
}

// A camera matrix [fx s cx; 0 fy cy; 0 0 1] with positive focal lengths that make sense
// for the image size (finite but absurd values, 1e-300 or 1e300, give clouds of inf, NaN
// or points all at the origin), and its principal point on or near the image.
void checkCameraMatrix(const cv::Mat &M, const char *key, cv::Size size, const std::string &origin) {
    requireFinite(M, key, origin);
    const double fx = M.at<double>(0, 0), fy = M.at<double>(1, 1);
    if (!(fx > 0) || !(fy > 0))
        throw Error(origin + ": calibration key '" + key + "': focal lengths fx = " + number(fx) + ", fy = " + number(fy) +
                    " px; expected both > 0");
    if (M.at<double>(1, 0) != 0 || M.at<double>(2, 0) != 0 || M.at<double>(2, 1) != 0 || M.at<double>(2, 2) != 1)
        throw Error(origin + ": calibration key '" + key + "': expected a camera matrix [fx 0 cx; 0 fy cy; 0 0 1]");
    const double side = std::max(size.width, size.height);
    const double lo = kFocalPerSide[0] * side, hi = kFocalPerSide[1] * side;
    for (const auto &[name, f] : {std::pair<const char *, double>{"fx", fx}, {"fy", fy}})
        if (f < lo || f > hi)
            throw Error(origin + ": calibration key '" + key + "': focal length " + name + " = " + number(f) +
                        " px; expected " + number(lo) + ".." + number(hi) + " px (" +
                        number(kFocalPerSide[0]) + " to " + number(kFocalPerSide[1]) +
                        " times the image's larger side, " + number(side) + " px)");
    const double skew = M.at<double>(0, 1);
    if (std::abs(skew) > hi)
        throw Error(origin + ": calibration key '" + key + "': skew = " + number(skew) + " px; expected at most " +
                    number(hi) + " in size");
    // The principal point: within one image size of the image (rectified pairs and
    // Middlebury's doffs move it, never by more than that).
    for (const auto &[name, v, n] : {std::tuple<const char *, double, int>{"cx", M.at<double>(0, 2), size.width},
                                     {"cy", M.at<double>(1, 2), size.height}})
        if (v < -n || v > 2.0 * n)
            throw Error(origin + ": calibration key '" + key + "': principal point " + name + " = " + number(v) +
                        " px; expected " + number(-n) + ".." + number(2.0 * n) + " px (on or near the " +
                        std::to_string(size.width) + "x" + std::to_string(size.height) + " image)");
}

// A calibration whose lens distortion cannot be undone (k1 = 1e6) gives rectified images
// that show next to nothing of the camera's (a few pixels at its centre, magnified, or
// nothing at all): a run would give 0 points and exit 0. Rays through a grid over each
// rectified image are taken back through R_i, M_i and D_i (what the rectification maps
// sample): at least half of them must land on the camera's image, spanning at least a
// quarter of its width and of its height.
void checkRectifiable(const StereoCalibration &c, const std::string &origin) {
    if (c.rectified) return;
    constexpr int kGrid = 9;
    const int w = c.image_size.width, h = c.image_size.height;
    for (int side = 0; side < 2; ++side) {
        const cv::Mat &M = side ? c.M2 : c.M1, &D = side ? c.D2 : c.D1, &Rs = side ? c.R2 : c.R1, &P = side ? c.P2 : c.P1;
        const cv::Matx33d back = cv::Matx33d(Rs).t();
        std::vector<cv::Point3d> rays;
        for (int j = 0; j < kGrid; ++j)
            for (int i = 0; i < kGrid; ++i) {
                const double x = ((i + 0.5) * w / kGrid - P.at<double>(0, 2)) / P.at<double>(0, 0);
                const double y = ((j + 0.5) * h / kGrid - P.at<double>(1, 2)) / P.at<double>(1, 1);
                rays.emplace_back(back * cv::Vec3d(x, y, 1));
            }
        std::vector<cv::Point2d> at;
        cv::projectPoints(rays, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), M, D, at);
        int inside = 0;
        double x0 = w, x1 = 0, y0 = h, y1 = 0;
        for (size_t k = 0; k < at.size(); ++k)
            if (rays[k].z > 0 && at[k].x >= 0 && at[k].x < w && at[k].y >= 0 && at[k].y < h) {
                ++inside;
                x0 = std::min(x0, at[k].x), x1 = std::max(x1, at[k].x), y0 = std::min(y0, at[k].y), y1 = std::max(y1, at[k].y);
            }
        // The samples span (kGrid - 1) / kGrid of the rectified image.
        const double full = (kGrid - 1.0) / kGrid;
        const double shownX = inside ? (x1 - x0) / (full * w) : 0, shownY = inside ? (y1 - y0) / (full * h) : 0;
        if (2 * inside >= kGrid * kGrid && shownX >= 0.25 && shownY >= 0.25) continue;
        std::ostringstream d;
        for (int k = 0; k < static_cast<int>(D.total()); ++k) d << (k ? ", " : "") << number(D.at<double>(k));
        const char *m = side ? "M2" : "M1", *dk = side ? "D2" : "D1";
        throw Error(origin + ": calibration keys '" + m + "' and '" + dk + "' (" + dk + " = [" + d.str() +
                    "]) cannot be rectified: the rectified " + (side ? "right" : "left") + " image would show " +
                    number(std::round(shownX * 1000) / 10) + " % of the width and " + number(std::round(shownY * 1000) / 10) +
                    " % of the height of the " + std::to_string(w) + "x" + std::to_string(h) + " camera image (" +
                    std::to_string(inside) + " of " + std::to_string(kGrid * kGrid) +
                    " sampled points on it); expected a lens distortion that can be undone (at least a quarter of each)");
    }
}

} // namespace

void StereoCalibration::validate(const std::string &origin) const {
    checkCameraMatrix(M1, "M1", image_size, origin);
    checkCameraMatrix(M2, "M2", image_size, origin);
    requireFinite(D1, "D1", origin);
    requireFinite(D2, "D2", origin);
    requireFinite(R, "R", origin);
    requireFinite(T, "T", origin);
    // R must be a rotation: orthonormal with determinant 1 (loosely: files are rounded).
    const cv::Mat err = R * R.t() - cv::Mat::eye(3, 3, CV_64F);
    if (cv::norm(err, cv::NORM_INF) > 1e-3 || std::abs(cv::determinant(R) - 1) > 1e-3)
        throw Error(origin + ": calibration key 'R' is not a rotation matrix (expected R R^T = I, det R = 1)");
    const double b = baselineMm();
    if (!(b >= kMinBaselineMm) || b > kMaxBaselineMm)
        throw Error(origin + ": calibration key 'T' gives a baseline of " + number(b) + " mm; expected " +
                    number(kMinBaselineMm) + ".." + number(kMaxBaselineMm) + " mm");
}

StereoCalibration StereoCalibration::fromYaml(const std::string &text, const std::string &originText) {
    std::string origin = originText;
    // OpenCV writes "%YAML:1.0" as its first line; that is not a YAML 1.2 directive, so it
    // is blanked (lines and columns stay) before the strict parse; the rest of its line is not.
    std::string yaml = text;
    if (yaml.rfind("%YAML:", 0) == 0)
        for (size_t i = 0; i < yaml.size() && (i < 6 || yaml[i] == '.' || std::isdigit(static_cast<unsigned char>(yaml[i]))); ++i)
            yaml[i] = ' ';
    YAML::Node root;
    try {
        root = input::parseYaml(yaml, origin);
    } catch (const input::YamlError &e) {
        throw Error(std::string(e.what()) + " (expected an OpenCV FileStorage YAML calibration)");
    }
    if (!root.IsMap())
        throw Error(origin + ": not a calibration: expected a map of keys (image_width, image_height, M1, D1, M2, D2, R, T)");
    // Where a published calibration came from (replay: the bag and its CameraInfo topics):
    // every message below names it.
    if (const YAML::Node from = root["source"]; from && from.IsScalar())
        origin += " (" + sdk::printable(from.Scalar(), 400) + ")";
    // The keys written by toYaml() (R1 ... Q, baseline_mm and focal_length_px are derived:
    // read again from M1 ... T, not from the file); any other key is a mistake.
    if (const auto unknown = input::findUnknownKey(root, {"image_width", "image_height", "configuration", "rectified", "M1", "D1",
                                                          "M2", "D2", "R", "T", "R1", "R2", "P1", "P2", "Q", "baseline_mm",
                                                          "focal_length_px", "rms_px", "source"},
                                                   "in a calibration"))
        throw Error(input::located(unknown->key, origin) + ": " + unknown->message);
    StereoCalibration c;
    try {
        const int w = imageSide(root, "image_width", origin), h = imageSide(root, "image_height", origin);
        c.image_size = cv::Size(w, h);
        c.M1 = readMatrix(root, "M1", 3, 3, origin);
        c.M2 = readMatrix(root, "M2", 3, 3, origin);
        c.D1 = readMatrix(root, "D1", 0, 0, origin, false);
        c.D2 = readMatrix(root, "D2", 0, 0, origin, false);
        if (c.D1.empty()) c.D1 = cv::Mat::zeros(1, 5, CV_64F);
        if (c.D2.empty()) c.D2 = cv::Mat::zeros(1, 5, CV_64F);
        c.D1 = c.D1.reshape(1, 1);
        c.D2 = c.D2.reshape(1, 1);
        for (const auto &[key, D] : {std::pair<const char *, const cv::Mat *>{"D1", &c.D1}, {"D2", &c.D2}})
            if (D->cols != 4 && D->cols != 5 && D->cols != 8 && D->cols != 12 && D->cols != 14)
                throw Error(origin + ": calibration key '" + key + "' holds " + std::to_string(D->cols) +
                            " coefficients; expected 4, 5, 8, 12 or 14 (OpenCV's distortion models)");
        c.R = readMatrix(root, "R", 3, 3, origin);
        c.T = readMatrix(root, "T", 3, 1, origin);
        if (const YAML::Node r = root["rectified"]) {
            if (!r.IsScalar() || (r.Scalar() != "0" && r.Scalar() != "1"))
                throw Error(input::located(r, origin) + ": calibration key 'rectified' must be 0 or 1");
            c.rectified = r.Scalar() == "1";
        }
        if (const YAML::Node r = root["rms_px"]) c.rms_px = readReal(r, "'rms_px'", origin);
        if (const YAML::Node n = root["configuration"]) {
            if (!n.IsScalar()) throw Error(input::located(n, origin) + ": calibration key 'configuration': expected a name");
            c.configuration = n.Scalar();
        }
        c.validate(origin);
        c.computeRectification();
        checkRectifiable(c, origin);
    } catch (const cv::Exception &e) {
        throw Error(origin + ": calibration cannot be used: " + e.err);
    }
    for (const auto &[key, m] : {std::pair<const char *, const cv::Mat *>{"P1", &c.P1}, {"P2", &c.P2}, {"Q", &c.Q}})
        requireFinite(*m, key, origin + " (after rectification)");
    return c;
}

StereoCalibration StereoCalibration::load(const std::string &path) {
    std::string text;
    try {
        text = readTextFile(path);
    } catch (const Error &e) {
        throw Error("calibration file " + path + ": " + e.what());
    }
    return fromYaml(text, path);
}

std::string StereoCalibration::toYaml() const {
    cv::FileStorage fs(".yml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
    fs << "image_width" << image_size.width << "image_height" << image_size.height;
    if (!configuration.empty()) fs << "configuration" << configuration;
    fs << "rectified" << (rectified ? 1 : 0);
    fs << "M1" << M1 << "D1" << D1 << "M2" << M2 << "D2" << D2 << "R" << R << "T" << T;
    if (!R1.empty()) fs << "R1" << R1 << "R2" << R2 << "P1" << P1 << "P2" << P2 << "Q" << Q;
    fs << "baseline_mm" << baselineMm() << "focal_length_px" << focalLengthPx();
    if (rms_px >= 0) fs << "rms_px" << rms_px;
    return fs.releaseAndGetString();
}

void StereoCalibration::save(const std::string &path) const { writeFileAtomic(path, toYaml()); }

std::string sizeText(cv::Size size) { return std::to_string(size.width) + "x" + std::to_string(size.height); }

StereoCalibration StereoCalibration::ideal(cv::Size size, double focal_length_px, double baseline_mm, double cx, double cy) {
    StereoCalibration c;
    c.image_size = size;
    if (cx < 0) cx = (size.width - 1) / 2.0;
    if (cy < 0) cy = (size.height - 1) / 2.0;
    c.M1 = (cv::Mat_<double>(3, 3) << focal_length_px, 0, cx, 0, focal_length_px, cy, 0, 0, 1);
    c.M2 = c.M1.clone();
    c.D1 = cv::Mat::zeros(1, 5, CV_64F);
    c.D2 = cv::Mat::zeros(1, 5, CV_64F);
    c.R = cv::Mat::eye(3, 3, CV_64F);
    c.T = (cv::Mat_<double>(3, 1) << -baseline_mm, 0, 0);
    c.rectified = true;
    c.computeRectification();
    return c;
}

} // namespace binocle
