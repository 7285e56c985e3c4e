#!/usr/bin/env bash
# End to end, `info`, `formats` and `convert`: the JSON keys scripts rely on, every format keeping every return,
# bad and real input, channels a file does not hold, and what a target cannot hold.
# Run by ctest as `info_cli_test` (tests/cli_fixture.sh says how to run it by hand).
source "$(dirname "$0")/cli_fixture.sh"
make_scan
make_labels_ply

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
check "info mug pcd" "$lidarshop" info "$shared/rgbd/table_scene_mug_stereo_textured.pcd"

json_stdout "info --json -" scans "$lidarshop" info "$work/scan.ptx" --json -
json_stdout "convert --json -" returns "$lidarshop" convert "$work/scan.ptx" "$work/j_convert.e57" --json - --quiet

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

finish
