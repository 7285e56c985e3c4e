#!/usr/bin/env bash
# Installs every Debian package lidarshop needs to build, test and benchmark. Idempotent: packages already
# present are skipped, so running it again costs a few seconds.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config git ccache
  clang clang-format libclang-rt-14-dev
  libeigen3-dev libembree-dev libtbb-dev libnanoflann-dev
  libopencv-dev libopencv-contrib-dev libopenexr-dev
  libcli11-dev nlohmann-json3-dev libspdlog-dev libfmt-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libmaxflow-dev libsuitesparse-dev liblzf-dev libpugixml-dev libcgal-dev
  libcpp-httplib-dev libkainjow-mustache-dev pybind11-dev python3-dev python3-numpy python3-pytest python3-distributed
  nodejs chromium
)

missing=()
for package in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$package")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages present"
  exit 0
fi

sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then sudo_cmd=(sudo); fi
echo "setup: installing ${#missing[@]} packages: ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "setup: done"
