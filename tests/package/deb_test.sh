#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Builds the binocle and binocle-dev packages (cpack -G DEB) from the build tree given as
# $1, extracts them with dpkg -x into a temporary prefix and runs `binocle plugins` and
# a rig from there, with BINOCLE_PLUGIN_PATH unset: the extracted tree must find its own
# plugins and configs.
set -euo pipefail
build_dir=$(cd "$1" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
if ! cpack -G DEB --config "$build_dir/CPackConfig.cmake" -B "$work/pkg" >cpack.log 2>&1; then
  cat cpack.log
  exit 1
fi
ls pkg/*.deb
for name in binocle binocle-dev; do
  deb=$(ls pkg/"${name}"_*.deb)
  dpkg-deb --field "$deb" Package | grep -qx "$name"
  dpkg -x "$deb" root
done
unset BINOCLE_PLUGIN_PATH
bin="$work/root/usr/bin/binocle"
fail() { echo "FAIL: $*"; exit 1; }
[ -x "$bin" ] || fail "no usr/bin/binocle in the package"
plugins=$("$bin" plugins --verbose)
# Here-strings, not pipes: under pipefail, a reader that stops early (head, grep -q)
# would make the writer's SIGPIPE fail the test.
head -n 40 <<<"$plugins"
for p in sim replay sgbm bm ground paper disparity; do
  grep -qF "file: $work/root/usr/lib/binocle/plugins/binocle_$p.so" <<<"$plugins" || fail "plugin $p not loaded from the package"
done
"$bin" run "$work/root/usr/share/binocle/configs/rigs/opencv-aloe.yaml" --quiet --frames 1 --out "$work/out"
grep -q '"status": "ok"' "$work/out/summary.json" || fail "the rig did not run from the package"
[ -f root/usr/share/bash-completion/completions/binocle ] || fail "no bash completion"
grep -q "complete .*binocle" root/usr/share/bash-completion/completions/binocle || fail "empty bash completion"
[ -f root/usr/include/binocle/plugin.hpp ] || fail "binocle-dev lacks the SDK headers"
[ -f root/usr/lib/cmake/Binocle/BinocleConfig.cmake ] || fail "binocle-dev lacks the CMake package"
echo "packages OK"
