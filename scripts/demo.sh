#!/usr/bin/env bash
# Builds the lidarshop command (only what it needs: the library and the CLI, not the tests, benchmarks or the
# Python module) and runs the main job on the built-in scene; results go to ./out/.
set -euo pipefail
cd "$(dirname "$0")/.."
start=$SECONDS
bash scripts/build.sh lidarshop_cli
echo "demo: the lidarshop command was built in $((SECONDS - start)) s" >&2
./build/release/lidarshop demo --out out "$@"
