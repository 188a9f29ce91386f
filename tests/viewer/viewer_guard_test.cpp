// SPDX-License-Identifier: MIT
// The viewer's guards (issue 24): command caps before parsing, which settings and paths a
// page may set, the Host and Origin rules, anti-forgery on POST, safe download names,
// bounded queues, the connection cap, commands off the I/O thread, snapshots that write
// through no planted link. Servers bind 127.0.0.1 only.
#include "config/rig_config.hpp"
#include "core/error.hpp"
#include "viewer/command.hpp"
#include "viewer/frame_snapshot.hpp"
#include "viewer/page_settings.hpp"
#include "viewer/server.hpp"
#include "viewer/web_guard.hpp"

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <gtest/gtest.h>

#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <fstream>
#include <future>
#include <sys/resource.h>
#include <thread>

namespace fs = std::filesystem;
using namespace binocle;
using namespace binocle::viewer;
namespace http = boost::beast::http;
namespace websocket = boost::beast::websocket;
namespace net = boost::asio;

namespace {

std::string rigFile() { return std::string(BINOCLE_SOURCE_DIR) + "/configs/rigs/sim-videre.yaml"; }

PluginHost &host() {
    static PluginHost h({BINOCLE_BUILD_PLUGIN_DIR});
    static bool scanned = (h.scan(), true);
    (void)scanned;
    return h;
}

template <class P> bool eventually(P predicate, int ms = 5000) {
    for (int i = 0; i < ms / 10; ++i) {
        if (predicate()) return true;
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return predicate();
}

http::response<http::string_body> request(uint16_t port, http::request<http::string_body> req) {
    net::io_context io;
    net::ip::tcp::socket socket(io);
    socket.connect({net::ip::make_address("127.0.0.1"), port});
    req.prepare_payload();
    http::write(socket, req);
    boost::beast::flat_buffer buffer;
    http::response<http::string_body> res;
    http::read(socket, buffer, res);
    return res;
}

http::request<http::string_body> post(uint16_t port, const std::string &target, const std::string &body) {
    http::request<http::string_body> req{http::verb::post, target, 11};
    req.set(http::field::host, "127.0.0.1:" + std::to_string(port));
    req.body() = body;
    return req;
}

fs::path freshDir(const std::string &name) {
    const fs::path d = fs::path(BINOCLE_BINARY_DIR) / "tests" / "viewer" / "guard" / name;
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
}

ServerOptions local(const std::string &token) {
    ServerOptions o;
    o.token = token;
    return o;
}

} // namespace

// ---- Commands: caps before parsing ----------------------------------------------------

TEST(ViewerCommand, KeysWithManyPartsAreRefusedBeforeParsing) {
    // The probe's crash: 100 000 dotted parts (200 KB) in one key; and 20 KB, which took
    // 14 s and 680 MB. Both end at the size or part checks, before any YAML is built.
    for (size_t parts : {100000u, 10000u, 4u}) {
        std::string key = "a";
        for (size_t i = 1; i < parts; ++i) key += ".a";
        const std::string text = R"({"op":"set","key":")" + key + R"(","value":"1"})";
        try {
            parseCommand(text);
            FAIL() << parts << " parts accepted";
        } catch (const CommandError &e) {
            const std::string m = e.what();
            EXPECT_LT(m.size(), 400u) << "an excerpt, not the key";
            EXPECT_TRUE(m.find("bytes") != std::string::npos || m.find("parts") != std::string::npos) << m;
        }
    }
    const Command ok = parseCommand(R"({"op":"set","key":"transforms.0.inclination_deg","value":"2"})");
    EXPECT_EQ(ok.op, Op::Set);
    EXPECT_EQ(ok.key, "transforms.0.inclination_deg");
}

TEST(ViewerCommand, ShapesAndSizes) {
    EXPECT_EQ(parseCommand(R"({"op":"pause"})").op, Op::Pause);
    EXPECT_EQ(parseCommand(R"({"op":"snapshot"})").op, Op::Snapshot);
    const auto refused = [](const std::string &text) {
        try {
            parseCommand(text);
            return std::string();
        } catch (const CommandError &e) {
            return std::string(e.what());
        }
    };
    EXPECT_NE(refused(std::string(kMaxCommandBytes + 1, ' ')).find("at most"), std::string::npos);
    EXPECT_NE(refused(std::string(1000, '[')).find("flat"), std::string::npos);
    EXPECT_NE(refused(R"({"op":"set","key":"matcher.x","value":")" + std::string(kMaxValueBytes + 1, 'x') + "\"}").find("at most"),
              std::string::npos);
    EXPECT_NE(refused(R"({"op":"set","key":"matcher.x","value":"a\u0000b"})").find("NUL"), std::string::npos);
    EXPECT_NE(refused(R"({"op":"set","key":"matcher/x","value":"1"})").find("character"), std::string::npos);
    EXPECT_NE(refused(R"({"op":"set","key":"matcher..x","value":"1"})").find("empty part"), std::string::npos);
    EXPECT_NE(refused(R"({"op":"set","key":"matcher.x"})").find("needs"), std::string::npos);
    EXPECT_NE(refused(R"({"op":"rm -rf"})").find("unknown command"), std::string::npos);
    EXPECT_NE(refused("not json").find("JSON object"), std::string::npos);
}

// ---- What a page may set --------------------------------------------------------------

TEST(ViewerPageSettings, ResourceLimitsAndFrameworkKeysAreNotPageControls) {
    const RigConfig rig = loadRig(rigFile(), {}, host());
    const PageSettings page(rig);
    EXPECT_EQ(page.refuseKey("matcher.num_disparities"), "");
    EXPECT_EQ(page.refuseKey("transforms.0.inclination_deg"), "");
    EXPECT_NE(page.refuseKey("matcher.max_memory_mb").find("resource limit"), std::string::npos);
    for (const char *key : {"runtime.matcher_instances", "runtime.queue_depth", "outputs.cloud_ply", "matcher.plugin", "name",
                            "matcher.no_such_setting", "transforms.7.inclination_deg"})
        EXPECT_NE(page.refuseKey(key), "") << key;
}

TEST(ViewerPageSettings, PathsStayInsideTheRigsFolders) {
    // A rig in a folder of its own, its scene beside it, a secret outside, and a link in
    // the rig's folder that leads to the secret.
    const fs::path root = freshDir("paths");
    fs::create_directories(root / "rigs");
    fs::create_directories(root / "scenes");
    fs::copy_file(std::string(BINOCLE_SOURCE_DIR) + "/configs/scenes/e1_panel.yaml", root / "scenes" / "e1_panel.yaml");
    fs::copy_file(std::string(BINOCLE_SOURCE_DIR) + "/configs/scenes/e1_panel.yaml", root / "scenes" / "other.yaml");
    fs::copy_file(rigFile(), root / "rigs" / "rig.yaml");
    std::ofstream(root / "secret.yaml") << "SECRET-FIRST-LINE: 1\n";
    fs::create_symlink(root / "secret.yaml", root / "scenes" / "link.yaml");
    const std::string rigPath = (root / "rigs" / "rig.yaml").string();
    const PageSettings page(loadRig(rigPath, {}, host()));
    auto check = [&](const std::string &value) {
        return page.refusePaths(loadRig(rigPath, {Override::parse("source.scene=" + value)}, host()));
    };
    EXPECT_EQ(check("../scenes/other.yaml"), "");
    EXPECT_EQ(check((root / "scenes" / "other.yaml").string()), "");
    EXPECT_EQ(check("\"\""), "") << "empty: the built-in scene";
    for (const std::string &bad : std::vector<std::string>{"/etc/shadow", "../secret.yaml", (root / "secret.yaml").string(),
                                                            "../scenes/link.yaml", "../scenes/../../secret.yaml", "'/etc/passwd'"}) {
        const std::string why = check(bad);
        EXPECT_NE(why.find("inside the rig's folders"), std::string::npos) << bad << ": " << why;
        EXPECT_EQ(why.find("SECRET"), std::string::npos) << "the path is named, never what the file holds";
    }
}

// ---- The Host and Origin rules ----------------------------------------------------------

TEST(ViewerWebGuard, HostRuleFollowsTheAddressTheConnectionArrivedOn) {
    for (const char *ok : {"127.0.0.1", "127.0.0.1:8080", "localhost:1", "LOCALHOST", "[::1]:8080", "::1", "127.1.2.3:9"})
        EXPECT_TRUE(hostAllowed(ok, "127.0.0.1", {})) << ok;
    for (const char *bad : {"", "evil.example", "evil.example:8080", "127.0.0.1.evil.example", "localhost.evil:80", "192.168.1.10:8080",
                            "[::1]x", "127.0.0.1:80x", "10.0.0.1", "127.0.0.1:8080\r\nX: y", "user@127.0.0.1"})
        EXPECT_FALSE(hostAllowed(bad, "127.0.0.1", {})) << bad;
    // Bound to 0.0.0.0 (or the address itself), reached from the network on 192.168.1.10:
    // the browser names that address and is served; a client naming 127.0.0.1 or
    // localhost over the network is not.
    EXPECT_TRUE(hostAllowed("192.168.1.10:8080", "192.168.1.10", {}));
    EXPECT_TRUE(hostAllowed("192.168.1.10:8080", "::ffff:192.168.1.10", {}));
    EXPECT_FALSE(hostAllowed("127.0.0.1:8080", "192.168.1.10", {}));
    EXPECT_FALSE(hostAllowed("localhost:8080", "192.168.1.10", {}));
    EXPECT_FALSE(hostAllowed("mybox.lan:8080", "192.168.1.10", {}));
    EXPECT_TRUE(hostAllowed("MyBox.lan:8080", "192.168.1.10", {"mybox.lan"}));
    EXPECT_TRUE(hostAllowed("[fe80::1]:8080", "fe80::1", {}));
}

TEST(ViewerWebGuard, OriginMustMatchHostAndPort) {
    EXPECT_TRUE(sameOrigin("http://127.0.0.1:8080", "127.0.0.1:8080"));
    EXPECT_TRUE(sameOrigin("HTTP://LOCALHOST:8080", "localhost:8080"));
    EXPECT_TRUE(sameOrigin("http://127.0.0.1", "127.0.0.1:80"));
    EXPECT_FALSE(sameOrigin("http://127.0.0.1:9999", "127.0.0.1:8080")) << "another local server's page";
    EXPECT_FALSE(sameOrigin("http://localhost:8080", "127.0.0.1:8080"));
    EXPECT_FALSE(sameOrigin("https://127.0.0.1:8080", "127.0.0.1:8080"));
    EXPECT_FALSE(sameOrigin("null", "127.0.0.1:8080"));
    EXPECT_FALSE(sameOrigin("http://127.0.0.1:8080/x", "127.0.0.1:8080"));
}

TEST(ViewerWebGuard, BindsFileNamesAndLogs) {
    EXPECT_EQ(remoteBindRisk("127.0.0.1"), "");
    EXPECT_EQ(remoteBindRisk("::1"), "");
    EXPECT_NE(remoteBindRisk("0.0.0.0").find("every network"), std::string::npos);
    EXPECT_NE(remoteBindRisk("192.168.1.10").find("unencrypted"), std::string::npos);
    EXPECT_EQ(safeFileName("sim-videre-view.yaml", "rig"), "sim-videre-view.yaml");
    EXPECT_EQ(safeFileName("a\r\nSet-Cookie: x=1\"-view.yaml", "rig"), "a__Set-Cookie__x_1_-view.yaml");
    EXPECT_EQ(safeFileName("../../.bashrc", "rig"), "_.._.bashrc");
    EXPECT_EQ(safeFileName("\r\n", "rig"), "rig");
    EXPECT_EQ(safeFileName(std::string(500, 'a'), "rig").size(), 80u);
    EXPECT_FALSE(headerSafe("a\r\nb"));
    EXPECT_TRUE(headerSafe("text/plain; charset=utf-8"));
    LogLimiter limiter(3, std::chrono::hours(1));
    size_t suppressed = 0, logged = 0;
    for (int i = 0; i < 1000; ++i) logged += limiter.allow(suppressed);
    EXPECT_EQ(logged, 3u);
    EXPECT_LE(logExcerpt(std::string(100000, 'h')).size(), LogLimiter::kMaxLogChars + 40);
}

// ---- The server over real sockets -------------------------------------------------------

TEST(ViewerServerGuard, PostNeedsTheTokenHeaderAndItsOwnOrigin) {
    ServerHandlers h;
    std::atomic<int> commands{0};
    h.command = [&](const std::string &) {
        ++commands;
        return std::string(R"({"type":"ok"})");
    };
    Server server(local("tok"), h);
    const uint16_t port = server.port();
    // The form a cross-origin page can send: text/plain, token in the URL, no header.
    auto forged = post(port, "/api/command?token=tok", R"({"op":"pause"})");
    forged.set(http::field::content_type, "text/plain");
    forged.set(http::field::origin, "http://evil.example");
    EXPECT_EQ(request(port, forged).result_int(), 403u);
    auto noHeader = post(port, "/api/command?token=tok", R"({"op":"pause"})");
    EXPECT_EQ(request(port, noHeader).result_int(), 403u);
    auto wrong = post(port, "/api/command", R"({"op":"pause"})");
    wrong.set(kTokenHeader, "tok2");
    EXPECT_EQ(request(port, wrong).result_int(), 403u);
    auto foreignOrigin = post(port, "/api/command", R"({"op":"pause"})");
    foreignOrigin.set(kTokenHeader, "tok");
    foreignOrigin.set(http::field::origin, "http://127.0.0.1:" + std::to_string(port + 1));
    EXPECT_EQ(request(port, foreignOrigin).result_int(), 403u);
    auto crossSite = post(port, "/api/command", R"({"op":"pause"})");
    crossSite.set(kTokenHeader, "tok");
    crossSite.set("Sec-Fetch-Site", "cross-site");
    EXPECT_EQ(request(port, crossSite).result_int(), 403u);
    EXPECT_EQ(commands, 0);
    auto good = post(port, "/api/command", R"({"op":"pause"})");
    good.set(kTokenHeader, "tok");
    good.set(http::field::origin, "http://127.0.0.1:" + std::to_string(port));
    const auto res = request(port, good);
    EXPECT_EQ(res.result_int(), 200u);
    EXPECT_EQ(res.body(), R"({"type":"ok"})");
    EXPECT_EQ(commands, 1);
    // A body over the command cap is refused before it is read whole.
    auto big = post(port, "/api/command", std::string(kMaxCommandBytes + 10, ' '));
    big.set(kTokenHeader, "tok");
    EXPECT_EQ(request(port, big).result_int(), 413u);
    EXPECT_EQ(commands, 1);
}

TEST(ViewerServerGuard, DownloadNamesCannotBreakTheHeader) {
    ServerHandlers h;
    h.api = [](const std::string &) { return HttpReply{200, "application/yaml", "x: 1\n", "evil\r\nSet-Cookie: a=b\r\n-view.yaml"}; };
    Server server(local("tok"), h);
    http::request<http::string_body> req{http::verb::get, "/api/rig.yaml?token=tok", 11};
    req.set(http::field::host, "127.0.0.1:" + std::to_string(server.port()));
    const auto res = request(server.port(), req);
    EXPECT_EQ(res.result_int(), 200u);
    EXPECT_EQ(res.count(http::field::set_cookie), 0u);
    EXPECT_EQ(std::string(res[http::field::content_disposition]), "attachment; filename=\"evil__Set-Cookie__a_b__-view.yaml\"");
    EXPECT_EQ(std::string(res["Referrer-Policy"]), "no-referrer");
}

namespace {

struct Ws {
    net::io_context io;
    websocket::stream<net::ip::tcp::socket> ws{io};
    Ws(uint16_t port, const std::string &origin = "") {
        ws.next_layer().connect({net::ip::make_address("127.0.0.1"), port});
        if (!origin.empty())
            ws.set_option(websocket::stream_base::decorator([origin](websocket::request_type &r) { r.set(http::field::origin, origin); }));
        ws.handshake("127.0.0.1:" + std::to_string(port), "/ws?token=tok");
    }
    std::string read() {
        boost::beast::flat_buffer b;
        ws.read(b);
        return boost::beast::buffers_to_string(b.data());
    }
};

} // namespace

TEST(ViewerServerGuard, WebSocketOriginIncludesThePort) {
    ServerHandlers h;
    h.hello = [] { return std::string("hello"); };
    Server server(local("tok"), h);
    const uint16_t port = server.port();
    Ws same(port, "http://127.0.0.1:" + std::to_string(port));
    EXPECT_EQ(same.read(), "hello");
    EXPECT_THROW(Ws(port, "http://127.0.0.1:" + std::to_string(port + 1)), boost::system::system_error);
    EXPECT_THROW(Ws(port, "http://localhost"), boost::system::system_error);
    Ws noOrigin(port); // not a browser: the token alone
    EXPECT_EQ(noOrigin.read(), "hello");
}

TEST(ViewerServerGuard, OversizedWebSocketMessageClosesThatSocketOnly) {
    ServerHandlers h;
    std::atomic<int> commands{0};
    h.command = [&](const std::string &) {
        ++commands;
        return std::string();
    };
    Server server(local("tok"), h);
    Ws big(server.port()), other(server.port());
    ASSERT_TRUE(eventually([&] { return server.browsers() == 2; }));
    big.ws.write(net::buffer(std::string(kMaxCommandBytes + 1, 'x')));
    // The server closes with 1009 (too big); reading answers its close frame.
    boost::beast::flat_buffer b;
    boost::system::error_code ec;
    while (!ec) big.ws.read(b, ec);
    EXPECT_EQ(ec, websocket::error::closed);
    EXPECT_EQ(big.ws.reason().code, websocket::close_code::too_big);
    EXPECT_TRUE(eventually([&] { return server.browsers() == 1; }));
    EXPECT_EQ(commands, 0);
    other.ws.write(net::buffer(std::string(R"({"op":"pause"})")));
    EXPECT_TRUE(eventually([&] { return commands == 1; }));
}

// States supersede each other; texts a client never reads are bounded in bytes.
TEST(ViewerServerGuard, AClientThatNeverReadsHoldsBoundedMemory) {
    ServerHandlers h;
    Server server(local("tok"), h);
    Ws idle(server.port());
    ASSERT_TRUE(eventually([&] { return server.browsers() == 1; }));
    const std::string state(200 * 1024, 's');
    for (int i = 0; i < 1000; ++i) server.broadcastState(state); // 200 MB if each were kept
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    EXPECT_EQ(server.browsers(), 1u) << "states do not pile up: the browser stays";
    const std::string text(200 * 1024, 't');
    for (int i = 0; i < 200; ++i) server.broadcastText(text); // 40 MB, beyond the socket's buffers
    EXPECT_TRUE(eventually([&] { return server.browsers() == 0; })) << "a client holding megabytes of unread texts is dropped";
}

TEST(ViewerServerGuard, ConnectionsBeyondTheCapAreClosed) {
    ServerOptions o = local("tok");
    o.max_connections = 4;
    Server server(o, {});
    EXPECT_EQ(server.maxConnections(), 4u);
    net::io_context io;
    std::vector<net::ip::tcp::socket> sockets;
    for (int i = 0; i < 12; ++i) {
        sockets.emplace_back(io);
        sockets.back().connect({net::ip::make_address("127.0.0.1"), server.port()});
    }
    ASSERT_TRUE(eventually([&] { return server.connections() == 4; }));
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    EXPECT_EQ(server.connections(), 4u);
    size_t closedByServer = 0;
    for (auto &s : sockets) {
        s.non_blocking(true);
        char c;
        boost::system::error_code ec;
        s.read_some(net::buffer(&c, 1), ec);
        if (ec == net::error::eof || ec == net::error::connection_reset) ++closedByServer;
    }
    EXPECT_EQ(closedByServer, 8u);
    sockets.clear();
    EXPECT_TRUE(eventually([&] { return server.connections() == 0; }));
}

// Out of file descriptors, accept() fails at once again and again: the server waits
// instead of spinning on it, and takes the waiting connections once descriptors are back.
TEST(ViewerServerGuard, AcceptBacksOffWhenDescriptorsRunOut) {
    ServerOptions o = local("tok");
    o.max_connections = 1000; // only the descriptors limit it here
    Server server(o, {});
    net::io_context io;
    std::vector<net::ip::tcp::socket> sockets;
    for (int i = 0; i < 40; ++i) sockets.emplace_back(io, net::ip::tcp::v4()); // their descriptors, before the limit
    size_t open = 0;
    for ([[maybe_unused]] const auto &e : fs::directory_iterator("/proc/self/fd")) ++open; // its own descriptor too
    rlimit saved{};
    ASSERT_EQ(getrlimit(RLIMIT_NOFILE, &saved), 0);
    rlimit tight = saved;
    tight.rlim_cur = open + 2; // two accepts, then EMFILE
    ASSERT_EQ(setrlimit(RLIMIT_NOFILE, &tight), 0);
    for (auto &s : sockets) s.connect({net::ip::make_address("127.0.0.1"), server.port()});
    rusage r0{}, r1{};
    getrusage(RUSAGE_SELF, &r0);
    const auto t0 = std::chrono::steady_clock::now();
    std::this_thread::sleep_for(std::chrono::milliseconds(1500));
    getrusage(RUSAGE_SELF, &r1);
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    auto seconds = [](const rusage &r) {
        return r.ru_utime.tv_sec + r.ru_stime.tv_sec + (r.ru_utime.tv_usec + r.ru_stime.tv_usec) / 1e6;
    };
    const double busy = (seconds(r1) - seconds(r0)) / wall;
    ASSERT_EQ(setrlimit(RLIMIT_NOFILE, &saved), 0);
    EXPECT_LT(busy, 0.3) << "the process used " << busy * 100 << " % of a core while accept() failed (a spin takes ~100 %)";
    EXPECT_TRUE(eventually([&] { return server.connections() == 40; }, 5000)) << server.connections();
}

// A slow command (a snapshot) runs on the command thread: the I/O thread keeps serving.
TEST(ViewerServerGuard, SlowCommandsDoNotStallTheIoThread) {
    std::promise<void> release;
    std::shared_future<void> released = release.get_future().share();
    std::atomic<bool> running{false};
    ServerHandlers h;
    h.command = [&](const std::string &) {
        running = true;
        released.wait();
        return std::string(R"({"type":"done"})");
    };
    h.api = [](const std::string &) { return HttpReply{200, "application/json", "{}", ""}; };
    Server server(local("tok"), h);
    Ws ws(server.port());
    ws.ws.write(net::buffer(std::string(R"({"op":"snapshot"})")));
    ASSERT_TRUE(eventually([&] { return running.load(); }));
    http::request<http::string_body> req{http::verb::get, "/api/state?token=tok", 11};
    req.set(http::field::host, "127.0.0.1:" + std::to_string(server.port()));
    EXPECT_EQ(request(server.port(), req).result_int(), 200u) << "answered while the command still runs";
    release.set_value();
    EXPECT_EQ(ws.read(), R"({"type":"done"})");
}

// ---- Snapshots write through nothing planted ---------------------------------------------

TEST(ViewerSnapshot, PlantedLinksInTheFolderAreReplacedNotFollowed) {
    const fs::path dir = freshDir("snapshot");
    const fs::path victim = dir.parent_path() / "victim.txt";
    std::ofstream(victim) << "untouched";
    FrameProducts p;
    p.result.sequence = 5;
    p.result.rectified_left = cv::Mat(24, 32, CV_8UC1, cv::Scalar(90));
    p.result.rectified_right = p.result.rectified_left.clone();
    p.result.disparity = cv::Mat(24, 32, CV_32F, cv::Scalar(12.5f));
    for (int i = 0; i < 10; ++i) p.result.cloud.xyz.insert(p.result.cloud.xyz.end(), {float(i), 6000.f, 500.f});
    OutputOptions outputs;
    // The names a writer used to pick (".tmp-<pid>-<name>", "<name>.tmp-<pid>") and the
    // final names, all links to a file outside.
    const std::string pid = std::to_string(::getpid());
    for (const std::string name : {"disparity_000005.png", "disparity_color_000005.png", "cloud_000005.ply", "view_top_000005.png",
                                   "frame_000005.json"}) {
        fs::create_symlink(victim, dir / name);
        fs::create_symlink(victim, dir / (".tmp-" + pid + "-" + name));
        fs::create_symlink(victim, dir / (name + ".tmp-" + pid));
    }
    const auto files = writeSnapshot(p, outputs, "name: x\n", method::GridSpec{}, dir.string());
    EXPECT_FALSE(files.empty());
    std::ifstream in(victim);
    EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}), "untouched");
    for (const std::string name : {"disparity_000005.png", "cloud_000005.ply", "view_top_000005.png", "frame_000005.json"}) {
        EXPECT_TRUE(fs::is_regular_file(fs::symlink_status(dir / name))) << name << " is a file of its own now";
    }
}
