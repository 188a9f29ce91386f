// SPDX-License-Identifier: MIT
// The application layer called directly, as the CLI and the Python module call it: the
// output folder's refusals in each caller's words, the bad requests (the view's address,
// the report's file), and the design ranking against the one `binocle design` printed
// before the ranking moved here.
#include "common/test_util.hpp"

#include "app/design.hpp"
#include "app/experiment_run.hpp"
#include "app/record.hpp"
#include "app/report.hpp"
#include "app/run_rig.hpp"
#include "app/view.hpp"
#include "config/rig_config.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

using binocle::test::TempDir;
using binocle::test::writeText;
namespace app = binocle::app;

namespace {

const std::string kSimRig = BINOCLE_SOURCE_DIR "/configs/rigs/sim-e1.yaml";
const std::string kE1 = BINOCLE_SOURCE_DIR "/configs/experiments/e1.yaml";

// The message of what `f` throws, with its type checked.
template <class E, class F> std::string thrown(F f) {
    try {
        f();
    } catch (const E &e) {
        return e.what();
    }
    ADD_FAILURE() << "nothing thrown";
    return "";
}

bool contains(const std::string &text, const std::string &part) { return text.find(part) != std::string::npos; }

// A folder that holds a recording (its frames.csv) and nothing else Binocle marked.
std::string makeRecordingFolder(const std::string &dir) {
    std::filesystem::create_directories(dir);
    writeText(dir + "/frames.csv", "sequence,timestamp_left_ns,timestamp_right_ns,left,right\n");
    return dir;
}

// The simulated rig, loaded as the CLI loads it.
struct SimRig {
    binocle::PluginHost host;
    binocle::RigConfig rig = binocle::loadRig(kSimRig, {}, host);
};

TEST(AppRun, AFolderHoldingARecordingIsRefusedNamingItAndTheCallersFlag) {
    TempDir tmp;
    const std::string dir = makeRecordingFolder(tmp.str("rec"));
    const SimRig sim;
    const binocle::RigConfig &rig = sim.rig;
    const binocle::PluginHost &host = sim.host;
    app::RunRequest request;
    request.out = dir;
    request.frames = 1;
    const std::string cli = thrown<binocle::Error>([&] { app::RigRun run(rig, host, request); });
    EXPECT_TRUE(contains(cli, "output folder " + dir + " holds a recording (frames.csv)")) << cli;
    EXPECT_TRUE(contains(cli, "binocle run writes the output of a run only into a new or empty folder")) << cli;
    EXPECT_TRUE(contains(cli, "pass --force to replace what it holds")) << cli;
    request.caller.command = "binocle.Rig.run";
    const std::string python = thrown<binocle::Error>([&] { app::RigRun run(rig, host, request); });
    EXPECT_TRUE(contains(python, "holds a recording (frames.csv)")) << python;
    EXPECT_TRUE(contains(python, "binocle.Rig.run writes") && contains(python, "pass force=True")) << python;
    // Nothing of the recording went, nothing was added.
    EXPECT_TRUE(std::filesystem::exists(dir + "/frames.csv"));
    EXPECT_EQ(binocle::entriesOf(dir), std::vector<std::string>{"frames.csv"});
}

TEST(AppRun, McapWithoutAFolderIsARequestErrorInTheCallersWords) {
    const SimRig sim;
    const binocle::RigConfig &rig = sim.rig;
    const binocle::PluginHost &host = sim.host;
    app::RunRequest request;
    request.mcap = true;
    EXPECT_EQ(thrown<app::RequestError>([&] { app::RigRun run(rig, host, request); }),
              "--mcap: expected --out DIR (the bag goes into DIR/bag)");
}

TEST(AppRun, ARunWritesItsFolderAndReturnsTheSummary) {
    TempDir tmp;
    const SimRig sim;
    const binocle::RigConfig &rig = sim.rig;
    const binocle::PluginHost &host = sim.host;
    app::RunRequest request;
    request.out = tmp.str("run");
    request.frames = 1;
    request.progress = false;
    const std::atomic<bool> stop{false};
    request.stop = &stop; // no signal handlers in a test
    const app::RunResult result = app::runRig(rig, host, request);
    EXPECT_EQ(result.summary.value("frame_count", int64_t{0}), 1);
    EXPECT_FALSE(result.interrupted);
    EXPECT_EQ(binocle::outputKindOf(request.out), binocle::OutputKind::Run);
    EXPECT_TRUE(std::filesystem::exists(request.out + "/summary.json"));
    EXPECT_FALSE(std::filesystem::exists(request.out + "/" + binocle::OutputFolder::kLockFile)); // let go
}

TEST(AppRecord, NoFolderOrAnUnknownFormatIsRefusedBeforeAnythingRuns) {
    const SimRig sim;
    const binocle::RigConfig &rig = sim.rig;
    app::RecordRequest request;
    EXPECT_EQ(thrown<app::RequestError>([&] { app::record(rig, request); }), "--out: expected the folder to record into");
    TempDir tmp;
    request.out = tmp.str("rec");
    request.format = "avi";
    EXPECT_EQ(thrown<app::RequestError>([&] { app::record(rig, request); }), "--format avi: expected folder or mcap");
    EXPECT_FALSE(std::filesystem::exists(request.out));
}

TEST(AppRecord, ARecordingIsNeverWrittenOver) {
    TempDir tmp;
    const std::string dir = makeRecordingFolder(tmp.str("rec"));
    const SimRig sim;
    app::RecordRequest request;
    request.out = dir;
    const std::atomic<bool> stop{false};
    request.stop = &stop;
    const std::string message = thrown<binocle::Error>([&] { app::record(sim.rig, request); });
    EXPECT_TRUE(contains(message, "output folder " + dir + " holds a recording (frames.csv)")) << message;
    EXPECT_TRUE(contains(message, "; choose another folder") && !contains(message, "--force")) << message;
}

TEST(AppExperiment, AFolderHoldingARecordingIsRefusedAndABadTestIdIsARequestError) {
    TempDir tmp;
    const std::string dir = makeRecordingFolder(tmp.str("rec"));
    app::ExperimentRequest request;
    request.file = kE1;
    request.out = dir;
    request.caller.command = "binocle.experiment";
    const std::string message = thrown<binocle::Error>([&] { app::ExperimentRun run(request); });
    EXPECT_TRUE(contains(message, "output folder " + dir + " holds a recording (frames.csv)")) << message;
    EXPECT_TRUE(contains(message, "pass force=True")) << message;
    request.out = tmp.str("e1");
    request.tests = {"99"};
    const std::string bad = thrown<app::RequestError>([&] { app::ExperimentRun run(request); });
    EXPECT_TRUE(contains(bad, "has no test '99'")) << bad;
    EXPECT_FALSE(std::filesystem::exists(request.out));
}

// The (B, f) of a ranking, best first: "200/8 190/8 ...".
std::string order(const app::DesignResult &result) {
    std::string text;
    char item[64];
    for (const auto &c : result.candidates) {
        std::snprintf(item, sizeof item, "%s%g/%g", text.empty() ? "" : " ", c.baseline_mm, c.focal_length_mm);
        text += item;
    }
    return text;
}

// Recorded from `binocle design --range 6000` and `--band 5000,12000` at 77939e9, when the
// ranking still lived in cli/cmd_design.cpp (the shipped predictors: sensor_aware ranks).
TEST(AppDesign, TheRankingIsTheOneTheCommandPrintedBefore) {
    app::DesignRequest request;
    request.range = "6000";
    const app::DesignResult range = app::design(request);
    EXPECT_EQ(range.predictor, "sensor_aware");
    EXPECT_EQ(order(range),
              "200/8 190/8 180/8 170/8 160/8 150/8 140/8 130/8 120/8 110/8 100/8 200/4 190/4 180/4 170/4 160/4 150/4 140/4 130/4 "
              "120/4 110/4 100/4 200/2.8 190/2.8 180/2.8 170/2.8 160/2.8 150/2.8 140/2.8 130/2.8 120/2.8 110/2.8 100/2.8 200/12 "
              "190/12 180/12 170/12 160/12 150/12 140/12 130/12 120/12 110/12 100/12 200/16 190/16 180/16 170/16 160/16 150/16 "
              "140/16 130/16 120/16 110/16 100/16");
    request.range.clear();
    request.band = "5000,12000";
    const app::DesignResult band = app::design(request);
    EXPECT_EQ(band.ranges.size(), 5u);
    EXPECT_EQ(order(band),
              "200/8 190/8 180/8 170/8 160/8 150/8 140/8 130/8 120/8 110/8 100/8 200/4 190/4 180/4 170/4 160/4 150/4 140/4 200/2.8 "
              "190/2.8 130/4 180/2.8 120/4 170/2.8 160/2.8 110/4 150/2.8 100/4 140/2.8 130/2.8 120/2.8 110/2.8 100/2.8 200/12 "
              "190/12 180/12 170/12 160/12 150/12 140/12 130/12 120/12 110/12 200/16 190/16 180/16 170/16 160/16 150/16 140/16 "
              "130/16 120/16 110/16 100/16 100/12");
    // design.json's list is the same ranking.
    const binocle::Json json = app::designJson(band);
    ASSERT_EQ(json["candidates"].size(), band.candidates.size());
    EXPECT_EQ(json["candidates"][20]["baseline_mm"].get<double>(), 130);
    EXPECT_EQ(json["candidates"][20]["focal_length_mm"].get<double>(), 4);
}

TEST(AppDesign, BadValuesNameTheCallersArgument) {
    app::DesignRequest request;
    request.range = "6000,";
    EXPECT_EQ(thrown<app::RequestError>([&] { app::design(request); }),
              "--range 6000,: '' is not valid: expected a decimal number (e.g. 6000,12000)");
    request.caller.command = "binocle.design";
    EXPECT_EQ(thrown<app::RequestError>([&] { app::design(request); }),
              "range='6000,': '' is not valid: expected a decimal number (e.g. 6000,12000)");
    request.range.clear();
    EXPECT_EQ(thrown<app::RequestError>([&] { app::design(request); }),
              "give a target: range='6000' (mm) or band='5000,12000'");
    request.range = "6000";
    request.simulate_count = 0;
    EXPECT_EQ(thrown<app::RequestError>([&] { app::design(request); }), "simulate_count='0': expected a whole number >= 1");
}

TEST(AppDesign, OutGetsTheFilesAndAnotherKindIsRefused) {
    TempDir tmp;
    app::DesignRequest request;
    request.range = "6000";
    request.out = tmp.str("design");
    app::design(request);
    EXPECT_TRUE(std::filesystem::exists(request.out + "/design.json"));
    EXPECT_TRUE(std::filesystem::exists(request.out + "/design.csv"));
    EXPECT_EQ(binocle::outputKindOf(request.out), binocle::OutputKind::Design);
    request.out = tmp.str("rec");
    makeRecordingFolder(request.out);
    const std::string message = thrown<binocle::Error>([&] { app::design(request); });
    EXPECT_TRUE(contains(message, "holds a recording (frames.csv)") && contains(message, "--force")) << message;
    EXPECT_FALSE(std::filesystem::exists(request.out + "/design.json"));
}

// Without an output folder the simulated runs go into a scratch folder under $TMPDIR that
// is removed afterwards: nothing lands in the working folder (it used to get an unclaimed
// out/design/simulated), nothing is left in $TMPDIR, and the candidates still get η3D.
TEST(AppDesign, SimulatingWithoutAFolderWritesNothingAndLeavesNothing) {
    TempDir tmp;
    const std::string work = tmp.str("work"), scratch = tmp.str("tmp");
    std::filesystem::create_directories(work);
    std::filesystem::create_directories(scratch);
    const std::filesystem::path before = std::filesystem::current_path();
    const char *oldTmp = std::getenv("TMPDIR");
    const std::string savedTmp = oldTmp ? oldTmp : "";
    ::setenv("TMPDIR", scratch.c_str(), 1);
    std::filesystem::current_path(work);
    app::DesignRequest request;
    request.range = "6000";
    request.lenses = "8";
    request.baselines = "100";
    request.simulate = true;
    request.simulate_count = 1;
    request.progress = false;
    request.rig = kSimRig;
    app::DesignResult result;
    EXPECT_NO_THROW(result = app::design(request));
    std::filesystem::current_path(before);
    if (oldTmp) ::setenv("TMPDIR", savedTmp.c_str(), 1); else ::unsetenv("TMPDIR");
    ASSERT_EQ(result.candidates.size(), 1u);
    EXPECT_TRUE(std::isfinite(result.candidates[0].eta_3d) && result.candidates[0].eta_3d > 0) << result.candidates[0].eta_3d;
    EXPECT_TRUE(std::filesystem::is_empty(work)) << "the working folder got files";
    EXPECT_TRUE(std::filesystem::is_empty(scratch)) << "the scratch folder was left in $TMPDIR";
}

// The view's folder is claimed before the rig is read or any plugin opens: the rig named
// does not exist, and the refusal is the folder's, in the caller's words.
TEST(AppView, AFolderHoldingARecordingIsRefusedBeforeAnyPluginOpens) {
    TempDir tmp;
    const std::string dir = makeRecordingFolder(tmp.str("rec"));
    app::ViewRequest request;
    request.rig_file = tmp.str("no-such-rig.yaml");
    request.options.out_dir = dir;
    request.options.port = 0;
    bool listened = false;
    const auto listening = [&](const std::string &) { listened = true; };
    const std::string cli = thrown<binocle::Error>([&] { app::view(request, listening); });
    EXPECT_TRUE(contains(cli, "output folder " + dir + " holds a recording (frames.csv)")) << cli;
    EXPECT_TRUE(contains(cli, "binocle view writes") && contains(cli, "pass --force")) << cli;
    EXPECT_FALSE(contains(cli, "no-such-rig")) << cli;
    request.caller.command = "binocle.view";
    const std::string python = thrown<binocle::Error>([&] { app::view(request, listening); });
    EXPECT_TRUE(contains(python, "binocle.view writes") && contains(python, "pass force=True")) << python;
    EXPECT_FALSE(listened);
    EXPECT_EQ(binocle::entriesOf(dir), std::vector<std::string>{"frames.csv"});
}

// A bad address is a bad request (exit status 2), found before the folder is made.
TEST(AppView, ABadBindIsARequestErrorBeforeTheFolderIsMade) {
    TempDir tmp;
    app::ViewRequest request;
    request.rig_file = kSimRig;
    request.options.out_dir = tmp.str("view");
    request.options.address = "localhost";
    const auto listening = [](const std::string &) { ADD_FAILURE() << "served"; };
    EXPECT_EQ(thrown<app::RequestError>([&] { app::view(request, listening); }),
              "--bind localhost: expected an IP address, e.g. 127.0.0.1 or ::1 (not a name)");
    request.caller.command = "binocle.view";
    EXPECT_EQ(thrown<app::RequestError>([&] { app::view(request, listening); }),
              "bind='localhost': expected an IP address, e.g. 127.0.0.1 or ::1 (not a name)");
    request.options.address = "0.0.0.0";
    const std::string remote = thrown<app::RequestError>([&] { app::view(request, listening); });
    EXPECT_TRUE(contains(remote, "Add --allow-remote to serve it anyway")) << remote;
    request.options.address = "127.0.0.1";
    request.overrides = {"matcher"};
    const std::string override = thrown<app::RequestError>([&] { app::view(request, listening); });
    EXPECT_TRUE(contains(override, "matcher")) << override;
    EXPECT_FALSE(std::filesystem::exists(request.options.out_dir)); // made for the claim, gone again
}

// A short view on loopback: the page's URL is given, the frames run, and the folder made
// for snapshots is gone again since none was taken.
TEST(AppView, AViewServesItsFramesAndLeavesNoEmptyFolder) {
    TempDir tmp;
    app::ViewRequest request;
    request.rig_file = kSimRig;
    request.options.out_dir = tmp.str("view");
    request.options.port = 0;
    request.frames = 1; // the simulated E1 rig's source gives one pair
    std::string url;
    const binocle::viewer::ViewSummary summary = app::view(request, [&](const std::string &u) { url = u; });
    EXPECT_EQ(summary.frames, 1);
    EXPECT_TRUE(contains(url, "http://127.0.0.1:")) << url;
    EXPECT_FALSE(std::filesystem::exists(request.options.out_dir));
}

// An experiment's folder, as far as the report's checks look: its results.json.
std::string makeExperimentFolder(const std::string &dir) {
    std::filesystem::create_directories(dir);
    writeText(dir + "/results.json", "{}\n");
    return dir;
}

TEST(AppReport, AnOutputThatIsAFolderOrServesSeveralExperimentsIsRefused) {
    TempDir tmp;
    const std::string demo = tmp.str("demo");
    makeExperimentFolder(demo + "/e1");
    makeExperimentFolder(demo + "/e2");
    const std::string folder = tmp.str("reports");
    std::filesystem::create_directories(folder);
    app::ReportRequest request;
    request.dir = demo + "/e1";
    request.output = folder;
    EXPECT_EQ(thrown<app::RequestError>([&] { app::writeReports(request); }),
              "--output " + folder + ": is a folder; expected the report's file name (e.g. " + folder + "/report.html)");
    request.output = tmp.str("new/");
    EXPECT_TRUE(contains(thrown<app::RequestError>([&] { app::writeReports(request); }), ": is a folder;"));
    request.dir = demo;
    request.output = tmp.str("report.html");
    EXPECT_EQ(thrown<app::RequestError>([&] { app::writeReports(request); }),
              "--output " + request.output + ": " + demo + " holds 2 experiments; without --output each gets DIR/<experiment>/report.html");
    request.caller.command = "binocle.report";
    EXPECT_TRUE(contains(thrown<app::RequestError>([&] { app::writeReports(request); }), "without output each gets"));
    EXPECT_TRUE(std::filesystem::is_empty(folder));
    EXPECT_FALSE(std::filesystem::exists(request.output));
    EXPECT_FALSE(std::filesystem::exists(demo + "/e1/report.html"));
}

// Each experiment folder is locked while its report is written: one that an experiment
// still writes into (its claim held) is refused, and its report is not written.
TEST(AppReport, AnExperimentStillWritingIsRefused) {
    TempDir tmp;
    const std::string dir = tmp.str("e1");
    const binocle::OutputFolder running(dir, binocle::OutputClaim{binocle::OutputKind::Experiment, false, "binocle experiment"});
    makeExperimentFolder(dir); // its first results written
    app::ReportRequest request;
    request.dir = dir;
    std::vector<std::string> written;
    const std::string message =
        thrown<binocle::Error>([&] { app::writeReports(request, [&](const std::string &path) { written.push_back(path); }); });
    EXPECT_TRUE(contains(message, "output folder " + dir + " is in use by")) << message;
    EXPECT_TRUE(written.empty());
    EXPECT_FALSE(std::filesystem::exists(dir + "/report.html"));
}

} // namespace
