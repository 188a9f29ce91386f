// SPDX-License-Identifier: MIT
// The viewer's parts without a browser: Host and token guards over real HTTP, the frame
// message's layout, controls from settings tables, reconfiguring a running pipeline,
// and the HTML report from an experiment folder.
#include "config/rig_config.hpp"
#include "core/error.hpp"
#include "core/image_io.hpp"
#include "pipeline/pipeline.hpp"
#include "report/html_report.hpp"
#include "viewer/frame_snapshot.hpp"
#include "viewer/server.hpp"
#include "viewer/settings_schema.hpp"

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>

namespace fs = std::filesystem;
using namespace binocle;
using OJson = nlohmann::ordered_json;

namespace {

struct Reply {
    int status = 0;
    std::string body;
};

Reply httpRequest(uint16_t port, const std::string &target, const std::string &host,
                  boost::beast::http::verb verb = boost::beast::http::verb::get, const std::string &body = "",
                  const std::string &tokenHeader = "") {
    namespace http = boost::beast::http;
    boost::asio::io_context io;
    boost::asio::ip::tcp::socket socket(io);
    socket.connect({boost::asio::ip::make_address("127.0.0.1"), port});
    http::request<http::string_body> req{verb, target, 11};
    req.set(http::field::host, host);
    if (!tokenHeader.empty()) req.set(viewer::kTokenHeader, tokenHeader);
    req.body() = body;
    req.prepare_payload();
    http::write(socket, req);
    boost::beast::flat_buffer buffer;
    http::response<http::string_body> res;
    http::read(socket, buffer, res);
    return {static_cast<int>(res.result_int()), res.body()};
}

std::string rigFile() { return std::string(BINOCLE_SOURCE_DIR) + "/configs/rigs/sim-videre.yaml"; }

PluginHost &host() {
    static PluginHost h({BINOCLE_BUILD_PLUGIN_DIR});
    static bool scanned = (h.scan(), true);
    (void)scanned;
    return h;
}

} // namespace

TEST(ViewerServer, TokenAndHostGuardTheEndpoints) {
    viewer::ServerHandlers h;
    std::atomic<int> commands{0};
    h.command = [&](const std::string &c) {
        ++commands;
        return std::string("{\"echo\":") + c + "}";
    };
    h.api = [](const std::string &name) {
        return name == "state" ? viewer::HttpReply{200, "application/json", "{\"ok\":true}", ""} : viewer::HttpReply{404, "", "", ""};
    };
    viewer::ServerOptions o;
    o.token = "secret123";
    viewer::Server server(o, h);
    const uint16_t port = server.port();
    const std::string local = "127.0.0.1:" + std::to_string(port);
    EXPECT_NE(server.url().find("token=secret123"), std::string::npos);

    Reply page = httpRequest(port, "/", local);
    EXPECT_EQ(page.status, 200);
    EXPECT_NE(page.body.find("app.js"), std::string::npos);
    EXPECT_EQ(httpRequest(port, "/app.js", local).status, 200);
    EXPECT_EQ(httpRequest(port, "/nothing.js", local).status, 404);
    EXPECT_EQ(httpRequest(port, "/api/state", local).status, 403);
    EXPECT_EQ(httpRequest(port, "/api/state?token=secret12", local).status, 403);
    EXPECT_EQ(httpRequest(port, "/api/state?token=secret123", local).body, "{\"ok\":true}");
    EXPECT_EQ(httpRequest(port, "/api/state?token=secret123", "rebind.example:" + std::to_string(port)).status, 403);
    EXPECT_EQ(httpRequest(port, "/", "rebind.example").status, 403);
    EXPECT_EQ(httpRequest(port, "/api/command", local, boost::beast::http::verb::post, "{\"op\":\"x\"}").status, 403);
    EXPECT_EQ(commands, 0);
    // A command carries the token in its header (anti-forgery); the URL's is not enough.
    EXPECT_EQ(httpRequest(port, "/api/command?token=secret123", local, boost::beast::http::verb::post, "{\"op\":\"x\"}").status, 403);
    EXPECT_EQ(commands, 0);
    Reply c = httpRequest(port, "/api/command", local, boost::beast::http::verb::post, "{\"op\":\"x\"}", "secret123");
    EXPECT_EQ(c.status, 200);
    EXPECT_EQ(c.body, "{\"echo\":{\"op\":\"x\"}}");
    EXPECT_EQ(commands, 1);
    EXPECT_FALSE(server.wantsFrame()); // no browser: nothing to encode
}

namespace {

// Waits until `predicate` holds (true) or a few seconds pass (false).
template <class P> bool eventually(P predicate) {
    for (int i = 0; i < 500; ++i) {
        if (predicate()) return true;
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return predicate();
}

} // namespace

// A browser gets the next frame only once its page says it has shown the last one: the
// encoder is not asked for frames a page cannot draw.
TEST(ViewerServer, ABrowserWantsAFrameOnlyAfterShowingTheLast) {
    namespace websocket = boost::beast::websocket;
    viewer::ServerHandlers h;
    h.hello = [] { return std::string("{\"type\":\"hello\"}"); };
    std::atomic<int> commands{0};
    h.command = [&](const std::string &) {
        ++commands;
        return std::string();
    };
    viewer::ServerOptions o;
    o.token = "tok";
    viewer::Server server(o, h);
    EXPECT_FALSE(server.wantsFrame());
    boost::asio::io_context io;
    websocket::stream<boost::asio::ip::tcp::socket> ws(io);
    ws.next_layer().connect({boost::asio::ip::make_address("127.0.0.1"), server.port()});
    ws.handshake("127.0.0.1:" + std::to_string(server.port()), "/ws?token=tok");
    boost::beast::flat_buffer buffer;
    ws.read(buffer); // hello
    buffer.consume(buffer.size());
    ASSERT_TRUE(eventually([&] { return server.wantsFrame(); })) << "a new browser wants a frame";
    server.broadcastFrame(std::make_shared<const std::string>("frame 1"));
    EXPECT_FALSE(server.wantsFrame()) << "right after a frame is queued";
    ws.read(buffer);
    EXPECT_EQ(boost::beast::buffers_to_string(buffer.data()), "frame 1");
    buffer.consume(buffer.size());
    // Written to the socket, but the page has not shown it: still not ready.
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    EXPECT_FALSE(server.wantsFrame());
    ws.write(boost::asio::buffer(std::string(viewer::kShownMessage)));
    EXPECT_TRUE(eventually([&] { return server.wantsFrame(); }));
    EXPECT_EQ(commands, 0) << "the acknowledgement is the server's, not a command";
    // A page that never says so (an old page, a hidden tab) gets frames again after a while.
    server.broadcastFrame(std::make_shared<const std::string>("frame 2"));
    ws.read(buffer);
    EXPECT_TRUE(eventually([&] { return server.wantsFrame(); }));
    ws.close(websocket::close_code::normal);
}

TEST(ViewerServer, BusyPortIsNamed) {
    viewer::Server first({}, {});
    try {
        viewer::ServerOptions o;
        o.port = first.port();
        viewer::Server second(o, {});
        FAIL() << "a second server bound the same port";
    } catch (const Error &e) {
        EXPECT_NE(std::string(e.what()).find(std::to_string(first.port())), std::string::npos) << e.what();
    }
}

// The cells an evaluator's reading took (view_overlays' cells_mm, the paper evaluator's
// panel) are outlined over the live density views, in the overlay's colour.
TEST(ViewerFrame, OutlinesTheCellsAReadingTook) {
    viewer::FrameProducts p;
    p.result.cloud.frame = BINOCLE_FRAME_GROUND;
    for (int i = 0; i < 3000; ++i)
        p.result.cloud.xyz.insert(p.result.cloud.xyz.end(), {float(i % 1000) - 500.f, 6000.f, 300.f + float(i / 3)});
    method::GridSpec grid;
    auto red = [&](const std::string &overlays) {
        p.metrics = {{"paper", {{"view_overlays", overlays}}}};
        const std::vector<cv::Mat> views = viewer::renderDensityViews(p, grid, 400);
        cv::Mat mask;
        cv::inRange(views[1], cv::Scalar(0, 0, 250), cv::Scalar(5, 5, 255), mask); // the front view
        return cv::countNonZero(mask);
    };
    // The box itself out of the way (beyond the grid): what is red is the cells' outline.
    const std::string box = R"("u_mm":[7000,7001],"v_mm":[300,301],"label":"","bgr":[0,0,255])";
    EXPECT_EQ(red("{\"front\":[{" + box + "}]}"), 0);
    std::string cells = "{\"front\":[{" + box + R"(,"cell_mm":100,"cells_mm":[)";
    for (int c = 0; c < 5; ++c) cells += std::string(c ? "," : "") + "[" + std::to_string(-500 + 200 * c) + ",600]";
    EXPECT_GE(red(cells + "]}]}"), 5 * 8) << "five separate cells, each outlined";
}

TEST(ViewerFrame, MessageLayout) {
    viewer::FrameProducts p;
    p.result.sequence = 7;
    p.result.rectified_left = cv::Mat(24, 32, CV_8UC1, cv::Scalar(90));
    p.result.rectified_right = cv::Mat(24, 32, CV_8UC1, cv::Scalar(80));
    p.result.disparity = cv::Mat(24, 32, CV_32F, cv::Scalar(12.5f));
    p.result.disparity(cv::Rect(0, 0, 8, 8)).setTo(-1); // one JPEG block of invalid pixels
    p.result.cloud.frame = BINOCLE_FRAME_GROUND;
    for (int i = 0; i < 1000; ++i) p.result.cloud.xyz.insert(p.result.cloud.xyz.end(), {float(i), 6000.f, 500.f});
    p.result.stage_seconds = {{"match", 0.01}};
    p.metrics = {{"paper", {{"eta_3d_percent", 91.5}, {"view_overlays", R"({"top":[{"u_mm":[-500,500],"v_mm":[5900,6100],"label":"#1","bgr":[1,2,3]}],"front":[],"side":[]})"}}}};
    p.disparity_range = {0, 64};
    p.focal_length_px = 400;
    p.baseline_mm = 150;
    viewer::EncodeOptions o;
    o.max_cloud_points = 100;
    o.view_px = 200;
    const std::string m = viewer::encodeFrame(p, o);
    ASSERT_GT(m.size(), 4u);
    const uint32_t len = uint8_t(m[0]) | uint8_t(m[1]) << 8 | uint8_t(m[2]) << 16 | uint32_t(uint8_t(m[3])) << 24;
    const OJson h = OJson::parse(m.substr(4, len));
    size_t base = 4 + len;
    base += (4 - base % 4) % 4;
    EXPECT_EQ(h["sequence"], 7);
    EXPECT_EQ(h["matcher"]["num_disparities"], 64);
    EXPECT_EQ(h["disparity_scale"]["hi_px"], 64.0);
    EXPECT_EQ(h["metrics"]["paper"]["eta_3d_percent"], 91.5);
    EXPECT_EQ(h["cloud"]["points"], 100u);
    std::map<std::string, std::pair<size_t, size_t>> blobs;
    for (const auto &b : h["blobs"]) blobs[b["name"]] = {b["offset"], b["size"]};
    for (const char *name : {"left", "right", "disparity", "top", "front", "side"}) {
        ASSERT_TRUE(blobs.count(name)) << name;
        const auto [offset, size] = blobs[name];
        ASSERT_LE(base + offset + size, m.size());
        const std::vector<uchar> bytes(m.begin() + long(base + offset), m.begin() + long(base + offset + size));
        EXPECT_FALSE(cv::imdecode(bytes, cv::IMREAD_COLOR).empty()) << name;
    }
    EXPECT_EQ(blobs["cloud_xyz"].second, 100 * 3 * sizeof(float));
    // The disparity's colours use the matcher's range; invalid pixels are black (JPEG:
    // within its rounding).
    const auto [doff, dsize] = blobs["disparity"];
    const cv::Mat d = cv::imdecode(std::vector<uchar>(m.begin() + long(base + doff), m.begin() + long(base + doff + dsize)), cv::IMREAD_COLOR);
    EXPECT_LT(cv::norm(cv::Vec3d(d.at<cv::Vec3b>(3, 3))), 30.0);
    EXPECT_GT(cv::norm(cv::Vec3d(d.at<cv::Vec3b>(16, 20))), 100.0);
    for (const auto &b : h["blobs"]) // cheap encodings only: no PNG in a live frame
        if (b["name"] != "cloud_xyz" && b["name"] != "cloud_rgb") EXPECT_EQ(b["type"], "image/jpeg") << b["name"];

    // Without the cloud (the 3D view's own rate): no cloud in the header, no cloud blobs.
    o.with_cloud = false;
    const std::string lean = viewer::encodeFrame(p, o);
    const uint32_t leanLen = uint8_t(lean[0]) | uint8_t(lean[1]) << 8 | uint8_t(lean[2]) << 16 | uint32_t(uint8_t(lean[3])) << 24;
    const OJson lh = OJson::parse(lean.substr(4, leanLen));
    EXPECT_FALSE(lh.contains("cloud"));
    for (const auto &b : lh["blobs"]) EXPECT_EQ(b["type"], "image/jpeg") << b["name"];
    EXPECT_EQ(lh["blobs"].size(), 6u);
    EXPECT_LT(lean.size() + 1000, m.size());
}

TEST(ViewerControls, FromSettingsTables) {
    const RigConfig rig = loadRig(rigFile(), {}, host());
    const OJson blocks = viewer::settingsSchema(rig);
    ASSERT_GE(blocks.size(), 4u);
    EXPECT_EQ(blocks[1]["key"], "matcher");
    EXPECT_EQ(blocks[1]["plugin"], "sgbm");
    const OJson *num = nullptr, *mode = nullptr;
    for (const auto &p : blocks[1]["params"]) {
        if (p["name"] == "num_disparities") num = &p;
        if (p["name"] == "mode") mode = &p;
    }
    ASSERT_TRUE(num && mode);
    EXPECT_EQ((*num)["type"], "int");
    EXPECT_EQ((*num)["value"], "64");
    EXPECT_EQ((*num)["multiple_of"], 16);
    EXPECT_EQ((*num)["min"], 16.0);
    EXPECT_FALSE(num->contains("max")); // no upper bound in its table: a number field, no slider
    EXPECT_EQ((*mode)["type"], "enum");
    EXPECT_EQ((*mode)["choices"].size(), 4u);
    EXPECT_EQ(blocks[2]["key"], "transforms.0");
}

TEST(PipelineReconfigure, MatcherChangesBetweenFrames) {
    const RigConfig rig = loadRig(rigFile(), {}, host());
    const RigConfig wider = loadRig(rigFile(), {Override::parse("matcher.num_disparities=128")}, host());
    Pipeline pipeline(rig, host());
    RunOptions o;
    o.max_frames = 3;
    o.progress = false;
    int calls = 0;
    o.between_frames = [&] {
        if (++calls == 2) pipeline.reconfigure(wider);
        return true;
    };
    std::vector<int32_t> ranges;
    pipeline.run(o, [&](const FrameResult &r) {
        ranges.push_back(pipeline.matcherDisparityRange().second);
        ASSERT_EQ(r.stage_seconds.size(), 5u);
        EXPECT_EQ(r.stage_seconds[1].first, "match");
    });
    EXPECT_EQ(ranges, (std::vector<int32_t>{64, 128, 128}));
    EXPECT_EQ(pipeline.rig().matcher().params.find("num_disparities")->i, 128);
}

// With parallel matcher instances every one of them is replaced, and the hook runs only
// once the frame before it is through the writer (nothing in flight while it swaps).
TEST(PipelineReconfigure, TwoMatcherInstancesDrainFirst) {
    const RigConfig rig = loadRig(rigFile(), {Override::parse("runtime.matcher_instances=2")}, host());
    const RigConfig wider =
        loadRig(rigFile(), {Override::parse("runtime.matcher_instances=2"), Override::parse("matcher.num_disparities=128")}, host());
    Pipeline pipeline(rig, host());
    RunOptions o;
    o.max_frames = 6;
    o.progress = false;
    int calls = 0, written = 0;
    std::vector<int> writtenAtCall;
    o.between_frames = [&] {
        writtenAtCall.push_back(written);
        if (++calls == 4) pipeline.reconfigure(wider);
        return true;
    };
    std::vector<int32_t> maxDisparity;
    pipeline.run(o, [&](const FrameResult &r) {
        EXPECT_EQ(r.index, static_cast<uint64_t>(written));
        maxDisparity.push_back(pipeline.matcherDisparityRange().second);
        ++written;
    });
    EXPECT_EQ(writtenAtCall, (std::vector<int>{0, 1, 2, 3, 4, 5}));
    EXPECT_EQ(maxDisparity, (std::vector<int32_t>{64, 64, 64, 128, 128, 128}));
}

TEST(PipelineReconfigure, StopsWhenTheHookSaysSo) {
    const RigConfig rig = loadRig(rigFile(), {}, host());
    Pipeline pipeline(rig, host());
    RunOptions o;
    o.progress = false; // the rig's source is endless
    int frames = 0;
    o.between_frames = [&] { return frames < 2; };
    const OJson summary = pipeline.run(o, [&](const FrameResult &) { ++frames; });
    EXPECT_EQ(frames, 2);
    EXPECT_EQ(summary["status"], "ok");
}

// With RunOptions::between_frames_wanted the hook runs only while the flag is set: the
// stages keep several frames in flight the rest of the time, and drain before the hook.
TEST(PipelineReconfigure, HookOnlyWhenWanted) {
    const RigConfig rig = loadRig(rigFile(), {Override::parse("runtime.matcher_instances=2")}, host());
    const RigConfig wider =
        loadRig(rigFile(), {Override::parse("runtime.matcher_instances=2"), Override::parse("matcher.num_disparities=128")}, host());
    Pipeline pipeline(rig, host());
    RunOptions o;
    // Far more frames than the stages can hold at once (their pool and queues), so that
    // the acquire stage is still grabbing when the writer asks for the hook.
    o.max_frames = 40;
    o.progress = false;
    std::atomic<bool> wanted{false};
    o.between_frames_wanted = &wanted;
    std::atomic<int> written{0};
    int calls = 0;
    std::vector<int> writtenAtCall;
    o.between_frames = [&] {
        writtenAtCall.push_back(written);
        ++calls;
        pipeline.reconfigure(wider);
        wanted = false;
        return true;
    };
    std::vector<int32_t> ranges;
    pipeline.run(o, [&](const FrameResult &r) {
        ranges.push_back(pipeline.matcherDisparityRange().second);
        ++written;
        if (r.index == 2) wanted = true;
    });
    ASSERT_EQ(calls, 1) << "the hook ran only when asked";
    // Asked after frame 2 was written: every frame grabbed before the hook was through.
    EXPECT_GE(writtenAtCall[0], 3);
    EXPECT_EQ(ranges.front(), 64);
    EXPECT_EQ(ranges.back(), 128);
    EXPECT_EQ(std::count(ranges.begin(), ranges.end(), 64) + std::count(ranges.begin(), ranges.end(), 128), 40);
    // Frames after the change are all matched with the new matcher, none before it.
    EXPECT_TRUE(std::is_sorted(ranges.begin(), ranges.end()));
    EXPECT_EQ(std::count(ranges.begin(), ranges.end(), 64), writtenAtCall[0]);
}

TEST(HtmlReport, FromAnExperimentFolder) {
    // A parent of its own: experimentFolders() below lists the parent's folders, and the
    // browser tests write theirs beside this one.
    const fs::path dir = fs::path(BINOCLE_BINARY_DIR) / "tests" / "viewer" / "report-unit" / "experiment";
    fs::remove_all(dir.parent_path());
    fs::create_directories(dir / "test_1");
    fs::create_directories(dir / "test_2");
    EXPECT_THROW(report::writeExperimentReport(dir.string()), Error);
    const OJson results = {{"experiment", "unit"},
                           {"file", "(none)"},
                           {"rig", "(none)"},
                           {"software", {{"binocle", "9.9.9"}, {"plugins", {{{"name", "sgbm"}, {"version", "1.2"}, {"kind", "matcher"}}}}}},
                           {"tests",
                            {{{"test", "1"}, {"status", "ok"}, {"eta_3d_percent", 80.0}, {"form_factor", 1.5}, {"paper.eta_3d_percent", 50.0},
                              {"paper_reported.eta_3d_percent", 82.0},
                              {"paper_reported", {{"eta_3d_percent", {{"reported", 82.0}, {"measured", 80.0}, {"difference", -2.0}}}}}},
                             {{"test", "2"}, {"status", "failed"}, {"eta_3d_percent", nullptr}, {"error", "boom <b>"}}}}};
    std::ofstream(dir / "results.json") << results.dump();
    writeImage((dir / "test_1" / "disparity_color_000000.png").string(), cv::Mat(8, 8, CV_8UC3, cv::Scalar(1, 2, 3)));
    const std::string out = report::writeExperimentReport(dir.string());
    EXPECT_EQ(out, (dir / "report.html").string());
    std::ifstream in(out);
    const std::string html((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NE(html.find("data:image/png;base64,"), std::string::npos);
    EXPECT_NE(html.find("data-test=\"2\""), std::string::npos);
    EXPECT_NE(html.find("η3D paper"), std::string::npos);
    EXPECT_NE(html.find(">-2.0<"), std::string::npos) << "measured 80 against the paper's 82";
    EXPECT_NE(html.find("boom &lt;b&gt;"), std::string::npos) << "errors are escaped";
    EXPECT_NE(html.find("9.9.9"), std::string::npos);
    EXPECT_NE(html.find("no top view (XY) image"), std::string::npos);
    EXPECT_EQ(html.find("{{"), std::string::npos) << "every placeholder filled";
    EXPECT_EQ(report::experimentFolders(dir.parent_path().string()), std::vector<std::string>{dir.string()});
}
