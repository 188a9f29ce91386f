#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The second tree of the test command: clang with AddressSanitizer + UndefinedBehavior
# Sanitizer (-DBINOCLE_SANITIZE=address,undefined, float-cast-overflow included) and the
# libFuzzer harnesses (-DBINOCLE_FUZZ=ON), in ./build-sanitize (or
# $BINOCLE_SANITIZE_BUILD_DIR). Builds only what it runs:
#   1. the test executables labelled "sanitize" (host, config, replay, recorder, pipeline
#      and the bad-input corpus) under ASan + UBSan, halting on the first finding;
#   2. each fuzz harness for $BINOCLE_FUZZ_SECONDS seconds (default 10) from its seed
#      corpus in tests/fuzz/corpus/.
# A finding fails the step. BINOCLE_SKIP_FUZZ=1 skips 2.
set -euo pipefail
cd "$(dirname "$0")/.."
dir="${BINOCLE_SANITIZE_BUILD_DIR:-build-sanitize}"
seconds="${BINOCLE_FUZZ_SECONDS:-10}"
jobs="$(nproc)"
start=$(date +%s)
# ccache (when installed), as scripts/build.sh: scripts/ccache-env.sh.
source scripts/ccache-env.sh
if [ ! -f "$dir/build.ninja" ]; then
  # -O0 -g1: half the compile time of -O1 (measured: 4.5 vs 8.8 CPU-s for a typical
  # translation unit), which is what CI's budget is short of; line tables for the reports.
  cmake -S . -B "$dir" -G Ninja -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O0 -g1" \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O0 -g1" \
    -DBINOCLE_SANITIZE=address,undefined -DBINOCLE_FUZZ=ON -DBINOCLE_BUILD_BENCH=OFF \
    -DBINOCLE_FUZZ_SECONDS="$seconds" "${launcher[@]}"
fi
# The plugins at -O1 (still instrumented): the simulated rig renders a frame in about 7 s
# at -O0 and 0.65 s at -O1, and the tests that run it held most of the step's test time.
cmake -S . -B "$dir" -DBINOCLE_FUZZ_SECONDS="$seconds" -DBINOCLE_PLUGIN_OPTIMIZATION=-O1 >/dev/null
# The executables of the labelled tests (tests/CMakeLists.txt collects them, one
# "<target> <gtest filter>" per line).
mapfile -t lines < <(grep -v '^$' "$dir/sanitize-targets.txt")
targets=()
for line in "${lines[@]}"; do targets+=("${line%% *}"); done
cmake --build "$dir" -j "$jobs" --target binocle "${targets[@]}" binocle_fuzzers
built=$(date +%s)
# Leak detection is off: the plugins' libraries (OpenCV's thread pool, GLib, Aravis)
# keep allocations for the life of the process by design.
export ASAN_OPTIONS="halt_on_error=1:abort_on_error=1:detect_leaks=0:strict_string_checks=1:detect_stack_use_after_return=1"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
# The labelled executables themselves, each running its tests with its SANITIZE_FILTER
# (which CTest's registration knows nothing of), $jobs at a time; each one's output goes to its log, printed when it fails.
export BINOCLE_PLUGIN_PATH="$PWD/$dir/lib/binocle/plugins"
mkdir -p "$dir/sanitize-logs"
run_one() { # <target> <gtest filter> <shard index>
  local exe log t0 status=0
  exe=$(find "$dir/tests" -type f -name "$1" -perm -u+x | head -n 1)
  log="$PWD/$dir/sanitize-logs/$1.$3.log"
  [ -n "$exe" ] || { echo "sanitize: no executable for $1" >&2; return 1; }
  t0=$(date +%s)
  (cd "$(dirname "$exe")" && GTEST_TOTAL_SHARDS="$jobs" GTEST_SHARD_INDEX="$3" timeout 900 "./$1" --gtest_brief=1 "--gtest_filter=$2") >"$log" 2>&1 || status=$?
  if [ "$status" = 0 ]; then
    echo "== $1 shard $(( $3 + 1 ))/$jobs (ASan + UBSan, filter $2): passed in $(( $(date +%s) - t0 )) s"
  else
    cat "$log"
    echo "sanitize: $1 shard $(( $3 + 1 ))/$jobs FAILED (exit $status; log: $log)" >&2
    return 1
  fi
}
export -f run_one
export dir jobs
# Each executable in $jobs shards (GoogleTest's GTEST_TOTAL_SHARDS): a few executables
# hold most of the time under ASan (cli_test, record_test, bad_input_test: a minute or
# more each), and whole executables left one core idle at the end. The tests of one
# executable already run side by side under ctest, so shards may too.
failed=0
for line in "${lines[@]}"; do
  for ((shard = 0; shard < jobs; ++shard)); do echo "$shard $line"; done
done | xargs -d '\n' -P "$jobs" -I{} bash -fc 'set -- $0; run_one "$2" "$3" "$1"' {} || failed=1
[ "$failed" = 0 ] || exit 1
tested=$(date +%s)
if [ "${BINOCLE_SKIP_FUZZ:-0}" != 1 ]; then
  ctest --test-dir "$dir" -L fuzz --output-on-failure -j "$jobs" --timeout 600
fi
end=$(date +%s)
echo "sanitize: build $((built - start)) s, tests under ASan+UBSan $((tested - built)) s, fuzzing $((end - tested)) s"
