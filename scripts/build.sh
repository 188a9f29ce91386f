#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Configures and builds Binocle into ./build (or $BINOCLE_BUILD_DIR). Idempotent.
# Uses ccache when it is installed, so that a rebuild from a fresh clone is quick.
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir="${BINOCLE_BUILD_DIR:-build}"
# ccache: paths inside the checkout are hashed relative to it, so that clones in other
# folders (CI's fresh clone) share the cache.
export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$PWD}" CCACHE_NOHASHDIR="${CCACHE_NOHASHDIR:-1}"
if [ ! -f "$build_dir/build.ninja" ]; then
  launcher=()
  if command -v ccache >/dev/null 2>&1; then
    launcher=(-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
  fi
  cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo "${launcher[@]}" ${BINOCLE_CMAKE_ARGS:-}
fi
cmake --build "$build_dir" -j "$(nproc)"
