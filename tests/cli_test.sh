#!/usr/bin/env bash
# End-to-end test of the `lidarshop` command line: every command on small inputs, the JSON contracts scripts rely
# on, exit codes, and one-line errors on bad input. Run by ctest as `cli_test` with the binary and the shared data.
# Usage: cli_test.sh LIDARSHOP_BINARY SHARED_DATA_DIR
set -uo pipefail
lidarshop=$1
shared=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
passed=0
failed=0
# shellcheck source=check_lib.sh
source "$(dirname "$0")/check_lib.sh"

exits_with() {  # exits_with CODE NAME PATTERN COMMAND...: that exit code and one line on stderr matching PATTERN
  local code=$1 name=$2 pattern=$3
  shift 3
  "$@" >"$work/last.out" 2>"$work/last.err"
  local status=$?
  if [ "$status" -eq "$code" ] && [ "$(wc -l <"$work/last.err")" -eq 1 ] && grep -qE -e "$pattern" "$work/last.err"; then
    passed=$((passed + 1))
  else
    failed=$((failed + 1))
    echo "FAILED: $name: expected exit $code and one line matching '$pattern', got exit $status:"
    sed 's/^/  | /' "$work/last.err" | head -10
  fi
}

# The scene form of docs/scene-format.md, with a mesh from the shared data (paths relative to the scene file).
mkdir -p "$work/scene/meshes"
cp "$shared/meshes/beetle.obj" "$work/scene/meshes/car.obj"
cat >"$work/scene/scene.json" <<'JSON'
{"scanner": {"position": [0, 0, 1.5], "rotate_deg": [0, 0, 0],
             "azimuth_deg": [-45, 45], "elevation_deg": [-30, 30], "columns": 180, "rows": 120,
             "max_range": 100, "los_noise_sigma": 0.0, "orthogonal_noise_sigma": 0.0, "seed": 1},
 "objects": [
   {"primitive": "plane", "size": [200, 200], "translate": [0, 0, 0], "label": 0, "texture": "grass"},
   {"primitive": "sphere", "radius": 1.0, "translate": [2, 10, 1], "label": 1, "color": [200, 40, 40]},
   {"primitive": "box", "size": [1, 0.6, 1.2], "translate": [-2, 8, 0.6], "label": 2},
   {"primitive": "cylinder", "radius": 0.1, "height": 3, "translate": [4, 12, 1.5], "label": 3},
   {"mesh": "meshes/car.obj", "scale": 4.2, "rotate_deg": [90, 0, 30], "translate": [0, 15, 0], "label": 4}]}
JSON

# Usage.
check "help" "$lidarshop" --help
check "scan help" "$lidarshop" scan --help
fails_clearly "unknown command" "unknown command" "$lidarshop" no-such-command

# scan: PTX, labels, mesh, stats.
check "scan" "$lidarshop" scan "$work/scene/scene.json" -o "$work/scan.ptx" --labels "$work/labels.png" \
  --mesh "$work/mesh.ply" --stats
cp "$work/last.out" "$work/stats.json"
cp "$work/last.err" "$work/scan.err"
json_check "scan --stats is one JSON object with stage seconds" "$work/stats.json" \
  "isinstance(d, dict) and len(json.dumps(d)) > 10"
check "scan wrote its outputs" test -s "$work/scan.ptx" -a -s "$work/labels.png" -a -s "$work/mesh.ply"
# car.obj names an MTL file that is not there: the mesh reader's warning is one line on stderr naming the
# OBJ and the missing file.
check "scan prints the mesh reader's warning" \
  grep -qE "^lidarshop: warning: .*scene/meshes/car\.obj: .*VWBugMesh002\.mtl.*without its materials" "$work/scan.err"
# Besides warnings, one summary line (#35): what it wrote, how much, how long; no progress bar off a terminal.
check "scan ends with one summary line when stderr is not a terminal" \
  test "$(grep -v '^lidarshop: warning: ' "$work/scan.err" | grep -cE '^lidarshop scan: 120 x 180 scan, [0-9]+ returns of 21600 rays -> .*scan\.ptx \([0-9.]+ s\)$')" -eq 1 \
  -a "$(grep -vc '^lidarshop: warning: ' "$work/scan.err")" -eq 1
fails_clearly "scan: missing scene" "no_such_scene.json" "$lidarshop" scan "$work/no_such_scene.json" -o "$work/x.ptx"
# A built-in scene by name, as `demo --scene NAME`; an unknown name lists the built-in ones.
check "scan a built-in scene by name" sh -c "'$lidarshop' scan parking_lot -o '$work/parking.ply' --rows 30 \
  --columns 60 --json - --quiet >'$work/parking.json'"
json_check "the built-in scene was scanned" "$work/parking.json" \
  "d['rows'] == 30 and d['columns'] == 60 and d['objects'] > 3 and d['returns'] > 0"
fails_clearly "scan: an unknown scene name lists the built-in ones" "no_such_scene.*parking_lot.*" \
  "$lidarshop" scan no_such_scene -o "$work/x.ptx"
# A random scene from a seed (scanner/random_scene.h): the same seed writes the same scene and scan, and the
# written scene scans as a file to the same points; SCENE and --random exclude each other.
check "scan a random scene" sh -c "'$lidarshop' scan --random 7 -o '$work/random7.ply' \
  --write-scene '$work/random7.json' --json - --quiet >'$work/random7_stats.json'"
json_check "the random scene is 400 x 300 and names its target" "$work/random7_stats.json" \
  "d['rows'] == 300 and d['columns'] == 400 and d['target_label'] >= 1 and d['returns'] > 0"
check "the same seed writes the same scene and scan" sh -c "'$lidarshop' scan --random 7 -o '$work/random7b.ply' \
  --write-scene '$work/random7b.json' --quiet && cmp '$work/random7.json' '$work/random7b.json' \
  && cmp '$work/random7.ply' '$work/random7b.ply'"
check "the written random scene scans to the same points" sh -c "'$lidarshop' scan '$work/random7.json' \
  -o '$work/random7c.ply' --quiet && cmp '$work/random7.ply' '$work/random7c.ply'"
fails_clearly "scan: a scene and --random" "exactly one of SCENE and --random" \
  "$lidarshop" scan parking_lot --random 3 -o "$work/x.ptx"
fails_clearly "scan: --write-scene without --random" "write-scene needs --random" \
  "$lidarshop" scan parking_lot --write-scene "$work/x.json" -o "$work/x.ptx"
# The scene example of docs/scene-format.md runs as the document says: saved in the repository's top folder
# (here: beside a link to its data/ folder), its mesh path names a mesh of the repository.
repo=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$work/doc_example"
ln -s "$repo/data" "$work/doc_example/data"
check "extract the scene example of docs/scene-format.md" python3 -c 'import re, sys
fence = chr(96) * 3
text = open(sys.argv[1]).read()
open(sys.argv[2], "w").write(re.search(fence + "json\n(.*?)" + fence, text, re.S).group(1))' \
  "$repo/docs/scene-format.md" "$work/doc_example/example.json"
check "the documented scene example scans" sh -c "'$lidarshop' scan '$work/doc_example/example.json' \
  -o '$work/doc_example/example.ply' --json - --quiet >'$work/doc_example.json'"
json_check "the documented example has its four objects, the mesh among them" "$work/doc_example.json" \
  "d['objects'] == 4 and d['returns'] > 0"

# info: the header alone by default, in reading order; --stats reads the points (the keys scripts rely on).
check "info" "$lidarshop" info "$work/scan.ptx"
cp "$work/last.out" "$work/info_header.json"
json_check "info header keys" "$work/info_header.json" \
  "list(d)[:4] == ['file', 'format', 'format_version', 'size_bytes'] and d['size_bytes'] > 0 and \
   d['scans'][0]['rows'] == 120 and d['scans'][0]['cols'] == 180 and d['scans'][0]['organized'] and \
   d['scans'][0]['points'] == 120 * 180 and 'intensity' in d['scans'][0]['channels'] and \
   'valid' not in d['scans'][0] and abs(d['scans'][0]['world_from_scanner'][2][3] - 1.5) < 1e-6"
check "info --stats" "$lidarshop" info "$work/scan.ptx" --stats
cp "$work/last.out" "$work/info.json"
json_check "info --stats keys" "$work/info.json" \
  "d['format'] == 'ptx' and d['file'].endswith('scan.ptx') and len(d['scans']) == 1 and \
   all(k in d['scans'][0] for k in ('rows', 'cols', 'valid', 'bounds', 'world_from_scanner', 'channels')) and \
   d['scans'][0]['rows'] == 120 and d['scans'][0]['cols'] == 180 and 0 < d['scans'][0]['valid'] <= 120 * 180 and \
   len(d['scans'][0]['world_from_scanner']) == 4 and abs(d['scans'][0]['world_from_scanner'][2][3] - 1.5) < 1e-6"

# formats: the registry the convert warnings come from, as JSON and as the docs' table.
check "formats --json" sh -c "'$lidarshop' formats --json - >'$work/formats.json'"
json_check "formats lists every format read, LAZ not written" "$work/formats.json" \
  "[f['extension'] for f in d['formats']] == ['ptx', 'e57', 'ply', 'pcd', 'las', 'laz', 'xyz', 'pts'] and \
   [f['extension'] for f in d['formats'] if not f['write']] == ['laz'] and \
   next(f for f in d['formats'] if f['extension'] == 'las')['label'] == 'classification'"
check "formats --markdown is the docs' table" sh -c "'$lidarshop' formats --markdown >'$work/formats.md'"
check "the docs hold that table, one row per format" python3 -c \
  "import sys; t = open(sys.argv[1]).read(); assert t.count('\n') == 10 and t in open(sys.argv[2]).read()" \
  "$work/formats.md" "$(dirname "$0")/../docs/file-formats.md"
exits_with 2 "formats: an unknown option" "formats" "$lidarshop" formats --csv

# convert: every format keeps every return.
valid=$(python3 -c "import json; print(json.load(open('$work/info.json'))['scans'][0]['valid'])")
for format in e57 ply pcd las xyz pts; do
  check "convert ptx -> $format" "$lidarshop" convert "$work/scan.ptx" "$work/scan.$format" --quiet
  check "info $format" "$lidarshop" info --stats "$work/scan.$format"
  cp "$work/last.out" "$work/info_$format.json"
  json_check "convert to $format keeps the returns" "$work/info_$format.json" "d['scans'][0]['valid'] == $valid"
done
check "convert ptx -> LAS 1.2 format 3" "$lidarshop" convert "$work/scan.ptx" "$work/scan12.las" \
  --las-minor-version 2 --las-point-format 3 --quiet
check "LAS 1.2 format 3 header" python3 -c "import sys; d=open('$work/scan12.las','rb').read(); sys.exit(not (d[25] == 2 and d[104] == 3))"
fails_clearly "convert: LAS format 6 needs 1.4" "las-minor-version|las-point-format|1.4" \
  "$lidarshop" convert "$work/scan.ptx" "$work/bad.las" --las-minor-version 2 --las-point-format 6
fails_clearly "LAZ is read, not written" "LAZ is not written" "$lidarshop" convert "$work/scan.ptx" "$work/scan.laz"
check "convert e57 -> ptx" "$lidarshop" convert "$work/scan.e57" "$work/back.ptx" --quiet
check "info back.ptx" "$lidarshop" info --stats "$work/back.ptx"
cp "$work/last.out" "$work/info_back.json"
json_check "ptx -> e57 -> ptx keeps the grid" "$work/info_back.json" \
  "d['scans'][0]['rows'] == 120 and d['scans'][0]['cols'] == 180 and d['scans'][0]['valid'] == $valid"

# render: every channel, one pixel per ray.
for channel in range rgb intensity normals valid; do
  check "render $channel" "$lidarshop" render "$work/scan.ptx" -o "$work/render_$channel.png" --channel "$channel"
done
# PTX has no label channel (a clear error); PLY keeps the synthetic scanner's labels.
fails_clearly "render labels of a PTX" "label" "$lidarshop" render "$work/scan.ptx" -o "$work/x.png" --channel labels
check "scan to PLY" "$lidarshop" scan "$work/scene/scene.json" -o "$work/scan_labels.ply" --quiet
check "render labels of a PLY" "$lidarshop" render "$work/scan_labels.ply" -o "$work/render_labels.png" --channel labels
check "render with legend" "$lidarshop" render "$work/scan.ptx" -o "$work/legend.png" --channel range --legend
fails_clearly "render into a missing folder" "no_such_dir" \
  "$lidarshop" render "$work/scan.ptx" -o "$work/no_such_dir/x.png" --channel range
fails_clearly "render: bad channel" "channel" "$lidarshop" render "$work/scan.ptx" -o "$work/x.png" --channel nope

# Bad input: a truncated PTX names the file and the line; the input is untouched, no output is left behind.
head -c 2000 "$work/scan.ptx" >"$work/truncated.ptx"
before=$(md5sum <"$work/truncated.ptx")
fails_clearly "truncated ptx" "truncated.ptx.*line" "$lidarshop" convert "$work/truncated.ptx" "$work/out.ply"
check "no partial output" test ! -e "$work/out.ply"
check "input untouched" test "$before" = "$(md5sum <"$work/truncated.ptx")"
printf 'garbage\n' >"$work/garbage.e57"
fails_clearly "garbage e57" "garbage.e57" "$lidarshop" info "$work/garbage.e57"
fails_clearly "corrupt e57 names the page" "page [0-9]+" "$lidarshop" info --stats "$shared/e57/corrupt_crc.e57"

# Real data: the E57 scan and the organized RGB-D cloud.
check "info pumpA (header)" "$lidarshop" info "$shared/e57/pumpA.e57"
cp "$work/last.out" "$work/pump_header.json"
json_check "pumpA header: grid, records, photo, guid" "$work/pump_header.json" \
  "d['scans'][0]['rows'] * d['scans'][0]['cols'] == 1074 * 345 and d['scans'][0]['points'] == 155201 and \
   d['guid'] == '{4F947749-517F-49D1-9AD9-A899110EFFDD}' and d['created_utc'].startswith('2011-08-03') and \
   d['images'][0]['width_px'] == 3072 and d['images'][0]['representation'] == 'visual' and \
   d['images'][0]['encoding'] == 'jpeg' and d['size_bytes'] == $(stat -c %s "$shared/e57/pumpA.e57")"
check "info pumpA --stats" "$lidarshop" info --stats "$shared/e57/pumpA.e57"
cp "$work/last.out" "$work/pump.json"
json_check "pumpA grid and counts" "$work/pump.json" \
  "d['scans'][0]['rows'] * d['scans'][0]['cols'] == 1074 * 345 and d['scans'][0]['valid'] == 155201"
# read_error.e57 (docs/e57.md): the header describes it, reading its points refuses its corrupt grid indices.
check "info read_error.e57 (header)" sh -c "'$lidarshop' info '$shared/e57/read_error.e57' >'$work/read_error.json'"
json_check "read_error.e57: one organized scan of 2,651 spherical records, grid unknown" "$work/read_error.json" \
  "d['scans'][0]['points'] == 2651 and d['scans'][0]['organized'] and d['scans'][0]['rows'] is None and \
   d['scans'][0]['coordinates'] == 'spherical'"
exits_with 1 "read_error.e57: its points are refused as documented" \
  "read_error.e57: XML section: field 'e57Root/data3D/vectorChild/points': records 0 and 1 both claim row 0, column 0" \
  "$lidarshop" info --stats "$shared/e57/read_error.e57"
check "render pumpA" "$lidarshop" render "$shared/e57/pumpA.e57" -o "$work/pump.png" --channel rgb

# render: square angular pixels. pumpA's rays are 0.250 deg across and 0.0675 deg down (345 x 1074): the
# picture is 3.7 times as wide as one pixel per ray, its aspect the scan's angular aspect (86 deg x 72.5 deg).
picture_size() {  # picture_size FILE.png: "width height" from the PNG header
  python3 -c "import struct,sys; d=open(sys.argv[1],'rb').read(24); print(*struct.unpack('>II', d[16:24]))" "$1"
}
check "render pumpA --json" "$lidarshop" render "$shared/e57/pumpA.e57" -o "$work/pump_range.png" --json "$work/pump_range.json"
json_check "render pumpA: square angular pixels" "$work/pump_range.json" \
  "d['layout']['view'] == 'grid' and abs(d['layout']['pixel_width'] - d['layout']['pixel_height']) < 0.001 and \
   abs(d['width_px'] / d['height_px'] - (345 * 0.2498) / (1074 * 0.06754)) < 0.01 and d['height_px'] == 1074"
check "render pumpA: the picture has the size --json says" test "$(picture_size "$work/pump_range.png")" = "1276 1074"
check "render --aspect native: one pixel per ray" "$lidarshop" render "$shared/e57/pumpA.e57" -o "$work/pump_native.png" \
  --aspect native --quiet
check "render --aspect native size" test "$(picture_size "$work/pump_native.png")" = "345 1074"
check "render --width keeps the aspect" "$lidarshop" render "$shared/e57/pumpA.e57" -o "$work/pump_w.png" --width 638 --quiet
check "render --width size" test "$(picture_size "$work/pump_w.png")" = "638 537"
check "render --width --height" "$lidarshop" render "$shared/e57/pumpA.e57" -o "$work/pump_wh.png" --width 300 \
  --height 100 --quiet
check "render --width --height size" test "$(picture_size "$work/pump_wh.png")" = "300 100"
fails_clearly "render --width below 16" "width" "$lidarshop" render "$work/scan.ptx" -o "$work/x.png" --width 8

# render: an unorganized cloud (an E57 without row/column) is projected onto a spherical grid, and says so.
check "render an unorganized E57" "$lidarshop" render "$shared/e57/bunnyFloat.e57" -o "$work/bunny.png" \
  --json "$work/bunny.json"
cp "$work/last.err" "$work/bunny.err"
check "render says it projected the cloud" grep -q "^lidarshop render: unorganized cloud of 30571 points projected onto a spherical grid" "$work/bunny.err"
json_check "render of a cloud is not N x 1" "$work/bunny.json" \
  "d['layout']['view'] == 'sphere' and d['width_px'] > 50 and d['height_px'] > 50 and \
   d['layout']['points'] == 30571 and 0 < d['layout']['points_kept'] <= 30571"
check "render --view top" "$lidarshop" render "$shared/e57/bunnyFloat.e57" -o "$work/bunny_top.png" --view top \
  --channel normals --legend --json "$work/bunny_top.json" --quiet
cp "$work/last.err" "$work/bunny_top.err"
check "render --quiet says nothing" test ! -s "$work/bunny_top.err"
json_check "render --view top is orthographic in metres" "$work/bunny_top.json" \
  "d['layout']['view'] == 'top' and d['layout']['pixel_unit'] == 'm'"
# render: pictures of an aerial LAS cloud from above, its own units on the legends.
autzen="$shared/interop/las/autzen-thin.las"
check "render LAS --view top" "$lidarshop" render "$autzen" -o "$work/autzen_top.png" --view top --legend \
  --json "$work/autzen_top.json" --quiet
json_check "render LAS top: elevation in metres, >= 1000 px, points as squares" "$work/autzen_top.json" \
  "d['channel'] == 'elevation' and d['scale']['unit'] == 'm' and 400 < d['scale']['min'] < d['scale']['max'] < 600 \
   and max(d['layout']['source_cols'], d['layout']['source_rows']) >= 1000 and d['layout']['point_size_px'] > 1"
check "render LAS top intensity" "$lidarshop" render "$autzen" -o "$work/autzen_int.png" --view top \
  --channel intensity --width 800 --point-size 3 --json "$work/autzen_int.json" --quiet
json_check "render LAS intensity in 16-bit units, --width and --point-size honoured" "$work/autzen_int.json" \
  "d['scale']['max'] > 50 and d['width_px'] == 800 and d['layout']['point_size_px'] == 3"
check "render LAS classes" "$lidarshop" render "$autzen" -o "$work/autzen_cls.png" --view side \
  --channel classification --legend --json "$work/autzen_cls.json" --quiet
json_check "render LAS classes are named" "$work/autzen_cls.json" \
  "d['legend'] == ['1  unclassified', '2  ground'] and d['layout']['view'] == 'side'"
check "render LAS --hillshade" "$lidarshop" render "$autzen" -o "$work/autzen_hs.png" --view top --hillshade --quiet
fails_clearly "render --hillshade of a ray grid" "orthographic" "$lidarshop" render "$work/scan.ptx" \
  -o "$work/x.png" --hillshade
python3 - "$work/cloud.pcd" <<'PY'
import math, sys
# An unorganized cloud as Open3D writes it (HEIGHT 1): a wall 6 m ahead seen over 60 x 20 degrees.
points = [(6 * math.cos(math.radians(e)) * math.sin(math.radians(a)), 6 * math.cos(math.radians(e)) * math.cos(math.radians(a)),
           6 * math.sin(math.radians(e))) for a in range(-30, 31) for e in range(-10, 11)]
with open(sys.argv[1], "w") as f:
    f.write("# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n")
    f.write(f"WIDTH {len(points)}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {len(points)}\nDATA ascii\n")
    f.writelines(f"{x:.5f} {y:.5f} {z:.5f}\n" for x, y, z in points)
PY
check "render an unorganized PCD" "$lidarshop" render "$work/cloud.pcd" -o "$work/cloud.png" \
  --json "$work/cloud.json" --quiet
json_check "render of a PCD cloud is projected" "$work/cloud.json" \
  "d['layout']['view'] == 'sphere' and d['height_px'] > 10 and abs(d['width_px'] / d['height_px'] - 3) < 0.3"

# render: float pictures hold the values (the C++ test checks them value by value).
for extension in exr tif; do
  check "render range .$extension" "$lidarshop" render "$work/scan.ptx" -o "$work/range.$extension" --json \
    "$work/range_$extension.json" --quiet
  json_check "render range .$extension is float metres" "$work/range_$extension.json" "'metres' in d['values']"
done
check "range.exr is OpenEXR" python3 -c "import sys; sys.exit(open('$work/range.exr','rb').read(4) != b'\x76\x2f\x31\x01')"
fails_clearly "render rgb as .exr" "range, elevation, intensity or normals" "$lidarshop" render "$work/scan.ptx" -o "$work/x.exr" --channel rgb
fails_clearly "render --legend as .exr" "legend" "$lidarshop" render "$work/scan.ptx" -o "$work/x.exr" --legend

# Label legends name the scene's objects; scan --labels writes the colour picture beside the raw one.
check "scan wrote the colour labels beside the raw ones" test -s "$work/labels_color.png"
check "render labels with the scene's names" "$lidarshop" render "$work/scan_labels.ply" -o "$work/named.png" \
  --channel labels --legend --scene "$work/scene/scene.json" --quiet
check "render labels without names" "$lidarshop" render "$work/scan_labels.ply" -o "$work/unnamed.png" \
  --channel labels --legend --quiet
check "names widen the label legend" test "$(picture_size "$work/named.png" | cut -d' ' -f1)" -gt \
  "$(picture_size "$work/unnamed.png" | cut -d' ' -f1)"
check "info mug pcd" "$lidarshop" info "$shared/rgbd/table_scene_mug_stereo_textured.pcd"

# verify: the box (label 2) at its true pose, and 1 m towards the scanner.
cat >"$work/box.obj" <<'OBJ'
v -0.5 -0.3 -0.6
v 0.5 -0.3 -0.6
v 0.5 0.3 -0.6
v -0.5 0.3 -0.6
v -0.5 -0.3 0.6
v 0.5 -0.3 0.6
v 0.5 0.3 0.6
v -0.5 0.3 0.6
f 1 3 2
f 1 4 3
f 5 6 7
f 5 7 8
f 1 2 6
f 1 6 5
f 2 3 7
f 2 7 6
f 3 4 8
f 3 8 7
f 4 1 5
f 4 5 8
OBJ
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

# segment: the sphere (label 1) from JSON strokes in grid coordinates. Its centre (2, 10, 1) seen from (0, 0, 1.5)
# is at azimuth atan2(2, 10) = 11.31 deg and elevation atan2(-0.5, sqrt(104)) = -2.81 deg: column
# (11.31 + 45) / 90 * 179 = 112, image row (30 + 2.81) / 60 * 119 = 65 (row 0 = top).
cat >"$work/strokes.json" <<'JSON'
{"strokes": [{"label": "object", "width": 3, "points": [[110, 65], [114, 65]]},
             {"label": "background", "width": 2, "points": [[5, 115], [175, 115]]}]}
JSON
check "segment" "$lidarshop" segment "$work/scan.ptx" --strokes "$work/strokes.json" -o "$work/mask.png" \
  --object "$work/object.e57" --rest "$work/rest.ply" --quiet
check "segment wrote mask, overlay and scans" test -s "$work/mask.png" -a -s "$work/mask_overlay.png" \
  -a -s "$work/object.e57" -a -s "$work/rest.ply"
# --object and --rest are organized scans of the input's grid and pose that split its returns between them.
check "info object.e57" "$lidarshop" info --stats "$work/object.e57"
cp "$work/last.out" "$work/info_object.json"
check "info rest.ply" "$lidarshop" info --stats "$work/rest.ply"
cp "$work/last.out" "$work/info_rest.json"
json_check "segment --object keeps the grid and pose" "$work/info_object.json" \
  "d['scans'][0]['rows'] == 120 and d['scans'][0]['cols'] == 180 and 0 < d['scans'][0]['valid'] < $valid and \
   abs(d['scans'][0]['world_from_scanner'][2][3] - 1.5) < 1e-6"
object_valid=$(python3 -c "import json; print(json.load(open('$work/info_object.json'))['scans'][0]['valid'])")
json_check "segment --rest holds the other returns" "$work/info_rest.json" \
  "d['scans'][0]['rows'] == 120 and d['scans'][0]['cols'] == 180 and \
   d['scans'][0]['valid'] + $object_valid == $valid and abs(d['scans'][0]['world_from_scanner'][2][3] - 1.5) < 1e-6"
# Every point output is in the world frame (docs/file-formats.md): the cut-out written as PCD and PLY lies on the
# scan's own world points (scan.xyz from convert), and the headers say so. Read here without lidarshop, as a tool
# that ignores VIEWPOINT and comments would.
cat >"$work/frame_check.py" <<'PY'
import math, struct, sys

def header_of(data, end_marker):
    end = data.index(end_marker)
    end = data.index(b"\n", end + 1) + 1
    return data[:end].decode("ascii"), end

def read_pcd(path):
    data = open(path, "rb").read()
    header, start = header_of(data, b"\nDATA ")
    # The numbers are world points; VIEWPOINT is the scanner's pose (PCL's convention).
    assert "\n# frame world\n" in header and "\nVIEWPOINT " in header, header
    keys = {line.split()[0]: line.split()[1:] for line in header.splitlines() if line and line[0] != "#"}
    assert keys["DATA"] == ["binary"]
    codes = {("F", "4"): "f", ("F", "8"): "d", ("U", "1"): "B", ("I", "4"): "i", ("U", "4"): "I"}
    fmt = "<" + "".join(codes[t, s] for t, s in zip(keys["TYPE"], keys["SIZE"]))
    size = struct.calcsize(fmt)
    count = int(keys["POINTS"][0])
    names = keys["FIELDS"]
    points = []
    for i in range(count):
        record = struct.unpack_from(fmt, data, start + i * size)
        x, y, z = (record[names.index(n)] for n in "xyz")
        if not math.isnan(x):
            points.append((x, y, z))
    return points

def read_ply(path):
    data = open(path, "rb").read()
    header, start = header_of(data, b"end_header")
    assert "\ncomment frame world\n" in header and "binary_little_endian" in header, header
    codes = {"float": "f", "double": "d", "uchar": "B", "int": "i", "uint": "I", "char": "b", "short": "h",
             "ushort": "H"}
    fmt, names, count, in_vertex = "<", [], 0, False
    for line in header.splitlines():
        words = line.split()
        if words[:2] == ["element", "vertex"]:
            count, in_vertex = int(words[2]), True
        elif words[:1] == ["element"]:
            in_vertex = False
        elif words[:1] == ["property"] and in_vertex:
            fmt += codes[words[1]]
            names.append(words[2])
    size = struct.calcsize(fmt)
    return [tuple(struct.unpack_from(fmt, data, start + i * size)[names.index(n)] for n in "xyz")
            for i in range(count)]

scan = {}
for line in open(sys.argv[1]):
    words = line.split()
    if len(words) >= 3:
        p = tuple(float(w) for w in words[:3])
        scan.setdefault(tuple(round(c * 100) for c in p), []).append(p)

def on_scan(p):
    key = [round(c * 100) for c in p]
    for dx in (-1, 0, 1):
        for dy in (-1, 0, 1):
            for dz in (-1, 0, 1):
                for q in scan.get((key[0] + dx, key[1] + dy, key[2] + dz), []):
                    if max(abs(a - b) for a, b in zip(p, q)) < 1e-4:
                        return True
    return False

for path in sys.argv[2:]:
    points = read_pcd(path) if path.endswith(".pcd") else read_ply(path)
    assert len(points) > 50, (path, len(points))
    missing = sum(not on_scan(p) for p in points)
    assert missing == 0, f"{path}: {missing} of {len(points)} points are not on the scan's world points"
    mean_z = sum(p[2] for p in points) / len(points)
    assert "object" not in path or 0.5 < mean_z < 1.5, f"{path}: mean z {mean_z}: the sphere's centre is 1 m up in the world"
PY
check "segment --object as PCD and PLY" "$lidarshop" segment "$work/scan.ptx" --strokes "$work/strokes.json" \
  -o "$work/mask_frames.png" --overlay none --object "$work/object.pcd" --rest "$work/rest.pcd" --quiet
check "segment --object as PLY" "$lidarshop" segment "$work/scan.ptx" --strokes "$work/strokes.json" \
  -o "$work/mask_frames.png" --overlay none --object "$work/object.ply" --quiet
check "segment outputs lie on the scan's world points" python3 "$work/frame_check.py" "$work/scan.xyz" \
  "$work/object.pcd" "$work/object.ply" "$work/scan.pcd" "$work/scan.ply"
check "PCD round trip keeps the pose" "$lidarshop" info --stats "$work/object.pcd"
cp "$work/last.out" "$work/info_object_pcd.json"
json_check "segment --object .pcd reads back with its grid and pose" "$work/info_object_pcd.json" \
  "d['scans'][0]['rows'] == 120 and d['scans'][0]['cols'] == 180 and d['scans'][0]['valid'] == $object_valid and \
   abs(d['scans'][0]['world_from_scanner'][2][3] - 1.5) < 1e-9"
fails_clearly "segment: --object needs a scan format" "unknown scan format" "$lidarshop" segment "$work/scan.ptx" \
  --strokes "$work/strokes.json" -o "$work/mask3.png" --object "$work/object.txt" --quiet
fails_clearly "segment: strokes of the wrong size" "stroke" "$lidarshop" segment "$work/scan.ptx" \
  --strokes "$shared/images/bungee/bungee_mask.png" -o "$work/mask2.png" --quiet

# Image editing: inpainting and Poisson.
images=$shared/images
check "inpaint lettera" "$lidarshop" inpaint "$images/lettera/lettera.png" --mask "$images/lettera/lettera_mask.png" \
  -o "$work/lettera_filled.png" --quiet
# Review / resume (thesis ch. 7 "User action"): stop at the first target no candidate passes, choose one, go on.
check "inpaint review" "$lidarshop" inpaint "$images/lettera/lettera.png" --mask "$images/lettera/lettera_mask.png" \
  -o "$work/lettera_reviewed.png" --search exhaustive --accept combined --review "$work/review" --quiet
json_check "inpaint review.json" "$work/review/review.json" \
  "d['decisions'] == [] and len(d['review']['candidates']) == 200 and 1 <= len(d['review']['clusters']) < 200"
check "inpaint resume" "$lidarshop" inpaint "$images/lettera/lettera.png" --mask "$images/lettera/lettera_mask.png" \
  -o "$work/lettera_reviewed.png" --search exhaustive --accept combined --resume "$work/review" --choose 1 --quiet
json_check "inpaint resume keeps the decision" "$work/review/review.json" "len(d['decisions']) == 1"
fails_clearly "inpaint resume: no such candidate" "choose" "$lidarshop" inpaint "$images/lettera/lettera.png" \
  --mask "$images/lettera/lettera_mask.png" -o "$work/x.png" --accept combined --resume "$work/review" --choose 999 --quiet
check "poisson fill" "$lidarshop" poisson fill "$images/bungee/bungee.png" --mask "$images/bungee/bungee_mask.png" \
  -o "$work/bungee_fill.png" --quiet
check "poisson clone" "$lidarshop" poisson clone "$images/f16/f16.png" --mask "$images/f16/f16_mask.png" \
  --target "$images/f16/canyon.png" --offset 110,130 -o "$work/clone.png" --quiet
fails_clearly "inpaint: mask of another size" "mask" "$lidarshop" inpaint "$images/lettera/lettera.png" \
  --mask "$images/bungee/bungee_mask.png" -o "$work/x.png" --quiet

# fill and remove (docs/fill.md): the sphere's cells from the segment mask above, then the same from strokes.
check "fill" "$lidarshop" fill "$work/scan.ptx" --mask "$work/mask.png" -o "$work/filled.ply" \
  --report "$work/fill.json" --synthesized-mask "$work/synthesized.png" --debug "$work/fill_debug" --quiet
json_check "fill report" "$work/fill.json" \
  "d['options']['method'] == 'gradient' and d['synthesized_cells'] > 0 and \
   d['synthesized_cells'] + d['no_return_cells'] == d['hole_cells']"
check "fill wrote the mask and the debug pictures" test -s "$work/synthesized.png" \
  -a -s "$work/fill_debug/gradient_after.png" -a -s "$work/fill_debug/source_cells.png"
check "fill laplace into E57" "$lidarshop" fill "$work/scan.ptx" --mask "$work/mask.png" --method laplace \
  -o "$work/filled.e57" --quiet
check "info on the filled E57" sh -c "'$lidarshop' info '$work/filled.e57' > '$work/filled_e57.json'"
json_check "the E57 keeps the synthesized flag" "$work/filled_e57.json" "'synthesized' in d['scans'][0]['channels']"
check "remove" "$lidarshop" remove "$work/scan.ptx" --strokes "$work/strokes.json" -o "$work/removed.ptx" \
  --report "$work/remove.json" --quiet
# batch (src/python/lidarshop_batch.py through the CLI): a two-step pipeline, then a bad pipeline file.
# Builds without the Python layer (the sanitizer builds) answer "built without Python" and skip this.
if "$lidarshop" batch --help >/dev/null 2>&1; then
  printf '{"steps": [{"command": "fill", "options": {"method": "laplace"}, "mask": "%s", "output": "{name}_filled.e57"},
    {"command": "convert", "output": "{name}.ply"}]}' "$work/mask.png" >"$work/pipeline.json"
  check "batch" "$lidarshop" batch "$work/pipeline.json" "$work/scan.ptx" --out "$work/batch" --serial --quiet
  json_check "batch summary" "$work/batch/summary.json" "d['scans'] == 1 and d['done'] == 1 and d['failed'] == 0"
  echo '{"steps": []}' >"$work/empty_pipeline.json"
  exits_with 2 "usage: batch names the pipeline's problem" "empty_pipeline.json: expected .*at least one step" \
    "$lidarshop" batch "$work/empty_pipeline.json" "$work/scan.ptx" --out "$work/batch2"
fi
exits_with 2 "usage: did you mean" "unknown option --patch-radus \(did you mean --patch-radius\?\)" \
  "$lidarshop" fill "$work/scan.ptx" --mask "$work/mask.png" -o "$work/x.ply" --patch-radus 3
exits_with 2 "usage: out of range names the flag" "^lidarshop fill: --patch-radius: 0 is out of range \[1, 15\]" \
  "$lidarshop" fill "$work/scan.ptx" --mask "$work/mask.png" -o "$work/x.ply" --patch-radius 0
exits_with 2 "usage: a value suggests the closest" "'patch-match' is not a source search.*did you mean 'patchmatch'" \
  "$lidarshop" fill "$work/scan.ptx" --mask "$work/mask.png" -o "$work/x.ply" --search patch-match
exits_with 2 "usage: cross-field check names the flag" "--window: 5 is less than the patch radius 9" \
  "$lidarshop" fill "$work/scan.ptx" --mask "$work/mask.png" -o "$work/x.ply" --patch-radius 9 --window 5
exits_with 2 "usage: output extension checked first" "-o .*x.txt: expected a .ptx, .e57, .ply, .pcd file" \
  "$lidarshop" fill "$work/no_such_scan.ptx" --mask "$work/mask.png" -o "$work/x.txt"
exits_with 2 "usage: unwritable output folder checked first" "no_such_dir" \
  "$lidarshop" fill "$work/scan.ptx" --mask "$work/mask.png" -o "$work/no_such_dir/x.ply"
exits_with 1 "bad input: a missing scan" "no_such_scan.ptx" \
  "$lidarshop" fill "$work/no_such_scan.ptx" --mask "$work/mask.png" -o "$work/x.ply"
printf 'not a scan\n' >"$work/garbage.ptx"
exits_with 1 "bad input: a file that does not parse" "garbage.ptx" \
  "$lidarshop" fill "$work/garbage.ptx" --mask "$work/mask.png" -o "$work/x.ply"
printf '{"patch_radius": 3, "method": "laplace", "acceptance": {"band_px": 3}}\n' >"$work/fill_options.json"
check "fill --options FILE, flags win" "$lidarshop" fill "$work/scan.ptx" --mask "$work/mask.png" -o "$work/opt.ply" \
  --options "$work/fill_options.json" --method gradient --json "$work/opt.json" --quiet
json_check "fill --options keys reach the options" "$work/opt.json" \
  "d['options']['patch_radius'] == 3 and d['options']['method'] == 'gradient' and d['options']['acceptance']['band_px'] == 3"
printf '{"patch_radius": 3, "acceptance": {"band": 3}}\n' >"$work/bad_options.json"
exits_with 2 "--options: an unknown key names the path" "acceptance.band: unknown option \(did you mean 'band_px'\?\)" \
  "$lidarshop" fill "$work/scan.ptx" --mask "$work/mask.png" -o "$work/opt.ply" --options "$work/bad_options.json"
json_check "remove report" "$work/remove.json" "d['cut']['object_cells'] > 0 and d['fill']['synthesized_cells'] > 0 and d['options']['margin_cells'] == 2"
check "remove --keep-object into E57 (second returns)" "$lidarshop" remove "$work/scan.ptx" \
  --strokes "$work/strokes.json" -o "$work/two_layers.e57" --keep-object --quiet
check "remove --keep-object into PLY" "$lidarshop" remove "$work/scan.ptx" --strokes "$work/strokes.json" \
  -o "$work/two_layers.ply" --keep-object --quiet
check "info on the two-layer PLY" sh -c "'$lidarshop' info --stats '$work/two_layers.ply' > '$work/two_layers.json'"
json_check "the PLY holds the scan and the layer behind the object" "$work/two_layers.json" \
  "len(d['scans']) == 2 and d['scans'][1]['valid'] > 0"
fails_clearly "fill: mask of another size" "mask" "$lidarshop" fill "$work/scan.ptx" \
  --mask "$shared/images/bungee/bungee_mask.png" -o "$work/x.ply" --quiet
fails_clearly "fill: output onto its input" "overwrite" "$lidarshop" fill "$work/scan.ptx" --mask "$work/mask.png" \
  -o "$work/scan.ptx" --quiet
fails_clearly "fill: unknown method" "method" "$lidarshop" fill "$work/scan.ptx" --mask "$work/mask.png" \
  -o "$work/x.ply" --method magic --quiet
fails_clearly "fill: --scan-index out of range" "scan-index" "$lidarshop" fill "$work/scan.ptx" \
  --mask "$work/mask.png" -o "$work/x.ply" --scan-index 3 --quiet
fails_clearly "fill: unknown search" "search" "$lidarshop" fill "$work/scan.ptx" --mask "$work/mask.png" \
  -o "$work/x.ply" --search magic --quiet
fails_clearly "remove: margin out of range" "margin" "$lidarshop" remove "$work/scan.ptx" \
  --strokes "$work/strokes.json" -o "$work/x.ply" --margin 500 --quiet
fails_clearly "render: --eye without --target" "target" "$lidarshop" render "$work/scan.ptx" --eye 1,2,3 \
  -o "$work/x.png"
check "render from a second viewpoint" "$lidarshop" render "$work/filled.ply" --orbit 30 \
  --around "$work/synthesized.png" --tint-synthesized 0.5 -o "$work/second_view.png"
fails_clearly "remove: two layers in PTX" "PTX" "$lidarshop" remove "$work/scan.ptx" --strokes "$work/strokes.json" \
  -o "$work/x.ptx" --keep-object --quiet
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

# points and register (docs/points.md): every scan keeps its grid; clouds for voxel and merge.
check "points outliers" "$lidarshop" points outliers "$work/scan.ptx" -o "$work/clean.ptx" --json "$work/clean.json"
json_check "points outliers summary" "$work/clean.json" "0 < d['output_points'] < d['input_points']"
check "points crop polygon" "$lidarshop" points crop "$work/scan.ptx" -o "$work/crop.ply" \
  --polygon=-3,7,-1,7,-1,9,-3,9 --json "$work/crop.json"
json_check "points crop keeps the box" "$work/crop.json" "100 < d['output_points'] < 2000"
check "points voxel" "$lidarshop" points voxel "$work/scan.ptx" -o "$work/voxel.ply" --voxel 0.2
check "points normals" "$lidarshop" points normals "$work/scan.ptx" -o "$work/normals.ptx" --grid
check "points planes" "$lidarshop" points planes "$work/scan.ptx" -o "$work/planes.ply" --planes 2 --distance 0.02 \
  --json "$work/planes.json"
json_check "points planes: the ground first" "$work/planes.json" \
  "len(d['planes']) == 2 and abs(abs(d['planes'][0]['normal'][2]) - 1) < 1e-3"
check "points planes --hough" "$lidarshop" points planes "$work/scan.ptx" -o "$work/hough.ply" --hough \
  --distance 0.02 --min-inliers 100 --json "$work/hough.json"
json_check "points planes --hough: the ground" "$work/hough.json" "abs(abs(d['planes'][0]['normal'][2]) - 1) < 1e-3"
check "points cluster" "$lidarshop" points cluster "$work/scan.ptx" -o "$work/clusters.ply" --radius 0.3 \
  --json "$work/clusters.json"
check "points transform" "$lidarshop" points transform "$work/scan.ptx" -o "$work/moved.ptx" \
  --matrix 1,0,0,0.05,0,1,0,0.02,0,0,1,0,0,0,0,1
check "register" "$lidarshop" register "$work/scan.ptx" "$work/moved.ptx" -o "$work/registered.ptx" \
  --json "$work/register.json"
json_check "register undoes the move" "$work/register.json" \
  "d['converged'] and abs(d['world_from_scanner'][0][3]) < 1e-3 and abs(d['world_from_scanner'][1][3]) < 1e-3"
check "points mesh" "$lidarshop" points mesh "$work/clean.ptx" -o "$work/grid_mesh.ply" --json "$work/mesh.json"
json_check "points mesh summary" "$work/mesh.json" "d['triangles'] > 1000"
check "points regions" "$lidarshop" points regions "$work/scan.ptx" -o "$work/regions.ply" --min-cells 20 \
  --json "$work/regions.json"
json_check "points regions summary" "$work/regions.json" "d['regions'] >= 3"
check "points superpixels" "$lidarshop" points superpixels "$work/scan.ptx" -o "$work/superpixels.ptx" \
  --superpixel-method graph
check "points sample-mesh" "$lidarshop" points sample-mesh "$work/grid_mesh.ply" -o "$work/mesh_samples.ply" \
  --count 5000 --json "$work/mesh_samples.json"
json_check "points sample-mesh summary" "$work/mesh_samples.json" "d['output_points'] == 5000"
fails_clearly "points: k larger than the cloud" "larger than the cloud" "$lidarshop" points kmeans "$work/scan.ptx" \
  -o "$work/x.ply" --k 100000000
exits_with 2 "points: radius 0 names the flag" "--radius: 0(\.0)? is out of range > 0" "$lidarshop" points outliers \
  "$work/scan.ptx" -o "$work/x.ply" --method radius --radius 0
fails_clearly "points: unknown operation" "unknown operation" "$lidarshop" points smooth "$work/scan.ptx" -o "$work/x.ply"

# Every command writes its result as one JSON object with --json (- = stdout), its options under "options"
# where it has library options; summaries for people go to stderr.
json_stdout() {  # json_stdout NAME KEY COMMAND...: succeeds, and stdout is one JSON object holding KEY
  local name=$1 key=$2
  shift 2
  if "$@" >"$work/last.out" 2>"$work/last.err" && python3 -c "import json,sys; d=json.load(open(sys.argv[1])); \
assert isinstance(d, dict) and sys.argv[2] in d, 'no key ' + sys.argv[2]" "$work/last.out" "$key" 2>"$work/json.err"; then
    passed=$((passed + 1))
  else
    failed=$((failed + 1))
    echo "FAILED: $name: expected one JSON object with '$key' on stdout: $*"
    sed 's/^/  | /' "$work/last.out" "$work/last.err" "$work/json.err" | head -20
  fi
}
json_stdout "scan --json -" returns "$lidarshop" scan "$work/scene/scene.json" -o "$work/j_scan.ptx" --rows 40 \
  --columns 60 --json - --quiet
json_stdout "scan --json - has its options" options "$lidarshop" scan "$work/scene/scene.json" -o "$work/j_scan.ptx" \
  --rows 40 --columns 60 --json - --quiet
json_stdout "info --json -" scans "$lidarshop" info "$work/scan.ptx" --json -
json_stdout "convert --json -" returns "$lidarshop" convert "$work/scan.ptx" "$work/j_convert.e57" --json - --quiet
json_stdout "render --json -" width_px "$lidarshop" render "$work/scan.ptx" -o "$work/j_render.png" --json -
json_stdout "render --orbit --json -" eye_in_world "$lidarshop" render "$work/scan.ptx" -o "$work/j_orbit.png" \
  --orbit 20 --width 64 --height 48 --json -
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
json_stdout "segment --json -" object_cells "$lidarshop" segment "$work/scan.ptx" --strokes "$work/strokes.json" \
  -o "$work/j_mask.png" --json - --quiet
json_stdout "inpaint --json -" iterations "$lidarshop" inpaint "$images/lettera/lettera.png" \
  --mask "$images/lettera/lettera_mask.png" -o "$work/j_lettera.png" --search local --json - --quiet
json_stdout "poisson --json -" unknowns "$lidarshop" poisson fill "$images/bungee/bungee.png" \
  --mask "$images/bungee/bungee_mask.png" -o "$work/j_bungee.png" --solver direct --json - --quiet
json_stdout "fill --json -" synthesized_cells "$lidarshop" fill "$work/scan.ptx" --mask "$work/mask.png" \
  -o "$work/j_filled.ply" --method laplace --json - --quiet
json_stdout "remove --json -" cut "$lidarshop" remove "$work/scan.ptx" --strokes "$work/strokes.json" \
  -o "$work/j_removed.ply" --method laplace --json - --quiet
json_stdout "resection --json -" rms_px "$lidarshop" resection --correspondences "$work/pairs.json" \
  -o "$work/j_cam.json" --json -
json_stdout "recolor --json -" recolored "$lidarshop" recolor "$work/scan.ptx" --photo "$work/photo.png" \
  --camera "$work/cam.json" -o "$work/j_recolored.ply" --json -
json_stdout "images --json -" images "$lidarshop" images "$shared/e57/pumpA.e57" --json -
json_stdout "align --json -" rms_m "$lidarshop" align --correspondences "$work/landmarks.json" -o "$work/j_T.txt" --json -
json_stdout "photo --json -" scene_pixels "$lidarshop" photo "$work/scene/scene.json" --camera "$work/cam.json" \
  -o "$work/j_photo.png" --samples 1 --json -
json_stdout "points --json -" output_points "$lidarshop" points outliers "$work/scan.ptx" -o "$work/j_clean.ptx" --json -
json_stdout "register --json -" converged "$lidarshop" register "$work/scan.ptx" "$work/moved.ptx" \
  -o "$work/j_registered.ptx" --json -
json_stdout "demo --json -" scan "$lidarshop" demo --scene mailbox --out "$work/j_demo" --json - --quiet
# Older JSON on stdout stays there without --json; --json FILE moves it.
check "resection --json FILE" "$lidarshop" resection --correspondences "$work/pairs.json" -o "$work/j_cam2.json" \
  --json "$work/j_resection.json"
check "resection --json FILE leaves stdout empty" test ! -s "$work/last.out"
json_check "resection --json FILE" "$work/j_resection.json" "d['inliers'] == 12 and d['options']['ransac_threshold_px'] > 0"

# --options FILE: the command's first options struct, by key; flags win.
printf '{"method": "depth", "ring_radius_cells": 3}\n' >"$work/segment_options.json"
check "segment --options" "$lidarshop" segment "$work/scan.ptx" --strokes "$work/strokes.json" -o "$work/j_mask2.png" \
  --options "$work/segment_options.json" --model histogram --json "$work/j_segment.json" --quiet
json_check "segment --options reach the options, flags win" "$work/j_segment.json" \
  "d['options']['method'] == 'depth' and d['options']['ring_radius_cells'] == 3 and d['options']['model'] == 'histogram'"
printf '{"rows": 30, "seed": 7}\n' >"$work/scanner_options.json"
check "scan --options overrides the scene's scanner" "$lidarshop" scan "$work/scene/scene.json" -o "$work/j_scan2.ptx" \
  --options "$work/scanner_options.json" --columns 50 --json "$work/j_scan.json" --quiet
json_check "scan --options and flags reach the scanner" "$work/j_scan.json" \
  "d['rows'] == 30 and d['columns'] == 50 and d['options']['seed'] == 7 and d['options']['azimuth_min_deg'] == -45"
printf '{"sigma_m": 0.07}\n' >"$work/verify_options.json"
check "verify --options" "$lidarshop" verify --scan "$work/scan.ptx" --model "$work/box.obj" --pose "-2,8,0.6,0" \
  --options "$work/verify_options.json" --json "$work/j_verify2.json" --quiet
json_check "verify --options reach the options" "$work/j_verify2.json" "d['options']['sigma_m'] == 0.07"
printf '{"planes": {"max_planes": 1}}\n' >"$work/points_options.json"
check "points --options by operation" "$lidarshop" points planes "$work/scan.ptx" -o "$work/j_planes.ply" \
  --options "$work/points_options.json" --distance 0.02 --json "$work/j_planes.json"
json_check "points --options reach the operation" "$work/j_planes.json" \
  "len(d['planes']) == 1 and d['options']['planes']['max_planes'] == 1 and d['options']['planes']['distance_threshold_m'] == 0.02"

# Bad values exit 2 naming the flag the user typed; unknown flags suggest the closest; help shows choices as words.
exits_with 2 "scan: bad value names the flag" "^lidarshop scan: --rows: 1 is out of range >= 2" \
  "$lidarshop" scan "$work/scene/scene.json" -o "$work/x.ptx" --rows 1
exits_with 2 "segment: bad value names the flag" "^lidarshop segment: --ring-threshold: -1(\.0)? is out of range >= 0" \
  "$lidarshop" segment "$work/scan.ptx" --strokes "$work/strokes.json" -o "$work/x.png" --ring-threshold -1
exits_with 2 "segment: bad choice names the flag" "--method: 'two_step' is not a segmentation method.*did you mean 'two-step'" \
  "$lidarshop" segment "$work/scan.ptx" --strokes "$work/strokes.json" -o "$work/x.png" --method two_step
exits_with 2 "verify: bad value names the flag" "^lidarshop verify: --allowance: -1(\.0)? is out of range \[0, 1000\]" \
  "$lidarshop" verify --scan "$work/scan.ptx" --model "$work/box.obj" --pose "-2,8,0.6,0" --allowance -1
exits_with 2 "sweep: cross-field check names the flag" "^lidarshop sweep: --x-range: is below x_min_m" \
  "$lidarshop" sweep --scan "$work/scan.ptx" --model "$work/box.obj" --x-range 3:1 --out "$work/x_sweep"
exits_with 2 "recolor: bad value names the flag" "^lidarshop recolor: --zbuffer-scale: 2(\.0)? is out of range" \
  "$lidarshop" recolor "$work/scan.ptx" --photo "$work/photo.png" --camera "$work/cam.json" -o "$work/x.ply" \
  --zbuffer-scale 2
exits_with 2 "inpaint: bad value names the flag" "^lidarshop inpaint: --patch-radius: 0 is out of range \[1, 64\]" \
  "$lidarshop" inpaint "$images/lettera/lettera.png" --mask "$images/lettera/lettera_mask.png" -o "$work/x.png" \
  --patch-radius 0
exits_with 2 "poisson: bad choice names the flag" "--solver: 'cholesky' is not a Poisson solver" \
  "$lidarshop" poisson fill "$images/bungee/bungee.png" --mask "$images/bungee/bungee_mask.png" -o "$work/x.png" \
  --solver cholesky
exits_with 2 "segment: did you mean" "unknown option --ring-treshold \(did you mean --ring-threshold\?\)" \
  "$lidarshop" segment "$work/scan.ptx" --strokes "$work/strokes.json" -o "$work/x.png" --ring-treshold 0.2
exits_with 2 "verify: did you mean" "unknown option --alowance \(did you mean --allowance\?\)" \
  "$lidarshop" verify --scan "$work/scan.ptx" --model "$work/box.obj" --pose "-2,8,0.6,0" --alowance 0.1
exits_with 2 "points: did you mean" "unknown option --std-ration \(did you mean --std-ratio\?\)" \
  "$lidarshop" points outliers "$work/scan.ptx" -o "$work/x.ply" --std-ration 2
help_shows() {  # help_shows NAME TEXT COMMAND...: --help output holds TEXT
  local name=$1 text=$2
  shift 2
  "$@" --help >"$work/help.txt" 2>&1
  if grep -qF -e "$text" "$work/help.txt"; then
    passed=$((passed + 1))
  else
    failed=$((failed + 1))
    echo "FAILED: $name: '$text' not in the help of: $*"
  fi
}
help_shows "inpaint help: fill order as words" "criminisi|onion-peel|random" "$lidarshop" inpaint
help_shows "segment help: methods as words" "two-step|depth|color|rgbd" "$lidarshop" segment
help_shows "recolor help: visibility as words" "zbuffer|segment" "$lidarshop" recolor
help_shows "render help: channels as words" "range|rgb|intensity|normals|labels|valid" "$lidarshop" render
help_shows "points help: superpixel methods as words" "slic|graph" "$lidarshop" points
help_shows "verify help: units and ranges" "(m, [0, 1000])" "$lidarshop" verify

# A channel the file does not hold is absent: a PCD of bare points has no intensity, and says so.
printf '# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 3\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 3\nDATA ascii\n1 2 3\n2 3 4\n3 4 5\n' \
  >"$work/plain.pcd"
check "info of a PCD without intensity" sh -c "'$lidarshop' info '$work/plain.pcd' >'$work/plain.json'"
json_check "no intensity channel is invented" "$work/plain.json" \
  "'intensity' not in d['scans'][0]['channels'] and 'intensity' not in d['scans'][0] and 'xyz' in d['scans'][0]['channels']"
fails_clearly "render intensity of a scan without it" "plain.pcd has no intensity channel; it has: xyz$" \
  "$lidarshop" render "$work/plain.pcd" -o "$work/x.png" --channel intensity
check "convert the PCD to PCD" "$lidarshop" convert "$work/plain.pcd" "$work/plain_copy.pcd" --quiet
check "the copy has no intensity field" grep -qa "^FIELDS x y z$" "$work/plain_copy.pcd"
for format in ply e57 las xyz; do
  check "convert the PCD to $format" "$lidarshop" convert "$work/plain.pcd" "$work/plain.$format" --quiet
  check "info plain.$format" sh -c "'$lidarshop' info --stats '$work/plain.$format' >'$work/plain_$format.json'"
  json_check "$format: still no intensity" "$work/plain_$format.json" \
    "'intensity' not in d['scans'][0]['channels'] and d['scans'][0]['valid'] == 3"
done

# convert says what the target cannot hold (one warning line each) and what it wrote (one line).
check "convert to PTX without intensity" "$lidarshop" convert "$work/plain.pcd" "$work/plain.ptx"
cp "$work/last.err" "$work/plain_ptx.err"
check "PTX: the convention intensity is a warning" \
  grep -q "^lidarshop: warning: .*plain.ptx: the input has no intensity, but PTX requires an intensity column: written as 0.5" "$work/plain_ptx.err"
check "convert prints what it wrote" \
  grep -qxE "lidarshop convert: wrote .*plain.ptx: 1 scan, 3 points, channels xyz intensity=0.5 \([0-9.]+ s\)" "$work/plain_ptx.err"
check "convert labels to PTX" "$lidarshop" convert "$work/scan_labels.ply" "$work/labels.ptx" --json "$work/labels_convert.json"
cp "$work/last.err" "$work/labels_ptx.err"
check "PTX drops labels and normals, one line each" sh -c \
  "grep -c '^lidarshop: warning: .*labels.ptx: labels are not written' '$work/labels_ptx.err' | grep -qx 1 && \
   grep -q '^lidarshop: warning: .*labels.ptx: normals are not written' '$work/labels_ptx.err'"
json_check "convert --json lists channels and what was dropped" "$work/labels_convert.json" \
  "d['channels'][:3] == ['xyz', 'intensity', 'rgb'] and any('labels are not written' in x for x in d['dropped'])"
check "convert labels to LAS" "$lidarshop" convert "$work/scan_labels.ply" "$work/labels.las"
cp "$work/last.err" "$work/labels_las.err"
check "LAS: labels become classification, the grid is dropped" sh -c \
  "grep -q 'wrote .*labels.las: 1 scan, [0-9,]* points, channels xyz intensity rgb label→classification' '$work/labels_las.err' && \
   grep -q 'warning: .*labels.las: the grid (120 rows x 180 columns) and the scanner pose are not kept' '$work/labels_las.err'"
check "E57 -> E57 keeps the second returns" "$lidarshop" convert "$work/two_layers.e57" "$work/two_layers_copy.e57"
cp "$work/last.err" "$work/e57_copy.err"
check "no second returns dropped E57 -> E57" sh -c "grep -q 'wrote .*two_layers_copy.e57' '$work/e57_copy.err' && \
  ! grep -q 'second returns' '$work/e57_copy.err'"
check "the copy still has them (PLY drops them)" "$lidarshop" convert "$work/two_layers_copy.e57" "$work/x2.ply"
cp "$work/last.err" "$work/x2.err"
check "PLY says it drops the second returns" grep -q "x2.ply: the second returns of 1 scan are not written" "$work/x2.err"
check "pumpA to PLY drops the photo" "$lidarshop" convert "$shared/e57/pumpA.e57" "$work/pumpA.ply"
cp "$work/last.err" "$work/pumpA_ply.err"
check "the photo is one warning" grep -q "pumpA.ply: 1 image (E57 images2D) not written" "$work/pumpA_ply.err"
check "E57 scaled-integer precision" "$lidarshop" convert "$work/scan.ptx" "$work/scaled.e57" \
  --e57-precision-m 0.0001 --json "$work/scaled.json" --quiet
json_check "the precision is in the options" "$work/scaled.json" "d['options']['coordinate_scale_m'] == 0.0001"
check "the E57 stores scaled integers" python3 -c \
  "import sys; sys.exit(b'ScaledInteger' not in open('$work/scaled.e57', 'rb').read())"
check "the old flag still works" "$lidarshop" convert "$work/scan.ptx" "$work/scaled2.e57" --coordinate-scale-m 0.001 --quiet
fails_clearly "a negative precision is refused" "e57-precision-m" \
  "$lidarshop" convert "$work/scan.ptx" "$work/bad.e57" --e57-precision-m -1

# The demo on a small built-in scene.
check "demo" "$lidarshop" demo --scene mailbox --out "$work/demo" --quiet
json_check "demo summary" "$work/demo/summary.json" "d['scene'] == 'mailbox' and d['scan']['valid'] > 0"
# The page links every file the demo wrote and shows every picture.
for file in "$work"/demo/*; do
  name=$(basename "$file")
  [ "$name" = index.html ] && continue
  check "demo index links $name" grep -qF "href=\"$name\"" "$work/demo/index.html"
  case "$name" in *.png) check "demo index shows $name" grep -qF "src=\"$name\"" "$work/demo/index.html" ;; esac
done
check "demo wrote a second viewpoint and float range" test -s "$work/demo/top_view.png" -a -s "$work/demo/range.exr"
check "demo index explains the verification thresholds" grep -qE "passes above 0\.75.*passes above 0\.30" "$work/demo/index.html"
check "demo index colours pass and fail" grep -qE "<td>(pass|fail)</td>" "$work/demo/index.html"

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
