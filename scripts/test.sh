#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Installs what is missing (the test group: running Binocle's packages and the test
# tools), builds everything, and runs the whole test suite (CTest), then the
# sanitizer and fuzzing step (scripts/sanitize.sh: a second tree, clang with ASan +
# UBSan, the labelled fast subset and every fuzz harness for a bounded time).
# BINOCLE_SANITIZE_STEP=0 skips that step (a quicker local run; CI never sets it).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh test
bash scripts/build.sh
build_dir="${BINOCLE_BUILD_DIR:-build}"
ctest --test-dir "$build_dir" --output-on-failure -j "$(nproc)" --timeout 600
# Second tree: the fast subset under ASan + UBSan, then every fuzz harness for a bounded
# time (scripts/sanitize.sh).
if [ "${BINOCLE_SANITIZE_STEP:-1}" != 0 ]; then
  bash scripts/sanitize.sh
fi
