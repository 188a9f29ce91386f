#!/bin/sh
# SPDX-License-Identifier: MIT
# Makes a folder of KITTI scene folders, one per pair with ground truth, of symlinks into a
# KITTI stereo training tree, for the benchmark (configs/experiments/benchmark-kitti.yaml):
# a tree's pairs are of several image sizes, and one run of the pipeline plays one size, so
# the benchmark runs each pair as a scene of its own. Nothing is copied.
#
# usage: scripts/kitti-scene-folders.sh TREE OUT
#   TREE: KITTI 2015 (image_2/, image_3/, disp_occ_0/, disp_noc_0/) or 2012 (image_0/,
#         image_1/, disp_occ/, disp_noc/) training folder
#   OUT:  made; OUT/<frame>/ holds left.png, right.png, disp_occ_<frame>.png and
#         disp_noc_<frame>.png (as ../shared/data/stereo-gt/kitti2012-000070/ does)
set -eu
[ $# -eq 2 ] || { echo "usage: $0 TREE OUT" >&2; exit 2; }
tree=$(cd "$1" && pwd) || { echo "kitti-scene-folders.sh: no folder '$1'" >&2; exit 2; }
out=$2
if [ -d "$tree/image_2" ]; then l=image_2 r=image_3 occ=disp_occ_0 noc=disp_noc_0
elif [ -d "$tree/image_0" ]; then l=image_0 r=image_1 occ=disp_occ noc=disp_noc
else echo "kitti-scene-folders.sh: '$1' holds neither image_2/ nor image_0/: not a KITTI stereo tree" >&2; exit 2; fi
[ -d "$tree/$occ" ] || [ -d "$tree/$noc" ] || { echo "kitti-scene-folders.sh: '$1' holds no $occ/ nor $noc/ (ground truth)" >&2; exit 2; }
mkdir -p "$out"
n=0
for gt in "$tree/$occ"/*.png "$tree/$noc"/*.png; do
    [ -f "$gt" ] || continue
    name=$(basename "$gt" .png)
    [ -d "$out/$name" ] && continue
    [ -f "$tree/$l/$name.png" ] && [ -f "$tree/$r/$name.png" ] || { echo "kitti-scene-folders.sh: $gt has no pair in $l/, $r/" >&2; exit 1; }
    mkdir -p "$out/$name"
    ln -sf "$tree/$l/$name.png" "$out/$name/left.png"
    ln -sf "$tree/$r/$name.png" "$out/$name/right.png"
    [ -f "$tree/$occ/$name.png" ] && ln -sf "$tree/$occ/$name.png" "$out/$name/disp_occ_$name.png"
    [ -f "$tree/$noc/$name.png" ] && ln -sf "$tree/$noc/$name.png" "$out/$name/disp_noc_$name.png"
    n=$((n + 1))
done
echo "kitti-scene-folders.sh: $n pairs in $out"
