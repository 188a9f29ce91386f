#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Submits a design sweep to Slurm as a job array of N shards and a merge job that runs
# when every shard has succeeded:
#   submit-sweep.sh SWEEP.yaml OUT N [sbatch options...]
# e.g. scripts/slurm/make-sweep.sh sweep.yaml && scripts/slurm/submit-sweep.sh sweep.yaml out/sweep 64 --partition=cpu
# The merged results (the same rows as one unsharded run) land in OUT/merged.
set -euo pipefail
[ $# -ge 3 ] || { sed -n '3,7p' "$0" | sed 's/^# \{0,1\}//' >&2; exit 2; }
file=$(realpath "$1") out=$(realpath -m "$2") n=$3; shift 3
here=$(cd "$(dirname "$0")" && pwd)
binocle=$(realpath "${BINOCLE:-$here/../../build/bin/binocle}")
[ -x "$binocle" ] || { echo "submit-sweep.sh: $binocle is not executable (build first, or set BINOCLE)" >&2; exit 1; }
mkdir -p "$out/logs"
array=$(sbatch --parsable --array="1-$n" --output="$out/logs/%A_%a.out" \
  --export="ALL,SWEEP_FILE=$file,SWEEP_OUT=$out,BINOCLE=$binocle" "$@" "$here/sweep-array.sbatch")
array=${array%%;*}
shards=()
for k in $(seq 1 "$n"); do shards+=("$out/shard_$k"); done
merge=$(sbatch --parsable --dependency="afterok:$array" --output="$out/logs/merge_%j.out" "$@" \
  --wrap="'$binocle' experiment merge '$out/merged' ${shards[*]}")
echo "array job $array ($n shards), merge job ${merge%%;*}: results in $out/merged"
