// SPDX-License-Identifier: MIT
// Designing a head (`binocle design`, binocle.design()): which baseline and which lens
// for a target range (or band)? Ranks every (B, f) of the available hardware by the
// predictor of highest rho with η3D (the form factor of Eq. 7 and the sensor-aware
// figures); with simulate, by the stereo efficiency η3D measured on the simulated rig.
#pragma once

#include "app/request.hpp"
#include "core/json.hpp"
#include "method/design.hpp"

#include <cstddef>
#include <string>
#include <vector>

namespace binocle::app {

struct DesignRequest {
    Caller caller{"binocle design"};
    // The caller's texts: "6000,12000"; a band "MIN,MAX"; lenses "2.8,4,8"; baselines
    // "MIN:MAX:STEP" or a list. One of range and band is required.
    std::string range, band, lenses = method::kVidereLensesMm, baselines = "100:200:10";
    // The head's sensor and matcher, and its pose (method's one head description); each
    // candidate configures its baseline and lens.
    method::StereoDesign head = method::videreHead();
    double panel_width_mm = 2500, panel_height_mm = 2000;
    std::string predictors_from; // results.json whose rho chooses; empty: configs/predictors/e1-sim.json
    std::string predictor;       // rank by this one; empty: the highest rho
    bool simulate = false;       // measure η3D on the simulated rig for the best candidates
    int simulate_count = 12;
    std::string rig;             // simulate's base rig; empty: configs/rigs/sim-e1.yaml
    std::string out;             // design.json, design.csv (and simulated/); empty: nothing written
    bool force = false;          // replace what `out` holds when another command (or the user) wrote it
    bool progress = true;        // simulate's progress display
};

// One (B, f) with its figures at each range.
struct DesignCandidate {
    double baseline_mm = 0, focal_length_mm = 0;
    std::vector<method::DesignFigures> at; // one per target range
    double worst_score = 0;                // the ranking predictor at the band's worst range
    bool panel_fits = true, in_search = true;
    double eta_3d = NAN;                   // simulate: η3D (%) averaged over the ranges
};

struct DesignResult {
    std::vector<double> ranges;               // the target ranges (mm)
    std::string predictor;                    // the one that ranked
    std::vector<DesignCandidate> candidates;  // best first
    bool simulated = false;
};

// Ranks the candidates; with `out`, claims it (marked as a design's) and writes
// design.json and design.csv there (and simulated/ with simulate). Bad values are
// RequestErrors naming the caller's argument, before anything is written.
DesignResult design(const DesignRequest &request);

// The ranking as design.json holds it: {"candidates": [{rank, baseline_mm, ...}]}.
Json designJson(const DesignResult &result);
// The ranking as design.csv: a row per candidate and range.
std::string designCsv(const DesignResult &result);

// Candidates are ranked in memory and each is printed to the CSV once per range: more
// than this many baselines (or baseline x lens pairs) is a typo, not a design question.
constexpr size_t kMaxBaselines = 100000;
constexpr size_t kMaxCandidates = 1000000;

} // namespace binocle::app
