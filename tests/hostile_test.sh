#!/usr/bin/env bash
# Runs every case of tests/hostile/cases.txt (hostile input) against the `lidarshop` binary, each
# with a time limit and an address-space limit, and classifies the outcome per reader:
#   clean   — a non-zero exit with one line on stderr (or success where the case allows it)
#   crash   — killed by a signal, or a sanitizer report
#   hang    — still running after the time limit
#   memory  — an allocation failure (bad_alloc, OpenCV "Insufficient memory", ...) under the limit
#   silent  — exit 0 on input that must be refused, or an input file modified
#   refused — a valid case that failed
# Prints the table and exits non-zero unless every case is clean. Run by ctest as `hostile_test`.
# Usage: hostile_test.sh LIDARSHOP_BINARY [SHARED_DATA_DIR] [SECONDS_PER_CASE=30] [MEMORY_LIMIT_KB=3000000]
set -uo pipefail
lidarshop=$1
shared=${2:-$(dirname "$0")/../../shared/data}
seconds=${3:-30}
memory_kb=${4:-3000000}
here=$(cd "$(dirname "$0")" && pwd)
# Under AddressSanitizer (scripts/test.sh --sanitize) an address-space limit cannot work (the shadow memory
# alone reserves terabytes): ASan's own RSS limit takes its place.
limit_memory=(ulimit -v "$memory_kb")
if ldd "$lidarshop" 2>/dev/null | grep libasan >/dev/null; then  # not grep -q: SIGPIPE under pipefail
  limit_memory=(true)
  export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}hard_rss_limit_mb=$((memory_kb / 1024)):detect_leaks=0"
  seconds=$((seconds * 4))
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cp -r "$here/hostile/corpus" "$work/corpus"
mkdir -p "$work/scratch"
for ext in ptx ply pcd e57 las xyz json png txt; do mkfifo "$work/fifo.$ext"; done
mkfifo "$work/corpus/fifo.obj" "$work/corpus/fifo.mtl"
# Inputs of the data-safety cases.
cp "$work/corpus/good.ptx" "$work/scratch/copy.ptx"
"$lidarshop" render "$work/scratch/copy.ptx" -o "$work/scratch/img.png" >/dev/null 2>&1
"$lidarshop" render "$work/scratch/copy.ptx" --channel valid -o "$work/scratch/mask.png" >/dev/null 2>&1
checksum_before=$(cat "$work/scratch/copy.ptx" "$work/scratch/img.png" | md5sum)

declare -A total clean crash hang memory silent refused
readers=()
failures=0
while IFS='|' read -r reader expect arguments; do
  [[ -z "$reader" || "$reader" == \#* ]] && continue
  if [[ -z "${total[$reader]+x}" ]]; then
    readers+=("$reader")
    total[$reader]=0; clean[$reader]=0; crash[$reader]=0; hang[$reader]=0; memory[$reader]=0
    silent[$reader]=0; refused[$reader]=0
  fi
  total[$reader]=$((total[$reader] + 1))
  arguments=${arguments//\{C\}/$work/corpus}
  arguments=${arguments//\{W\}/$work/scratch}
  arguments=${arguments//\{S\}/$shared}
  arguments=${arguments//\{FIFO\}/$work/fifo}
  # shellcheck disable=SC2086  # the arguments are words by design
  ("${limit_memory[@]}"; exec timeout -s KILL "$seconds" "$lidarshop" $arguments) \
    >"$work/out" 2>"$work/err" </dev/null
  rc=$?
  lines=$(wc -l <"$work/err")
  outcome=clean
  if [[ $rc -eq 137 ]]; then
    outcome=hang
  elif grep -qE "bad_alloc|Insufficient memory|Failed to allocate|out of memory|Cannot allocate|hard rss limit" "$work/err"; then
    outcome=memory
  elif [[ $rc -ge 128 ]] || grep -qE "AddressSanitizer|runtime error:|Segmentation|Aborted|terminate called" "$work/err"; then
    outcome=crash
  elif [[ $expect == error && $rc -eq 0 ]]; then
    outcome=silent
  elif [[ $expect == ok && $rc -ne 0 ]]; then
    outcome=refused
  elif [[ $rc -ne 0 && $lines -ne 1 ]]; then
    outcome=refused  # an error, but not one clean line
  fi
  case $outcome in
    clean) clean[$reader]=$((clean[$reader] + 1)) ;;
    crash) crash[$reader]=$((crash[$reader] + 1)) ;;
    hang) hang[$reader]=$((hang[$reader] + 1)) ;;
    memory) memory[$reader]=$((memory[$reader] + 1)) ;;
    silent) silent[$reader]=$((silent[$reader] + 1)) ;;
    refused) refused[$reader]=$((refused[$reader] + 1)) ;;
  esac
  if [[ $outcome != clean ]]; then
    failures=$((failures + 1))
    echo "$outcome ($expect, exit $rc): lidarshop $arguments"
    sed 's/^/  | /' "$work/err" | head -5
  fi
done <"$here/hostile/cases.txt"

if [[ "$(cat "$work/scratch/copy.ptx" "$work/scratch/img.png" | md5sum)" != "$checksum_before" ]]; then
  echo "silent: an input of the data-safety cases was modified"
  failures=$((failures + 1))
fi

printf '\n| reader | cases | clean | crashes | hangs | memory blow-ups | silent wrong results | valid refused |\n'
printf '|---|---|---|---|---|---|---|---|\n'
for r in "${readers[@]}"; do
  printf '| %s | %d | %d | %d | %d | %d | %d | %d |\n' "$r" "${total[$r]}" "${clean[$r]}" "${crash[$r]}" \
    "${hang[$r]}" "${memory[$r]}" "${silent[$r]}" "${refused[$r]}"
done
echo
[[ $failures -eq 0 ]]
