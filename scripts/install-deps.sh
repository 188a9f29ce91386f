#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Installs the Debian 12 packages Binocle needs, only those missing. Idempotent.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config git
  libopencv-dev libeigen3-dev libyaml-cpp-dev libboost-dev libboost-filesystem-dev
  libaravis-dev libusb-1.0-0-dev aravis-tools aravis-tools-cli
  libdc1394-dev libv4l-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  opencv-doc util-linux iproute2 ccache
  libcli11-dev nlohmann-json3-dev libspdlog-dev libfmt-dev
  clang libfuzzer-14-dev abigail-tools
  chromium chromium-driver python3-selenium
  slurm-wlm munge
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
if [ "$(id -u)" -ne 0 ]; then
  echo "install-deps: missing packages and not root: run as root, or: sudo apt-get install ${missing[*]}" >&2
  exit 1
fi
export DEBIAN_FRONTEND=noninteractive
apt-get update -q
apt-get install -y -q --no-install-recommends "${missing[@]}"
