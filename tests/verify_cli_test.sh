#!/usr/bin/env bash
# End to end, `verify` and `sweep`: a consistent and an inconsistent pose, model scale, --json, --options and bad
# values.
# Run by ctest as `verify_cli_test` (tests/cli_fixture.sh says how to run it by hand).
source "$(dirname "$0")/cli_fixture.sh"
make_scan
make_box

# verify: the box (label 2) at its true pose, and 1 m towards the scanner.
check "verify at the true pose" "$lidarshop" verify --scan "$work/scan.ptx" --model "$work/box.obj" \
  --pose "-2,8,0.6,0" --json "$work/verify.json" --scene-points "$work/scene_points.ply" \
  --model-points "$work/model_points.ply"
json_check "verify JSON keys and a consistent pose" "$work/verify.json" \
  "all(k in d for k in ('consistency', 'confidence', 'comparable_pairs', 'icp_cost', 'inlier_fraction', \
   'per_scan')) and d['comparable_pairs'] > 0 and d['consistency'] > 0.95 and d['confidence'] > 0"
check "verify 1 m towards the scanner" "$lidarshop" verify --scan "$work/scan.ptx" --model "$work/box.obj" \
  --pose "-2,7,0.6,0" --json "$work/verify_front.json"
json_check "a pose in front of the seen surface is inconsistent" "$work/verify_front.json" "d['consistency'] < 0.3"
fails_clearly "verify: bad pose" "pose" "$lidarshop" verify --scan "$work/scan.ptx" --model "$work/box.obj" \
  --pose "1,2"
# The same box in millimetres: --model-scale 0.001, or the scale in the pose, give the numbers of metres.
python3 -c "import sys; print(''.join('v ' + ' '.join(str(1000 * float(w)) for w in l.split()[1:]) + '\n' \
  if l.startswith('v ') else l for l in open(sys.argv[1])), end='')" "$work/box.obj" >"$work/box_mm.obj"
check "verify --model-scale" "$lidarshop" verify --scan "$work/scan.ptx" --model "$work/box_mm.obj" \
  --model-scale 0.001 --pose "-2,8,0.6,0" --json "$work/verify_mm.json"
check "verify with the scale in the pose" "$lidarshop" verify --scan "$work/scan.ptx" --model "$work/box_mm.obj" \
  --pose "0.001,0,0,-2,0,0.001,0,8,0,0,0.001,0.6,0,0,0,1" --json "$work/verify_mm_pose.json"
for file in verify_mm verify_mm_pose; do
  json_check "$file: the numbers of the box in metres" "$work/$file.json" \
    "abs(d['confidence'] - $(python3 -c "import json; print(json.load(open('$work/verify.json'))['confidence'])")) < 1e-3 \
     and abs(d['consistency'] - 1) < 0.05 and d['icp_cost'] < 0.02"
done

json_stdout "verify --json -" consistency "$lidarshop" verify --scan "$work/scan.ptx" --model "$work/box.obj" \
  --pose "-2,8,0.6,0" --json - --quiet
cp "$work/last.out" "$work/j_verify.json"
json_check "verify --json: the described result and the older keys" "$work/j_verify.json" \
  "d['icp_cost_m'] == d['icp_cost'] and d['options']['allowance_m'] == 0.1 and 'num_surface_samples' in d['model_options']"
json_stdout "sweep --json -" detections "$lidarshop" sweep --scan "$work/scan.ptx" --model "$work/box.obj" \
  --x-range=-3:-1 --y-range 7:9 --step 0.5 --yaws 0 --out "$work/j_sweep" --json - --quiet
cp "$work/last.out" "$work/j_sweep.json"
json_stdout "sweep --search full --json -" detections "$lidarshop" sweep --scan "$work/scan.ptx" \
  --model "$work/box.obj" --x-range=-3:-1 --y-range 7:9 --step 0.5 --yaws 0 --out "$work/j_sweep_full" \
  --search full --json - --quiet
cp "$work/last.out" "$work/j_sweep_full.json"
json_check "sweep --json: the search and the poses it verified" "$work/j_sweep.json" \
  "d['grid']['search'] == 'coarse-to-fine' and 0 < d['grid']['evaluated_poses'] <= d['grid']['poses'] == 25"
json_check "sweep --search full: every pose verified, the same detections" "$work/j_sweep_full.json" \
  "d['grid']['search'] == 'full' and d['grid']['evaluated_poses'] == 25 and \
d['detections'] == json.load(open('$work/j_sweep.json'))['detections']"

printf '{"sigma_m": 0.07}\n' >"$work/verify_options.json"
check "verify --options" "$lidarshop" verify --scan "$work/scan.ptx" --model "$work/box.obj" --pose "-2,8,0.6,0" \
  --options "$work/verify_options.json" --json "$work/j_verify2.json" --quiet
json_check "verify --options reach the options" "$work/j_verify2.json" "d['options']['sigma_m'] == 0.07"

exits_with 2 "verify: bad value names the flag" "^lidarshop verify: --allowance: -1(\.0)? is out of range \[0, 1000\]" \
  "$lidarshop" verify --scan "$work/scan.ptx" --model "$work/box.obj" --pose "-2,8,0.6,0" --allowance -1
exits_with 2 "sweep: cross-field check names the flag" "^lidarshop sweep: --x-range: is below x_min_m" \
  "$lidarshop" sweep --scan "$work/scan.ptx" --model "$work/box.obj" --x-range 3:1 --out "$work/x_sweep"
exits_with 2 "verify: did you mean" "unknown option --alowance \(did you mean --allowance\?\)" \
  "$lidarshop" verify --scan "$work/scan.ptx" --model "$work/box.obj" --pose "-2,8,0.6,0" --alowance 0.1
help_shows "verify help: units and ranges" "(m, [0, 1000])" "$lidarshop" verify

finish
