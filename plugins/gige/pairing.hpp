// SPDX-License-Identifier: MIT
// How the gige source makes stereo pairs: it takes finished buffers out of the streams,
// refuses images of the wrong size, and pairs left and right by time stamp (free run,
// hardware trigger) or by the trigger they answer (software trigger). It counts what it
// could not pair.
#pragma once

#include "gige_slot.hpp"

#include <optional>
#include <string>
#include <vector>

namespace binocle::gige {

// The images of one frame, one per slot, in slot order, and their slots.
struct Pair {
    std::vector<Pending> parts;
    std::vector<Slot *> slots;
};

class Pairing {
public:
    Pairing(Trigger trigger, bool sideBySide, int64_t toleranceNs, bool deviceTime)
        : trigger_(trigger), sideBySide_(sideBySide), toleranceNs_(toleranceNs), deviceTime_(deviceTime) {}

    // Takes every finished buffer out of the streams of the cameras present; throws
    // sdk::Error(BINOCLE_ERR_DEVICE) for an image that is not what the camera was set to.
    void collect(Slots &slots, Clock::time_point now);
    // The next pair, if the images waiting make one.
    std::optional<Pair> next(Slots &slots);
    // Software trigger: asks every camera for one image.
    void requestTrigger(Slots &slots, Clock::time_point now);
    bool triggerOutstanding() const { return triggerOutstanding_; }
    void forgetTrigger() { triggerOutstanding_ = false; }

    // Gives the slot's waiting buffers back to their streams, counted as unpaired or not.
    void dropPending(Slot &slot, bool countUnpaired);

    uint64_t unpaired() const { return unpaired_; }
    int64_t lastUnpairedDtNs() const { return lastUnpairedDtNs_; }
    // Images that arrived incomplete, and frame ids skipped between complete ones.
    static uint64_t incompleteImages(const Slot &slot);
    static uint64_t skippedIds(const Slot &slot);

private:
    void noteUnpaired(Slot &slot);
    static void countIdGap(Slot &slot, uint64_t id);
    void checkImage(Camera &camera, ArvBuffer *buffer);
    std::optional<Pair> nextByTimestamp(Slots &slots);
    std::optional<Pair> nextTriggered(Slots &slots);

    Trigger trigger_;
    bool sideBySide_;
    int64_t toleranceNs_;
    bool deviceTime_;
    bool triggerOutstanding_ = false;
    uint64_t unpaired_ = 0;
    int64_t lastUnpairedDtNs_ = 0;
};

} // namespace binocle::gige
