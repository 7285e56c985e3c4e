#!/usr/bin/env bash
# Configures and builds lidarshop in ./build/release (installing the Debian packages first).
#   scripts/build.sh             everything: the library, the CLI, every test, benchmark, the Python module and
#                                the editor's front end
#   scripts/build.sh TARGET...   only those CMake targets and what they need (scripts/demo.sh builds the CLI:
#                                lidarshop_cli), without the front end
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
# Paths relative to the checkout in ccache's hash: a fresh clone elsewhere reuses the objects of an earlier build.
export CCACHE_BASEDIR="$PWD" CCACHE_NOHASHDIR=true
# The release preset of CMakePresets.json: build/release, Ninja, Release.
cmake --preset release >/dev/null
if [[ $# -gt 0 ]]; then
  cmake --build build/release -j "$(nproc)" --target "$@"
  exit
fi
cmake --build build/release -j "$(nproc)"
bash scripts/web.sh build
