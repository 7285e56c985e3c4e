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
unformatted=()
for file in "${files[@]}"; do
  if ! "$clang_format" --dry-run -Werror "$file" > /dev/null 2>&1; then unformatted+=("$file"); fi
done
if [ "${#unformatted[@]}" -ne 0 ]; then
  echo "check_format: clang-format would change ${#unformatted[@]} of ${#files[@]} files (run clang-format -i on them):"
  printf '  %s\n' "${unformatted[@]}"
  exit 1
fi
echo "check_format: ${#files[@]} files are clang-format clean ($("$clang_format" --version))"
