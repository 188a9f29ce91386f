#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The first ten minutes: installs what running Binocle needs (only what is missing),
# builds what the demo runs (the CLI, its plugins and helper; no test), and runs the
# main job on its built-in default. Idempotent. The test tools and the test targets come
# with scripts/test.sh.
set -euo pipefail
cd "$(dirname "$0")/.."
start=$(date +%s)
bash scripts/install-deps.sh run
installed=$(date +%s)
bash scripts/build.sh --app
built=$(date +%s)
build_dir="${BINOCLE_BUILD_DIR:-build}"
out="${BINOCLE_DEMO_OUT:-out/demo}"
binocle="$build_dir/bin/binocle"
"$binocle" plugins
# A second run replaces the demo's own folders of the first (the commands refuse, or
# would mix, a folder that already holds results).
for d in e1 design-6m design-12m; do
  rm -rf -- "${out:?}/$d"
done
# The main job: experiment E1 of docs/method.md on the simulated Videre-like head
# (nothing to download), then the design question it answers, for 6 m and 12 m.
"$binocle" experiment configs/experiments/e1.yaml --out "$out/e1"
"$binocle" design --range 6000 --top 5 --out "$out/design-6m"
"$binocle" design --range 12000 --top 5 --out "$out/design-12m"
end=$(date +%s)
echo "demo: E1 results in $out/e1 (results.csv, results.json, eta_3d_bars.png, eta_3d_vs_ff.png, test_<id>/)"
echo "demo: the designs in $out/design-6m and $out/design-12m (design.csv, design.json)"
echo "demo: install $((installed - start)) s, build $((built - installed)) s, E1 and designs $((end - built)) s"
