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
sanitize="${BINOCLE_SANITIZE_STEP:-1}"
if [ "$sanitize" != 0 ]; then
  # The sanitizer tree builds while CTest runs, at the lowest priority: the tests leave
  # much of the two cores idle (they wait on child processes, sockets and deadlines) and
  # the build takes only that. Its own session, so that a failed CTest stops all of it.
  sanitize_log="$(mktemp)"
  setsid nice -n 19 bash scripts/sanitize.sh --build-only >"$sanitize_log" 2>&1 &
  sanitize_pid=$!
  trap 'kill -- "-$sanitize_pid" 2>/dev/null || true; rm -f "$sanitize_log"' EXIT
fi
ctest --test-dir "$build_dir" --output-on-failure -j "$(nproc)" --timeout 600
# Second tree: the fast subset under ASan + UBSan, then every fuzz harness for a bounded
# time (scripts/sanitize.sh; its build is done or finishing by now).
if [ "$sanitize" != 0 ]; then
  t0=$(date +%s)
  if ! wait "$sanitize_pid"; then
    cat "$sanitize_log"
    echo "test.sh: the sanitizer tree's build failed" >&2
    exit 1
  fi
  echo "$(tail -n 1 "$sanitize_log") while CTest ran, then $(( $(date +%s) - t0 )) s after it"
  bash scripts/sanitize.sh
fi
