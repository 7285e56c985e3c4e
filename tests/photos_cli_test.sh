#!/usr/bin/env bash
# End-to-end test of the camera models and the station's photos (#32 items 1-2): `photo` renders a scene with a
# pinhole (old camera file, no "model"), fisheye, spherical and cylindrical camera; `scan --photos cube|sphere`
# writes six pinhole faces or one spherical panorama into the E57 with their poses (camera centre 0.15 m above
# the scanner of parking_lot, at 1.6 m) and gains; `recolor --from-e57-images` colours the scan from them, and
# `recolor --photo P --camera C` repeated from the same faces extracted; `images` lists them with their models; other outputs refuse --photos; the real files
# with images still list. Run by ctest as `photos_cli_test`. Usage: photos_cli_test.sh LIDARSHOP_BINARY SHARED
set -uo pipefail
lidarshop=$1
shared=$2
scene=$(cd "$(dirname "$0")/.." && pwd)/data/scenes/parking_lot.json
pairs=$(dirname "$scene")/../recolor/pumpA_correspondences.json
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
passed=0
failed=0
# shellcheck source=check_lib.sh
source "$(dirname "$0")/check_lib.sh"

pose='"world_from_camera": [[1,0,0,0],[0,1,0,0],[0,0,1,1.6],[0,0,0,1]]'
# The pinhole looks along +y (camera z = world y, camera y = world -z), in the form written before models.
echo '{"width_px": 64, "height_px": 48, "fx_px": 40, "fy_px": 40, "cx_px": 32, "cy_px": 24,
  "world_from_camera": [[1,0,0,0],[0,0,1,0],[0,-1,0,1.6],[0,0,0,1]]}' >"$work/pinhole.json"
echo '{"model": "fisheye", "width_px": 64, "height_px": 64, "fx_px": 20, "fy_px": 20, "cx_px": 32, "cy_px": 32,
  "distortion": {"k1": 0.01}, "world_from_camera": [[1,0,0,0],[0,0,1,0],[0,-1,0,1.6],[0,0,0,1]]}' \
  >"$work/fisheye.json"
echo "{\"model\": \"spherical\", \"width_px\": 128, \"height_px\": 64, \"pixel_width_rad\": 0.04908738521234052,
  \"pixel_height_rad\": 0.04908738521234052, $pose}" >"$work/spherical.json"
echo "{\"model\": \"cylindrical\", \"width_px\": 128, \"height_px\": 48, \"pixel_width_rad\": 0.04908738521234052,
  \"pixel_height_m\": 0.05, \"radius_m\": 1, \"principal_y_px\": 24, $pose}" >"$work/cylindrical.json"
for model in pinhole fisheye spherical cylindrical; do
  check "photo with a $model camera" "$lidarshop" photo "$scene" --camera "$work/$model.json" \
    -o "$work/$model.png" --json "$work/$model.out.json" --quiet
  json_check "photo $model: the model, and pixels that see the scene" "$work/$model.out.json" \
    "d['model'] == '$model' and d['scene_pixels'] > 100"
done
echo '{"model": "orthographic", "width_px": 4, "height_px": 4}' >"$work/bad.json"
fails_clearly "an unknown model is refused naming the field" "bad.json.*'model': unknown model" \
  "$lidarshop" photo "$scene" --camera "$work/bad.json" -o "$work/bad.png"
fails_clearly "recolor's pinhole cameras refuse other models" "fisheye.json.*'model'" \
  "$lidarshop" resection --correspondences "$pairs" --scan "$shared/e57/pumpA.e57" --intrinsics "$work/fisheye.json" -o "$work/x.json"

scan=(scan parking_lot --rows 50 --columns 100 --seed 3 --quiet)
check "scan --photos cube" "$lidarshop" "${scan[@]}" -o "$work/cube.e57" --photos cube --photo-size 48 \
  --json "$work/cube_scan.json"
json_check "scan --photos cube: six faces, photo 0 at gain 1, the others within 30 %" "$work/cube_scan.json" \
  "[p['name'] for p in d['photos']] == ['front', 'right', 'back', 'left', 'up', 'down'] and \
   d['photos'][0]['gain'] == 1 and all(0.7 <= p['gain'] <= 1.3 for p in d['photos']) and \
   len(set(p['gain'] for p in d['photos'])) == 6"
check "images cube.e57" sh -c "'$lidarshop' images '$work/cube.e57' >'$work/cube_images.json'"
json_check "cube faces: pinhole, 90°, camera 0.15 m above the scanner, scan 0" "$work/cube_images.json" \
  "len(d['images']) == 6 and all(i['model'] == 'pinhole' and i['representation'] == 'pinhole' and \
   i['scan'] == 0 and abs(i['camera']['fx_px'] - 24) < 1e-9 and i['width_px'] == 48 and \
   abs(i['world_from_camera'][2][3] - 1.75) < 1e-9 for i in d['images'])"
check "scan --photos sphere" "$lidarshop" "${scan[@]}" -o "$work/sphere.e57" --photos sphere --photo-size 32
check "images sphere.e57" sh -c "'$lidarshop' images '$work/sphere.e57' >'$work/sphere_images.json'"
json_check "sphere: one spherical 64 x 32 panorama at the camera centre" "$work/sphere_images.json" \
  "len(d['images']) == 1 and d['images'][0]['model'] == 'spherical' and d['images'][0]['width_px'] == 64 and \
   abs(d['images'][0]['intrinsics']['pixel_height_rad'] - math.pi / 32) < 1e-12 and \
   abs(d['images'][0]['world_from_camera'][2][3] - 1.75) < 1e-9"
check "convert keeps the photos" "$lidarshop" convert "$work/sphere.e57" "$work/sphere2.e57" --quiet
check "images sphere2.e57" sh -c "'$lidarshop' images '$work/sphere2.e57' >'$work/sphere2_images.json'"
json_check "converted: the same panorama" "$work/sphere2_images.json" \
  "d['images'][0]['camera'] == json.load(open('$work/sphere_images.json'))['images'][0]['camera']"
fails_clearly "--photos into a PTX is refused" "--photos needs an output that holds photos \(E57\)" \
  "$lidarshop" "${scan[@]}" -o "$work/s.ptx" --photos sphere
fails_clearly "--photo-size without --photos is refused" "--photo-size is for --photos" \
  "$lidarshop" "${scan[@]}" -o "$work/s.e57" --photo-size 64

# Colour the cube station from its own images: the fitted gains are the true ones where a face colours the scan.
check "scan a finer cube station" "$lidarshop" scan parking_lot --rows 150 --columns 300 --seed 3 --quiet \
  -o "$work/cube_fine.e57" --photos cube --photo-size 256 --json "$work/cube_fine_scan.json"
check "recolor --from-e57-images (cube)" "$lidarshop" recolor "$work/cube_fine.e57" --from-e57-images \
  -o "$work/cube_coloured.ply" --photo-index-mask "$work/cube_index.png" --json "$work/cube_recolor.json" --quiet
json_check "cube recolour: most returns coloured, gains of the faces used within 3 %" "$work/cube_recolor.json" \
  "d['coloured'] > 0.9 * d['returns'] and len(d['photos']) == 6 and \
   all(abs(g / s['gain'] - 1) < 0.03 for p, s in zip(d['photos'], json.load(open('$work/cube_fine_scan.json'))['photos']) \
       for g in p['gain'] if g != 1.0)"
check "the photo index mask is written" test -s "$work/cube_index.png"
# Into an E57 the station's photos go on with the recoloured scan, bit for bit; another format says they go.
check "recolor --from-e57-images into an E57" "$lidarshop" recolor "$work/cube_fine.e57" --from-e57-images \
  -o "$work/cube_coloured.e57" --quiet
check "images cube_coloured.e57" sh -c "'$lidarshop' images '$work/cube_coloured.e57' --extract '$work/carried' >'$work/carried.json'"
check "images cube_fine.e57 (the input's)" sh -c "'$lidarshop' images '$work/cube_fine.e57' --extract '$work/given' >'$work/given.json'"
json_check "the recoloured E57 keeps the six faces with their cameras, on scan 0" "$work/carried.json" \
  "(lambda e: len(d['images']) == 6 and [i['camera'] for i in d['images']] == [i['camera'] for i in e['images']])(json.load(open('$work/given.json')))"
check "the first face is carried bit for bit" sh -c "cmp \"\$(python3 -c \"import json; print(json.load(open('$work/carried.json'))['images'][0]['extracted'])\")\" \"\$(python3 -c \"import json; print(json.load(open('$work/given.json'))['images'][0]['extracted'])\")\""
check "a recoloured PLY warns that the photos go" sh -c "'$lidarshop' recolor '$work/cube_fine.e57' --from-e57-images -o '$work/cube_coloured2.ply' 2>&1 | grep -q 'photo(s) are not carried on'"
# The same faces given as separate photos with their cameras (--photo repeated): the same colouring.
check "images --extract cube_fine.e57" sh -c "'$lidarshop' images '$work/cube_fine.e57' --extract '$work/faces' >'$work/faces.json'"
python3 - "$work" <<'PY'
import json, sys
work = sys.argv[1]
args = []
for i, image in enumerate(json.load(open(work + "/faces.json"))["images"]):
    json.dump(image["camera"], open(f"{work}/face{i}.json", "w"))
    args += ["--photo", image["extracted"], "--camera", f"{work}/face{i}.json"]
open(work + "/face_args", "w").write("\n".join(args))
PY
mapfile -t face_args <"$work/face_args"
check "recolor --photo x6 --camera x6" "$lidarshop" recolor "$work/cube_fine.e57" "${face_args[@]}" \
  -o "$work/faces_coloured.ply" --photo-index-mask "$work/faces_index.png" --json "$work/faces_recolor.json" --quiet
json_check "repeated --photo: the gains and counts of --from-e57-images" "$work/faces_recolor.json" \
  "(lambda e: d['coloured'] == e['coloured'] and d['seam_edges'] == e['seam_edges'] and d['seam_edges'] > 0 and \
   [p['gain'] for p in d['photos']] == [p['gain'] for p in e['photos']])(json.load(open('$work/cube_recolor.json')))"
check "repeated --photo: the same photo index mask" cmp "$work/faces_index.png" "$work/cube_index.png"
fails_clearly "repeated --photo needs a --camera each" "2 --photo need as many --camera" \
  "$lidarshop" recolor "$work/cube_fine.e57" --photo "$work/pinhole.png" --photo "$work/pinhole.png" \
  --camera "$work/pinhole.json" -o "$work/x.ply"
fails_clearly "pumpA has no image with a camera" "no image of scan 0 holds a photo with a camera" \
  "$lidarshop" recolor "$shared/e57/pumpA.e57" --from-e57-images -o "$work/pump.ply"
fails_clearly "--from-e57-images takes no --photo" "--from-e57-images takes the photos" \
  "$lidarshop" recolor "$work/cube.e57" --from-e57-images --photo "$work/pinhole.png" -o "$work/x.ply"

check "images of the real file with every representation" \
  sh -c "'$lidarshop' images '$shared/e57/tiny_pc_and_images.e57' >'$work/tiny.json'"
json_check "tiny_pc_and_images: visual, spherical, pinhole, cylindrical" "$work/tiny.json" \
  "[i['model'] for i in d['images']] == [None, 'spherical', 'pinhole', 'cylindrical'] and \
   d['images'][3]['intrinsics']['radius_m'] == 666"
check "images pumpA" sh -c "'$lidarshop' images '$shared/e57/pumpA.e57' >'$work/pump.json'"
json_check "pumpA: one visual reference, no model" "$work/pump.json" \
  "len(d['images']) == 1 and d['images'][0]['model'] is None and d['images'][0]['representation'] == 'visual'"

echo "photos_cli_test: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
