// SPDX-License-Identifier: MIT
// Tests of `binocle record` and the recording writer: what is recorded replays bit for bit,
// a recorder killed mid-run leaves a readable recording, nothing is ever overwritten.
#include "../common/test_util.hpp"

#include "config/rig_config.hpp"
#include "core/error.hpp"
#include "host/plugin_host.hpp"
#include "pipeline/recorder.hpp"

#include <binocle/recording.hpp>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <yaml-cpp/yaml.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <fcntl.h>
#include <fstream>
#include <set>
#include <sstream>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

namespace {

namespace fs = std::filesystem;
using binocle::Source;
using binocle::test::TempDir;

binocle::PluginHost &host() {
    static binocle::PluginHost h(std::vector<std::string>{BINOCLE_BUILD_PLUGIN_DIR});
    static const bool scanned = (h.scan(), true);
    (void)scanned;
    return h;
}

bool haveSim() { return host().find("sim", BINOCLE_KIND_STEREO_SOURCE) != nullptr; }

std::string readFile(const std::string &path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

int countLines(const std::string &path) {
    std::ifstream in(path);
    int n = 0;
    for (std::string line; std::getline(in, line);) ++n;
    return n;
}

struct Frame {
    cv::Mat left, right;
    int64_t tl = 0, tr = 0;
};

// Every frame a source gives (at most `max`), deep-copied.
std::vector<Frame> framesOf(const binocle::PluginRecord &record, const std::string &yaml, int max = 1000) {
    Source s(record, binocle::paramsFromYaml(record, yaml));
    s.start();
    std::vector<Frame> out;
    while (static_cast<int>(out.size()) < max) {
        auto f = s.grab(5000);
        if (!f) break;
        out.push_back({f->left().clone(), f->right().clone(), f->raw().timestamp_left_ns, f->raw().timestamp_right_ns});
    }
    return out;
}

std::vector<Frame> replayOf(const std::string &folder, const std::string &color) {
    return framesOf(host().require("replay", BINOCLE_KIND_STEREO_SOURCE), "{folder: " + folder + ", color: " + color + "}");
}

bool same(const cv::Mat &a, const cv::Mat &b) {
    return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0;
}

// Colour pairs on disk, played by replay's glob layout.
void writeColourPairs(const TempDir &dir, int n) {
    fs::create_directories(dir.path() / "in");
    for (int i = 0; i < n; ++i) {
        cv::Mat l(90, 120, CV_8UC3), r(90, 120, CV_8UC3);
        cv::RNG rng(static_cast<uint64_t>(i) + 11);
        rng.fill(l, cv::RNG::UNIFORM, 0, 256);
        rng.fill(r, cv::RNG::UNIFORM, 0, 256);
        cv::imwrite(dir.str("in/left_" + std::to_string(i) + ".png"), l);
        cv::imwrite(dir.str("in/right_" + std::to_string(i) + ".png"), r);
    }
}

std::string replayRig(const TempDir &dir, const std::string &extra = "") {
    return "name: colour-files\nsource:\n  plugin: replay\n  left: in/left_*.png\n  right: in/right_*.png\n  rate_hz: 30\n" + extra +
           "matcher: {plugin: sgbm}\n";
}

const char *kSimSettings = "  image_width: 160\n  image_height: 120\n  forward_mm_per_frame: 100\n  color: gray\n  seed: 3\n";

std::string simRig(int frames) {
    return "name: sim-record\nsource:\n  plugin: sim\n" + std::string(kSimSettings) + "  frames: " + std::to_string(frames) +
           "\nmatcher: {plugin: sgbm}\n";
}

void expectSameFrames(const std::vector<Frame> &a, const std::vector<Frame> &b) {
    ASSERT_EQ(a.size(), b.size());
    for (size_t i = 0; i < a.size(); ++i) {
        EXPECT_TRUE(same(a[i].left, b[i].left)) << "frame " << i << " left";
        EXPECT_TRUE(same(a[i].right, b[i].right)) << "frame " << i << " right";
        EXPECT_EQ(a[i].tl, b[i].tl) << "frame " << i;
        EXPECT_EQ(a[i].tr, b[i].tr) << "frame " << i;
    }
}

TEST(Record, SimRecordingReplaysBitForBit) {
    if (!haveSim()) GTEST_SKIP() << "sim plugin not built";
    TempDir dir;
    binocle::test::writeText(dir.str("rig.yaml"), simRig(4));
    const auto r = binocle::test::runCli("record " + dir.str("rig.yaml") + " --out " + dir.str("rec") + " --quiet");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("4 frame(s) of rig 'sim-record' recorded"), std::string::npos) << r.output;
    EXPECT_EQ(countLines(dir.str("rec/frames.csv")), 5);
    EXPECT_EQ(readFile(dir.str("rec/frames.csv")).substr(0, 57), "sequence,timestamp_left_ns,timestamp_right_ns,left,right\n");
    EXPECT_TRUE(fs::exists(dir.str("rec/left/000003.png")));
    EXPECT_TRUE(fs::exists(dir.str("rec/rig.yaml")));

    const auto &sim = host().require("sim", BINOCLE_KIND_STEREO_SOURCE);
    const std::string settings = "{image_width: 160, image_height: 120, forward_mm_per_frame: 100, color: gray, seed: 3, frames: 4}";
    const auto original = framesOf(sim, settings);
    expectSameFrames(original, replayOf(dir.str("rec"), "gray"));
    // The calibration is the simulated rig's own, verbatim.
    Source s(sim, binocle::paramsFromYaml(sim, settings));
    EXPECT_EQ(readFile(dir.str("rec/calibration.yml")), s.calibration());
}

TEST(Record, ColourReplaySourceRecordingReplaysBitForBit) {
    TempDir dir;
    writeColourPairs(dir, 3);
    binocle::test::writeText(dir.str("rig.yaml"), replayRig(dir));
    const auto r = binocle::test::runCli("record " + dir.str("rig.yaml") + " --out " + dir.str("rec") + " --quiet");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const auto &replay = host().require("replay", BINOCLE_KIND_STEREO_SOURCE);
    const auto original = framesOf(replay, "{left: " + dir.str("in/left_*.png") + ", right: " + dir.str("in/right_*.png") + ", rate_hz: 30}");
    ASSERT_EQ(original.size(), 3u);
    EXPECT_EQ(original[0].left.type(), CV_8UC3);
    expectSameFrames(original, replayOf(dir.str("rec"), "bgr"));
    // The rig as resolved, --set included, lies beside the frames.
    EXPECT_NE(readFile(dir.str("rec/rig.yaml")).find("plugin: replay"), std::string::npos);
}

TEST(Record, FramesAndSetOptionsAndTheRigsCalibration) {
    TempDir dir;
    writeColourPairs(dir, 3);
    const std::string calibration = std::string(BINOCLE_SOURCE_DIR) + "/configs/calibrations/opencv-aloe-ideal.yml";
    binocle::test::writeText(dir.str("rig.yaml"), replayRig(dir) + "calibration: " + calibration + "\n");
    const auto r = binocle::test::runCli("record " + dir.str("rig.yaml") + " --out " + dir.str("rec") +
                                         " --frames 5 --set source.loop=true --quiet");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_EQ(countLines(dir.str("rec/frames.csv")), 6);
    EXPECT_EQ(readFile(dir.str("rec/calibration.yml")), readFile(calibration));
    EXPECT_NE(readFile(dir.str("rec/rig.yaml")).find("loop: true"), std::string::npos);
    EXPECT_EQ(replayOf(dir.str("rec"), "bgr").size(), 5u);
}

TEST(Record, SummarySaysWhatWasTakenWrittenAndLostAndCompressionIsSettable) {
    TempDir dir;
    writeColourPairs(dir, 3);
    binocle::test::writeText(dir.str("rig.yaml"), replayRig(dir, "  loop: true\n"));
    for (int level : {0, 9}) {
        const std::string out = dir.str("rec" + std::to_string(level));
        const auto r = binocle::test::runCli("record " + dir.str("rig.yaml") + " --out " + out + " --frames 6 --png-compression " +
                                             std::to_string(level) + " --writer-threads 3 --quiet");
        ASSERT_EQ(r.exit_code, 0) << r.output;
        // A file source is never dropped from: the writers make it wait.
        EXPECT_NE(r.output.find("6 pair(s) taken from the source, 0 dropped because the writers were behind (wait when behind)"),
                  std::string::npos)
            << r.output;
        const auto summary = nlohmann::ordered_json::parse(readFile(out + "/summary.json"));
        EXPECT_EQ(summary["status"], "complete");
        EXPECT_EQ(summary["pairs_taken"], 6);
        EXPECT_EQ(summary["pairs_written"], 6);
        EXPECT_EQ(summary["lost"]["pairs_dropped_by_writer"], 0);
        EXPECT_EQ(summary["lost"]["when_writers_behind"], "wait");
        EXPECT_EQ(summary["writer"]["threads"], 3);
        EXPECT_EQ(summary["writer"]["png_compression"], level);
        EXPECT_EQ(replayOf(out, "bgr").size(), 6u);
    }
    const auto bad = binocle::test::runCli("record " + dir.str("rig.yaml") + " --out " + dir.str("bad") + " --png-compression 12");
    EXPECT_EQ(bad.exit_code, 2); // a usage error
    EXPECT_NE(bad.output.find("--png-compression: Value 12 not in range 0 to 9"), std::string::npos) << bad.output;
}

TEST(Record, RefusesAFolderThatHoldsAnythingAndLosesNothing) {
    TempDir dir;
    writeColourPairs(dir, 2);
    binocle::test::writeText(dir.str("rig.yaml"), replayRig(dir));
    fs::create_directories(dir.path() / "busy");
    binocle::test::writeText(dir.str("busy/notes.txt"), "keep me");
    auto r = binocle::test::runCli("record " + dir.str("rig.yaml") + " --out " + dir.str("busy"));
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_NE(r.output.find("output folder " + dir.str("busy") + " holds files Binocle did not write there (notes.txt): "
                            "binocle record writes a recording only into a new or empty folder; choose another folder"),
              std::string::npos)
        << r.output;
    EXPECT_EQ(readFile(dir.str("busy/notes.txt")), "keep me");
    EXPECT_FALSE(fs::exists(dir.str("busy/frames.csv")));

    // A finished recording is never touched by a second run.
    ASSERT_EQ(binocle::test::runCli("record " + dir.str("rig.yaml") + " --out " + dir.str("rec") + " --quiet").exit_code, 0);
    const std::string before = readFile(dir.str("rec/frames.csv"));
    const std::string image = readFile(dir.str("rec/left/000000.png"));
    r = binocle::test::runCli("record " + dir.str("rig.yaml") + " --out " + dir.str("rec") + " --quiet");
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.output.find("refusing to record over it"), std::string::npos) << r.output;
    EXPECT_EQ(readFile(dir.str("rec/frames.csv")), before);
    EXPECT_EQ(readFile(dir.str("rec/left/000000.png")), image);

    // An empty folder is fine.
    fs::create_directories(dir.path() / "empty");
    EXPECT_EQ(binocle::test::runCli("record " + dir.str("rig.yaml") + " --out " + dir.str("empty") + " --quiet").exit_code, 0);
}

TEST(Record, CommandLineErrorsSayWhatIsWrong) {
    TempDir dir;
    writeColourPairs(dir, 1);
    binocle::test::writeText(dir.str("rig.yaml"), replayRig(dir));
    // Usage mistakes: exit status 2, the option named.
    auto r = binocle::test::runCli("record " + dir.str("rig.yaml"));
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.output.find("--out is required"), std::string::npos) << r.output;
    r = binocle::test::runCli("record " + dir.str("rig.yaml") + " --out " + dir.str("x") + " --frames 0");
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.output.find("--frames: '0': expected a whole number >= 1"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(dir.str("x")));
}

// Starts `binocle record` as a child process; returns its pid.
pid_t spawnRecorder(const std::string &rig, const std::string &out) {
    const pid_t pid = ::fork();
    if (pid == 0) {
        ::signal(SIGHUP, SIG_DFL); // as a terminal leaves it, even when the tests run under nohup
        ::setenv("BINOCLE_PLUGIN_PATH", BINOCLE_BUILD_PLUGIN_DIR, 1);
        const int devnull = ::open("/dev/null", O_WRONLY);
        ::dup2(devnull, 2);
        ::execl(BINOCLE_CLI, BINOCLE_CLI, "record", rig.c_str(), "--out", out.c_str(), "--quiet", static_cast<char *>(nullptr));
        ::_exit(127);
    }
    return pid;
}

TEST(Record, KilledRecorderLeavesARecordingReadableToItsLastFrame) {
    TempDir dir;
    if (haveSim()) {
        binocle::test::writeText(dir.str("rig.yaml"), simRig(0)); // endless
    } else {
        writeColourPairs(dir, 3);
        binocle::test::writeText(dir.str("rig.yaml"), replayRig(dir, "  loop: true\n"));
    }
    const std::string color = haveSim() ? "gray" : "bgr";
    std::vector<Frame> original;
    // Killed without warning at several moments, while it is busy writing more frames.
    // extraMs < 0: the moment an image of the next frame is half written (its temporary file exists).
    const struct {
        int frames;
        int extraMs;
    } moments[] = {{6, 0}, {9, 1}, {12, 3}, {15, 7}, {8, -1}, {11, -1}};
    for (const auto &moment : moments) {
        const std::string out = dir.str("rec" + std::to_string(moment.frames));
        const pid_t pid = spawnRecorder(dir.str("rig.yaml"), out);
        ASSERT_GT(pid, 0);
        const auto t0 = std::chrono::steady_clock::now();
        while (countLines(out + "/frames.csv") < 1 + moment.frames && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(60))
            std::this_thread::sleep_for(std::chrono::milliseconds(1));
        if (moment.extraMs >= 0) {
            std::this_thread::sleep_for(std::chrono::milliseconds(moment.extraMs));
        } else {
            const auto t1 = std::chrono::steady_clock::now();
            auto writing = [&] {
                for (const char *side : {"/left", "/right"})
                    for (const auto &e : fs::directory_iterator(out + side))
                        if (e.path().filename().string().rfind(".tmp-", 0) == 0) return true;
                return false;
            };
            while (!writing() && std::chrono::steady_clock::now() - t1 < std::chrono::seconds(5)) {
            }
        }
        ::kill(pid, SIGKILL);
        int status = 0;
        ::waitpid(pid, &status, 0);
        ASSERT_TRUE(WIFSIGNALED(status));
        const int lines = countLines(out + "/frames.csv") - 1;
        ASSERT_GE(lines, moment.frames);

        const auto replayed = replayOf(out, color);
        EXPECT_EQ(static_cast<int>(replayed.size()), lines) << "every frame with its line must replay";
        if (original.size() < replayed.size()) {
            if (haveSim())
                original = framesOf(host().require("sim", BINOCLE_KIND_STEREO_SOURCE),
                                    "{image_width: 160, image_height: 120, forward_mm_per_frame: 100, color: gray, seed: 3, frames: 0}",
                                    static_cast<int>(replayed.size()));
            else
                original = framesOf(host().require("replay", BINOCLE_KIND_STEREO_SOURCE),
                                    "{left: " + dir.str("in/left_*.png") + ", right: " + dir.str("in/right_*.png") +
                                        ", rate_hz: 30, loop: true}",
                                    static_cast<int>(replayed.size()));
        }
        for (size_t i = 0; i < replayed.size(); ++i) {
            EXPECT_TRUE(same(replayed[i].left, original[i].left)) << "frame " << i;
            EXPECT_TRUE(same(replayed[i].right, original[i].right)) << "frame " << i;
        }
        int leftovers = 0, images = 0;
        for (const auto &e : fs::recursive_directory_iterator(out)) {
            const std::string name = e.path().filename().string();
            if (name.rfind(".tmp-", 0) == 0) ++leftovers;
            else if (e.path().extension() == ".png") ++images;
        }
        std::cout << "[ figures  ] recorder killed "
                  << (moment.extraMs < 0 ? std::string("while writing an image") : std::to_string(moment.extraMs) + " ms")
                  << " after frame " << moment.frames << ": " << lines
                  << " frame(s) in frames.csv, " << replayed.size() << " replayed bit for bit (" << images << " images, "
                  << leftovers << " temporary file(s) of the frame being written)\n";
    }
}

// The recorder takes pairs as the pipeline's acquire stage does (pipeline/source_grab.hpp):
// a stop asked while the source is silent ends the recording as interrupted, with the pairs
// already written, instead of waiting out the grab's timeout or failing on the source's
// short timeouts; and whether to drop when behind comes from the source's own `live` word.
TEST(Record, AStopWhileTheSourceIsSilentEndsTheRecordingAtOnce) {
    binocle::PluginHost fixtures(std::vector<std::string>{BINOCLE_TEST_PLUGIN_DIR});
    fixtures.scan();
    TempDir dir;
    // Two pairs, then every grab times out after 50 ms for ten minutes.
    const binocle::RigConfig rig = binocle::rigFromNode(
        YAML::Load("name: silent\nsource:\n  plugin: mock_source\n  frames: 100\n  live: true\n  fail_after: 2\n"
                   "  fail_for_ms: 600000\n  fail_code: timeout\nmatcher:\n  plugin: mock_matcher\n"),
        dir.str("rig.yaml"), fixtures);
    std::atomic<bool> stop{false};
    binocle::RecordOptions options;
    options.progress = false;
    options.grab_timeout_ms = 120000;
    options.stop = &stop;
    std::thread stopper([&] {
        std::this_thread::sleep_for(std::chrono::milliseconds(500));
        stop = true;
    });
    const auto t0 = std::chrono::steady_clock::now();
    const binocle::RecordResult r = binocle::recordRig(rig, dir.str("rec"), options);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    stopper.join();
    EXPECT_EQ(r.status, "interrupted") << r.error;
    EXPECT_TRUE(r.error.empty()) << r.error;
    EXPECT_EQ(r.grabbed, 2);
    EXPECT_EQ(r.frames, 2);
    EXPECT_TRUE(r.dropped_when_behind) << "the source says live: true";
    EXPECT_LT(seconds, 60.0) << "the stop was seen only when the grab's timeout ran out";
    const nlohmann::json summary = nlohmann::json::parse(readFile(dir.str("rec") + "/summary.json"));
    EXPECT_EQ(summary["status"], "interrupted");
    EXPECT_EQ(summary["lost"]["when_writers_behind"], "drop");
}

TEST(RecordingWriter, AFullQueueRefusesWithoutWaitingAndRowsKeepTheirOrder) {
    TempDir dir;
    binocle::RecordingWriterOptions options;
    options.threads = 1;
    options.queue_frames = 2;
    options.sync_batch_frames = 4;
    std::vector<uint64_t> accepted;
    {
        binocle::RecordingWriter w(dir.str("rec"), "", "", options);
        cv::Mat noise(480, 640, CV_8UC1);
        for (uint64_t i = 0; i < 40; ++i) {
            cv::randu(noise, 0, 256);
            if (w.submit(i, static_cast<int64_t>(i), static_cast<int64_t>(i), noise.clone(), noise.clone(), false, false))
                accepted.push_back(i);
        }
        w.finish();
        EXPECT_EQ(w.frameCount(), static_cast<int64_t>(accepted.size()));
        EXPECT_LE(w.stats().max_queued, 2);
        EXPECT_GE(w.stats().syncs, 1);
    }
    // One writer thread cannot encode 640x480 noise as fast as a loop submits it.
    EXPECT_LT(accepted.size(), 40u);
    std::ifstream csv(dir.str("rec/frames.csv"));
    std::string line;
    std::getline(csv, line);
    for (uint64_t sequence : accepted) {
        ASSERT_TRUE(std::getline(csv, line));
        EXPECT_EQ(line.substr(0, line.find(',')), std::to_string(sequence));
        EXPECT_TRUE(fs::exists(dir.str("rec/" + binocle::recording::imagePath(1, sequence))));
    }
    EXPECT_FALSE(std::getline(csv, line)) << "a row for a frame that was refused";
}

TEST(RecordingWriter, PngCompressionLevelIsTheOneAsked) {
    TempDir dir;
    cv::Mat ramp(120, 160, CV_8UC1);
    for (int y = 0; y < ramp.rows; ++y)
        for (int x = 0; x < ramp.cols; ++x) ramp.at<uint8_t>(y, x) = static_cast<uint8_t>(x + y);
    uintmax_t bytes[2] = {0, 0};
    for (int level : {0, 9}) {
        binocle::RecordingWriterOptions options;
        options.png_compression = level;
        const std::string out = dir.str("rec" + std::to_string(level));
        binocle::RecordingWriter w(out, "", "", options);
        w.append(0, 0, 0, ramp, ramp);
        bytes[level ? 1 : 0] = fs::file_size(out + "/left/000000.png");
        EXPECT_TRUE(same(cv::imread(out + "/left/000000.png", cv::IMREAD_UNCHANGED), ramp));
    }
    EXPECT_GT(bytes[0], 160u * 120u) << "level 0 stores the pixels";
    EXPECT_LT(bytes[1] * 4, bytes[0]) << "level 9 compresses a ramp";
    binocle::RecordingWriterOptions bad;
    bad.png_compression = 10;
    try {
        binocle::RecordingWriter w(dir.str("bad"), "", "", bad);
        ADD_FAILURE() << "level 10 accepted";
    } catch (const binocle::Error &e) {
        EXPECT_NE(std::string(e.what()).find("PNG compression level = 10: expected 0..9"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(dir.str("bad"))) << "nothing created for a refused level";
}

TEST(RecordingWriter, WritesTheLayoutReplayReads) {
    TempDir dir;
    {
        binocle::RecordingWriter w(dir.str("rec"), "%YAML:1.0\n---\nimage_width: 8\n", "name: x\n");
        cv::Mat l(4, 8, CV_8UC1, cv::Scalar(7)), r(4, 8, CV_8UC1, cv::Scalar(9));
        w.append(17, 1000, 1001, l, r);
        w.append(19, 2000, 2002, l, r);
        EXPECT_EQ(w.frameCount(), 2);
    }
    EXPECT_EQ(readFile(dir.str("rec/frames.csv")),
              "sequence,timestamp_left_ns,timestamp_right_ns,left,right\n"
              "17,1000,1001,left/000017.png,right/000017.png\n"
              "19,2000,2002,left/000019.png,right/000019.png\n");
    EXPECT_EQ(readFile(dir.str("rec/calibration.yml")), "%YAML:1.0\n---\nimage_width: 8\n");
    EXPECT_EQ(cv::imread(dir.str("rec/right/000019.png"), cv::IMREAD_UNCHANGED).at<uint8_t>(0, 0), 9);
    EXPECT_THROW(binocle::RecordingWriter(dir.str("rec"), "", ""), binocle::Error);
}

} // namespace

namespace {

// Runs a shell script (bash), capturing its output; the recorder inside gets the build
// tree's plugins. `timeout -s KILL` turns a hang into exit 137.
binocle::test::CommandResult runScript(const std::string &script) {
    return binocle::test::runCommand("BINOCLE_PLUGIN_PATH='" + std::string(BINOCLE_BUILD_PLUGIN_DIR) + "' BINOCLE='" +
                                     std::string(BINOCLE_CLI) + "' bash -c '" + script + "'");
}

// Every row of frames.csv names two images that exist and decode; no image lies there
// without its row. Returns the rows.
int expectEveryRowWhole(const std::string &rec) {
    std::ifstream in(rec + "/frames.csv");
    std::string line;
    std::getline(in, line);
    EXPECT_EQ(line, "sequence,timestamp_left_ns,timestamp_right_ns,left,right");
    int rows = 0;
    std::set<std::string> listed;
    while (std::getline(in, line)) {
        ++rows;
        std::vector<std::string> cells;
        std::stringstream s(line);
        for (std::string c; std::getline(s, c, ',');) cells.push_back(c);
        EXPECT_EQ(cells.size(), 5u) << "row " << rows << ": " << line;
        if (cells.size() != 5) continue;
        for (int i = 3; i < 5; ++i) {
            listed.insert(cells[static_cast<size_t>(i)]);
            EXPECT_FALSE(cv::imread(rec + "/" + cells[static_cast<size_t>(i)], cv::IMREAD_UNCHANGED).empty())
                << cells[static_cast<size_t>(i)];
        }
    }
    for (const char *side : {"left", "right"})
        for (const auto &e : fs::directory_iterator(rec + "/" + side)) {
            const std::string name = std::string(side) + "/" + e.path().filename().string();
            EXPECT_TRUE(listed.count(name)) << name << " lies in the recording without its row";
        }
    return rows;
}

// A full disk: a 2 MiB tmpfs in a private mount namespace (root only). The recorder stops
// with an error naming the disk within the timeout (it used to spin and ignore signals),
// keeps every pair listed, removes the images no row will name and writes its summary.
TEST(Record, OnAFullDiskTheRecorderStopsNamingTheDiskAndKeepsEveryListedPair) {
    if (!haveSim()) GTEST_SKIP() << "sim plugin not built";
    TempDir dir;
    binocle::test::writeText(dir.str("rig.yaml"), "name: sim-full-disk\nsource:\n  plugin: sim\n  image_width: 320\n"
                                                   "  image_height: 240\n  forward_mm_per_frame: 100\n  color: gray\n"
                                                   "  seed: 3\n  frames: 0\nmatcher: {plugin: sgbm}\n");
    fs::create_directories(dir.path() / "disk");
    fs::create_directories(dir.path() / "copy");
    const std::string disk = dir.str("disk"), rec = disk + "/rec";
    const binocle::test::CommandResult probe = binocle::test::runCommand("unshare -m true");
    if (probe.exit_code != 0) GTEST_SKIP() << "cannot make a mount namespace here (needs root): " << probe.output;
    const auto t0 = std::chrono::steady_clock::now();
    const binocle::test::CommandResult r = runScript(
        "unshare -m sh -c \"mount -t tmpfs -o size=2m tmpfs " + disk + " || exit 99; timeout -s KILL 120 \\$BINOCLE record " +
        dir.str("rig.yaml") + " --out " + rec + " --quiet; echo exit=\\$?; cp -a " + rec + " " + dir.str("copy") + "\"");
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (r.exit_code == 99) GTEST_SKIP() << "cannot mount a tmpfs here: " << r.output;
    EXPECT_NE(r.output.find("exit=1"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("No space left on device"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("the disk holding " + rec), std::string::npos) << r.output;
    const std::string copy = dir.str("copy/rec");
    const int rows = expectEveryRowWhole(copy);
    EXPECT_GT(rows, 0);
    const auto summary = nlohmann::json::parse(readFile(copy + "/summary.json"));
    EXPECT_EQ(summary["status"], "error");
    EXPECT_EQ(summary["pairs_written"], rows);
    EXPECT_NE(summary["error"].get<std::string>().find("No space left on device"), std::string::npos);
    EXPECT_EQ(static_cast<int>(replayOf(copy, "gray").size()), rows);
    std::cout << "[ figures  ] recorder on a 2 MiB disk: stopped after " << rows << " pair(s) in " << seconds << " s\n";
}

// A file size limit (ulimit -f, SIGXFSZ ignored): frames.csv is the file that reaches it.
// The index ends with its last whole row and the summary is written.
TEST(Record, AtTheFileSizeLimitTheIndexKeepsItsLastWholeRow) {
    TempDir dir;
    fs::create_directories(dir.path() / "in");
    for (int i = 0; i < 4; ++i) {
        cv::Mat l(12, 16, CV_8UC1, cv::Scalar(10 * i)), r(12, 16, CV_8UC1, cv::Scalar(10 * i + 5));
        cv::imwrite(dir.str("in/left_" + std::to_string(i) + ".png"), l);
        cv::imwrite(dir.str("in/right_" + std::to_string(i) + ".png"), r);
    }
    binocle::test::writeText(dir.str("rig.yaml"), "name: tiny\nsource:\n  plugin: replay\n  left: in/left_*.png\n"
                                                   "  right: in/right_*.png\n  rate_hz: 200\n  loop: true\n"
                                                   "matcher: {plugin: sgbm}\n");
    const std::string rec = dir.str("rec");
    const binocle::test::CommandResult r =
        runScript("trap \"\" XFSZ; ulimit -f 4; exec timeout -s KILL 120 \"$BINOCLE\" record " + dir.str("rig.yaml") + " --out " +
                  rec + " --quiet");
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_NE(r.output.find("frames.csv"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("ulimit -f"), std::string::npos) << r.output;
    const int rows = expectEveryRowWhole(rec);
    EXPECT_GT(rows, 20);
    EXPECT_LE(fs::file_size(rec + "/frames.csv"), 4096u);
    const auto summary = nlohmann::json::parse(readFile(rec + "/summary.json"));
    EXPECT_EQ(summary["status"], "error");
    EXPECT_EQ(summary["pairs_written"], rows);
    EXPECT_EQ(static_cast<int>(replayOf(rec, "gray").size()), rows);
}

// SIGHUP (the terminal closed) ends a recording as SIGINT does: cleanly, with its summary.
TEST(Record, SighupEndsTheRecordingWithItsSummary) {
    TempDir dir;
    if (haveSim()) {
        binocle::test::writeText(dir.str("rig.yaml"), simRig(0)); // endless
    } else {
        writeColourPairs(dir, 3);
        binocle::test::writeText(dir.str("rig.yaml"), replayRig(dir, "  loop: true\n"));
    }
    const std::string out = dir.str("rec");
    const pid_t pid = spawnRecorder(dir.str("rig.yaml"), out);
    ASSERT_GT(pid, 0);
    const auto t0 = std::chrono::steady_clock::now();
    while (countLines(out + "/frames.csv") < 4 && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(60))
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    ASSERT_EQ(::kill(pid, SIGHUP), 0);
    int status = 0;
    ::waitpid(pid, &status, 0);
    ASSERT_TRUE(WIFEXITED(status)) << "killed by signal " << WTERMSIG(status);
    EXPECT_EQ(WEXITSTATUS(status), 0);
    const auto summary = nlohmann::json::parse(readFile(out + "/summary.json"));
    EXPECT_EQ(summary["status"], "interrupted");
    EXPECT_EQ(summary["pairs_written"].get<int>(), countLines(out + "/frames.csv") - 1);
}

} // namespace
