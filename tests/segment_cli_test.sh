#!/usr/bin/env bash
# End to end, `segment`: the sphere from JSON strokes, --object and --rest as organized scans, world-frame point
# outputs read without lidarshop, --json, --options and bad values.
# Run by ctest as `segment_cli_test` (tests/cli_fixture.sh says how to run it by hand).
source "$(dirname "$0")/cli_fixture.sh"
make_scan

# The outputs a tool reads in the world frame, from convert (the frame check below compares with them).
for format in xyz pcd ply; do
  check "convert ptx -> $format" "$lidarshop" convert "$work/scan.ptx" "$work/scan.$format" --quiet
done

# segment: the sphere (label 1) from JSON strokes in grid coordinates. Its centre (2, 10, 1) seen from (0, 0, 1.5)
# is at azimuth atan2(2, 10) = 11.31 deg and elevation atan2(-0.5, sqrt(104)) = -2.81 deg: column
# (11.31 + 45) / 90 * 179 = 112, image row (30 + 2.81) / 60 * 119 = 65 (row 0 = top).
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

json_stdout "segment --json -" object_cells "$lidarshop" segment "$work/scan.ptx" --strokes "$work/strokes.json" \
  -o "$work/j_mask.png" --json - --quiet

printf '{"method": "depth", "ring_radius_cells": 3}\n' >"$work/segment_options.json"
check "segment --options" "$lidarshop" segment "$work/scan.ptx" --strokes "$work/strokes.json" -o "$work/j_mask2.png" \
  --options "$work/segment_options.json" --model histogram --json "$work/j_segment.json" --quiet
json_check "segment --options reach the options, flags win" "$work/j_segment.json" \
  "d['options']['method'] == 'depth' and d['options']['ring_radius_cells'] == 3 and d['options']['model'] == 'histogram'"

exits_with 2 "segment: bad value names the flag" "^lidarshop segment: --ring-threshold: -1(\.0)? is out of range >= 0" \
  "$lidarshop" segment "$work/scan.ptx" --strokes "$work/strokes.json" -o "$work/x.png" --ring-threshold -1
exits_with 2 "segment: bad choice names the flag" "--method: 'two_step' is not a segmentation method.*did you mean 'two-step'" \
  "$lidarshop" segment "$work/scan.ptx" --strokes "$work/strokes.json" -o "$work/x.png" --method two_step
exits_with 2 "segment: did you mean" "unknown option --ring-treshold \(did you mean --ring-threshold\?\)" \
  "$lidarshop" segment "$work/scan.ptx" --strokes "$work/strokes.json" -o "$work/x.png" --ring-treshold 0.2
help_shows "segment help: methods as words" "two-step|depth|color|rgbd" "$lidarshop" segment

finish
