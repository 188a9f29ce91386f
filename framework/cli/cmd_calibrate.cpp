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

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <optional>
#include <unistd.h>

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

// One line per pair as it is screened.
void printScreened(const PairRecord &p) {
    std::cerr << "  pair " << pad(p.id, 6);
    if (!p.rejection.empty()) {
        std::cerr << "rejected: " << p.rejection << "\n";
        return;
    }
    std::cerr << "board found: " << fixed(std::min(p.left.area_percent, p.right.area_percent), 1) << " % of the image, edges "
              << fixed(std::max(p.left.edge_width_px, p.right.edge_width_px), 1) << " px\n";
}

void printSummary(const CalibrationResult &r, double squareMm, double pixelPitchUm) {
    std::cerr << "\n  " << pad("pair", 8) << pad("left", 16) << pad("right", 16) << pad("error px", 10) << pad("left/right px", 15)
              << "status\n";
    for (const auto &p : r.pairs) {
        std::cerr << "  " << pad(p.id, 8) << pad(baseName(p.left_name), 16) << pad(baseName(p.right_name), 16);
        if (p.used)
            std::cerr << pad(fixed(p.errorPx(), 3), 10) << pad(fixed(p.error_left_px, 2) + "/" + fixed(p.error_right_px, 2), 15)
                      << "used\n";
        else
            std::cerr << pad(p.errorPx() >= 0 ? fixed(p.errorPx(), 3) : "-", 10) << pad("", 15) << "rejected: " << p.rejection
                      << "\n";
    }
    const StereoCalibration &c = r.calibration;
    std::cerr << "\n  overall RMS reprojection error " << fixed(r.rms_px, 3) << " px over " << r.usedPairs() << " of "
              << r.pairs.size() << " pairs (" << r.rounds << " calibration round" << (r.rounds > 1 ? "s" : "")
              << "; single-camera RMS left " << fixed(r.rms_left_px, 3) << ", right " << fixed(r.rms_right_px, 3) << " px)\n";
    std::cerr << "  baseline |T| " << fixed(c.baselineMm(), 2) << " mm, T = (" << fixed(c.T.at<double>(0), 2) << ", "
              << fixed(c.T.at<double>(1), 2) << ", " << fixed(c.T.at<double>(2), 2) << ") mm  (scales with --square-mm "
              << squareMm << ")\n";
    std::cerr << "  focal length left " << fixed(c.M1.at<double>(0, 0), 1) << " px, right " << fixed(c.M2.at<double>(0, 0), 1)
              << " px, rectified " << fixed(c.focalLengthPx(), 1) << " px";
    if (pixelPitchUm > 0)
        std::cerr << "  = " << fixed(c.M1.at<double>(0, 0) * pixelPitchUm / 1000, 2) << " / "
                  << fixed(c.M2.at<double>(0, 0) * pixelPitchUm / 1000, 2) << " / "
                  << fixed(c.focalLengthPx() * pixelPitchUm / 1000, 2) << " mm at " << pixelPitchUm << " um pixels";
    std::cerr << "\n";
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

int calibrate(const Args &args) {
    // Every input is checked before anything is read or written.
    if (args.positional().size() > 1) throw Error("expected at most one rig file: binocle calibrate [RIG.yaml] ... (see --help)");
    if (!args.has("--board")) throw Error("missing --board COLSxROWS: the chessboard's inner corners per row and column, e.g. 9x6");
    if (!args.has("--square-mm"))
        throw Error("missing --square-mm: the side of one chessboard square in mm (the recovered baseline scales with it)");
    CalibrationOptions options;
    options.board = BoardSpec::parse(args.get("--board"), args.real("--square-mm", 0));
    options.min_board_area_percent = args.real("--min-board-percent", options.min_board_area_percent);
    options.max_edge_width_px = args.real("--max-edge-width-px", options.max_edge_width_px);
    options.max_pair_error_px = args.real("--max-pair-error-px", options.max_pair_error_px);
    options.min_pairs = static_cast<int>(args.integer("--min-pairs", options.min_pairs));
    options.fix_intrinsic = args.has("--fix-intrinsic");
    options.fix_k3 = args.has("--fix-k3");
    if (options.min_pairs < 3) throw Error("--min-pairs " + std::to_string(options.min_pairs) + ": expected at least 3");
    if (!(options.max_pair_error_px > 0)) throw Error("--max-pair-error-px: expected a value > 0");
    const bool live = args.has("--live");
    const std::string pairsDir = args.get("--pairs");
    if (live && args.has("--pairs")) throw Error("--pairs and --live exclude each other: pairs come from a folder or from the rig's source");
    if (args.has("--pairs") && pairsDir.empty()) throw Error("--pairs: expected a folder");
    if (args.positional().empty() && !args.has("--pairs"))
        throw Error("expected a rig file (its source delivers the pairs) or --pairs DIR (see --help)");
    const long long wanted = args.integer("--pairs-wanted", live ? 12 : -1);
    const long long maxFrames = args.integer("--frames", -1);
    const long long stillFrames = args.integer("--still-frames", 5);
    const double stillPx = args.real("--still-px", 1.0);
    if (args.has("--pairs-wanted") && wanted < options.min_pairs)
        throw Error("--pairs-wanted " + std::to_string(wanted) + ": expected at least --min-pairs (" +
                    std::to_string(options.min_pairs) + ")");
    if (stillFrames < 2) throw Error("--still-frames " + std::to_string(stillFrames) + ": expected at least 2");

    std::optional<RigConfig> rig;
    std::optional<PluginHost> host;
    StatedGeometry stated;
    if (!args.positional().empty()) {
        host.emplace();
        // No scan: the rig opens only the plugins it names.
        rig = loadRigFromArgs(args, *host);
        stated = statedGeometry(rig->source);
    } else if (args.has("--set")) {
        throw Error("--set changes a rig, but no rig file was given");
    }
    const double pixelPitchUm = args.real("--pixel-pitch-um", stated.pixel_pitch_um.value_or(0));
    const std::string out = args.get("--out");
    if (args.has("--out") && out.empty()) throw Error("--out: expected a file name");

    StereoCalibrator calibrator(options);
    const std::string boardText = std::to_string(options.board.cols) + "x" + std::to_string(options.board.rows);
    if (args.has("--pairs")) {
        const PairListing listing = listImagePairs(pairsDir);
        for (const auto &u : listing.unmatched) std::cerr << "  ignored " << u << "\n";
        if (listing.pairs.empty())
            throw Error("--pairs " + pairsDir + ": no image pairs found (expected left<N>.png|jpg with right<N>.png|jpg, e.g. "
                        "left01.jpg and right01.jpg)");
        std::cerr << "binocle calibrate: " << boardText << " board, " << options.board.square_mm << " mm squares, "
                  << listing.pairs.size() << " pair(s) in " << pairsDir << "\n";
        for (const auto &pair : listing.pairs) {
            const cv::Mat l = cv::imread(pair.left, cv::IMREAD_GRAYSCALE), r = cv::imread(pair.right, cv::IMREAD_GRAYSCALE);
            const PairRecord &rec = l.empty() || r.empty()
                                        ? calibrator.addRejected(pair.id, "cannot read " + (l.empty() ? pair.left : pair.right) +
                                                                              " as an image", pair.left, pair.right)
                                        : calibrator.addPair(pair.id, l, r, pair.left, pair.right);
            printScreened(rec);
        }
    } else {
        Source source(*rig->source.record, rig->source.params);
        std::cerr << "binocle calibrate: " << boardText << " board, " << options.board.square_mm << " mm squares, pairs from source '"
                  << rig->source.plugin << "'"
                  << (live ? " (live: a pair is taken when the board has been still for " + std::to_string(stillFrames) + " frames)"
                           : "")
                  << "\n";
        source.start();
        StillBoard still(static_cast<int>(stillFrames), stillPx, 20.0);
        const bool tty = ::isatty(2) != 0;
        long long frames = 0;
        while ((maxFrames < 0 || frames < maxFrames) && (wanted < 0 || calibrator.goodPairs() < wanted)) {
            std::unique_ptr<LentFrame> frame = source.grab(5000);
            if (!frame) break;
            ++frames;
            const std::string id = std::to_string(frame->raw().sequence);
            const auto [leftFile, rightFile] = filesOf(*frame);
            if (!live) {
                printScreened(calibrator.addPair(id, frame->left(), frame->right(), leftFile, rightFile));
                continue;
            }
            BoardView l = findBoard(frame->left(), options.board, true), r = findBoard(frame->right(), options.board, true);
            if (still.update(l, r)) {
                const PairRecord &rec = calibrator.addViews(id, frame->left().size(), std::move(l), std::move(r), leftFile, rightFile);
                if (tty) std::cerr << "\r";
                printScreened(rec);
            }
            const std::string status = "frame " + std::to_string(frames) + ": " + std::to_string(calibrator.goodPairs()) +
                                       (wanted > 0 ? "/" + std::to_string(wanted) : "") + " good pairs, board " +
                                       (l.found || r.found ? "still for " + std::to_string(still.stillFrames()) + " frame(s)" : "not in view");
            if (tty) std::cerr << "\r" << pad(status, 70) << std::flush;
            else if (frames % 30 == 0) std::cerr << "  " << status << "\n";
        }
        if (tty && live) std::cerr << "\n";
        source.stop();
        if (calibrator.pairs().empty()) throw Error("source '" + rig->source.plugin + "' delivered no pair to calibrate with");
    }

    CalibrationResult result = calibrator.calibrate();
    StereoCalibration &c = result.calibration;
    printSummary(result, options.board.square_mm, pixelPitchUm);

    // Named after the configuration: what the rig states, else what was recovered.
    const double fx = c.M1.at<double>(0, 0);
    std::optional<double> focalMm = stated.focal_length_mm;
    if (!focalMm && pixelPitchUm > 0) focalMm = fx * pixelPitchUm / 1000.0;
    c.configuration = configurationName(stated.baseline_mm.value_or(c.baselineMm()), focalMm, fx);
    if (stated.baseline_mm && std::abs(c.baselineMm() - *stated.baseline_mm) > 0.05 * *stated.baseline_mm)
        std::cerr << "  warning: recovered baseline " << fixed(c.baselineMm(), 1) << " mm but the rig says baseline_mm: "
                  << *stated.baseline_mm << "; pipelines will refuse this calibration (check --square-mm and the rig)\n";
    if (stated.focal_length_mm && pixelPitchUm > 0 &&
        std::abs(fx * pixelPitchUm / 1000.0 - *stated.focal_length_mm) > 0.05 * *stated.focal_length_mm)
        std::cerr << "  warning: recovered focal length " << fixed(fx * pixelPitchUm / 1000.0, 2)
                  << " mm but the rig says focal_length_mm: " << *stated.focal_length_mm << "\n";

    std::string path = out;
    const std::string fileName = "calib_" + c.configuration + ".yml";
    std::error_code ec;
    if (path.empty()) path = fileName;
    else if (path.back() == '/' || fs::is_directory(path, ec)) path = (fs::path(path) / fileName).string();
    const CalibrationFiles files = CalibrationFiles::beside(path);
    writeCalibrationFiles(files, c, calibrationReport(result, options, pixelPitchUm));
    std::cerr << "  wrote " << files.calibration << " (configuration " << c.configuration << "), " << baseName(files.left_info)
              << ", " << baseName(files.right_info) << ", " << baseName(files.report) << "\n";
    std::cout << files.calibration << "\n";
    return 0;
}

Register reg({"calibrate", "stereo calibration from chessboard pairs: calib_B<mm>_f<mm>.yml per configuration",
              "usage: binocle calibrate [RIG.yaml] --board COLSxROWS --square-mm S [--pairs DIR | --live]\n"
              "                         [--out FILE] [--set KEY=VALUE]... [options]\n\n"
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
              "                      since the last pair; good pairs counted on stderr\n\n"
              "  --board COLSxROWS   inner corners per row and per column, e.g. 9x6 (required)\n"
              "  --square-mm S       side of one square in mm (required; the baseline scales with it)\n"
              "  --out FILE          the calibration file (default: calib_<configuration>.yml here);\n"
              "                      an existing folder: that file in it\n"
              "  --pairs-wanted N    stop after N good pairs (default 12 with --live, else all frames)\n"
              "  --frames N          read at most N frames from the source\n"
              "  --still-frames N    live: frames the board must be still (default 5)\n"
              "  --still-px P        live: largest corner motion of a still board (default 1)\n"
              "  --pixel-pitch-um P  pixel pitch, for focal lengths in mm (default: the rig's pixel_pitch_um)\n"
              "  --min-board-percent A  reject boards covering less of the image (default 1.5)\n"
              "  --max-edge-width-px W  reject blurred boards, edges wider than W px (default 4)\n"
              "  --max-pair-error-px E  drop pairs with a larger reprojection error and recalibrate (default 1)\n"
              "  --min-pairs N       fewest good pairs to calibrate with (default 4)\n"
              "  --fix-intrinsic     keep each camera's own calibration in the stereo step\n"
              "  --fix-k3            distortion k1, k2, p1, p2 only\n"
              "  --set KEY=VALUE     override a value of the rig, e.g. --set source.baseline_mm=190\n",
              {"--live", "--fix-intrinsic", "--fix-k3"},
              calibrate});

} // namespace
} // namespace binocle::cli
