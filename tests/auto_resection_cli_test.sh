#!/usr/bin/env bash
# End to end, photos without pairs: `resection --auto` and `recolor --auto` (docs/recolor.md, "Automatic
# resection"). Run by ctest as `auto_resection_cli_test` (tests/cli_fixture.sh says how to run it by hand).
source "$(dirname "$0")/cli_fixture.sh"

# A textured street: bricks the scanner resolves (scale 3), gravel, a checkered box and a plain pillar.
cat >"$work/street.json" <<'JSON'
{"scanner": {"position": [0, 0, 1.5], "azimuth_deg": [-40, 40], "elevation_deg": [-35, 25],
             "columns": 900, "rows": 600, "max_range": 100},
 "objects": [
   {"primitive": "plane", "size": [60, 60], "translate": [0, 0, 0], "label": 0, "texture": "gravel",
    "texture_scale": 3, "color": [120, 110, 100]},
   {"primitive": "box", "size": [24, 0.4, 6], "translate": [0, 12.2, 3], "label": 1, "texture": "brick",
    "texture_scale": 3},
   {"primitive": "box", "size": [1.2, 1.2, 1.2], "translate": [-0.8, 6, 0.6], "label": 2, "texture": "checker",
    "color": [200, 50, 40]},
   {"primitive": "box", "size": [0.5, 0.5, 2.5], "translate": [1.6, 8, 1.25], "label": 3, "color": [40, 70, 190]}]}
JSON
# 640 x 480, f = 500 px, 0.8 m right of and 0.3 m behind the scanner, 0.1 m higher, looking along +y.
cat >"$work/cam.json" <<'JSON'
{"width_px": 640, "height_px": 480, "fx_px": 500, "fy_px": 500, "cx_px": 320, "cy_px": 240,
 "world_from_camera": [[1, 0, 0, 0.8], [0, 0, 1, -0.3], [0, -1, 0, 1.6], [0, 0, 0, 1]]}
JSON
# A rough guess: 0.4 m to the right and 0.2 m up, turned 3° to the left.
cat >"$work/rough.json" <<'JSON'
{"width_px": 640, "height_px": 480, "fx_px": 500, "fy_px": 500, "cx_px": 320, "cy_px": 240,
 "world_from_camera": [[0.9986295347545738, 0, -0.052335956242943835, 1.2], [0.052335956242943835, 0, 0.9986295347545738, -0.3], [0, -1, 0, 1.8], [0, 0, 0, 1]]}
JSON
# The same camera looking straight up at the empty sky: nothing the scan holds.
cat >"$work/sky.json" <<'JSON'
{"width_px": 640, "height_px": 480, "fx_px": 500, "fy_px": 500, "cx_px": 320, "cy_px": 240,
 "world_from_camera": [[1, 0, 0, 0.8], [0, 1, 0, -0.3], [0, 0, 1, 1.6], [0, 0, 0, 1]]}
JSON
check "scan" "$lidarshop" scan "$work/street.json" -o "$work/street.e57"
check "photo" "$lidarshop" photo "$work/street.json" --camera "$work/cam.json" -o "$work/photo.png" --samples 2
check "sky photo" "$lidarshop" photo "$work/street.json" --camera "$work/sky.json" -o "$work/sky.png"

check "resection --auto" sh -c "'$lidarshop' resection --auto '$work/street.e57' '$work/photo.png' \
  --intrinsics '$work/cam.json' -o '$work/auto_cam.json' >'$work/auto.json'"
json_check "resection --auto finds the camera" "$work/auto.json" \
  "d['inliers'] >= 40 and d['inlier_share'] > 0.25 and d['rms_px'] < 1.5 and \
   sum((a - b) ** 2 for a, b in zip(d['camera_center'], [0.8, -0.3, 1.6])) ** 0.5 < 0.02"
json_check "the camera file holds the pose" "$work/auto_cam.json" \
  "abs(d['world_from_camera'][0][3] - 0.8) < 0.02 and abs(d['world_from_camera'][2][1] + 1) < 0.001"
check "resection --auto with --scan, --photo and a rough pose" sh -c "'$lidarshop' resection --auto \
  --scan '$work/street.e57' --photo '$work/photo.png' --intrinsics '$work/cam.json' \
  --rough-camera '$work/rough.json' -o '$work/auto_cam2.json' >'$work/auto2.json'"
json_check "from the rough pose" "$work/auto2.json" \
  "d['search_view'] == -1 and \
   sum((a - b) ** 2 for a, b in zip(d['camera_center'], [0.8, -0.3, 1.6])) ** 0.5 < 0.02"
check "recolor --auto" sh -c "'$lidarshop' recolor '$work/street.e57' --photo '$work/photo.png' --auto \
  --intrinsics '$work/cam.json' -o '$work/recolored.ply' >'$work/recolor.json'"
json_check "recolor --auto recolours with the camera it found" "$work/recolor.json" \
  "d['recolored'] > 10000 and d['auto_resection']['inliers'] >= 40"
exits_with 1 "resection --auto refuses a photo of the sky" "no rendering of the scan matches" \
  "$lidarshop" resection --auto "$work/street.e57" "$work/sky.png" --intrinsics "$work/cam.json" \
  -o "$work/sky_cam.json"
check "no camera file after a refusal" test ! -e "$work/sky_cam.json"
exits_with 2 "--auto needs a scan and a photo" "needs a scan and a photo" \
  "$lidarshop" resection --auto "$work/street.e57" -o "$work/x.json"
exits_with 2 "--auto with pairs" "no --correspondences" \
  "$lidarshop" resection --auto "$work/street.e57" "$work/photo.png" --correspondences "$work/cam.json" \
  -o "$work/x.json"
exits_with 2 "recolor --auto with a camera" "--auto finds the camera of one photo" \
  "$lidarshop" recolor "$work/street.e57" --photo "$work/photo.png" --auto --camera "$work/cam.json" \
  -o "$work/x.ply"
help_shows "resection --help shows the automatic options" "--auto-rounds" "$lidarshop" resection
finish
