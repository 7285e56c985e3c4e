#!/usr/bin/env bash
# web/src/api_types.generated.ts is what `lidarshop schema --typescript` writes now: a field added to a
# described struct of the editor's API (src/server/api_types.cc) without regenerating the file fails here, with
# the command that brings it up to date. The binary comes from LIDARSHOP_CLI (cli/CMakeLists.txt).
set -euo pipefail
cli=${LIDARSHOP_CLI:?LIDARSHOP_CLI names the lidarshop executable}
root=$(cd "$(dirname "$0")/.." && pwd)
committed=$root/web/src/api_types.generated.ts
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

"$cli" schema --typescript -o "$work/api_types.generated.ts" -q
if ! diff -u "$committed" "$work/api_types.generated.ts" >"$work/diff"; then
  head -n 60 "$work/diff"
  echo "FAIL: web/src/api_types.generated.ts is stale; run: lidarshop schema --typescript -o web/src/api_types.generated.ts"
  exit 1
fi
# Stdout gives the same text (the -o file is no different form).
"$cli" schema --typescript | cmp - "$committed"
echo "api_types.generated.ts is current ($(grep -c '^export interface' "$committed") interfaces)"
