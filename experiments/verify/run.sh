#!/usr/bin/env bash
# Verification evidence, reproducible: analytic, multi-scan, occlusion and parking-lot tables (the verify tests
# print them), then the CLI on the built-in parking lot (verify at the truth and halfway between two cars, sweeps
# with each car model: heat maps, CSV, detections).
#
#   experiments/verify/run.sh [BUILD_DIR=build/verify] [OUT_DIR=out/verify]
set -euo pipefail
cd "$(dirname "$0")/../.."
BUILD=${1:-build/verify}
OUT=${2:-out/verify}
mkdir -p "$OUT"
ninja -C "$BUILD" -j2 lidarshop_cli lidarshop_verify_tests >/dev/null
# The verify module's test program; each test file's suites (verify_analytic_test.cc, ...) by filter.
tests() { "$BUILD/src/lidarshop/verify/lidarshop_verify_tests" --gtest_brief=1 --gtest_filter="$1"; }

echo "== analytic (box seen from the front) =="
tests "VerifyAnalyticTest.*:VerifyModelTest.*:VerifyOptionsTest.*" | tail -n 3 || echo "(failures above)"
echo "== several scans, smaller model, occlusion =="
tests "VerifyMultiScanTest.*:VerifyOcclusionTest.*" | grep -E "vehicle|model|open|fenced|PASSED|FAILED" || echo "(failures above)"
echo "== parking lot (tests) =="
tests "ParkingLotTest.*" | grep -E "truth|PASSED|FAILED" || echo "(failures above)"

echo "== parking lot (CLI) =="
L="$BUILD/lidarshop"
"$L" scan data/scenes/parking_lot.json -o "$OUT/parking_lot.ptx" --quiet
echo -n "sedan at its true pose:        "
"$L" verify --scan "$OUT/parking_lot.ptx" --model builtin:sedan --pose 6.5,10,0,120 --json "$OUT/sedan_truth.json" \
  --scene-points "$OUT/sedan_truth_scene.ply" --model-points "$OUT/sedan_truth_model.ply" --quiet
echo -n "sedan halfway to the hatchback: "
"$L" verify --scan "$OUT/parking_lot.ptx" --model builtin:sedan --pose 3.25,10.5,0,120 --json "$OUT/halfway.json" \
  --scene-points "$OUT/halfway_scene.ply" --quiet
for car in sedan hatchback van; do
  echo "-- sweep with the $car model --"
  "$L" sweep --scan "$OUT/parking_lot.ptx" --model "builtin:$car" --x-range=-9.3:9.3 --y-range=7.7:13.3 --step 0.5 \
    --yaws 0:180:30 --out "$OUT/sweep_$car" --quiet
done
echo "outputs in $OUT"
