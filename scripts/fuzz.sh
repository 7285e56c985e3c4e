#!/usr/bin/env bash
# Fuzzes every reader with libFuzzer + AddressSanitizer + UBSan (clang 14 from scripts/setup.sh):
#   scripts/fuzz.sh [SECONDS_PER_READER=300] [READER...]     readers: ptx ply pcd las laz xyz pts e57 obj scene strokes
#   mask pose header routes (the editor's HTTP routes with the token, fuzz/routes_fuzz.cc)
# Configures build/fuzz (the whole library instrumented, LIDARSHOP_BUILD_FUZZ=ON), replays the regression
# inputs of data/fuzz_regressions/<reader>_*, seeds each target with the repository's files of its format
# (tests/hostile/corpus, data/, the shared E57 files) and runs it for the given time. Prints one line per
# reader (inputs executed, seconds, crashes) and exits non-zero on a crash or an out-of-memory report; crashing
# inputs are written to build/fuzz/artifacts/ — turn each into data/fuzz_regressions/<reader>_<what>.<ext>
# after fixing it.
# Memory: every target sets the memory budget to 256 MiB (fuzz/fuzz_util.h, LimitMemory), so a reader may
# hold about that much; libFuzzer's -rss_limit_mb is that budget + 200 MB + what AddressSanitizer adds (its
# shadow and a quarantine capped at 64 MB), and -malloc_limit_mb the budget + 200 MB for one allocation: an
# input that takes more went past the budget, and libFuzzer reports it as out-of-memory — a failure here.
# Same work on every machine: scripts/test.sh --long (and so CI) runs a fixed number of inputs per reader
# (LIDARSHOP_FUZZ_RUNS=ci, the table in runs_of, about 15 s a reader on an idle 2-core machine) from the seed
# corpus alone with LIDARSHOP_FUZZ_SEED=1; SECONDS only caps the time. A time budget alone ran 242 scene inputs
# here under load and 5,504 on CI's machine, so CI found what no local run had tried. Reproduce CI's run with
# `LIDARSHOP_FUZZ_RUNS=ci LIDARSHOP_FUZZ_SEED=1 scripts/fuzz.sh 120`. The inputs are the same only for a while:
# libFuzzer learns from coverage and compared values, which vary a little between runs, so two runs drift apart
# after some thousands of inputs (measured: 3,000 strokes inputs, coverage 1,040–1,051 edges over four runs).
# LIDARSHOP_FUZZ_RUNS=N runs N inputs per reader. By hand, without it, the time decides and the seed is random
# (0) unless set. Run it longer by hand.
set -uo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-300}
shift || true
readers=("$@")
[[ ${#readers[@]} -eq 0 ]] && readers=(ptx ply pcd las laz xyz pts e57 obj scene strokes mask pose header routes)
shared=${LIDARSHOP_SHARED_DATA_DIR:-$PWD/../shared/data}
build=build/fuzz
# Paths relative to the checkout in ccache's hash (as scripts/build.sh): a clone in any folder reuses the objects.
export CCACHE_BASEDIR="$PWD" CCACHE_NOHASHDIR=true

# The fuzz preset (CMakePresets.json): build/fuzz, clang++-14, LIDARSHOP_BUILD_FUZZ=ON, no tests or benchmarks.
build_started=$(date +%s)
cmake --preset fuzz >/dev/null || exit 1
cmake --build "$build" -j "$(nproc)" --target "${readers[@]/%/_fuzz}" >"$build/build.log" 2>&1 ||
  { tail -30 "$build/build.log"; exit 1; }
echo "fuzz.sh: the fuzz targets built in $(($(date +%s) - build_started)) s"

# Inputs per reader for LIDARSHOP_FUZZ_RUNS=ci: about 15 s each on an idle 2-core Xeon (AVX-512).
runs_of() {
  case $1 in
    laz) echo 2000 ;; scene) echo 8000 ;; ply | ptx) echo 40000 ;; e57 | strokes) echo 20000 ;;
    las | header) echo 50000 ;; pcd | pts) echo 60000 ;; xyz | obj) echo 75000 ;; pose) echo 80000 ;;
    mask) echo 90000 ;; routes) echo 150 ;; *) echo 20000 ;;
  esac
}

extension_of() {
  case $1 in scene | strokes | routes) echo json ;; mask) echo png ;; pose) echo txt ;; *) echo "$1" ;; esac
}

# OpenCV reads its own pixel limit once, when it loads: set here, it applies (a second line of defence behind
# the header checks of io/image_io.h, which apply the budget).
export OPENCV_IO_MAX_IMAGE_PIXELS=$((1 << 22))
budget_mb=256                                # what LimitMemory sets
malloc_limit_mb=$((budget_mb + 200))         # one allocation past this went past the budget
rss_limit_mb=$((budget_mb + 200 + 300))      # + AddressSanitizer's shadow, quarantine and the binary
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:allocator_may_return_null=1:quarantine_size_mb=64}
limits=(-rss_limit_mb="$rss_limit_mb" -malloc_limit_mb="$malloc_limit_mb")
mkdir -p "$build/artifacts"
status=0 fuzz_passed=0 fuzz_failed=0
printf '| reader | inputs | seconds | crashes |\n|---|---|---|---|\n'
for reader in "${readers[@]}"; do
  ext=$(extension_of "$reader")
  corpus="$build/corpus/$reader"
  # A fixed number of inputs starts from the seeds alone, as on a fresh clone: what earlier runs added to the
  # corpus would change which inputs run. A timed run keeps growing it.
  [[ -n ${LIDARSHOP_FUZZ_RUNS:-} ]] && rm -rf "$corpus"
  mkdir -p "$corpus"
  for f in tests/hostile/corpus/*."$ext" data/*/*."$ext" data/*/*/*."$ext"; do
    # The regressions are replayed above; as seeds, the slow ones (a facade of 15,000 windows: 12 s under the
    # sanitizers) would take the run's time.
    [[ -f $f && $f != data/fuzz_regressions/* ]] || continue
    if [[ $reader == e57 ]]; then
      # The E57 target reads logical streams (pages without CRCs).
      python3 -c 'import sys; d=open(sys.argv[1],"rb").read(); open(sys.argv[2],"wb").write(b"".join(d[i:i+1020] for i in range(0,len(d),1024)))' \
        "$f" "$corpus/$(basename "$f").logical"
    elif [[ $(stat -c %s "$f") -le 65536 ]]; then
      cp "$f" "$corpus/"
    fi
  done
  if [[ $reader == e57 ]]; then
    for f in "$shared"/e57/*.e57; do
      [[ -f $f && $(stat -c %s "$f") -le 4194304 ]] || continue
      python3 -c 'import sys; d=open(sys.argv[1],"rb").read(); open(sys.argv[2],"wb").write(b"".join(d[i:i+1020] for i in range(0,len(d),1024)))' \
        "$f" "$corpus/shared_$(basename "$f").logical"
    done
  fi
  if [[ $reader == laz ]]; then
    for f in "$shared"/interop/laz/*.laz; do
      [[ -f $f && $(stat -c %s "$f") -le 65536 ]] && cp "$f" "$corpus/"
    done
  fi
  if [[ $reader == header ]]; then
    # The header target's first byte picks the format (0 ptx, 1 ply, 2 pcd, 3 las, 4 e57 as a logical stream).
    for f in tests/hostile/corpus/*.{ptx,ply,pcd,las} "$shared"/e57/*.e57; do
      [[ -f $f && $(stat -c %s "$f") -le 4194304 ]] || continue
      python3 -c 'import sys
kinds = {"ptx": 0, "ply": 1, "pcd": 2, "las": 3, "e57": 4}
ext = sys.argv[1].rsplit(".", 1)[1]
d = open(sys.argv[1], "rb").read()
if ext == "e57": d = b"".join(d[i:i + 1020] for i in range(0, len(d), 1024))
open(sys.argv[2], "wb").write(bytes([kinds[ext]]) + d[:65535])' "$f" "$corpus/$(basename "$f").seed"
    done
  fi
  if [[ $reader == routes ]]; then
    # The first byte picks the route (fuzz/routes_fuzz.cc: 14 POST routes, 6 GET routes, /api/models): each
    # route with a few bodies that reach past the field checks.
    for route in $(seq 0 20); do
      for body in '{"object": [[10, 12], [11, 14]], "background": [[2, 3], [22, 30]], "radius": 2}' \
        '{"options": {}, "refine": true}' '{"hole": "painted", "margin_cells": 3}' \
        '{"pairs": [{"cell": [10, 10], "pixel": [5.5, 6.5]}], "target": 1}' '3' '{"since": 1}'; do
        printf "\\x$(printf %02x "$route")%s" "$body" >"$corpus/seed_${route}_$(printf %s "$body" | md5sum | cut -c1-8)"
      done
    done
  fi
  regressions=(data/fuzz_regressions/"${reader}"_*)
  crashes=0
  if [[ -f ${regressions[0]} ]]; then
    if ! "$build/fuzz/${reader}_fuzz" "${limits[@]}" -timeout=60 "${regressions[@]}" >"$build/$reader.regressions.log" 2>&1; then
      echo "$reader: a regression input fails again (see $build/$reader.regressions.log)"
      crashes=$((crashes + 1))
    fi
  fi
  before=$(find "$build/artifacts" -name "$reader-*" ! -name "$reader-slow-unit-*" | wc -l)
  runs=()
  case ${LIDARSHOP_FUZZ_RUNS:-} in
    '') ;;
    ci) runs=(-runs="$(runs_of "$reader")") ;;
    *) runs=(-runs="$LIDARSHOP_FUZZ_RUNS") ;;
  esac
  "$build/fuzz/${reader}_fuzz" "$corpus" "${runs[@]}" -max_total_time="$seconds" -max_len=65536 "${limits[@]}" -timeout=60 \
    -seed="${LIDARSHOP_FUZZ_SEED:-0}" -artifact_prefix="$build/artifacts/$reader-" -print_final_stats=1 \
    >"$build/$reader.log" 2>&1
  # A slow unit (over 10 s, written for a look) is not a failure; past -timeout it is one.
  after=$(find "$build/artifacts" -name "$reader-*" ! -name "$reader-slow-unit-*" | wc -l)
  crashes=$((crashes + after - before))
  if [[ $after -gt $before ]]; then  # say what broke where CI's log shows it, not only in build/fuzz
    grep -m1 -B2 -A12 -E "ERROR: (libFuzzer|AddressSanitizer|LeakSanitizer)|runtime error|terminate called" \
      "$build/$reader.log" | grep -vE "^ +#([0-9]|1[0-9]) .*(libFuzzer|libc\.so|libstdc|sanitizer)" | head -24
    grep -E "^artifact_prefix|Test unit written to" "$build/$reader.log" | tail -1
  fi
  # An out-of-memory report fails the run even when libFuzzer could not write its input (-rss_limit_mb is
  # checked by a thread; a malloc past -malloc_limit_mb dies inside the allocator).
  if grep -qE "ERROR: libFuzzer: out-of-memory|malloc limit|hard rss limit|allocation-size-too-big|out of memory" \
    "$build/$reader.log" && [[ $after -eq $before ]]; then
    echo "$reader: out of memory (see $build/$reader.log)"
    crashes=$((crashes + 1))
  fi
  inputs=$(grep -oE 'stat::number_of_executed_units: *[0-9]+' "$build/$reader.log" | grep -oE '[0-9]+$')
  took=$(grep -oE 'Done [0-9]+ runs in [0-9]+ second' "$build/$reader.log" | grep -oE '[0-9]+ second' |
    grep -oE '[0-9]+')
  if [[ -z $inputs ]]; then  # no final stats: the target did not run, or died without an artifact
    tail -5 "$build/$reader.log"
    crashes=$((crashes + 1))
  fi
  if [[ ${#runs[@]} -gt 0 && -n $inputs && $inputs -lt ${runs[0]#-runs=} && $crashes -eq 0 ]]; then
    echo "$reader: stopped at the ${seconds} s cap after $inputs of ${runs[0]#-runs=} inputs (a slow or loaded machine)"
  fi
  printf '| %s | %s | %s | %d |\n' "$reader" "${inputs:-?}" "${took:-$seconds}" "$crashes"
  if [[ $crashes -eq 0 ]]; then fuzz_passed=$((fuzz_passed + 1)); else status=1; fuzz_failed=$((fuzz_failed + 1)); fi
done
echo "fuzz: $fuzz_passed passed, $fuzz_failed failed"
exit $status
