// SPDX-License-Identifier: MIT
// v4l2: the errors a user reads when the kernel refuses a call (see v4l2_stream.hpp).
#include "v4l2_stream.hpp"

#include <cerrno>

namespace binocle::v4l2 {

using sdk::Error;

namespace {

const char *errnoName(int e) {
    switch (e) {
    case ENOENT: return "ENOENT";
    case ENODEV: return "ENODEV";
    case ENXIO: return "ENXIO";
    case EBUSY: return "EBUSY";
    case EACCES: return "EACCES";
    case EPERM: return "EPERM";
    case EINVAL: return "EINVAL";
    case ENOTTY: return "ENOTTY";
    case EIO: return "EIO";
    case ENOMEM: return "ENOMEM";
    case EPIPE: return "EPIPE";
    default: return "errno";
    }
}

std::string devicesHere() {
    std::vector<std::string> paths;
    try {
        paths = deviceSystem().listDevices();
    } catch (...) {
    }
    if (paths.empty()) return "no V4L2 device on this machine";
    std::string all;
    for (const auto &p : paths) all += (all.empty() ? "" : ", ") + p;
    return "V4L2 devices here: " + all;
}

} // namespace

[[noreturn]] void throwFor(const std::string &path, const DeviceError &e, const std::string &doing) {
    const std::string call = std::string(" (") + errnoName(e.err()) + " in " + e.call() + ")";
    switch (e.err()) {
    case ENOENT:
        throw Error(BINOCLE_ERR_NOT_FOUND, "v4l2: " + path + ": no such device" + call + " while " + doing + "; " +
                                               devicesHere());
    case ENODEV:
    case ENXIO:
        throw Error(BINOCLE_ERR_DEVICE, "v4l2: " + path + " went away" + call + " while " + doing +
                                            ": the device was unplugged or its driver reset it");
    case EBUSY:
        throw Error(BINOCLE_ERR_BUSY, "v4l2: " + path + " is busy" + call + " while " + doing +
                                          ": another program (or another source of this rig) is using it");
    case EACCES:
    case EPERM:
        throw Error(BINOCLE_ERR_IO, "v4l2: " + path + ": permission denied" + call + " while " + doing +
                                        "; is the user in the group that owns it (usually 'video')?");
    case ENOTTY:
        throw Error(BINOCLE_ERR_UNSUPPORTED, "v4l2: " + path + " is not a V4L2 device" + call + " while " + doing);
    default:
        throw Error(BINOCLE_ERR_DEVICE, "v4l2: " + path + ": " + e.what() + call + " while " + doing);
    }
}

} // namespace binocle::v4l2
