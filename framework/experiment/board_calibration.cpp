// SPDX-License-Identifier: MIT
// Calibration per configuration: board pairs from the test's own source, calibrated
// with framework/calibration, compared with the calibration the source publishes.
#include "experiment/board_calibration.hpp"

#include "calibration/calibration_files.hpp"
#include "calibration/stereo_calibrator.hpp"
#include "config/rig_config.hpp"
#include "core/error.hpp"

#include <spdlog/spdlog.h>

#include <cmath>

namespace binocle {

namespace {

nlohmann::ordered_json number(double v) { return std::isfinite(v) ? nlohmann::ordered_json(v) : nlohmann::ordered_json(); }

} // namespace

nlohmann::ordered_json BoardCalibrationOutcome::toJson() const {
    return {{"file", file},
            {"pairs_offered", pairs_offered},
            {"pairs_used", pairs_used},
            {"rms_px", number(rms_px)},
            {"baseline_mm", number(baseline_mm)},
            {"true_baseline_mm", number(true_baseline_mm)},
            {"baseline_error_percent", number(baseline_error_percent)},
            {"focal_length_px", number(focal_length_px)},
            {"true_focal_length_px", number(true_focal_length_px)},
            {"focal_length_error_percent", number(focal_length_error_percent)}};
}

BoardCalibrationOutcome calibrateConfiguration(const YAML::Node &testRig, const std::string &rigFile,
                                               const BoardCalibrationSpec &spec, const PluginHost &host,
                                               const std::string &calibrationFile, double pixelPitchUm) {
    if (spec.pairs < 4) throw Error("board_calibration.pairs = " + std::to_string(spec.pairs) + ": expected at least 4 pairs");
    YAML::Node captureRig = YAML::Clone(testRig);
    captureRig.remove("calibration"); // the truth to compare with is the source's own
    for (const auto &[path, value] : spec.capture)
        applyOverride(captureRig, Override{path, value, "board_calibration.capture: " + path});
    const RigConfig rig = rigFromNode(captureRig, rigFile, host);
    Source source(*rig.source().record, rig.source().params, rig.source().isolation);

    BoardCalibrationOutcome out;
    out.file = calibrationFile;
    StereoCalibration truth;
    bool haveTruth = false;
    if (const std::string published = source.calibration(); !published.empty()) {
        truth = StereoCalibration::fromYaml(published, "calibration published by source '" + rig.source().plugin + "'");
        haveTruth = true;
    }

    CalibrationOptions options;
    options.board = spec.board;
    StereoCalibrator calibrator(options);
    source.start();
    const int maxFrames = spec.max_frames > 0 ? spec.max_frames : 3 * spec.pairs;
    int frames = 0;
    while (calibrator.goodPairs() < spec.pairs && frames < maxFrames) {
        std::unique_ptr<LentFrame> frame = source.grab(5000);
        if (!frame) break;
        const PairRecord &p = calibrator.addPair(std::to_string(frames), frame->left(), frame->right());
        if (!p.used) spdlog::debug("board calibration {}: pair {} refused: {}", calibrationFile, frames, p.rejection);
        ++frames;
    }
    source.stop();
    out.pairs_offered = frames;
    if (calibrator.goodPairs() < spec.pairs)
        throw Error(rigFile + ": board calibration: " + std::to_string(calibrator.goodPairs()) + " usable board pairs in " +
                    std::to_string(frames) + " frames, " + std::to_string(spec.pairs) +
                    " wanted (does board_calibration.capture make the source show a " + std::to_string(spec.board.cols) + "x" +
                    std::to_string(spec.board.rows) + " board, and enough poses?)");
    CalibrationResult result = calibrator.calibrate();
    out.pairs_used = result.usedPairs();
    out.rms_px = result.rms_px;
    out.baseline_mm = result.calibration.baselineMm();
    out.focal_length_px = result.calibration.focalLengthPx();
    if (haveTruth) {
        out.true_baseline_mm = truth.baselineMm();
        out.true_focal_length_px = truth.M1.at<double>(0, 0);
        out.baseline_error_percent = 100.0 * (out.baseline_mm - out.true_baseline_mm) / out.true_baseline_mm;
        // The lens's own focal length (M1), not the rectified one: the rectified focal
        // length depends on alpha and the distortion, the lens's does not.
        out.focal_length_error_percent =
            100.0 * (result.calibration.M1.at<double>(0, 0) - out.true_focal_length_px) / out.true_focal_length_px;
    }
    writeCalibrationFiles(CalibrationFiles::beside(calibrationFile), result.calibration,
                          calibrationReport(result, options, pixelPitchUm));
    return out;
}

} // namespace binocle
