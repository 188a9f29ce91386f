#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Builds the binocle and binocle-dev packages, and python3-binocle when the module is
# built (cpack -G DEB), from the build tree given as $1, extracts them with dpkg -x into a
# temporary prefix and runs `binocle plugins` and a rig from there (and from Python),
# with BINOCLE_PLUGIN_PATH unset: the extracted tree must find its own plugins and configs.
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
# python3-binocle, when the module was built: imported from the unpacked tree, it finds
# the plugins and the helper of the unpacked binocle package from its own folder.
if ls pkg/python3-binocle_*.deb >/dev/null 2>&1; then
  pydeb=$(ls pkg/python3-binocle_*.deb)
  dpkg-deb --field "$pydeb" Package | grep -qx python3-binocle
  dpkg -x "$pydeb" root
  [ -f root/usr/lib/python3/dist-packages/binocle/__init__.pyi ] || fail "python3-binocle lacks its type stubs"
  PYTHONPATH="$work/root/usr/lib/python3/dist-packages" /usr/bin/python3 - "$work/root/usr" <<'PY' || fail "the python3-binocle package does not run from the package"
import sys
import binocle
prefix = sys.argv[1]
assert binocle.install_prefix() == prefix, binocle.install_prefix()
plugins = {p["name"]: p["path"] for p in binocle.plugins()}
for name in ("replay", "bm", "ground"):
    assert plugins[name] == f"{prefix}/lib/binocle/plugins/binocle_{name}.so", plugins
rig = binocle.Rig(f"{prefix}/share/binocle/configs/rigs/opencv-aloe.yaml",
                  set={"matcher.plugin": "bm", "matcher.num_disparities": 128, "matcher.block_size": 15,
                       "matcher.isolation": "process"})
run = rig.run(frames=1)
frames = list(run)
assert frames[0].disparity.shape == (1110, 1282) and run.summary["status"] == "ok", run.summary
print("python3-binocle OK")
PY
fi
echo "packages OK"
