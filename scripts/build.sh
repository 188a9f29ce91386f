#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Configures and builds Binocle into ./build (or $BINOCLE_BUILD_DIR). Idempotent.
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir="${BINOCLE_BUILD_DIR:-build}"
if [ ! -f "$build_dir/build.ninja" ]; then
  cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo
fi
cmake --build "$build_dir" -j "$(nproc)"
