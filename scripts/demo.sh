#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Installs what is missing, builds, and runs the main job on its built-in default.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
build_dir="${BINOCLE_BUILD_DIR:-build}"
out="${BINOCLE_DEMO_OUT:-out/demo}"
"$build_dir/bin/binocle" plugins
"$build_dir/bin/binocle" run configs/rigs/opencv-aloe.yaml --out "$out"
echo "demo: results in $out (disparity PNGs, PLY cloud in ground coordinates, summary.json)"
