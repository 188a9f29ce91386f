// SPDX-License-Identifier: MIT
// What crosses between Binocle and its helper process for the cloud transform's calls:
// apply's reply (its cloud crosses as ipc_planes.hpp's clouds).
// Next to the kind (kind_transform.cpp); round trips: tests/host/isolation_codec_test.cpp.
// Internal to host/.
#pragma once

#include "host/ipc_wire.hpp"

#include <cstdint>
#include <tuple>

namespace binocle::wire {

// Transform apply's reply: the cloud's count and frame, and where its arrays are now.
struct AppliedCloud {
    int64_t count = 0;
    int32_t frame = 0;
    uint64_t xyz = 0, rgb = 0, pixel = 0;
};
constexpr auto wireFields(const AppliedCloud *) {
    return std::make_tuple(&AppliedCloud::count, &AppliedCloud::frame, &AppliedCloud::xyz, &AppliedCloud::rgb, &AppliedCloud::pixel);
}

} // namespace binocle::wire
