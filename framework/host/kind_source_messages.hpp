// SPDX-License-Identifier: MIT
// What crosses between Binocle and its helper process for the source's calls: grab's
// request (its frame crosses as ipc_planes.hpp's frames).
// Next to the kind (kind_source.cpp); round trips: tests/host/isolation_codec_test.cpp.
// Internal to host/.
#pragma once

#include "host/ipc_wire.hpp"

#include <cstdint>

namespace binocle::wire {

// Source grab: the request's wait; the reply's bytes needed, then (when they fit the
// region) the frame.
inline void putGrabRequest(Writer &w, int32_t timeout_ms) { w.put<int32_t>(timeout_ms); }
inline int32_t getGrabRequest(Reader &r) { return r.get<int32_t>(); }

} // namespace binocle::wire
