#!/usr/bin/env bash
# End to end, `render`: every channel, square angular pixels, unorganized and aerial clouds from above, float
# pictures and label legends.
# Run by ctest as `render_cli_test` (tests/cli_fixture.sh says how to run it by hand).
source "$(dirname "$0")/cli_fixture.sh"
make_scan

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
check "render pumpA" "$lidarshop" render "$shared/e57/pumpA.e57" -o "$work/pump.png" --channel rgb

# render: square angular pixels. pumpA's rays are 0.250 deg across and 0.0675 deg down (345 x 1074): the
# picture is 3.7 times as wide as one pixel per ray, its aspect the scan's angular aspect (86 deg x 72.5 deg).
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

json_stdout "render --json -" width_px "$lidarshop" render "$work/scan.ptx" -o "$work/j_render.png" --json -
json_stdout "render --orbit --json -" eye_in_world "$lidarshop" render "$work/scan.ptx" -o "$work/j_orbit.png" \
  --orbit 20 --width 64 --height 48 --json -
help_shows "render help: channels as words" "range|rgb|intensity|normals|labels|valid" "$lidarshop" render

finish
