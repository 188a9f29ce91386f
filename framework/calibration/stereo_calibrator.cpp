// SPDX-License-Identifier: MIT
// Stereo calibration from chessboard pairs: screening, calibration, outlier rounds, report.
#include "calibration/stereo_calibrator.hpp"

#include "core/error.hpp"

#include <opencv2/calib3d.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

namespace binocle {

namespace {

std::string fixed(double v, int decimals) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
    return buf;
}

// The direction from the first corner to the last of the first row, and down the first
// column: the detector may start from the opposite end in the other image.
bool sameOrder(const std::vector<cv::Point2f> &l, const std::vector<cv::Point2f> &r, const BoardSpec &b) {
    const size_t rowEnd = static_cast<size_t>(b.cols - 1), colEnd = static_cast<size_t>((b.rows - 1) * b.cols);
    const cv::Point2f lRow = l[rowEnd] - l[0], rRow = r[rowEnd] - r[0];
    const cv::Point2f lCol = l[colEnd] - l[0], rCol = r[colEnd] - r[0];
    return lRow.dot(rRow) > 0 && lCol.dot(rCol) > 0;
}

} // namespace

double PairRecord::errorPx() const {
    if (error_left_px < 0 || error_right_px < 0) return -1;
    return std::sqrt((error_left_px * error_left_px + error_right_px * error_right_px) / 2.0);
}

int CalibrationResult::usedPairs() const {
    int n = 0;
    for (const auto &p : pairs) n += p.used ? 1 : 0;
    return n;
}

StereoCalibrator::StereoCalibrator(CalibrationOptions options) : options_(std::move(options)) {}

int StereoCalibrator::goodPairs() const {
    int n = 0;
    for (const auto &p : pairs_) n += p.used ? 1 : 0;
    return n;
}

const PairRecord &StereoCalibrator::addRejected(const std::string &id, const std::string &reason, const std::string &leftName,
                                                const std::string &rightName) {
    PairRecord p;
    p.id = id;
    p.left_name = leftName;
    p.right_name = rightName;
    p.rejection = reason;
    pairs_.push_back(std::move(p));
    return pairs_.back();
}

const PairRecord &StereoCalibrator::addPair(const std::string &id, const cv::Mat &left, const cv::Mat &right,
                                            const std::string &leftName, const std::string &rightName) {
    if (left.size() != right.size())
        return addRejected(id, "left image is " + sizeText(left.size()) + " but right image is " + sizeText(right.size()),
                           leftName, rightName);
    if (!imageSize_.empty() && left.size() != imageSize_)
        return addRejected(id, "images are " + sizeText(left.size()) + ", the first pair's were " + sizeText(imageSize_),
                           leftName, rightName);
    return addViews(id, left.size(), findBoard(left, options_.board), findBoard(right, options_.board), leftName, rightName);
}

const PairRecord &StereoCalibrator::addViews(const std::string &id, cv::Size imageSize, BoardView left, BoardView right,
                                             const std::string &leftName, const std::string &rightName) {
    if (!imageSize_.empty() && imageSize != imageSize_)
        return addRejected(id, "images are " + sizeText(imageSize) + ", the first pair's were " + sizeText(imageSize_),
                           leftName, rightName);
    if (imageSize_.empty()) imageSize_ = imageSize;
    PairRecord p;
    p.id = id;
    p.left_name = leftName;
    p.right_name = rightName;
    p.left = std::move(left);
    p.right = std::move(right);
    const CalibrationOptions &o = options_;
    const std::string board = std::to_string(o.board.cols) + "x" + std::to_string(o.board.rows) + " board";
    if (!p.left.found && !p.right.found) {
        p.rejection = board + " not found in either image";
    } else if (!p.left.found) {
        p.rejection = board + " not found in the left image";
    } else if (!p.right.found) {
        p.rejection = board + " not found in the right image";
    } else if (std::min(p.left.area_percent, p.right.area_percent) < o.min_board_area_percent) {
        const bool l = p.left.area_percent <= p.right.area_percent;
        p.rejection = "board too small in the image: it covers " + fixed(l ? p.left.area_percent : p.right.area_percent, 1) +
                      " % of the " + (l ? "left" : "right") + " image (at least " + fixed(o.min_board_area_percent, 1) +
                      " % wanted)";
    } else if (std::max(p.left.edge_width_px, p.right.edge_width_px) > o.max_edge_width_px) {
        const bool l = p.left.edge_width_px >= p.right.edge_width_px;
        p.rejection = std::string("blurred: the board's edges are ") + fixed(l ? p.left.edge_width_px : p.right.edge_width_px, 1) +
                      " px wide in the " + (l ? "left" : "right") + " image (at most " + fixed(o.max_edge_width_px, 1) +
                      " px wanted)";
    } else if (!sameOrder(p.left.corners, p.right.corners, o.board)) {
        p.rejection = "corner ordering flipped between left and right (the detector started from opposite ends of the board)";
    } else {
        p.used = true;
    }
    pairs_.push_back(std::move(p));
    return pairs_.back();
}

CalibrationResult StereoCalibrator::calibrate() const {
    CalibrationResult result;
    result.pairs = pairs_;
    const CalibrationOptions &o = options_;
    const std::vector<cv::Point3f> board = o.board.objectPoints();
    const int minPairs = std::max(o.min_pairs, 3);

    auto tooFew = [&](int usable) {
        std::map<std::string, int> reasons;
        for (const auto &p : result.pairs)
            if (!p.used) ++reasons[p.rejection.substr(0, p.rejection.find(':'))];
        std::string why;
        for (const auto &[reason, n] : reasons) why += (why.empty() ? "" : "; ") + std::to_string(n) + "x " + reason;
        return Error("only " + std::to_string(usable) + " usable pair(s) out of " + std::to_string(result.pairs.size()) +
                     ", at least " + std::to_string(minPairs) + " needed" + (why.empty() ? "" : " (rejected: " + why + ")"));
    };

    const cv::TermCriteria criteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 200, 1e-9);
    int monoFlags = o.fix_k3 ? cv::CALIB_FIX_K3 : 0;
    for (;;) {
        std::vector<size_t> used;
        for (size_t i = 0; i < result.pairs.size(); ++i)
            if (result.pairs[i].used) used.push_back(i);
        if (static_cast<int>(used.size()) < minPairs) throw tooFew(static_cast<int>(used.size()));

        std::vector<std::vector<cv::Point3f>> object(used.size(), board);
        std::vector<std::vector<cv::Point2f>> left, right;
        for (size_t i : used) {
            left.push_back(result.pairs[i].left.corners);
            right.push_back(result.pairs[i].right.corners);
        }
        cv::Mat M1, D1, M2, D2, R, T, E, F, perView;
        std::vector<cv::Mat> rvecs, tvecs;
        result.rms_left_px = cv::calibrateCamera(object, left, imageSize_, M1, D1, rvecs, tvecs, monoFlags, criteria);
        result.rms_right_px = cv::calibrateCamera(object, right, imageSize_, M2, D2, rvecs, tvecs, monoFlags, criteria);
        const int stereoFlags = (o.fix_intrinsic ? cv::CALIB_FIX_INTRINSIC : cv::CALIB_USE_INTRINSIC_GUESS) | monoFlags;
        result.rms_px = cv::stereoCalibrate(object, left, right, M1, D1, M2, D2, imageSize_, R, T, E, F, perView, stereoFlags,
                                            criteria);
        ++result.rounds;
        size_t worst = used.front();
        for (size_t k = 0; k < used.size(); ++k) {
            PairRecord &p = result.pairs[used[k]];
            p.error_left_px = perView.at<double>(static_cast<int>(k), 0);
            p.error_right_px = perView.at<double>(static_cast<int>(k), 1);
            if (p.errorPx() > result.pairs[worst].errorPx()) worst = used[k];
        }
        PairRecord &w = result.pairs[worst];
        if (w.errorPx() <= o.max_pair_error_px) {
            StereoCalibration &c = result.calibration;
            c.image_size = imageSize_;
            M1.convertTo(c.M1, CV_64F);
            M2.convertTo(c.M2, CV_64F);
            D1.convertTo(c.D1, CV_64F);
            D2.convertTo(c.D2, CV_64F);
            c.D1 = c.D1.reshape(1, 1);
            c.D2 = c.D2.reshape(1, 1);
            R.convertTo(c.R, CV_64F);
            T.convertTo(c.T, CV_64F);
            c.T = c.T.reshape(1, 3);
            c.rectified = false;
            c.rms_px = result.rms_px;
            c.computeRectification();
            return result;
        }
        // The worst pair goes, one at a time: a bad pair inflates the others' errors too.
        w.used = false;
        w.rejection = "reprojection error " + fixed(w.errorPx(), 2) + " px after calibration round " +
                      std::to_string(result.rounds) + " (at most " + fixed(o.max_pair_error_px, 2) +
                      " px wanted): dropped and recalibrated";
    }
}

Json calibrationReport(const CalibrationResult &r, const CalibrationOptions &o, double pixelPitchUm) {
    const StereoCalibration &c = r.calibration;
    Json report = Json::object();
    report["configuration"] = c.configuration;
    report["units"] = {{"length", "mm"}, {"error", "px (RMS reprojection error)"}};
    report["board"] = {{"cols", o.board.cols}, {"rows", o.board.rows}, {"square_mm", o.board.square_mm}};
    report["image_width"] = c.image_size.width;
    report["image_height"] = c.image_size.height;
    report["pairs_offered"] = r.pairs.size();
    report["pairs_used"] = r.usedPairs();
    report["rounds"] = r.rounds;
    report["rms_px"] = r.rms_px;
    report["rms_left_px"] = r.rms_left_px;
    report["rms_right_px"] = r.rms_right_px;
    report["baseline_mm"] = c.baselineMm();
    report["T_mm"] = {c.T.at<double>(0), c.T.at<double>(1), c.T.at<double>(2)};
    report["focal_length_px"] = {{"left_fx", c.M1.at<double>(0, 0)},  {"left_fy", c.M1.at<double>(1, 1)},
                                 {"right_fx", c.M2.at<double>(0, 0)}, {"right_fy", c.M2.at<double>(1, 1)},
                                 {"rectified", c.focalLengthPx()}};
    if (pixelPitchUm > 0) {
        const double mmPerPx = pixelPitchUm / 1000.0;
        report["pixel_pitch_um"] = pixelPitchUm;
        report["focal_length_mm"] = {{"left", c.M1.at<double>(0, 0) * mmPerPx},
                                     {"right", c.M2.at<double>(0, 0) * mmPerPx},
                                     {"rectified", c.focalLengthPx() * mmPerPx}};
    }
    Json used = Json::array(), rejected = Json::array();
    for (const auto &p : r.pairs) {
        Json j = {{"id", p.id}};
        if (!p.left_name.empty()) j["left"] = p.left_name;
        if (!p.right_name.empty()) j["right"] = p.right_name;
        if (p.used) {
            j["error_px"] = p.errorPx();
            j["error_left_px"] = p.error_left_px;
            j["error_right_px"] = p.error_right_px;
            j["board_area_percent"] = std::min(p.left.area_percent, p.right.area_percent);
            j["edge_width_px"] = std::max(p.left.edge_width_px, p.right.edge_width_px);
            used.push_back(std::move(j));
        } else {
            j["reason"] = p.rejection;
            if (p.errorPx() >= 0) j["error_px"] = p.errorPx();
            rejected.push_back(std::move(j));
        }
    }
    report["pairs"] = std::move(used);
    report["rejected"] = std::move(rejected);
    return report;
}

} // namespace binocle
