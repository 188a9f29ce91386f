// SPDX-License-Identifier: MIT
// What crosses between Binocle and its helper process for the evaluator's calls:
// evaluate's input, encoded and decoded in kind_evaluator.cpp.
// Next to the kind (kind_evaluator.cpp); round trips: tests/host/isolation_codec_test.cpp.
// Internal to host/.
#pragma once

#include "host/ipc_planes.hpp"
#include "host/ipc_wire.hpp"

#include <binocle/abi.h>

#include <string>
#include <utility>

namespace binocle::wire {

// Evaluator evaluate: the input's planes in a Layout. The calibration and rig texts,
// which change rarely, are sent only when `sendTexts` (else the helper process keeps
// the last ones it got).
struct EvaluateTexts {
    std::pair<bool, std::string> calibration{false, ""}, rig{false, ""};
};
void putEvaluate(Writer &w, Layout &layout, const binocle_eval_input &in, bool sendCalibration, bool sendRig);
// What a decoded input points into; `texts` keeps the texts last sent.
struct EvaluateInput {
    binocle_eval_input in{};
    binocle_stereo_frame frame{};
    FrameTexts frameTexts;
    NamedImages disparityExtras;
    binocle_image images[3]{};
    binocle_cloud cloud{};
    std::pair<bool, std::string> output{false, ""};
};
void getEvaluate(Reader &r, Region region, EvaluateTexts &texts, EvaluateInput &out);

} // namespace binocle::wire
