#!/usr/bin/env bash
# End to end, photos: the synthetic camera (`photo`), `resection`, `recolor`, E57 `images` and landmark `align`.
# Run by ctest as `recolor_cli_test` (tests/cli_fixture.sh says how to run it by hand).
source "$(dirname "$0")/cli_fixture.sh"
make_scan

# Photos: the synthetic camera, resection, recolouring, E57 images, landmark alignment (docs/recolor.md).
cat >"$work/cam.json" <<'JSON'
{"width_px": 320, "height_px": 240, "fx_px": 260, "fy_px": 260, "cx_px": 160, "cy_px": 120,
 "world_from_camera": [[1, 0, 0, 1], [0, 0, 1, -0.5], [0, -1, 0, 1.6], [0, 0, 0, 1]]}
JSON
check "photo" "$lidarshop" photo "$work/scene/scene.json" --camera "$work/cam.json" -o "$work/photo.png"
python3 - "$work" <<'PY'
import json, sys
work = sys.argv[1]
points = [[-2.5, 7.7, 0.05], [-1.5, 7.7, 0.05], [-2.5, 7.7, 1.15], [-1.5, 7.7, 1.15], [2, 9, 1], [4, 11.9, 2.9],
          [0, 5, 0], [3, 6, 0], [-3, 12, 0], [1, 20, 0], [-1.6, 7.7, 0.6], [2.5, 9.2, 1.3]]
pairs = []
for x, y, z in points:  # camera at (1, -0.5, 1.6) looking along +y: u = 160 + 260 (x - 1) / d, v = 120 - 260 (z - 1.6) / d
    d = y + 0.5
    pairs.append({"pixel": [160 + 260 * (x - 1) / d, 120 - 260 * (z - 1.6) / d], "point": [x, y, z]})
json.dump({"image_size_px": [320, 240], "pairs": pairs}, open(work + "/pairs.json", "w"))
pairs[3]["point"][0] = float("nan")
open(work + "/pairs_nan.json", "w").write(json.dumps({"pairs": pairs}))
PY
check "resection" sh -c "'$lidarshop' resection --correspondences '$work/pairs.json' -o '$work/cam_out.json' \
  >'$work/resection.json'"
json_check "resection recovers the camera" "$work/resection.json" \
  "d['inliers'] == 12 and d['rms_px'] < 0.01 and abs(d['focal_px'][0] - 260) < 0.5"
check "recolor with a camera" sh -c "'$lidarshop' recolor '$work/scan.ptx' --photo '$work/photo.png' \
  --camera '$work/cam.json' -o '$work/recolored.ply' --recolored-mask '$work/recolored.png' \
  --uncertain-mask '$work/uncertain.png' >'$work/recolor.json'"
json_check "recolor counts" "$work/recolor.json" \
  "d['recolored'] > 0 and d['hidden'] > 0 and d['uncertain'] > 0 and d['edge_margin_px'] > 1 and \
   d['recolored'] + d['hidden'] + d['uncertain'] + d['outside_image'] == d['returns']"
check "recolor wrote the uncertain mask" test -s "$work/uncertain.png"
fails_clearly "recolor: the uncertain mask onto the output" "would overwrite" "$lidarshop" recolor "$work/scan.ptx" \
  --photo "$work/photo.png" --camera "$work/cam.json" -o "$work/u.png" --recolored-mask "$work/m.png" \
  --uncertain-mask "$work/u.png"
check "recolor from correspondences" "$lidarshop" recolor "$work/scan.ptx" --photo "$work/photo.png" \
  --correspondences "$work/pairs.json" -o "$work/recolored2.ptx"
fails_clearly "recolor: a photo that does not decode" "photo.jpg" sh -c "echo garbage >'$work/photo.jpg' && \
  '$lidarshop' recolor '$work/scan.ptx' --photo '$work/photo.jpg' --camera '$work/cam.json' -o '$work/x.ply'"
fails_clearly "recolor: camera without fy_px" "'fy_px': missing" sh -c "sed 's/\"fy_px\": 260, //' \
  '$work/cam.json' >'$work/cam_bad.json' && '$lidarshop' recolor '$work/scan.ptx' --photo '$work/photo.png' \
  --camera '$work/cam_bad.json' -o '$work/x.ply'"
fails_clearly "resection: NaN in the correspondences" "pairs_nan.json" "$lidarshop" resection \
  --correspondences "$work/pairs_nan.json" -o "$work/x.json" --size 320 240
fails_clearly "recolor: never onto an input" "input" "$lidarshop" recolor "$work/scan.ptx" --photo \
  "$work/photo.png" --camera "$work/cam.json" -o "$work/scan.ptx"
check "images of pumpA" sh -c "'$lidarshop' images '$shared/e57/pumpA.e57' --extract '$work/images' \
  >'$work/images.json'"
json_check "pumpA holds its 3072 x 2304 photo" "$work/images.json" \
  "d['images'][0]['width_px'] == 3072 and d['images'][0]['representation'] == 'visual'"
check "convert E57 to E57 keeps the photo" "$lidarshop" convert "$shared/e57/pumpA.e57" "$work/pumpA_copy.e57" --quiet
check "images of the copy" sh -c "'$lidarshop' images '$work/pumpA_copy.e57' >'$work/images_copy.json'"
json_check "the copy holds the photo" "$work/images_copy.json" \
  "len(d['images']) == 1 and d['images'][0]['decoded'] and d['images'][0]['width_px'] == 3072"
check "info lists E57 images" sh -c "'$lidarshop' info '$shared/e57/tiny_pc_and_images.e57' >'$work/info_images.json'"
json_check "four images, their kinds, the scan of one" "$work/info_images.json" \
  "[i['representation'] for i in d['images']] == ['visual', 'spherical', 'pinhole', 'cylindrical'] and \
   d['images'][1]['scan'] == 0 and d['images'][1]['e57']['sensor_vendor'] == 'vendor'"
check "info --stats decodes E57 images" sh -c "'$lidarshop' info --stats '$shared/e57/tiny_pc_and_images.e57' >'$work/info_images.json'"
json_check "four images, two decoded" "$work/info_images.json" \
  "len(d['images']) == 4 and sum(i['decoded'] for i in d['images']) == 2 and d['images'][1]['scan'] == 0"
cat >"$work/landmarks.json" <<'JSON'
{"pairs": [{"source": [0, 0, 0], "target": [1, 2, 3]}, {"source": [1, 0, 0], "target": [2, 2, 3]},
           {"source": [0, 1, 0], "target": [1, 3, 3]}, {"source": [0, 0, 1], "target": [1, 2, 4]}]}
JSON
check "align landmarks" sh -c "'$lidarshop' align --correspondences '$work/landmarks.json' -o '$work/T.txt' \
  >'$work/align.json'"
json_check "a pure translation" "$work/align.json" "d['rms_m'] < 1e-9"

json_stdout "resection --json -" rms_px "$lidarshop" resection --correspondences "$work/pairs.json" \
  -o "$work/j_cam.json" --json -
json_stdout "recolor --json -" recolored "$lidarshop" recolor "$work/scan.ptx" --photo "$work/photo.png" \
  --camera "$work/cam.json" -o "$work/j_recolored.ply" --json -
json_stdout "images --json -" images "$lidarshop" images "$shared/e57/pumpA.e57" --json -
json_stdout "align --json -" rms_m "$lidarshop" align --correspondences "$work/landmarks.json" -o "$work/j_T.txt" --json -
json_stdout "photo --json -" scene_pixels "$lidarshop" photo "$work/scene/scene.json" --camera "$work/cam.json" \
  -o "$work/j_photo.png" --samples 1 --json -
# Older JSON on stdout stays there without --json; --json FILE moves it.
check "resection --json FILE" "$lidarshop" resection --correspondences "$work/pairs.json" -o "$work/j_cam2.json" \
  --json "$work/j_resection.json"
check "resection --json FILE leaves stdout empty" test ! -s "$work/last.out"
json_check "resection --json FILE" "$work/j_resection.json" "d['inliers'] == 12 and d['options']['ransac_threshold_px'] > 0"

exits_with 2 "recolor: bad value names the flag" "^lidarshop recolor: --zbuffer-scale: 2(\.0)? is out of range" \
  "$lidarshop" recolor "$work/scan.ptx" --photo "$work/photo.png" --camera "$work/cam.json" -o "$work/x.ply" \
  --zbuffer-scale 2
help_shows "recolor help: visibility as words" "zbuffer|segment" "$lidarshop" recolor

finish
