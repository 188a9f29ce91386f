#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Installs what is missing, builds, and runs the main job on its built-in default.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
build_dir="${BINOCLE_BUILD_DIR:-build}"
out="${BINOCLE_DEMO_OUT:-out/demo}"
binocle="$build_dir/bin/binocle"
"$binocle" plugins
# The main job: experiment E1 of METHOD.md on the simulated Videre-like head (nothing to
# download), then the design question it answers, for 6 m and 12 m.
"$binocle" experiment configs/experiments/e1.yaml --out "$out/e1"
"$binocle" design --range 6000 --top 5 --out "$out/design-6m"
"$binocle" design --range 12000 --top 5 --out "$out/design-12m"
echo "demo: E1 results in $out/e1 (results.csv, results.json, eta_3d_bars.png, eta_3d_vs_ff.png, test_<id>/)"
