// SPDX-License-Identifier: MIT
// `binocle calibrate`: stereo calibration of one configuration of the head from
// chessboard pairs (a folder, the rig's source, or live), written as calib_B<mm>_f<mm>.yml
// with ROS camera_info files and a JSON report beside it.
#include "calibration/calibration_files.hpp"
#include "calibration/geometry_check.hpp"
#include "calibration/pair_folder.hpp"
#include "calibration/stereo_calibrator.hpp"
#include "calibration/still_board.hpp"
#include "cli/command.hpp"
#include "config/rig_config.hpp"
#include "core/error.hpp"
#include "core/progress.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <spdlog/spdlog.h>
#include <sstream>
#include <opencv2/imgcodecs.hpp>
#include <optional>

namespace fs = std::filesystem;

namespace binocle::cli {
namespace {

std::string fixed(double v, int decimals) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
    return buf;
}

std::string pad(std::string s, size_t width) {
    if (s.size() < width) s.append(width - s.size(), ' ');
    return s;
}

std::string baseName(const std::string &path) { return path.empty() ? "" : fs::path(path).filename().string(); }

// The report of the command, line by line, into the log at info level (plain lines).
void logLines(const std::string &text) {
    std::stringstream ss(text);
    for (std::string line; std::getline(ss, line);) spdlog::info("{}", line);
}

// One line per pair as it is screened.
void printScreened(const PairRecord &p) {
    std::ostringstream os;
    os << "  pair " << pad(p.id, 6);
    if (!p.rejection.empty()) {
        os << "rejected: " << p.rejection << "\n";
        return logLines(os.str());
    }
    os << "board found: " << fixed(std::min(p.left.area_percent, p.right.area_percent), 1) << " % of the image, edges "
              << fixed(std::max(p.left.edge_width_px, p.right.edge_width_px), 1) << " px\n";
    logLines(os.str());
}

void printSummary(const CalibrationResult &r, double squareMm, double pixelPitchUm) {
    std::ostringstream os;
    os << "\n  " << pad("pair", 8) << pad("left", 16) << pad("right", 16) << pad("error px", 10) << pad("left/right px", 15)
              << "status\n";
    for (const auto &p : r.pairs) {
        os << "  " << pad(p.id, 8) << pad(baseName(p.left_name), 16) << pad(baseName(p.right_name), 16);
        if (p.used)
            os << pad(fixed(p.errorPx(), 3), 10) << pad(fixed(p.error_left_px, 2) + "/" + fixed(p.error_right_px, 2), 15)
                      << "used\n";
        else
            os << pad(p.errorPx() >= 0 ? fixed(p.errorPx(), 3) : "-", 10) << pad("", 15) << "rejected: " << p.rejection
                      << "\n";
    }
    const StereoCalibration &c = r.calibration;
    os << "\n  overall RMS reprojection error " << fixed(r.rms_px, 3) << " px over " << r.usedPairs() << " of "
              << r.pairs.size() << " pairs (" << r.rounds << " calibration round" << (r.rounds > 1 ? "s" : "")
              << "; single-camera RMS left " << fixed(r.rms_left_px, 3) << ", right " << fixed(r.rms_right_px, 3) << " px)\n";
    os << "  baseline |T| " << fixed(c.baselineMm(), 2) << " mm, T = (" << fixed(c.T.at<double>(0), 2) << ", "
              << fixed(c.T.at<double>(1), 2) << ", " << fixed(c.T.at<double>(2), 2) << ") mm  (scales with --square-mm "
              << squareMm << ")\n";
    os << "  focal length left " << fixed(c.M1.at<double>(0, 0), 1) << " px, right " << fixed(c.M2.at<double>(0, 0), 1)
              << " px, rectified " << fixed(c.focalLengthPx(), 1) << " px";
    if (pixelPitchUm > 0)
        os << "  = " << fixed(c.M1.at<double>(0, 0) * pixelPitchUm / 1000, 2) << " / "
                  << fixed(c.M2.at<double>(0, 0) * pixelPitchUm / 1000, 2) << " / "
                  << fixed(c.focalLengthPx() * pixelPitchUm / 1000, 2) << " mm at " << pixelPitchUm << " um pixels";
    os << "\n";
    logLines(os.str());
}

// The left and right file names a source reports in its frame metadata (replay does).
std::pair<std::string, std::string> filesOf(const LentFrame &frame) {
    try {
        const YAML::Node n = YAML::Load(frame.metadata());
        if (n.IsMap() && n["left_file"] && n["right_file"])
            return {n["left_file"].as<std::string>(), n["right_file"].as<std::string>()};
    } catch (const YAML::Exception &) {
    }
    return {};
}

struct CalibrateArgs {
    RigArgs rig;
    std::string board, pairs, out;
    std::optional<double> square_mm, pixel_pitch_um;
    CalibrationOptions options;
    bool live = false;
    std::optional<long long> pairs_wanted;
    int64_t frames = -1;
    long long still_frames = 5;
    double still_px = 1.0;
};

// Pairs from a folder of left<N>/right<N> images, each screened as it is added.
void pairsFromFolder(StereoCalibrator &calibrator, const std::string &pairsDir, const CalibrationOptions &options,
                     const std::string &boardText) {
    const PairListing listing = listImagePairs(pairsDir);
    for (const auto &u : listing.unmatched) spdlog::info("  ignored {}", u);
    if (listing.pairs.empty())
        throw Error("--pairs " + pairsDir + ": no image pairs found (expected left<N>.png|jpg with right<N>.png|jpg, e.g. "
                    "left01.jpg and right01.jpg)");
    spdlog::info("binocle calibrate: {} board, {} mm squares, {} pair(s) in {}", boardText, options.board.square_mm,
                 listing.pairs.size(), pairsDir);
    for (const auto &pair : listing.pairs) {
        const cv::Mat l = cv::imread(pair.left, cv::IMREAD_GRAYSCALE), r = cv::imread(pair.right, cv::IMREAD_GRAYSCALE);
        const PairRecord &rec = l.empty() || r.empty()
                                    ? calibrator.addRejected(pair.id, "cannot read " + (l.empty() ? pair.left : pair.right) +
                                                                          " as an image", pair.left, pair.right)
                                    : calibrator.addPair(pair.id, l, r, pair.left, pair.right);
        printScreened(rec);
    }
}

// How pairs are taken from a source.
struct SourcePairs {
    bool live = false;           // only when the board has been still (StillBoard)
    long long wanted = -1;       // good pairs to stop at; < 0: every frame
    long long maxFrames = -1;    // frames to read at most; < 0: until the source ends
    long long stillFrames = 5;
    double stillPx = 1.0;
};

// Pairs from the rig's source: every frame, or (live) those where the board is still.
void pairsFromSource(StereoCalibrator &calibrator, const RigConfig &rig, const SourcePairs &how, const CalibrationOptions &options,
                     const std::string &boardText) {
    Source source(*rig.source().record, rig.source().params, rig.source().isolation);
    spdlog::info("binocle calibrate: {} board, {} mm squares, pairs from source '{}'{}", boardText, options.board.square_mm,
                 rig.source().plugin,
                 how.live ? " (live: a pair is taken when the board has been still for " + std::to_string(how.stillFrames) + " frames)"
                          : "");
    source.start();
    StillBoard still(static_cast<int>(how.stillFrames), how.stillPx, 20.0);
    // The frame count and the board's state; the screened pairs are logged above it.
    Progress progress(how.live, "frame", how.maxFrames);
    long long frames = 0;
    while ((how.maxFrames < 0 || frames < how.maxFrames) && (how.wanted < 0 || calibrator.goodPairs() < how.wanted)) {
        std::unique_ptr<LentFrame> frame = source.grab(5000);
        if (!frame) break;
        ++frames;
        const std::string id = std::to_string(frame->raw().sequence);
        const auto [leftFile, rightFile] = filesOf(*frame);
        if (!how.live) {
            printScreened(calibrator.addPair(id, frame->left(), frame->right(), leftFile, rightFile));
            continue;
        }
        BoardView l = findBoard(frame->left(), options.board, true), r = findBoard(frame->right(), options.board, true);
        if (still.update(l, r)) {
            const PairRecord &rec = calibrator.addViews(id, frame->left().size(), std::move(l), std::move(r), leftFile, rightFile);
            printScreened(rec);
        }
        progress.update(frames, std::to_string(calibrator.goodPairs()) + (how.wanted > 0 ? "/" + std::to_string(how.wanted) : "") +
                                    " good pairs, board " +
                                    (l.found || r.found ? "still for " + std::to_string(still.stillFrames()) + " frame(s)"
                                                        : "not in view"));
    }
    progress.finish();
    source.stop();
    if (calibrator.pairs().empty()) throw Error("source '" + rig.source().plugin + "' delivered no pair to calibrate with");
}

// Names the calibration after its configuration (what the rig states, else what was
// recovered), warns where the two disagree, and writes it with its companions.
void writeResult(CalibrationResult &result, const CalibrationOptions &options, const StatedGeometry &stated, double pixelPitchUm,
                 const std::string &out) {
    StereoCalibration &c = result.calibration;
    const double fx = c.M1.at<double>(0, 0);
    std::optional<double> focalMm = stated.focal_length_mm;
    if (!focalMm && pixelPitchUm > 0) focalMm = fx * pixelPitchUm / 1000.0;
    c.configuration = configurationName(stated.baseline_mm.value_or(c.baselineMm()), focalMm, fx);
    if (stated.baseline_mm && std::abs(c.baselineMm() - *stated.baseline_mm) > 0.05 * *stated.baseline_mm)
        spdlog::warn("recovered baseline {} mm but the rig says baseline_mm: {}; pipelines will refuse this calibration "
                     "(check --square-mm and the rig)",
                     fixed(c.baselineMm(), 1), *stated.baseline_mm);
    if (stated.focal_length_mm && pixelPitchUm > 0 &&
        std::abs(fx * pixelPitchUm / 1000.0 - *stated.focal_length_mm) > 0.05 * *stated.focal_length_mm)
        spdlog::warn("recovered focal length {} mm but the rig says focal_length_mm: {}", fixed(fx * pixelPitchUm / 1000.0, 2),
                     *stated.focal_length_mm);

    std::string path = out;
    const std::string fileName = "calib_" + c.configuration + ".yml";
    std::error_code ec;
    if (path.empty()) path = fileName;
    else if (path.back() == '/' || fs::is_directory(path, ec)) path = (fs::path(path) / fileName).string();
    const CalibrationFiles files = CalibrationFiles::beside(path);
    writeCalibrationFiles(files, c, calibrationReport(result, options, pixelPitchUm));
    spdlog::info("  wrote {} (configuration {}), {}, {}, {}", files.calibration, c.configuration, baseName(files.left_info),
                 baseName(files.right_info), baseName(files.report));
    std::cout << files.calibration << "\n";
}

int calibrate(const CalibrateArgs &args, const CLI::App &app) {
    // Every input is checked before anything is read or written.
    const bool pairsGiven = app.count("--pairs") > 0;
    CalibrationOptions options = args.options;
    try {
        options.board = BoardSpec::parse(args.board, *args.square_mm);
    } catch (const Error &e) {
        throw UsageError(e.what());
    }
    if (!(options.max_pair_error_px > 0)) throw UsageError("--max-pair-error-px: expected a value > 0");
    if (args.live && pairsGiven) throw UsageError("--pairs and --live exclude each other: pairs come from a folder or from the rig's source");
    if (pairsGiven && args.pairs.empty()) throw UsageError("--pairs: expected a folder");
    if (args.rig.file.empty() && !pairsGiven)
        throw UsageError("expected a rig file (its source delivers the pairs) or --pairs DIR");
    SourcePairs how;
    how.live = args.live;
    how.wanted = args.pairs_wanted.value_or(args.live ? 12 : -1);
    how.maxFrames = args.frames;
    how.stillFrames = args.still_frames;
    how.stillPx = args.still_px;
    if (args.pairs_wanted && how.wanted < options.min_pairs)
        throw UsageError("--pairs-wanted " + std::to_string(how.wanted) + ": expected at least --min-pairs (" +
                         std::to_string(options.min_pairs) + ")");

    std::optional<RigConfig> rig;
    std::optional<PluginHost> host;
    StatedGeometry stated;
    if (!args.rig.file.empty()) {
        host.emplace();
        // No scan: the rig opens only the plugins it names.
        rig = loadRig(args.rig, *host);
        stated = statedGeometry(rig->source());
    } else if (!args.rig.overrides.empty()) {
        throw UsageError("--set changes a rig, but no rig file was given");
    }
    const double pixelPitchUm = args.pixel_pitch_um.value_or(stated.pixel_pitch_um.value_or(0));
    if (app.count("--out") && args.out.empty()) throw UsageError("--out: expected a file name");

    StereoCalibrator calibrator(options);
    const std::string boardText = std::to_string(options.board.cols) + "x" + std::to_string(options.board.rows);
    if (pairsGiven) pairsFromFolder(calibrator, args.pairs, options, boardText);
    else pairsFromSource(calibrator, *rig, how, options, boardText);

    CalibrationResult result = calibrator.calibrate();
    printSummary(result, options.board.square_mm, pixelPitchUm);
    writeResult(result, options, stated, pixelPitchUm, args.out);
    return 0;
}

Register calibrateCommand{{"calibrate", "stereo calibration from chessboard pairs: calib_B<mm>_f<mm>.yml per configuration",
              "Calibrates one configuration of the head (baseline, lenses) from chessboard pairs:\n"
              "finds the board with sub-pixel corners in each pair, rejects poor pairs and says why\n"
              "(board not found, too small, blurred, corner order flipped between left and right),\n"
              "calibrates each camera, then the pair, drops pairs whose reprojection error stands\n"
              "out and calibrates again. Reports the reprojection error per pair and overall, the\n"
              "baseline |T| and the focal lengths, and writes:\n"
              "  calib_B<baseline mm>_f<focal mm>.yml   the calibration (OpenCV FileStorage YAML, mm)\n"
              "  calib_..._left.yaml, calib_..._right.yaml   ROS camera_info of each camera\n"
              "  calib_..._report.json                  per-pair errors, RMS, baseline, focal lengths,\n"
              "                                         rejected pairs with reasons\n"
              "B and f are the rig's baseline_mm / focal_length_mm when its source states them,\n"
              "else the recovered ones (f in px, 'f532px', when the pixel pitch is unknown).\n\n"
              "Where the pairs come from:\n"
              "  --pairs DIR         left<N>.png|jpg and right<N>.* matched by N (left01.jpg, right01.jpg)\n"
              "  (default)           every frame of the rig's source (replay of files, sim's calibration_board)\n"
              "  --live              the rig's source, a pair taken when the board has been still for\n"
              "                      --still-frames frames (corners moved < --still-px) and has moved\n"
              "                      since the last pair; good pairs counted on stderr",
              define<CalibrateArgs>(
                  [](CLI::App &app, CalibrateArgs &a) {
                      addRigArgs(app, a.rig, false);
                      app.add_option("--board", a.board, "inner corners per row and per column, e.g. 9x6")->type_name("COLSxROWS")->required();
                      app.add_option("--square-mm", a.square_mm, "side of one square in mm (the baseline scales with it)")
                          ->type_name("S")
                          ->required()
                          ->check(decimalNumber());
                      app.add_option("--pairs", a.pairs, "image pairs left<N>.png|jpg and right<N>.* in this folder")->type_name("DIR");
                      app.add_flag("--live", a.live, "pairs from the rig's source, taken when the board is still");
                      app.add_option("--out", a.out, "the calibration file (default: calib_<configuration>.yml here); an existing folder: that file in it")
                          ->type_name("FILE");
                      addNumber(app, "--pairs-wanted", a.pairs_wanted, "stop after N good pairs (default 12 with --live, else all frames)", "N", wholeNumber());
                      addFramesOption(app, a.frames, "read at most N frames from the source");
                      addNumber(app, "--still-frames", a.still_frames, "live: frames the board must be still (default 5)", "N", atLeast(2));
                      addNumber(app, "--still-px", a.still_px, "live: largest corner motion of a still board (default 1)", "PX", positiveNumber());
                      addNumber(app, "--pixel-pitch-um", a.pixel_pitch_um,
                                "pixel pitch, for focal lengths in mm (default: the rig's pixel_pitch_um)", "UM", positiveNumber());
                      addNumber(app, "--min-board-percent", a.options.min_board_area_percent,
                                     "reject boards covering less of the image (default 1.5)", "A", decimalNumber());
                      addNumber(app, "--max-edge-width-px", a.options.max_edge_width_px,
                                "reject blurred boards, edges wider than W px (default 4)", "W", decimalNumber());
                      addNumber(app, "--max-pair-error-px", a.options.max_pair_error_px,
                                     "drop pairs with a larger reprojection error and recalibrate (default 1)", "E", decimalNumber());
                      addNumber(app, "--min-pairs", a.options.min_pairs, "fewest good pairs to calibrate with (default 4)", "N", atLeast(3));
                      app.add_flag("--fix-intrinsic", a.options.fix_intrinsic, "keep each camera's own calibration in the stereo step");
                      app.add_flag("--fix-k3", a.options.fix_k3, "distortion k1, k2, p1, p2 only");
                  },
                  calibrate)}};

} // namespace
} // namespace binocle::cli
