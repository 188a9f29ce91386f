#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Writes the experiment file of a design sweep: every baseline x lens x range of the
# grid, one test each, on the simulated head (configs/rigs/sim-e1.yaml, its lens table).
#   make-sweep.sh OUT.yaml [--baselines 50:300:10] [--lenses 2.8,4,8,12,16]
#                 [--ranges 4000:20000:2000] [--repeats 5]
# Default: 26 baselines x 5 lenses x 9 ranges = 1170 tests, 5 repeats each.
set -euo pipefail
usage() { sed -n '3,7p' "$0" | sed 's/^# \{0,1\}//' >&2; exit 2; }
[ $# -ge 1 ] || usage
out=$1; shift
baselines=50:300:10 lenses=2.8,4,8,12,16 ranges=4000:20000:2000 repeats=5
while [ $# -gt 0 ]; do
  case $1 in
    --baselines) baselines=$2; shift 2 ;;
    --lenses) lenses=$2; shift 2 ;;
    --ranges) ranges=$2; shift 2 ;;
    --repeats) repeats=$2; shift 2 ;;
    *) echo "make-sweep.sh: unknown option '$1'" >&2; usage ;;
  esac
done
# MIN:MAX:STEP or a comma list -> one value per line
expand() {
  case $1 in
    *:*:*) IFS=: read -r lo hi step <<<"$1"
           awk -v lo="$lo" -v hi="$hi" -v s="$step" 'BEGIN { if (s <= 0 || hi < lo) exit 1; for (v = lo; v <= hi + 1e-9; v += s) print v }' ||
             { echo "make-sweep.sh: '$1': expected MIN:MAX:STEP with STEP > 0 and MAX >= MIN" >&2; exit 2; } ;;
    *) tr ',' '\n' <<<"$1" ;;
  esac
}
mapfile -t B < <(expand "$baselines")
mapfile -t F < <(expand "$lenses")
mapfile -t R < <(expand "$ranges")
root=$(cd "$(dirname "$0")/../.." && pwd)
bmin=$(printf '%s\n' "${B[@]}" | sort -g | head -1)
bmax=$(printf '%s\n' "${B[@]}" | sort -g | tail -1)
tmp="$out.tmp.$$"
{
  echo "# Design sweep written by scripts/slurm/make-sweep.sh: baselines $baselines mm,"
  echo "# lenses $lenses mm, ranges $ranges mm, $repeats repeats per test."
  echo "name: sweep"
  echo "description: \"design sweep: ${#B[@]} baselines x ${#F[@]} lenses x ${#R[@]} ranges\""
  echo "rig: $root/configs/rigs/sim-e1.yaml"
  echo "lens_table: $root/configs/lenses/videre.yaml"
  echo "baseline_range_mm: [$bmin, $bmax]"
  echo "disparity_search_px: [0, 64]"
  echo "panel: {width_mm: 2500, height_mm: 2000, center_x_mm: 0, base_z_mm: 0}"
  echo "repeats: $repeats"
  echo "jitter: {source.range_mm: 50, source.main_object_lateral_mm: 50, source.camera_height_mm: 10}"
  echo "defaults: {camera_height_mm: 1500, inclination_deg: 0}"
  echo "tests:"
  id=0
  for r in "${R[@]}"; do for b in "${B[@]}"; do for f in "${F[@]}"; do
    id=$((id + 1))
    echo "  - {id: $id, range_mm: $r, baseline_mm: $b, focal_length_mm: $f}"
  done; done; done
} >"$tmp"
mv "$tmp" "$out"
echo "$out: $id tests" >&2
