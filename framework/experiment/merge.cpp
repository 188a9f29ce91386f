// SPDX-License-Identifier: MIT
// `binocle experiment merge`: the results of shards (or partial runs) joined into one table.
#include "experiment/dataset_tests.hpp"
#include "experiment/experiment.hpp"
#include "experiment/results.hpp"
#include "experiment/test_rig.hpp"

#include "core/error.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include <spdlog/spdlog.h>

namespace fs = std::filesystem;

namespace binocle {

using namespace experiment;

namespace {

OJson readResults(const std::string &dir) {
    const std::string path = (fs::path(dir) / "results.json").string();
    std::ifstream in(path);
    if (!in) throw Error("experiment merge: " + path + " cannot be read (is " + dir + " an experiment's output folder?)");
    OJson doc;
    try {
        doc = OJson::parse(in);
    } catch (const nlohmann::json::exception &x) {
        throw Error("experiment merge: " + path + ": not valid JSON: " + x.what());
    }
    if (!doc.is_object() || !doc.contains("file") || !doc["file"].is_string() || !doc.contains("tests") || !doc["tests"].is_array())
        throw Error("experiment merge: " + path + ": no 'file' or 'tests': not an experiment's results.json");
    if (doc.value("status", std::string()) == kStatusInterrupted)
        throw Error("experiment merge: " + dir + " holds an interrupted run (status: interrupted, " +
                    std::to_string(doc["tests"].size()) + " test(s) done): run that share again before merging");
    return doc;
}

// Rows measured on another rig, or tests the experiment file no longer holds as they
// were run, cannot stand in one table: the rig text and each row's variables are
// compared with the experiment as it is now.
void checkSameSetup(const Experiment &e, const OJson &doc, const std::string &dir) {
    if (doc.contains("rig_yaml") && doc["rig_yaml"].is_string() && doc["rig_yaml"].get<std::string>() != yamlBlock(e.rig))
        throw Error("experiment merge: " + dir + " was run on another rig than " + e.rig_file +
                    " (with the experiment's rig_set) holds now: the rig was edited since; run it again");
    for (const auto &row : doc["tests"]) {
        const std::string id = row.value("test", std::string());
        const auto t = std::find_if(e.tests.begin(), e.tests.end(), [&](const ExperimentTest &x) { return x.id == id; });
        if (t == e.tests.end()) continue; // said below, with the other folders
        for (const auto &var : kVariables) {
            if (!row.contains(var) || !row[var].is_number()) continue;
            const double was = row[var].get<double>(), now = valueOf(t->geometry, var);
            if (std::fabs(was - now) > 1e-9 * std::max(1.0, std::fabs(now)))
                throw Error("experiment merge: test " + id + " of " + dir + " was run with " + var + " = " + num(was) + "; " +
                            e.file + " now says " + num(now) + ": the experiment was edited since; run it again");
        }
    }
}

// Copies each test's folder from the shards into out_dir (not from out_dir itself).
void copyTestFolders(const std::string &out_dir, const std::vector<std::string> &dirs, const std::vector<OJson> &docs) {
    std::error_code ec;
    for (size_t i = 0; i < docs.size(); ++i) {
        if (fs::equivalent(fs::path(dirs[i]), fs::path(out_dir), ec)) continue;
        for (const auto &row : docs[i]["tests"]) {
            const fs::path from = fs::path(dirs[i]) / ("test_" + row["test"].get<std::string>());
            if (!fs::exists(from)) continue;
            const fs::path to = fs::path(out_dir) / from.filename();
            fs::copy(from, to, fs::copy_options::recursive | fs::copy_options::overwrite_existing, ec);
            if (ec) throw Error("experiment merge: copying " + from.string() + " to " + to.string() + ": " + ec.message());
        }
    }
}

// OUT may be one of the merged folders; any other folder holding results is replaced
// only when asked, and then cleared first.
void prepareMergeOutput(const std::string &out_dir, const std::vector<std::string> &dirs, bool replace) {
    std::error_code ec;
    if (!fs::exists(fs::path(out_dir) / "results.json", ec)) return;
    for (const auto &d : dirs)
        if (fs::equivalent(fs::path(d), fs::path(out_dir), ec)) return;
    if (!replace)
        throw Error("experiment merge: " + out_dir + " already holds results (of " +
                    (resultsOwner(out_dir).empty() ? std::string("another run") : resultsOwner(out_dir)) +
                    "): merge into a new folder, or --force to replace them");
    clearResults(out_dir);
}

} // namespace

ExperimentResult mergeExperimentResults(const std::string &out_dir, const std::vector<std::string> &dirs, const PluginHost &host,
                                        bool replace) {
    if (dirs.empty()) throw Error("experiment merge: no folder to merge (binocle experiment merge OUT DIR...)");
    std::vector<OJson> docs;
    for (const auto &d : dirs) docs.push_back(readResults(d));
    const std::string file = docs[0]["file"].get<std::string>();
    const auto overrides = docs[0].value("overrides", std::vector<std::string>{});
    for (size_t i = 1; i < docs.size(); ++i) {
        if (docs[i]["file"].get<std::string>() != file)
            throw Error("experiment merge: " + dirs[i] + " holds results of " + docs[i]["file"].get<std::string>() + ", " + dirs[0] +
                        " of " + file + ": not the same experiment");
        if (docs[i].value("overrides", std::vector<std::string>{}) != overrides)
            throw Error("experiment merge: " + dirs[i] + " ran with other --set overrides than " + dirs[0]);
    }
    const Experiment e = loadExperiment(file, host, overrides);
    for (size_t i = 0; i < docs.size(); ++i) checkSameSetup(e, docs[i], dirs[i]);
    std::map<std::string, std::pair<OJson, size_t>> byId; // test id -> (row, folder index)
    std::set<int> shards;
    int shardCount = 0;
    for (size_t i = 0; i < docs.size(); ++i) {
        if (docs[i].contains("shard")) {
            shards.insert(docs[i]["shard"]["index"].get<int>());
            shardCount = docs[i]["shard"]["count"].get<int>();
        }
        for (const auto &row : docs[i]["tests"]) {
            const std::string id = row["test"].get<std::string>();
            if (e.dataset_tests && id == "mean") continue; // the shard's own means: made again below
            if (byId.count(id))
                throw Error("experiment merge: test " + id + " is in both " + dirs[byId[id].second] + " and " + dirs[i]);
            byId[id] = {row, i};
        }
    }
    const ExperimentTest meanTest{"mean", {}, {}, 0, {}, 0}; // dataset: the row of the means
    std::vector<Row> rows;
    TablesMeta meta = metaOf(e, 1, 1, host);
    for (const auto &t : e.tests) {
        auto it = byId.find(t.id);
        if (it == byId.end()) {
            meta.missing_tests.push_back(t.id);
            continue;
        }
        rows.push_back(Row::fromJson(it->second.first, &t));
        byId.erase(it);
    }
    if (!byId.empty()) throw Error("experiment merge: test " + byId.begin()->first + " is not in " + file);
    if (shardCount > 0 && static_cast<int>(shards.size()) == shardCount && rows.size() != e.tests.size())
        throw Error("experiment merge: all " + std::to_string(shardCount) + " shards given but only " + std::to_string(rows.size()) +
                    " of " + std::to_string(e.tests.size()) + " tests found");
    if (!meta.missing_tests.empty()) {
        meta.status = kStatusPartial;
        spdlog::warn("experiment merge: {} of {} tests merged; missing: {} (results.json says status: partial)", rows.size(),
                     e.tests.size(), join(meta.missing_tests));
    }
    std::error_code ec;
    fs::create_directories(out_dir, ec);
    if (ec) throw Error("experiment merge: " + out_dir + ": cannot create the folder: " + ec.message());
    prepareMergeOutput(out_dir, dirs, replace);
    copyTestFolders(out_dir, dirs, docs);
    finishRows(out_dir, e, rows, meanTest);
    writeTables(out_dir, e, rows, meta);
    return resultOf(rows);
}

} // namespace binocle
