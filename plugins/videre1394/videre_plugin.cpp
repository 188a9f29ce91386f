// SPDX-License-Identifier: MIT
// videre1394: the plugin's registration; the logic is in videre_source.cpp, the device
// layer on libdc1394 in videre_device_dc1394.cpp.
#include "videre_source.hpp"

BINOCLE_EXPORT_SOURCE(binocle::videre1394::VidereSource, "videre1394", "1.0.0",
                      "Videre Design stereo heads on IEEE 1394 (libdc1394): interleaved pair split, decimation, "
                      "stored calibration")
