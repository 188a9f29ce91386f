// SPDX-License-Identifier: MIT
// The writer stage's outputs: what a run keeps of each finished frame. The folder of
// `binocle run --out DIR` is one FrameWriter; other containers (a bag) are others.
#pragma once

#include "config/rig_config.hpp"

#include <memory>
#include <nlohmann/json.hpp>
#include <string>

namespace binocle {

struct FrameResult;

// Called on the writer stage, in frame order, one frame at a time, after the frame's
// evaluators. A throw fails the run (the frames written before stay). The frame's images
// and cloud are valid during the call only.
class FrameWriter {
public:
    virtual ~FrameWriter() = default;
    virtual void write(const FrameResult &frame) = 0;
    // After the last frame, before summary.json is written: what the writer adds to it.
    virtual void finish(nlohmann::ordered_json &summary) { (void)summary; }
};

// Writes what `outputs` asks for of one frame into `dir` (disparity PNG/PFM, colourised
// disparity, rectified images, cloud PLY), each file atomically; names carry the sequence.
void writeFrameOutputs(const FrameResult &r, const OutputOptions &outputs, const std::string &dir);

// The folder outputs: writeFrameOutputs, then one line of figures per frame in
// DIR/frames.jsonl, flushed as it is written (a killed run keeps every finished frame).
std::unique_ptr<FrameWriter> makeFolderWriter(const std::string &dir, const OutputOptions &outputs);

} // namespace binocle
