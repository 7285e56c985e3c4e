#!/usr/bin/env bash
# Builds lidarshop and its front end, then starts the editor on the built-in parking lot. Open the URL it prints.
#   scripts/editor.sh [serve options...]     e.g. --port 9000, or scan files to open beside the scene
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh >&2
exec build/release/lidarshop serve --scene parking_lot --root "$PWD" "$@"
