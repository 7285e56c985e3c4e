#!/usr/bin/env bash
# Configures and builds lidarshop in ./build/release (installing the Debian packages first).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
# Paths relative to the checkout in ccache's hash: a fresh clone elsewhere reuses the objects of an earlier build.
export CCACHE_BASEDIR="$PWD" CCACHE_NOHASHDIR=true
cmake -S . -B build/release -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build/release -j "$(nproc)"
bash scripts/web.sh build
