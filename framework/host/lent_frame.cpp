// SPDX-License-Identifier: MIT
// The frames a source lends: views of their planes, and the release when they die.
#include "host/lent_frame.hpp"

#include "host/instance_support.hpp"
#include "host/plugin_record.hpp"

#include <spdlog/spdlog.h>

namespace binocle {

LentFrame::LentFrame(std::shared_ptr<void> keep, const binocle_source_api *api, binocle_source *src,
                     const binocle_stereo_frame &f)
    : keep_(std::move(keep)), api_(api), src_(src), frame_(f) {}

LentFrame::LentFrame(std::shared_ptr<void> keep, const binocle_stereo_frame &f)
    : keep_(std::move(keep)), api_(nullptr), src_(nullptr), frame_(f) {}

LentFrame::~LentFrame() {
    if (!api_) return; // keep_ holds the copy; dropping it is the release
    try {
        const int32_t rc = api_->release_frame(src_, frame_.frame_id);
        if (rc != BINOCLE_OK) {
            const char *why = api_->last_error(src_);
            spdlog::error("source plugin '{}': release_frame of frame {} (sequence {}) failed ({}){}{}",
                          api_->header.name ? api_->header.name : "?", frame_.frame_id,
                          frame_.sequence, resultName(rc), why && *why ? ": " : "", why ? why : "");
        }
    } catch (...) {
    }
}

cv::Mat LentFrame::left() const { return view(frame_.left); }
cv::Mat LentFrame::right() const { return view(frame_.right); }

cv::Mat LentFrame::extra(const std::string &name) const {
    for (int32_t i = 0; i < frame_.extra_count; ++i)
        if (frame_.extras[i].name && name == frame_.extras[i].name) return view(frame_.extras[i].image);
    return {};
}

} // namespace binocle
