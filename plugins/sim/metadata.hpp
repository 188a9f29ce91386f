// SPDX-License-Identifier: MIT
// The truth the `sim` source attaches to a frame: rig parameters and the positions and
// sizes of the scene's objects in the ground frame of that frame (YAML text).
#pragma once

#include "rig.hpp"
#include "scene.hpp"

#include <cstdint>
#include <string>

namespace binocle::sim {

std::string frameMetadata(const Scene &scene, const StereoRig &rig, const RigPose &pose, uint64_t frame);

} // namespace binocle::sim
