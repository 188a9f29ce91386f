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
# The executables of the labelled tests (tests/CMakeLists.txt collects them, one a line).
mapfile -t targets < <(grep -v '^$' "$dir/sanitize-targets.txt")
cmake --build "$dir" -j "$jobs" --target binocle "${targets[@]}" binocle_fuzzers
built=$(date +%s)
# Leak detection is off: the plugins' libraries (OpenCV's thread pool, GLib, Aravis)
# keep allocations for the life of the process by design.
export ASAN_OPTIONS="halt_on_error=1:abort_on_error=1:detect_leaks=0:strict_string_checks=1:detect_stack_use_after_return=1"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
# The labelled executables, as CTest registers them in this tree (tests/CMakeLists.txt:
# two GoogleTest shards each, with its SANITIZE_FILTER), $jobs at a time; a failing
# shard's output is printed. The shards matter here: a few executables hold most of the
# time under ASan (cli_test, bad_input_test, record_test), and whole ones left a core idle.
ctest --test-dir "$dir" -L sanitize --output-on-failure -j "$jobs" --timeout 600
tested=$(date +%s)
if [ "${BINOCLE_SKIP_FUZZ:-0}" != 1 ]; then
  ctest --test-dir "$dir" -L fuzz --output-on-failure -j "$jobs" --timeout 600
fi
end=$(date +%s)
echo "sanitize: build $((built - start)) s, tests under ASan+UBSan $((tested - built)) s, fuzzing $((end - tested)) s"
