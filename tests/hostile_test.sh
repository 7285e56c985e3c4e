#!/usr/bin/env bash
# Runs every case of tests/hostile/cases.txt (hostile input) against the `lidarshop` binary, each
# with a time limit, an address-space limit and a resident-memory limit, and classifies the outcome per reader:
#   clean   — a non-zero exit with one line on stderr (or success where the case allows it)
#   crash   — killed by a signal, or a sanitizer report
#   hang    — still running after the time limit
#   memory  — an allocation failure (bad_alloc, OpenCV "Insufficient memory", ...), or a peak resident set
#             past the case's limit: its `--max-memory` budget + 200 MB, the limit written after its
#             expectation (`error@300M`: what the bytes justify when the default budget would allow more), or
#             else MEMORY_LIMIT_KB
#   silent  — exit 0 on input that must be refused, or an input file modified
#   refused — a valid case that failed, or an image library's own line on stderr (libpng, libjpeg, OpenEXR)
# Cases run JOBS at a time (default: the processor count), each in its own scratch folder ({W}; the data-safety
# cases share one holding their inputs). Large inputs are written by `make_corpus.py --big` into {B} first.
# Prints the table and exits non-zero unless every case is clean. Run by ctest as `hostile_test`.
# Usage: hostile_test.sh LIDARSHOP_BINARY [SHARED_DATA_DIR] [SECONDS_PER_CASE=30] [MEMORY_LIMIT_KB=3000000]
set -uo pipefail
lidarshop=$1
shared=${2:-$(dirname "$0")/../../shared/data}
seconds=${3:-30}
memory_kb=${4:-3000000}
jobs=${JOBS:-$(nproc)}
here=$(cd "$(dirname "$0")" && pwd)
# Under AddressSanitizer (scripts/test.sh --sanitize) an address-space limit cannot work (the shadow memory
# alone reserves terabytes): ASan's own RSS limit takes its place, and resident sets are not compared.
limit_memory=(ulimit -v "$memory_kb")
asan=0
if ldd "$lidarshop" 2>/dev/null | grep libasan >/dev/null; then  # not grep -q: SIGPIPE under pipefail
  limit_memory=(true)
  asan=1
  export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}hard_rss_limit_mb=$((memory_kb / 1024)):detect_leaks=0"
  seconds=$((seconds * 4))
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cp -r "$here/hostile/corpus" "$work/corpus"
python3 "$here/hostile/make_corpus.py" --big "$work/big" || exit 1
mkdir -p "$work/scratch" "$work/results"
for ext in ptx ply pcd e57 las xyz json png txt; do mkfifo "$work/fifo.$ext"; done
mkfifo "$work/corpus/fifo.obj" "$work/corpus/fifo.mtl"
# Inputs of the data-safety cases.
cp "$work/corpus/good.ptx" "$work/scratch/copy.ptx"
"$lidarshop" render "$work/scratch/copy.ptx" -o "$work/scratch/img.png" >/dev/null 2>&1
"$lidarshop" render "$work/scratch/copy.ptx" --channel valid -o "$work/scratch/mask.png" >/dev/null 2>&1
checksum_before=$(cat "$work/scratch/copy.ptx" "$work/scratch/img.png" | md5sum)

# "512M" / "2G" / "800000" -> KiB, or nothing when not a whole number with an optional K/M/G.
kib_of() {
  [[ $1 =~ ^([0-9]+)([KMG]?)$ ]] || return
  case ${BASH_REMATCH[2]} in
    K) echo "${BASH_REMATCH[1]}" ;; M) echo $((BASH_REMATCH[1] * 1024)) ;;
    G) echo $((BASH_REMATCH[1] * 1048576)) ;; *) echo $((BASH_REMATCH[1] / 1024)) ;;
  esac
}

# Runs case number $1 (reader $2, expectation $3, arguments $4); writes "outcome reader" and, when not clean, a
# report to $work/results/$1.
run_case() {
  local index=$1 reader=$2 expect=$3 arguments=$4
  local scratch=$work/w.$index rss_kb=$memory_kb
  [[ $reader == safety ]] && scratch=$work/scratch
  mkdir -p "$scratch"
  if [[ $expect == *@* ]]; then
    rss_kb=$(kib_of "${expect#*@}")
    expect=${expect%@*}
  elif [[ $arguments =~ --max-memory\ ([^ ]+) ]]; then
    local budget_kb
    budget_kb=$(kib_of "${BASH_REMATCH[1]}")
    [[ -n $budget_kb ]] && rss_kb=$((budget_kb + 200 * 1024))
  fi
  arguments=${arguments//\{C\}/$work/corpus}
  arguments=${arguments//\{B\}/$work/big}
  arguments=${arguments//\{W\}/$scratch}
  arguments=${arguments//\{S\}/$shared}
  arguments=${arguments//\{FIFO\}/$work/fifo}
  local out=$work/out.$index err=$work/err.$index peak=$work/peak.$index
  # shellcheck disable=SC2086  # the arguments are words by design
  ("${limit_memory[@]}"; exec /usr/bin/time -f %M -o "$peak" timeout -s KILL "$seconds" "$lidarshop" $arguments) \
    >"$out" 2>"$err" </dev/null
  local rc=$?
  # `time` passes the exit status on (timeout's 137 after a kill) and ends its report with the peak resident
  # set in KiB of the process tree it waited for.
  local peak_kb
  peak_kb=$(tail -1 "$peak" 2>/dev/null)
  [[ $peak_kb =~ ^[0-9]+$ ]] || peak_kb=0
  local lines
  lines=$(wc -l <"$err")
  local outcome=clean why=""
  if [[ $rc -eq 137 ]]; then
    outcome=hang
  elif grep -qE "bad_alloc|Insufficient memory|Failed to allocate|out of memory|Cannot allocate|hard rss limit" "$err"; then
    outcome=memory
  elif [[ $asan -eq 0 && $peak_kb -gt $rss_kb ]]; then
    outcome=memory
    why=" peak resident set $((peak_kb / 1024)) MB, limit $((rss_kb / 1024)) MB"
  elif [[ $rc -ge 128 ]] || grep -qE "AddressSanitizer|runtime error:|Segmentation|Aborted|terminate called" "$err"; then
    outcome=crash
  elif [[ $expect == error && $rc -eq 0 ]]; then
    outcome=silent
  elif [[ $expect == ok && $rc -ne 0 ]]; then
    outcome=refused
  elif [[ $rc -ne 0 && $lines -ne 1 ]]; then
    outcome=refused  # an error, but not one clean line
  elif grep -qE "^(libpng|libjpeg|Corrupt JPEG|Premature end of JPEG|Invalid SOS|Iex|OpenEXR)" "$err"; then
    outcome=refused  # an image library's own line beside ours
  fi
  {
    echo "$outcome $reader"
    if [[ $outcome != clean ]]; then
      echo "$outcome ($expect, exit $rc$why): lidarshop $arguments"
      sed 's/^/  | /' "$err" | head -5
    fi
  } >"$work/results/$index"
  rm -rf "$out" "$err" "$peak"
  [[ $reader == safety ]] || rm -rf "$scratch"
}

index=0
while IFS='|' read -r reader expect arguments; do
  [[ -z "$reader" || "$reader" == \#* ]] && continue
  index=$((index + 1))
  while [[ $(jobs -rp | wc -l) -ge $jobs ]]; do wait -n; done
  run_case "$index" "$reader" "$expect" "$arguments" &
done <"$here/hostile/cases.txt"
wait

declare -A total clean crash hang memory silent refused
readers=()
failures=0
for ((i = 1; i <= index; ++i)); do
  read -r outcome reader <"$work/results/$i"
  if [[ -z "${total[$reader]+x}" ]]; then
    readers+=("$reader")
    total[$reader]=0; clean[$reader]=0; crash[$reader]=0; hang[$reader]=0; memory[$reader]=0
    silent[$reader]=0; refused[$reader]=0
  fi
  total[$reader]=$((total[$reader] + 1))
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
    tail -n +2 "$work/results/$i"
  fi
done

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
