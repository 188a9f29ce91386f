#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The long fuzzing run: builds the harnesses (scripts/sanitize.sh's tree, clang +
# ASan + UBSan + libFuzzer) and runs each for RUNS inputs (default 1000000), or the
# ones named: bash scripts/fuzz.sh [RUNS] [harness...]. New inputs go to
# build-sanitize/tests/fuzz/corpus/<harness>/; a crash leaves the input that caused it
# next to it (build-sanitize/tests/fuzz/<harness>-crash-*): copy it into the seed corpus
# tests/fuzz/corpus/<harness>/ and into a regression test once fixed.
set -euo pipefail
cd "$(dirname "$0")/.."
runs="${1:-1000000}"
shift || true
dir="${BINOCLE_SANITIZE_BUILD_DIR:-build-sanitize}"
if [ ! -f "$dir/build.ninja" ]; then
  BINOCLE_SKIP_FUZZ=1 bash scripts/sanitize.sh
fi
cmake --build "$dir" -j "$(nproc)" --target binocle_fuzzers
harnesses=("$@")
if [ ${#harnesses[@]} -eq 0 ]; then
  mapfile -t harnesses < <(ls tests/fuzz/corpus)
fi
export ASAN_OPTIONS="halt_on_error=1:abort_on_error=1:detect_leaks=1"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
failed=0
for h in "${harnesses[@]}"; do
  work="$dir/tests/fuzz/corpus/$h"
  log="$dir/tests/fuzz/$h.log"
  mkdir -p "$work"
  echo "== $h: $runs inputs"
  start=$(date +%s)
  status=0
  "$dir/fuzz/$h" -runs="$runs" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
    "-artifact_prefix=$dir/tests/fuzz/$h-" "$work" "tests/fuzz/corpus/$h" >"$log" 2>&1 || status=$?
  grep -E "stat::number_of_executed_units|stat::peak_rss_mb|ERROR|SUMMARY|Test unit written" "$log" || true
  echo "   $(( $(date +%s) - start )) s, exit $status (log: $log)"
  [ "$status" -eq 0 ] || failed=1
done
exit "$failed"
