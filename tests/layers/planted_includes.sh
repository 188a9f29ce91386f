#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# scripts/check-layers.sh fails where it should: on a copy of the tree's sdk/, base/,
# framework/, plugins/ and python/ it passes, then with includes planted across the
# layers (base/ -> framework/, a plugin -> framework/core, a plugin -> another plugin,
# sdk/ -> base/, framework/pipeline -> framework/app, the output folder's claim
# core/output_folder.hpp included by framework/cli and by python/, python/ -> a plugin,
# a cycle between two base/ modules) it exits 1 naming each planted file and line.
# Usage: planted_includes.sh SOURCE_DIR  (CTest: check_layers_planted).
set -euo pipefail
src="$(cd "${1:?usage: planted_includes.sh SOURCE_DIR}" && pwd)"
check="$src/scripts/check-layers.sh"
copy="$(mktemp -d "${TMPDIR:-/tmp}/binocle-layers.XXXXXX")"
trap 'rm -rf "$copy"' EXIT
# -L: the files themselves, never links back into the tree (planting must not touch it).
for top in sdk base framework plugins python; do cp -RL "$src/$top" "$copy/$top"; done
failed=0
fail() { echo "planted_includes: $*" >&2; failed=1; }

if ! out="$(bash "$check" "$copy" 2>&1)"; then
  fail "the unchanged copy is refused:"; echo "$out" >&2; exit 1
fi

# plant FILE INCLUDE: appends `#include INCLUDE` to FILE and prints "FILE:LINE".
plant() {
  printf '#include %s\n' "$2" >> "$copy/$1"
  echo "$1:$(wc -l < "$copy/$1")"
}
expect=(
  "$(plant base/input/names.cpp '"core/error.hpp"'): #include \"core/error.hpp\" (framework/core/error.hpp): base/input/ includes framework/"
  "$(plant plugins/replay/replay.cpp '"core/log.hpp"'): #include \"core/log.hpp\" (framework/core/log.hpp): plugin 'replay' includes framework/core/"
  "$(plant plugins/sim/scene.cpp '"replay/replay_files.hpp"'): #include \"replay/replay_files.hpp\" (plugins/replay/replay_files.hpp): plugin 'sim' includes plugins/replay/"
  "$(plant framework/pipeline/pipeline.cpp '"app/run_rig.hpp"'): #include \"app/run_rig.hpp\" (framework/app/run_rig.hpp): framework/pipeline/ includes framework/app/"
  "$(plant sdk/include/binocle/text.hpp '"input/names.hpp"'): #include \"input/names.hpp\" (base/input/names.hpp): the SDK includes base/"
  "$(plant framework/cli/cmd_run.cpp '"core/output_folder.hpp"'): #include \"core/output_folder.hpp\" (framework/core/output_folder.hpp): framework/cli/ includes the output folder's claim"
  "$(plant python/run.cpp '"core/output_folder.hpp"'): #include \"core/output_folder.hpp\" (framework/core/output_folder.hpp): python/ includes the output folder's claim"
  "$(plant python/convert.cpp '"replay/replay_files.hpp"'): #include \"replay/replay_files.hpp\" (plugins/replay/replay_files.hpp): python/ includes plugins/"
)
plant base/input/utf8.cpp '"method/statistics.hpp"' > /dev/null
plant base/method/statistics.cpp '"input/utf8.hpp"' > /dev/null
expect+=("include cycle between modules (base/, framework/): input -> method -> input")

status=0
out="$(bash "$check" "$copy" 2>&1)" || status=$?
[ "$status" = 1 ] || fail "expected exit status 1 with the planted includes, got $status"
for e in "${expect[@]}"; do
  grep -qF -- "check-layers: $e" <<< "$out" || fail "not reported: $e"
done
if [ "$failed" = 1 ]; then
  echo "--- check-layers.sh said:" >&2; echo "$out" >&2; exit 1
fi
echo "planted_includes: ok: the unchanged copy passes; ${#expect[@]} planted breaks each reported, exit 1"
