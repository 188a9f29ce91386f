#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Installs the Debian 12 packages Binocle needs, only those missing. Idempotent.
#
#   bash scripts/install-deps.sh run    what building and running Binocle needs (the demo)
#   bash scripts/install-deps.sh test   that, plus the test tools (the test command); the default
#
# The groups are apart so that a user who wants to see Binocle work does not wait for a
# browser, a batch scheduler, a second compiler and sample data (several hundred MB)
# that only the tests use.
set -euo pipefail
cd "$(dirname "$0")/.."

group="${1:-test}"
case "$group" in
  run | test) ;;
  *) echo "install-deps: unknown group '$group'; expected 'run' or 'test'" >&2; exit 2 ;;
esac

# Building and running: the compiler and build tools, the libraries the framework and
# the plugins link (gige: Aravis; videre1394: libdc1394; v4l2: libv4l; MCAP recordings:
# zstd and lz4; the Python module: pybind11, Python's headers and numpy).
run_packages=(
  build-essential cmake ninja-build pkg-config git ccache
  libopencv-dev libjpeg-dev libeigen3-dev libyaml-cpp-dev libboost-dev libboost-filesystem-dev
  libcli11-dev nlohmann-json3-dev libspdlog-dev libfmt-dev
  libaravis-dev libusb-1.0-0-dev libdc1394-dev libv4l-dev
  libzstd-dev liblz4-dev
  pybind11-dev python3-dev python3-numpy
)
# The tests and benchmarks: GoogleTest and Google Benchmark; opencv-doc's stereo pairs
# (the aloe rig, calibration boards); network namespaces (unshare, ip) and Aravis's
# fake GigE cameras; clang + libFuzzer for the sanitizer tree; LLD (links both trees'
# hundred-odd executables four times faster than GNU ld); libabigail for the ABI
# check; headless Chromium + Selenium for the browser tests; a one-node Slurm; pytest
# for the Python module.
test_packages=(
  libgtest-dev libgmock-dev libbenchmark-dev
  opencv-doc util-linux iproute2 aravis-tools aravis-tools-cli
  clang libfuzzer-14-dev lld abigail-tools
  chromium chromium-driver python3-selenium
  slurm-wlm munge
  python3-pytest
)

packages=("${run_packages[@]}")
if [ "$group" = test ]; then
  packages+=("${test_packages[@]}")
  # The MCAP tests read Binocle's files with the reference implementation's npm
  # packages. Node and npm from Debian only when there is no npm at all: a newer Node
  # that is already installed (with its own npm) stays.
  command -v npm >/dev/null 2>&1 || packages+=(nodejs npm)
fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages of the '$group' group present"
else
  echo "install-deps: installing ${missing[*]}"
  if [ "$(id -u)" -ne 0 ]; then
    echo "install-deps: missing packages and not root: run as root, or: sudo apt-get install ${missing[*]}" >&2
    exit 1
  fi
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -q
  apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

# The test group's npm packages (the MCAP reference reader and writer), when the script
# that installs them is in this tree.
if [ "$group" = test ] && [ -f scripts/install-npm-test-deps.sh ]; then
  bash scripts/install-npm-test-deps.sh
fi
