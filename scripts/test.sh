#!/usr/bin/env bash
# Builds everything and runs every test (one ctest per test file), then fuzzes every reader briefly.
#   scripts/test.sh [ctest arguments...]     release build (build/release), ctest, scripts/fuzz.sh 15
#   scripts/test.sh --sanitize [ctest args]  the whole suite built with AddressSanitizer + UBSan in build/asan
# LIDARSHOP_FUZZ_SECONDS sets the fuzzing time per reader (default 15; 0 skips fuzzing).
set -euo pipefail
cd "$(dirname "$0")/.."
# Paths relative to the checkout in ccache's hash (as scripts/build.sh): a clone in any folder reuses the objects.
export CCACHE_BASEDIR="$PWD" CCACHE_NOHASHDIR=true
if [[ ${1:-} == --sanitize ]]; then
  shift
  bash scripts/setup.sh
  # Debug info for reports; -O1 keeps the suite's synthetic scenes fast enough under ASan.
  cmake -S . -B build/asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g" \
    -DLIDARSHOP_SANITIZE=ON -DLIDARSHOP_BUILD_BENCH=OFF >/dev/null
  cmake --build build/asan -j "$(nproc)"
  # Leak checking stays on; TBB's and Embree's thread pools are torn down at exit.
  ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1} UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1} \
    ctest --test-dir build/asan --output-on-failure -j "$(nproc)" --timeout 3000 "$@"
  exit
fi
bash scripts/build.sh
ctest --test-dir build/release --output-on-failure -j "$(nproc)" "$@"
bash scripts/web.sh test
fuzz_seconds=${LIDARSHOP_FUZZ_SECONDS:-15}
if [[ $fuzz_seconds -gt 0 ]] && command -v clang++-14 >/dev/null; then
  LIDARSHOP_FUZZ_SEED=${LIDARSHOP_FUZZ_SEED:-1} bash scripts/fuzz.sh "$fuzz_seconds"
fi
