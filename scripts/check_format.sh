#!/usr/bin/env bash
# Fails when clang-format (the repository's .clang-format) would change any C++ file under src/, bench/ or
# fuzz/. Runs as the ctest `format_test`; to fix a failure, run clang-format -i on the files it names. Exits
# 1 when a file would change, 2 when the check cannot run (no clang-format, no C++ files under ROOT).
#
#   scripts/check_format.sh [ROOT] [CLANG_FORMAT]     ROOT defaults to the repository, CLANG_FORMAT to clang-format
set -euo pipefail
root=${1:-$(cd "$(dirname "$0")/.." && pwd)}
clang_format=${2:-clang-format}
cd "$root"
# A check that cannot run fails: without clang-format nothing is checked, which is not a pass.
if ! command -v "$clang_format" > /dev/null; then
  echo "check_format: FAILED: '$clang_format' not found, so no file was checked" \
    "(scripts/setup.sh installs clang-format)" >&2
  exit 2
fi
folders=()
for folder in src bench fuzz; do [ -d "$folder" ] && folders+=("$folder"); done
[ "${#folders[@]}" -ne 0 ] || { echo "check_format: no src/ under $root" >&2; exit 2; }
mapfile -d '' files < <(find "${folders[@]}" -type f \( -name '*.h' -o -name '*.hpp' -o -name '*.cc' -o -name '*.cpp' \) \
  -print0 | sort -z)
if [ "${#files[@]}" -eq 0 ]; then
  echo "check_format: no C++ files under $root/src" >&2
  exit 2
fi
# One clang-format process per batch of files, not per file (seconds instead of half a minute): with
# --dry-run -Werror it names every file it would change ("FILE:LINE:COL: error: code should be
# clang-formatted"); any other failure (an unreadable file, a broken .clang-format) stops the check.
report=$(printf '%s\0' "${files[@]}" |
  xargs -0 -n 100 -P "$(nproc 2>/dev/null || echo 2)" "$clang_format" --dry-run -Werror 2>&1) && status=0 || status=$?
mapfile -t unformatted < <(printf '%s\n' "$report" |
  sed -nE 's/^(.*):[0-9]+:[0-9]+: error: code should be clang-formatted.*/\1/p' | sort -u)
if [ "$status" -ne 0 ] && [ "${#unformatted[@]}" -eq 0 ]; then
  echo "check_format: $clang_format failed:" >&2
  printf '%s\n' "$report" | head -20 >&2
  exit 2
fi
if [ "${#unformatted[@]}" -ne 0 ]; then
  echo "check_format: clang-format would change ${#unformatted[@]} of ${#files[@]} files (run clang-format -i on them):"
  printf '  %s\n' "${unformatted[@]}"
  exit 1
fi
echo "check_format: ${#files[@]} files are clang-format clean ($("$clang_format" --version))"
