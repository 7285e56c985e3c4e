#!/usr/bin/env bash
# Builds everything and runs every test (one ctest per test file).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
ctest --test-dir build/release --output-on-failure -j "$(nproc)" "$@"
