// SPDX-License-Identifier: MIT
// Frame products for the viewer: deep copy, density views, colour scale, the binary
// message the page reads, and snapshots on disk.
#include "viewer/frame_snapshot.hpp"

#include "files/atomic_file.hpp"
#include "core/error.hpp"
#include "core/image_io.hpp"
#include "method/density_render.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

namespace fs = std::filesystem;

namespace binocle::viewer {

namespace {

using OJson = nlohmann::ordered_json;

std::string sequenceStem(uint64_t sequence) {
    char stem[32];
    std::snprintf(stem, sizeof stem, "%06llu", static_cast<unsigned long long>(sequence));
    return stem;
}

// A number for JSON: NaN and infinities have no JSON form; they become null.
OJson number(double v) { return std::isfinite(v) ? OJson(v) : OJson(nullptr); }

std::vector<method::ViewOverlay> overlaysOf(const OJson &metrics, const char *view) {
    std::vector<method::ViewOverlay> out;
    for (const auto &[evaluator, figures] : metrics.items()) {
        if (!figures.is_object() || !figures.contains("view_overlays") || !figures["view_overlays"].is_string()) continue;
        const OJson parsed = OJson::parse(figures["view_overlays"].get<std::string>(), nullptr, false);
        if (parsed.is_discarded() || !parsed.contains(view) || !parsed[view].is_array()) continue;
        for (const auto &o : parsed[view]) {
            if (!o.contains("u_mm") || !o.contains("v_mm")) continue;
            method::ViewOverlay v;
            v.u = {o["u_mm"][0].get<double>(), o["u_mm"][1].get<double>()};
            v.v = {o["v_mm"][0].get<double>(), o["v_mm"][1].get<double>()};
            v.label = o.value("label", std::string());
            if (o.contains("bgr") && o["bgr"].size() == 3) v.color = cv::Scalar(o["bgr"][0], o["bgr"][1], o["bgr"][2]);
            // The cells a reading took (the paper evaluator's panel), outlined.
            if (o.contains("cells_mm") && o["cells_mm"].is_array() && o.contains("cell_mm") && o["cell_mm"].is_number()) {
                v.cell_mm = o["cell_mm"].get<double>();
                for (const auto &c : o["cells_mm"])
                    if (c.is_array() && c.size() == 2 && c[0].is_number() && c[1].is_number())
                        v.cells.push_back({c[0].get<float>(), c[1].get<float>()});
            }
            out.push_back(v);
        }
    }
    return out;
}

std::string encodeImage(const char *ext, const cv::Mat &image, const std::vector<int> &params) {
    std::vector<uchar> bytes;
    cv::imencode(ext, image, bytes, params);
    return std::string(bytes.begin(), bytes.end());
}

} // namespace

FrameProducts copyFrame(const FrameResult &r) {
    FrameProducts p;
    p.result.sequence = r.sequence;
    p.result.rectified_left = r.rectified_left.clone();
    p.result.rectified_right = r.rectified_right.clone();
    p.result.disparity = r.disparity.clone();
    p.result.valid_pixel_ratio = r.valid_pixel_ratio;
    p.result.cloud = r.cloud;
    p.result.figures = r.figures;
    p.result.seconds = r.seconds;
    p.result.stage_seconds = r.stage_seconds;
    p.metrics = r.metrics.is_object() ? r.metrics : OJson::object();
    return p;
}

std::vector<cv::Mat> renderDensityViews(const FrameProducts &p, const method::GridSpec &grid, int target_px) {
    const Cloud &c = p.result.cloud;
    const method::CloudView cloud(c.xyz.data(), c.size());
    const bool ground = c.frame == BINOCLE_FRAME_GROUND;
    struct Item {
        method::View view;
        const char *name;
        bool aboveGround;
    };
    const Item items[] = {{method::View::Top, "top", true}, {method::View::Front, "front", false}, {method::View::Side, "side", false}};
    std::vector<cv::Mat> out;
    for (const Item &item : items) {
        const method::DensityView view =
            method::binView(cloud, item.view, grid, item.aboveGround && ground ? method::aboveGround(grid) : nullptr);
        method::RenderOptions r;
        r.density_threshold = grid.density_threshold;
        r.target_size_px = target_px;
        r.overlays = overlaysOf(p.metrics, item.name);
        std::string name = item.name;
        name[0] = static_cast<char>(name[0] - 'a' + 'A');
        r.title = name + " (" + method::viewAxes(item.view) + "), frame " + std::to_string(p.result.sequence) + ": " +
                  std::to_string(view.total()) + " points" + (!ground ? " (camera frame: no ground transform)" : "");
        out.push_back(method::renderDensityView(view, r));
    }
    return out;
}

cv::Mat colorizeDisparityRange(const cv::Mat &disparity, double lo_px, double hi_px) {
    CV_Assert(disparity.type() == CV_32F);
    if (!(hi_px > lo_px)) hi_px = lo_px + 1;
    cv::Mat scaled;
    disparity.convertTo(scaled, CV_8U, 255.0 / (hi_px - lo_px), -255.0 * lo_px / (hi_px - lo_px));
    cv::Mat color;
    cv::applyColorMap(scaled, color, cv::COLORMAP_TURBO);
    color.setTo(cv::Scalar::all(0), disparity <= 0);
    return color;
}

OJson colorScale() {
    cv::Mat ramp(1, 256, CV_8U), color;
    for (int i = 0; i < 256; ++i) ramp.at<uchar>(0, i) = static_cast<uchar>(i);
    cv::applyColorMap(ramp, color, cv::COLORMAP_TURBO);
    OJson out = OJson::array();
    for (int i = 0; i < 256; ++i) {
        const cv::Vec3b bgr = color.at<cv::Vec3b>(0, i);
        out.push_back({bgr[2], bgr[1], bgr[0]});
    }
    return out;
}

std::string encodeFrame(const FrameProducts &p, const EncodeOptions &options) {
    const FrameResult &r = p.result;
    OJson header = OJson::object();
    header["type"] = "frame";
    header["sequence"] = r.sequence;
    header["frames_processed"] = p.frames_processed;
    header["pipeline_fps"] = number(p.pipeline_fps);
    header["frame_ms"] = number(r.seconds * 1000);
    OJson stages = OJson::object();
    for (const auto &[name, seconds] : r.stage_seconds) stages[name] = number(seconds * 1000);
    header["stage_ms"] = stages;
    header["valid_pixel_ratio"] = number(r.valid_pixel_ratio);
    header["points"] = r.cloud.size();
    header["image"] = {{"width", r.disparity.cols}, {"height", r.disparity.rows}};
    header["metrics"] = p.metrics;
    header["source_statistics"] = p.source_statistics;
    header["matcher"] = {{"min_disparity_px", p.disparity_range.first}, {"num_disparities", p.disparity_range.second}};

    // A fixed colour scale: the matcher's search range, so that colours mean the same
    // distance from frame to frame.
    double lo = p.disparity_range.first, hi = p.disparity_range.first + p.disparity_range.second;
    if (!(hi > lo)) {
        double mn = 0, mx = 0;
        cv::minMaxLoc(r.disparity, &mn, &mx, nullptr, nullptr, r.disparity > 0);
        lo = 0;
        hi = mx > 0 ? mx : 1;
    }
    header["disparity_scale"] = {{"lo_px", lo},
                                 {"hi_px", hi},
                                 {"focal_length_px", number(p.focal_length_px)},
                                 {"baseline_mm", number(p.baseline_mm)}};

    std::string blobs;
    OJson list = OJson::array();
    auto add = [&](const std::string &name, const std::string &type, const std::string &bytes) {
        list.push_back({{"name", name}, {"type", type}, {"offset", blobs.size()}, {"size", bytes.size()}});
        blobs += bytes;
    };
    // JPEG throughout: a few times faster to write than PNG (even at PNG's fastest
    // level) and to decode in the page; snapshots keep the exact PNG files.
    const std::vector<int> jpeg = {cv::IMWRITE_JPEG_QUALITY, options.jpeg_quality};
    add("left", "image/jpeg", encodeImage(".jpg", r.rectified_left, jpeg));
    add("right", "image/jpeg", encodeImage(".jpg", r.rectified_right, jpeg));
    add("disparity", "image/jpeg", encodeImage(".jpg", colorizeDisparityRange(r.disparity, lo, hi), jpeg));
    const std::vector<cv::Mat> views = renderDensityViews(p, options.grid, options.view_px);
    const char *viewNames[] = {"top", "front", "side"};
    for (size_t i = 0; i < views.size(); ++i) add(viewNames[i], "image/jpeg", encodeImage(".jpg", views[i], jpeg));

    // The cloud, thinned evenly to what a browser draws smoothly.
    if (options.with_cloud) {
        const Cloud &c = r.cloud;
        const size_t n = c.size();
        const size_t stride = std::max<size_t>(1, (n + options.max_cloud_points - 1) / std::max<size_t>(1, options.max_cloud_points));
        std::vector<float> xyz;
        std::vector<uint8_t> rgb;
        for (size_t i = 0; i < n; i += stride) {
            const float x = c.xyz[3 * i], y = c.xyz[3 * i + 1], z = c.xyz[3 * i + 2];
            if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) continue;
            xyz.insert(xyz.end(), {x / 1000.f, y / 1000.f, z / 1000.f});
            if (c.rgb.size() == c.xyz.size()) rgb.insert(rgb.end(), {c.rgb[3 * i], c.rgb[3 * i + 1], c.rgb[3 * i + 2]});
        }
        header["cloud"] = {{"points", xyz.size() / 3},
                           {"frame", c.frame == BINOCLE_FRAME_GROUND ? "ground" : "camera"},
                           {"has_rgb", !rgb.empty()}};
        add("cloud_xyz", "application/octet-stream", std::string(reinterpret_cast<const char *>(xyz.data()), xyz.size() * sizeof(float)));
        if (!rgb.empty()) add("cloud_rgb", "application/octet-stream", std::string(rgb.begin(), rgb.end()));
    }
    header["blobs"] = list;

    const std::string head = header.dump(-1, ' ', false, OJson::error_handler_t::replace);
    std::string message(4, '\0');
    const uint32_t len = static_cast<uint32_t>(head.size());
    for (int i = 0; i < 4; ++i) message[i] = static_cast<char>((len >> (8 * i)) & 0xff);
    // Blobs start on a 4-byte boundary so the page can view the floats in place.
    message += head;
    message.append((4 - message.size() % 4) % 4, ' ');
    message += blobs;
    return message;
}

std::vector<std::string> writeSnapshot(const FrameProducts &p, const OutputOptions &outputs, const std::string &rigYaml,
                                       const method::GridSpec &grid, const std::string &dir) {
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec) throw Error("snapshot: cannot create the folder " + dir + ": " + ec.message());
    const std::string stem = sequenceStem(p.result.sequence);
    writeFrameOutputs(p.result, outputs, dir);
    const std::vector<cv::Mat> views = renderDensityViews(p, grid, 640);
    const char *names[] = {"top", "front", "side"};
    for (size_t i = 0; i < views.size(); ++i) {
        const std::string path = (fs::path(dir) / ("view_" + std::string(names[i]) + "_" + stem + ".png")).string();
        writeImage(path, views[i]); // core's safe temporary, like every other output
    }
    OJson frame = OJson::object();
    frame["sequence"] = p.result.sequence;
    frame["valid_pixel_ratio"] = number(p.result.valid_pixel_ratio);
    frame["points"] = p.result.cloud.size();
    frame["seconds"] = number(p.result.seconds);
    OJson stages = OJson::object();
    for (const auto &[name, seconds] : p.result.stage_seconds) stages[name + "_seconds"] = number(seconds);
    frame["stages"] = stages;
    frame["metrics"] = p.metrics;
    frame["source_statistics"] = p.source_statistics;
    frame["units"] = {{"length", "mm"}, {"disparity", "px"}, {"disparity_png_scale", 256}};
    frame["rig_yaml"] = rigYaml;
    const std::string json = (fs::path(dir) / ("frame_" + stem + ".json")).string();
    writeFileAtomic(json, frame.dump(2, ' ', false, OJson::error_handler_t::replace) + "\n");
    // Every file of this frame: names carry its sequence number.
    std::vector<std::string> written;
    for (const auto &e : fs::directory_iterator(dir))
        if (e.path().filename().string().find(stem) != std::string::npos) written.push_back(e.path().string());
    std::sort(written.begin(), written.end());
    return written;
}

} // namespace binocle::viewer
