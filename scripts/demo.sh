#!/usr/bin/env bash
# Builds lidarshop and runs the main job on the built-in scene; results go to ./out/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
./build/release/lidarshop demo --out out "$@"
