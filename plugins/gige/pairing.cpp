// SPDX-License-Identifier: MIT
// Stereo pairs from two streams (or one side-by-side stream): by time stamp, or by the
// software trigger the images answer.
#include "pairing.hpp"

#include <binocle/plugin.hpp>

#include <algorithm>
#include <cstdlib>
#include <sstream>

namespace binocle::gige {

namespace {

const char *statusName(ArvBufferStatus s) {
    switch (s) {
    case ARV_BUFFER_STATUS_SUCCESS: return "success";
    case ARV_BUFFER_STATUS_CLEARED: return "cleared";
    case ARV_BUFFER_STATUS_TIMEOUT: return "timeout";
    case ARV_BUFFER_STATUS_MISSING_PACKETS: return "missing_packets";
    case ARV_BUFFER_STATUS_WRONG_PACKET_ID: return "wrong_packet_id";
    case ARV_BUFFER_STATUS_SIZE_MISMATCH: return "size_mismatch";
    case ARV_BUFFER_STATUS_FILLING: return "filling";
    case ARV_BUFFER_STATUS_ABORTED: return "aborted";
    default: return "unknown";
    }
}

} // namespace

void Pairing::noteUnpaired(Slot &slot) {
    ++unpaired_;
    ++slot.unpaired;
}

// Frame ids between two complete images, not counted otherwise: the camera numbered
// them but they never left the stream (every packet lost, or no free buffer). Only
// complete images' ids are trusted: a buffer that lost packets may carry any id.
// GVSP 1.x ids run 1..65535, then wrap.
void Pairing::countIdGap(Slot &slot, uint64_t id) {
    if (id == 0) return;
    if (slot.lastFrameId) {
        const uint64_t last = *slot.lastFrameId;
        if (id > last) slot.idGap += id - last - 1;
        else if (last - id > 32768 && last <= 65535) slot.idGap += (65535 - last) + (id - 1);
        else return; // an older image given up late, or a repeat: nothing skipped, `last` stays
    }
    slot.lastFrameId = id;
}

uint64_t Pairing::incompleteImages(const Slot &slot) {
    uint64_t n = 0;
    for (const auto &[name, count] : slot.failures) n += count;
    return n;
}

// Ids skipped between complete images, less the incomplete images among them.
uint64_t Pairing::skippedIds(const Slot &slot) {
    const uint64_t incomplete = incompleteImages(slot);
    return slot.idGap > incomplete ? slot.idGap - incomplete : 0;
}

void Pairing::dropPending(Slot &slot, bool countUnpaired) {
    for (auto &p : slot.pending) {
        p.home->push(p.buffer);
        if (countUnpaired) noteUnpaired(slot);
    }
    slot.pending.clear();
}

void Pairing::requestTrigger(Slots &slots, Clock::time_point now) {
    for (auto &slot : slots) {
        dropPending(*slot, true);
        slot->answered = false;
        slot->trigger->request();
        if (!slot->awaitingSince) slot->awaitingSince = now;
    }
    triggerOutstanding_ = true;
}

void Pairing::collect(Slots &slots, Clock::time_point now) {
    for (auto &slotPtr : slots) {
        Slot &slot = *slotPtr;
        if (!slot.camera) continue;
        Camera &camera = *slot.camera;
        while (ArvBuffer *buffer = camera.tryPop()) {
            const ArvBufferStatus status = arv_buffer_get_status(buffer);
            if (trigger_ == Trigger::Software) {
                // Exactly one image per camera answers a trigger: anything more is stale.
                if (slot.answered) {
                    camera.home()->push(buffer);
                    if (status == ARV_BUFFER_STATUS_SUCCESS) noteUnpaired(slot);
                    continue;
                }
                slot.answered = true;
                slot.awaitingSince.reset();
            } else if (trigger_ == Trigger::FreeRun) {
                slot.awaitingSince = now;
            }
            if (status == ARV_BUFFER_STATUS_SUCCESS) countIdGap(slot, arv_buffer_get_frame_id(buffer));
            if (status != ARV_BUFFER_STATUS_SUCCESS) {
                ++slot.failures[statusName(status)];
                camera.home()->push(buffer);
                continue;
            }
            try {
                checkImage(camera, buffer);
            } catch (...) {
                if (trigger_ == Trigger::Software) triggerOutstanding_ = false;
                throw;
            }
            Pending p;
            p.buffer = buffer;
            p.home = camera.home();
            p.timestamp_ns = static_cast<int64_t>(deviceTime_ ? arv_buffer_get_timestamp(buffer) : arv_buffer_get_system_timestamp(buffer));
            p.frame_id = arv_buffer_get_frame_id(buffer);
            slot.pending.push_back(std::move(p));
            ++slot.images;
            // A partner that never comes must not hold every buffer of the stream.
            const size_t keep = std::max<size_t>(1, static_cast<size_t>(slot.settings.buffers / 2));
            while (slot.pending.size() > keep) {
                slot.pending.front().home->push(slot.pending.front().buffer);
                slot.pending.pop_front();
                noteUnpaired(slot);
            }
        }
    }
}

// Refuses a buffer that does not hold the image the camera was configured for.
void Pairing::checkImage(Camera &camera, ArvBuffer *buffer) {
    const int w = arv_buffer_get_image_width(buffer), h = arv_buffer_get_image_height(buffer);
    const ArvPixelFormat pf = arv_buffer_get_image_pixel_format(buffer);
    size_t size = 0;
    arv_buffer_get_image_data(buffer, &size);
    gint xPadding = 0, yPadding = 0;
    arv_buffer_get_image_padding(buffer, &xPadding, &yPadding);
    const PixelFormat &f = camera.format();
    const size_t needed = (static_cast<size_t>(w) * f.bytes_per_pixel + xPadding) * h;
    if (w == camera.width() && h == camera.height() && pf == f.arv && size >= needed) return;
    const PixelFormat *got = findPixelFormat(pf);
    std::ostringstream what;
    what << "gige: camera " << camera.label() << " sent a " << w << "x" << h << " "
         << (got ? got->name : ("pixel format 0x" + [&] { std::ostringstream x; x << std::hex << pf; return x.str(); }()))
         << " image of " << size << " bytes; expected " << camera.width() << "x" << camera.height() << " " << f.name
         << " (wrong frame size: was the camera reconfigured behind this source's back?)";
    camera.home()->push(buffer);
    throw sdk::Error(BINOCLE_ERR_DEVICE, what.str());
}

std::optional<Pair> Pairing::next(Slots &slots) {
    return trigger_ == Trigger::Software ? nextTriggered(slots) : nextByTimestamp(slots);
}

std::optional<Pair> Pairing::nextByTimestamp(Slots &slots) {
    if (sideBySide_) {
        Slot &slot = *slots[0];
        if (slot.pending.empty()) return std::nullopt;
        Pair pair{{std::move(slot.pending.front())}, {&slot}};
        slot.pending.pop_front();
        return pair;
    }
    Slot &l = *slots[0], &r = *slots[1];
    while (!l.pending.empty() && !r.pending.empty()) {
        const int64_t dt = l.pending.front().timestamp_ns - r.pending.front().timestamp_ns;
        if (std::llabs(dt) <= toleranceNs_) {
            Pair pair{{std::move(l.pending.front()), std::move(r.pending.front())}, {&l, &r}};
            l.pending.pop_front();
            r.pending.pop_front();
            return pair;
        }
        lastUnpairedDtNs_ = dt;
        Slot &older = dt < 0 ? l : r;
        older.pending.front().home->push(older.pending.front().buffer);
        older.pending.pop_front();
        noteUnpaired(older);
    }
    return std::nullopt;
}

// Software trigger: the images that answer one trigger make the pair, once every camera
// has answered; a failed image (or time stamps too far apart) drops the others and the
// next call triggers again. Time stamps alone could pair images of two triggers sent
// within pair_tolerance_ms.
std::optional<Pair> Pairing::nextTriggered(Slots &slots) {
    for (const auto &slot : slots)
        if (!slot->answered) return std::nullopt;
    triggerOutstanding_ = false;
    bool complete = true;
    for (const auto &slot : slots) complete = complete && slot->pending.size() == 1;
    if (complete && !sideBySide_) {
        const int64_t dt = slots[0]->pending.front().timestamp_ns - slots[1]->pending.front().timestamp_ns;
        if (std::llabs(dt) > toleranceNs_) {
            lastUnpairedDtNs_ = dt;
            complete = false;
        }
    }
    if (!complete) {
        for (auto &slot : slots) dropPending(*slot, true);
        return std::nullopt;
    }
    Pair pair;
    for (auto &slot : slots) {
        pair.parts.push_back(std::move(slot->pending.front()));
        slot->pending.clear();
        pair.slots.push_back(slot.get());
    }
    return pair;
}

} // namespace binocle::gige
