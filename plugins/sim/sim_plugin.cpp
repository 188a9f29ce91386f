// SPDX-License-Identifier: MIT
// The `sim` StereoSource: renders a YAML scene as a simulated stereo head sees it, with
// exact ground truth (extras), truth of the scene's objects (metadata) and the head's
// exact calibration. Settings and scene format: README.md beside this file.
#include "calibration_board.hpp"
#include "metadata.hpp"
#include "renderer.hpp"
#include "rig.hpp"
#include "scene.hpp"

#include "common/frame_pacer.hpp"

#include <binocle/plugin.hpp>
#include <yaml-cpp/yaml.h>

#include <chrono>
#include <fstream>
#include <initializer_list>
#include <memory>
#include <optional>
#include <sstream>
#include <utility>

namespace binocle::plugins {

namespace {

using sdk::Error;
using sdk::Param;

// A DOUBLE_LIST setting: `count` numbers (or one of `alternatives` counts).
std::vector<double> numberList(const sdk::CheckedParams &p, const std::string &key, std::initializer_list<size_t> counts) {
    const std::string text = p.string(key);
    std::vector<double> v;
    try {
        const YAML::Node n = YAML::Load(text.empty() ? "[]" : text);
        if (!n.IsSequence()) throw YAML::Exception(YAML::Mark::null_mark(), "not a list");
        for (const auto &item : n) v.push_back(item.as<double>());
    } catch (const YAML::Exception &) {
        p.refuse(key, text, "a list of numbers");
    }
    for (size_t c : counts)
        if (v.size() == c) return v;
    std::string expected;
    for (size_t c : counts) expected += (expected.empty() ? "" : " or ") + std::to_string(c);
    p.refuse(key, text, "a list of " + expected + " numbers, got " + std::to_string(v.size()));
}

sim::Distortion distortionOf(const std::vector<double> &v) {
    sim::Distortion d{};
    for (size_t i = 0; i < v.size(); ++i) d[i] = v[i];
    return d;
}

sim::Vec3 vec3Of(const std::vector<double> &v) { return {v[0], v[1], v[2]}; }

// Settings copied as they are into the member of the same name (a key of the sim is the
// name of the RigSettings or RenderSettings member it sets): one table, one loop.
template <class Settings>
void readWholeNumbers(const sdk::CheckedParams &p, Settings &s, std::initializer_list<std::pair<const char *, int Settings::*>> members) {
    for (const auto &[key, member] : members) s.*member = static_cast<int>(p.integer(key));
}
template <class Settings>
void readReals(const sdk::CheckedParams &p, Settings &s, std::initializer_list<std::pair<const char *, double Settings::*>> members) {
    for (const auto &[key, member] : members) s.*member = p.real(key);
}

// Pixels of a rendered frame, kept alive until the host releases the frame.
struct FramePixels {
    sim::RenderedFrame images;
};

} // namespace

class SimSource : public sdk::StereoSource {
public:
    static std::vector<binocle_param_desc> parameters() {
        return {
            Param::integer("image_width", "320").min(16).max(8192).unit("px").help("width of both images"),
            Param::integer("image_height", "240").min(16).max(8192).unit("px").help("height of both images"),
            Param::real("pixel_pitch_um", "20.8").min(0.1).unit("um")
                .help("effective pixel pitch (Videre head: 5.2 um decimated by 4)"),
            Param::integer("binning", "1").min(1).max(8)
                .help("sensor pixels per axis averaged into one output pixel (noise falls by this factor)"),
            Param::real("focal_length_mm", "8").min(0.1).unit("mm").help("lens focal length, both imagers"),
            Param::real("baseline_mm", "150").min(1).unit("mm").help("distance between the optical centres"),
            Param::real("camera_height_mm", "1500").min(1).unit("mm").help("hc: optical centre above the ground"),
            Param::real("inclination_deg", "0").min(-89).max(89).unit("deg")
                .help("theta: downward pitch of the optical axes (METHOD.md Eq. 1)"),
            Param::path("scene", "").help("scene YAML (plugins/sim/README.md); empty: the built-in E1 panel"),
            Param::real("range_mm", "0").min(0).unit("mm")
                .help("> 0: moves the scene's main object so that its near face is at this range; 0: as in the scene"),
            Param::real("main_object_lateral_mm", "0").unit("mm")
                .help("moves the scene's main object along X (lateral) by this much (placement jitter of repeats)"),
            Param::integer("frames", "1").min(0).help("frames before end of stream; 0 = endless"),
            Param::real("forward_mm_per_frame", "0").unit("mm").help("rig displacement along the range axis per frame"),
            Param::real("lateral_mm_per_frame", "0").unit("mm").help("rig displacement along the lateral axis per frame"),
            Param::real("frame_rate_hz", "15").min(0.001).unit("Hz").help("time stamps advance by 1 / frame_rate_hz"),
            Param::boolean("pace", false)
                .help("true: frames come no faster than frame_rate_hz, as a camera delivers them; false: as fast as rendered"),
            Param::integer("seed", "1").min(0).max(4294967295.0).help("seed of the sensor noise"),
            Param::real("noise_sigma", "2").min(0).unit("grey levels").help("Gaussian sensor noise, standard deviation"),
            Param::real("gain_right", "1").min(0).help("right imager's response relative to the left"),
            Param::real("offset_right", "0").unit("grey levels").help("added to every pixel of the right image"),
            Param::realList("distortion", "[0, 0, 0, 0, 0]")
                .help("Brown-Conrady k1, k2, p1, p2[, k3] of the left imager (and the right unless distortion_right)"),
            Param::realList("distortion_right", "[]").help("k1, k2, p1, p2[, k3] of the right imager; []: as distortion"),
            Param::realList("right_rotation_deg", "[0, 0, 0]").unit("deg")
                .help("roll (about Zc), pitch (Xc), yaw (Yc) of the right imager relative to the left"),
            Param::realList("right_offset_mm", "[0, 0, 0]").unit("mm")
                .help("right optical centre minus (baseline_mm, 0, 0), left camera frame"),
            Param::choice("color", "gray", "gray|bgr").help("GRAY8 or BGR8 images"),
            Param::integer("antialias", "2").min(1).max(8).help("samples per axis per sensor pixel"),
            Param::yaml("calibration_board", "")
                .help("{cols, rows, square_mm, poses (0: endless), max_tilt_deg, seed}: render a chessboard in varied poses instead of the scene"),
        };
    }

    SimSource(const sdk::CheckedParams &p, sdk::Host &host) : host_(host) {
        using Rig = sim::RigSettings;
        Rig rig;
        readWholeNumbers(p, rig, {{"image_width", &Rig::image_width}, {"image_height", &Rig::image_height}});
        readReals(p, rig, {{"pixel_pitch_um", &Rig::pixel_pitch_um}, {"focal_length_mm", &Rig::focal_length_mm},
                           {"baseline_mm", &Rig::baseline_mm}, {"camera_height_mm", &Rig::camera_height_mm},
                           {"inclination_deg", &Rig::inclination_deg}});
        rig.distortion = distortionOf(numberList(p, "distortion", {4, 5}));
        const auto right = numberList(p, "distortion_right", {0, 4, 5});
        rig.distortion_right = right.empty() ? rig.distortion : distortionOf(right);
        rig.right_rotation_deg = vec3Of(numberList(p, "right_rotation_deg", {3}));
        rig.right_offset_mm = vec3Of(numberList(p, "right_offset_mm", {3}));
        rig_.emplace(rig);

        using Render = sim::RenderSettings;
        Render render;
        readWholeNumbers(p, render, {{"antialias", &Render::antialias}, {"binning", &Render::binning}});
        readReals(p, render, {{"noise_sigma", &Render::noise_sigma}, {"gain_right", &Render::gain_right},
                              {"offset_right", &Render::offset_right}});
        render.color = p.string("color") == "bgr";
        render.seed = static_cast<uint32_t>(p.integer("seed"));
        renderer_.emplace(*rig_, render);

        frames_ = p.integer("frames");
        forward_ = p.real("forward_mm_per_frame");
        lateral_ = p.real("lateral_mm_per_frame");
        periodNs_ = static_cast<int64_t>(1e9 / p.real("frame_rate_hz"));
        pace_ = p.boolean("pace");

        try {
            const std::string board = p.string("calibration_board");
            if (!board.empty() && board != "null" && board != "~") {
                board_ = sim::BoardSettings::fromYaml(board);
                frames_ = board_->poses;
            } else {
                const std::string path = p.string("scene");
                if (path.empty()) {
                    scene_ = sim::Scene::builtIn();
                } else {
                    if (!std::ifstream(path)) throw Error(BINOCLE_ERR_NOT_FOUND, "sim: scene file " + path + " cannot be opened");
                    scene_ = sim::Scene::load(path);
                }
                if (p.real("range_mm") > 0) scene_.placeMainObjectAtRange(p.real("range_mm"));
                if (const double dx = p.real("main_object_lateral_mm"); dx != 0) {
                    if (scene_.mainObject < 0)
                        throw sim::SceneError("main_object_lateral_mm: the scene '" + scene_.name + "' has no main object");
                    scene_.moveObject(scene_.mainObject, sim::Vec3(dx, 0, 0));
                }
            }
        } catch (const sim::SceneError &e) {
            throw Error(BINOCLE_ERR_INVALID_ARGUMENT, std::string("sim: ") + e.what());
        }
    }

    void start() override { pacer_.start(periodNs_, "sim", "pace at frame_rate_hz " + std::to_string(1e9 / periodNs_)); }

    std::unique_ptr<sdk::Frame> grab(int32_t timeout_ms) override {
        if (frames_ > 0 && next_ >= static_cast<uint64_t>(frames_))
            throw Error(BINOCLE_ERR_END_OF_STREAM, "sim: all " + std::to_string(frames_) + " frames delivered");
        if (pace_) pacer_.wait(timeout_ms);
        const auto started = std::chrono::steady_clock::now();
        const uint64_t index = next_++;
        sim::RigPose pose;
        pose.forward_mm = forward_ * static_cast<double>(index);
        pose.lateral_mm = lateral_ * static_cast<double>(index);
        const sim::Scene *scene = &scene_;
        sim::Scene boardScene;
        if (board_) {
            boardScene = sim::boardScene(*board_, *rig_, static_cast<int>(index));
            scene = &boardScene;
        }
        auto pixels = std::make_shared<FramePixels>();
        pixels->images = renderer_->render(*scene, pose, index);
        const sim::RenderedFrame &r = pixels->images;

        auto frame = std::make_unique<sdk::Frame>();
        frame->sequence = index;
        frame->timestamp_left_ns = frame->timestamp_right_ns = static_cast<int64_t>(index) * periodNs_;
        const int32_t format = renderer_->settings().color ? BINOCLE_PIXEL_BGR8 : BINOCLE_PIXEL_GRAY8;
        frame->left = view(r.left, format);
        frame->right = view(r.right, format);
        frame->extras = {{"gt_disparity", view(r.gt_disparity, BINOCLE_PIXEL_FLOAT32)},
                         {"gt_depth", view(r.gt_depth, BINOCLE_PIXEL_FLOAT32)},
                         {"gt_valid", view(r.gt_valid, BINOCLE_PIXEL_GRAY8)},
                         {"gt_nonocc", view(r.gt_nonocc, BINOCLE_PIXEL_GRAY8)},
                         {"gt_object_id", view(r.gt_object_id, BINOCLE_PIXEL_GRAY16)}};
        frame->metadata = sim::frameMetadata(*scene, *rig_, pose, index);
        frame->owner = pixels;
        const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - started).count();
        renderMsTotal_ += ms;
        renderMsLast_ = ms;
        host_.debug("frame " + std::to_string(index) + " rendered in " + std::to_string(ms) + " ms");
        return frame;
    }

    std::string calibration() override { return rig_->calibrationYaml(); }

    std::string statistics() override {
        std::ostringstream s;
        s << "frames: " << next_ << "\n";
        s << "render_ms_last: " << renderMsLast_ << "\n";
        s << "render_ms_mean: " << (next_ ? renderMsTotal_ / static_cast<double>(next_) : 0.0) << "\n";
        return s.str();
    }

    static std::string enumerateDevices(sdk::Host &) {
        return "- {id: sim, description: \"simulated stereo head (ray-cast scene, exact ground truth)\"}\n";
    }

private:
    static binocle_image view(const cv::Mat &m, int32_t format) {
        return sdk::makeImage(m.cols, m.rows, format, const_cast<uint8_t *>(m.data), static_cast<int32_t>(m.step));
    }

    std::optional<sim::StereoRig> rig_;
    std::optional<sim::Renderer> renderer_;
    sim::Scene scene_;
    std::optional<sim::BoardSettings> board_;
    bool pace_ = false;
    FramePacer pacer_; // pace: frames one period apart from start(), as replay's rate_hz
    int64_t frames_ = 1;
    double forward_ = 0, lateral_ = 0;
    int64_t periodNs_ = 0;
    uint64_t next_ = 0;
    double renderMsTotal_ = 0, renderMsLast_ = 0;
    sdk::Host host_; // for debug lines (the host outlives the instance)
};

} // namespace binocle::plugins

BINOCLE_EXPORT_SOURCE(binocle::plugins::SimSource, "sim", "1.0.0",
                      "simulated stereo head: ray-cast YAML scene, exact calibration and ground truth")
