#!/usr/bin/env bash
# Builds everything and runs every test (one ctest per test file) and the editor's tests; --long fuzzes too.
#   scripts/test.sh [ctest arguments...]         release build (build/release), ctest, the editor's tests
#   scripts/test.sh --long [ctest arguments...]  the same, then fuzzes every reader briefly (CI runs this)
#   scripts/test.sh --sanitize [ctest args]      the whole suite built with AddressSanitizer + UBSan in build/asan
# Fuzzing builds every reader's fuzz target with clang (build/fuzz: the library a second time, instrumented), then
# runs a fixed number of inputs per reader with a fixed seed (scripts/fuzz.sh: LIDARSHOP_FUZZ_RUNS=ci,
# LIDARSHOP_FUZZ_SEED=1, at most 120 s a reader), so every machine runs the same inputs.
# LIDARSHOP_FUZZ_SECONDS=S fuzzes S seconds per reader instead; 0 skips fuzzing even with --long.
# The last line says how long each part took (wall clock), the numbers README.md states.
set -euo pipefail
cd "$(dirname "$0")/.."
# Paths relative to the checkout in ccache's hash (as scripts/build.sh): a clone in any folder reuses the objects.
export CCACHE_BASEDIR="$PWD" CCACHE_NOHASHDIR=true
if [[ ${1:-} == --sanitize ]]; then
  shift
  bash scripts/setup.sh
  # The asan preset (CMakePresets.json): build/asan, debug info for reports, -O1 keeps the suite's synthetic
  # scenes fast enough under ASan.
  cmake --preset asan >/dev/null
  cmake --build build/asan -j "$(nproc)"
  # Leak checking stays on; TBB's and Embree's thread pools are torn down at exit.
  ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1} UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1} \
    ctest --test-dir build/asan --output-on-failure -j "$(nproc)" --timeout 3000 "$@"
  exit
fi
long=false
if [[ ${1:-} == --long ]]; then
  long=true
  shift
fi
timings=()
started=$(date +%s)
took() {  # took PART: appends "PART N s" (since the last call) to the summary line
  local now
  now=$(date +%s)
  timings+=("$1 $((now - started)) s")
  started=$now
}
bash scripts/build.sh
took build
ctest --test-dir build/release --output-on-failure -j "$(nproc)" "$@"
took ctest
bash scripts/web.sh test
took "editor's tests"
fuzz_seconds=${LIDARSHOP_FUZZ_SECONDS:-}
if [[ $long == true && $fuzz_seconds != 0 ]]; then
  # A check that cannot run fails rather than skip (LIDARSHOP_FUZZ_SECONDS=0 skips fuzzing on purpose).
  command -v clang++-14 >/dev/null ||
    { echo "test.sh: clang++-14 not found, the fuzzers cannot run (scripts/setup.sh installs clang)" >&2; exit 1; }
  if [[ -z $fuzz_seconds ]]; then
    LIDARSHOP_FUZZ_RUNS=${LIDARSHOP_FUZZ_RUNS:-ci} LIDARSHOP_FUZZ_SEED=${LIDARSHOP_FUZZ_SEED:-1} bash scripts/fuzz.sh 120
  else
    LIDARSHOP_FUZZ_SEED=${LIDARSHOP_FUZZ_SEED:-1} bash scripts/fuzz.sh "$fuzz_seconds"
  fi
  took "fuzz build and fuzzing"
fi
summary=$(printf '%s, ' "${timings[@]}")
echo "test.sh: passed; ${summary%, }"
