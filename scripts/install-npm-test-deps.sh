#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Installs the reference MCAP and ROS 2 message implementations that the MCAP tests
# (tests/mcap) check Binocle's files against: @mcap/core, @mcap/support, @foxglove/rosmsg,
# @foxglove/rosmsg2-serialization, into tests/mcap/node/node_modules (git-ignored).
# Idempotent: when every package is already there, nothing is fetched, so it is safe to
# call offline (the tests skip, saying why, when the packages are absent).
# usage: bash scripts/install-npm-test-deps.sh [--force]
set -euo pipefail
cd "$(dirname "$0")/../tests/mcap/node"
packages=(@mcap/core @mcap/support @foxglove/rosmsg @foxglove/rosmsg2-serialization)
missing=0
for p in "${packages[@]}"; do
  [ -f "node_modules/$p/package.json" ] || missing=1
done
if [ "$missing" = 0 ] && [ "${1:-}" != "--force" ]; then
  echo "install-npm-test-deps: ${packages[*]} already in $(pwd)/node_modules"
  exit 0
fi
command -v npm >/dev/null || { echo "install-npm-test-deps: npm not found; install node and npm" >&2; exit 1; }
# package.json pins the versions; package-lock.json (when present) the whole tree.
if [ -f package-lock.json ]; then
  npm ci --no-audit --no-fund --loglevel=error
else
  npm install --no-audit --no-fund --loglevel=error
fi
for p in "${packages[@]}"; do
  [ -f "node_modules/$p/package.json" ] || { echo "install-npm-test-deps: $p did not install" >&2; exit 1; }
done
echo "install-npm-test-deps: installed ${packages[*]} into $(pwd)/node_modules"
