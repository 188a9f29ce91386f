// SPDX-License-Identifier: MIT
// The calibration of several scenes (see replay_plan.hpp).
#include "replay_plan.hpp"

#include "replay_files.hpp"

namespace fs = std::filesystem;

namespace binocle::replay {

std::string publishFirst(const std::vector<std::pair<fs::path, PinholePair>> &calibrations, const sdk::Host &host) {
    if (calibrations.empty()) return {};
    for (const auto &c : calibrations)
        if (!c.second.sameAs(calibrations.front().second)) {
            host.warning("replay: calibrations differ between frames (" + inQuotes(calibrations.front().first) + " vs " +
                         inQuotes(c.first) + "); the first one is published, each frame's metadata carries its own " +
                         "focal_length_px and baseline_mm");
            break;
        }
    return calibrations.front().second.toYaml();
}

Plan planBag(const McapSettings &m, bool calibrationGiven, const sdk::Host &host) {
    Plan plan;
    plan.layout = "mcap";
    plan.bag = std::make_shared<McapPairs>(m, host);
    const McapPairs &bag = *plan.bag;
    host.info("replay: bag " + bag.files() + ": " + std::to_string(bag.pairs().size()) + " pairs of " + bag.leftTopic() +
              " and " + bag.rightTopic() + "; topics: " + bag.topicList());
    for (size_t i = 0; i < bag.pairs().size(); ++i) {
        FrameFiles f;
        f.bagPair = static_cast<int64_t>(i);
        f.hasTimestamps = true;
        f.timestampLeftNs = bag.pairs()[i].stampLeftNs;
        f.timestampRightNs = bag.pairs()[i].stampRightNs;
        f.facts.emplace_back("left_topic", bag.leftTopic());
        f.facts.emplace_back("right_topic", bag.rightTopic());
        plan.frames.push_back(std::move(f));
    }
    std::string why;
    plan.calibration = bag.calibrationYaml(why);
    if (plan.calibration.empty() && !calibrationGiven)
        host.warning("replay: " + why + "; the bag brings no calibration (set `calibration`)");
    return plan;
}

} // namespace binocle::replay
