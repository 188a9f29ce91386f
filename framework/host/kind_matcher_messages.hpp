// SPDX-License-Identifier: MIT
// What crosses between Binocle and its helper process for the matcher's calls:
// compute's request and disparity_range's reply.
// Next to the kind (kind_matcher.cpp); round trips: tests/host/isolation_codec_test.cpp.
// Internal to host/.
#pragma once

#include "host/ipc_wire.hpp"

#include <cstdint>
#include <tuple>
#include <utility>

namespace binocle::wire {

// Matcher compute: left and right at 0 and image_bytes, the disparity (CV_32F) at
// 2 * image_bytes; images tightly packed. The matcher's extras go after the disparity
// (at its page-aligned end), within extras_bytes; the reply describes them
// (putNamedImages, offsets from there).
struct ComputeRequest {
    int32_t width = 0, height = 0, cv_type = 0;
    uint64_t image_bytes = 0;
    uint64_t extras_bytes = 0;
};
constexpr auto wireFields(const ComputeRequest *) {
    return std::make_tuple(&ComputeRequest::width, &ComputeRequest::height, &ComputeRequest::cv_type,
                           &ComputeRequest::image_bytes, &ComputeRequest::extras_bytes);
}

// Matcher disparity_range's reply.
inline void putRange(Writer &w, std::pair<int32_t, int32_t> range) { w.put<int32_t>(range.first).put<int32_t>(range.second); }
inline std::pair<int32_t, int32_t> getRange(Reader &r) {
    const auto first = r.get<int32_t>();
    return {first, r.get<int32_t>()};
}

} // namespace binocle::wire
