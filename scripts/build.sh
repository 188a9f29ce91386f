#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Configures and builds Binocle into ./build (or $BINOCLE_BUILD_DIR). Idempotent.
#
#   bash scripts/build.sh          everything: the CLI, the plugins, the tests, the benchmarks
#   bash scripts/build.sh --app    the CLI, its plugins and its helper process only (what
#                                  `binocle` runs; the demo): no test tool needed
#   bash scripts/build.sh [--app] TARGET...   those targets only
#
# $BINOCLE_CMAKE_ARGS: extra arguments for the first configuration of the tree.
# Uses ccache when it is installed, so that a rebuild from a fresh clone is quick.
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir="${BINOCLE_BUILD_DIR:-build}"
app=0
targets=()
for arg in "$@"; do
  case "$arg" in
    --app) app=1 ;;
    -*) echo "build.sh: unknown option '$arg'; expected --app or target names" >&2; exit 2 ;;
    *) targets+=("$arg") ;;
  esac
done
[ "$app" = 0 ] || [ ${#targets[@]} -gt 0 ] || targets=(binocle)
# ccache (when installed): scripts/ccache-env.sh.
source scripts/ccache-env.sh
# The tests and benchmarks need the test tools (scripts/install-deps.sh test): a tree
# for the application alone leaves them out; building everything turns them on.
if [ "$app" = 1 ]; then suite=OFF; else suite=ON; fi
if [ ! -f "$build_dir/build.ninja" ]; then
  # -g1 (line tables: backtraces keep their file:line) instead of -g: the same code,
  # measured 27-37 % less compile time per file and much smaller objects to link.
  # The tests' own code at -O0 (BINOCLE_TEST_OPTIMIZATION, tests/CMakeLists.txt): the test
  # files are mostly GoogleTest's macros. -O1 took 28-38 % less CPU per test file than -O2
  # (viewer_test 32 -> 23 s, record_test 16 -> 11 s, json_test 7.0 -> 4.4 s) and -O0 13 %
  # less than -O1 (14 test files, 51 -> 44 s); the framework and the plugins stay at -O2.
  cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo "${launcher[@]}" \
    -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" \
    -DBINOCLE_TEST_OPTIMIZATION=-O0 \
    -DBINOCLE_BUILD_TESTS="$suite" -DBINOCLE_BUILD_BENCH="$suite" ${BINOCLE_CMAKE_ARGS:-}
elif [ "$suite" = ON ] && ! grep -q '^BINOCLE_BUILD_TESTS:BOOL=ON$' "$build_dir/CMakeCache.txt"; then
  # A tree the demo configured for the application alone: now the whole suite.
  cmake -S . -B "$build_dir" -DBINOCLE_BUILD_TESTS=ON -DBINOCLE_BUILD_BENCH=ON
fi
target_args=()
for t in "${targets[@]}"; do target_args+=(--target "$t"); done
cmake --build "$build_dir" -j "$(nproc)" "${target_args[@]}"
