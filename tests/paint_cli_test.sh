#!/usr/bin/env bash
# End-to-end test of painting on what `render` draws (io/picture_mapping.h, docs/segment.md "Painting on a
# render picture") and of second viewpoints (io/render_view.h): strokes painted on render's square-pixel picture
# cut the same object as the same strokes on the grid; a mask painted on the picture fills the cells under it;
# a picture of a wrong size gets an error that says which sizes fit; the views before and after `remove` around
# the hole have the same camera and the same pixels away from the hole. Run by ctest as `paint_cli_test`.
# Usage: paint_cli_test.sh LIDARSHOP_BINARY SHARED_DATA_DIR
set -uo pipefail
lidarshop=$1
shared=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
passed=0
failed=0
# shellcheck source=check_lib.sh
source "$(dirname "$0")/check_lib.sh"

# PNG and PTX in plain Python (no imaging library needed): png.read -> (width, height, channels, rows of
# bytes), png.write_rgb, ptx.read -> (cols, rows, world_from_scanner, cells[row][col] = (x, y z) or None).
cat >"$work/pictures.py" <<'PY'
import struct, zlib
def read_png(path):
    data = open(path, "rb").read()
    pos, idat, width = 8, b"", 0
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, colour = struct.unpack(">IIBB", body[:10])
            assert depth == 8, "8-bit PNGs only"
            channels = {0: 1, 2: 3, 4: 2, 6: 4}[colour]
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    raw, stride, rows, prev = zlib.decompress(idat), width * channels, [], bytearray(width * channels)
    for y in range(height):
        f, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - channels] if i >= channels else 0
            b, c = prev[i], prev[i - channels] if i >= channels else 0
            if f == 1: line[i] = (line[i] + a) & 255
            elif f == 2: line[i] = (line[i] + b) & 255
            elif f == 3: line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(line)
        prev = line
    return width, height, channels, rows
def write_rgb(path, width, height, pixels):  # pixels: dict (x, y) -> (r, g, b); the rest black
    raw = bytearray()
    for y in range(height):
        raw.append(0)
        for x in range(width):
            raw.extend(pixels.get((x, y), (0, 0, 0)))
    chunk = lambda kind, body: struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))
    open(path, "wb").write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
                           + chunk(b"IDAT", zlib.compress(bytes(raw))) + chunk(b"IEND", b""))
def line(x0, y0, x1, y1):  # the pixels of a 1-pixel line
    n = max(abs(x1 - x0), abs(y1 - y0), 1)
    return {(round(x0 + (x1 - x0) * t / n), round(y0 + (y1 - y0) * t / n)) for t in range(n + 1)}
def read_ptx(path):
    lines = open(path).read().split("\n")
    cols, rows = int(lines[0]), int(lines[1])
    m = [[float(v) for v in lines[6 + k].split()] for k in range(4)]  # printed transposed
    world_from_scanner = [[m[c][r] for c in range(4)] for r in range(4)]
    cells = [[None] * cols for _ in range(rows)]
    for k in range(cols * rows):
        v = [float(t) for t in lines[10 + k].split()[:3]]
        if v != [0.0, 0.0, 0.0]:
            cells[rows - 1 - k % rows][k // rows] = v
    return cols, rows, world_from_scanner, cells
PY

# A ground and a box 8 m ahead; 90 columns over 90 degrees and 120 rows over 60 degrees: rays 1 degree apart
# across and 0.5 degree down, so render's square pixels make the picture about twice as wide as the grid.
cat >"$work/scene.json" <<'JSON'
{"scanner": {"position": [0, 0, 1.5], "rotate_deg": [0, 0, 0],
             "azimuth_deg": [-45, 45], "elevation_deg": [-30, 30], "columns": 90, "rows": 120,
             "max_range": 100, "los_noise_sigma": 0.0, "orthogonal_noise_sigma": 0.0, "seed": 1},
 "objects": [
   {"primitive": "plane", "size": [200, 200], "translate": [0, 0, 0], "label": 0, "texture": "grass"},
   {"primitive": "box", "size": [1.6, 0.6, 1.2], "translate": [0, 8, 0.6], "label": 1, "color": [200, 60, 40]}]}
JSON
check "scan the box scene" "$lidarshop" scan "$work/scene.json" -o "$work/scan.ptx" --quiet

# render writes the picture's layout beside it.
check "render" "$lidarshop" render "$work/scan.ptx" --channel rgb -o "$work/picture.png" --quiet
json_check "render's layout file" "$work/picture.png.layout.json" \
  "d['format'] == 'lidarshop picture layout' and d['view'] == 'grid' and d['scan_cols'] == 90 and \
   d['scan_rows'] == 120 and d['picture_height'] == 120 and abs(d['picture_width'] - 180) <= 1 and \
   d['image_width'] == d['picture_width']"

# The box spans azimuth +-5.9 deg (columns 39-50) and elevation -11.0..-2.2 deg (rows 64-82). The same strokes
# in grid coordinates (JSON) and painted 1 pixel thin on the render picture at the cells' centres.
cat >"$work/strokes.py" <<'PY'
import json, sys
sys.path.insert(0, sys.argv[1])
import pictures
layout = json.load(open(sys.argv[2]))
W, H, cols, rows = layout["picture_width"], layout["picture_height"], layout["scan_cols"], layout["scan_rows"]
strokes = [("object", (42, 72), (48, 75)), ("background", (33, 66), (33, 80)), ("background", (57, 66), (57, 80)),
           ("background", (30, 100), (60, 100))]
def px(cell): return (round((cell[0] + 0.5) * W / cols - 0.5), round((cell[1] + 0.5) * H / rows - 0.5))
pixels = {}
for label, a, b in strokes:
    for p in pictures.line(*px(a), *px(b)):
        pixels[p] = (0, 255, 0) if label == "object" else (255, 0, 0)
pictures.write_rgb(sys.argv[3], W, H, pixels)
json.dump({"strokes": [{"label": l, "points": [list(a), list(b)]} for l, a, b in strokes]}, open(sys.argv[4], "w"))
PY
check "paint strokes" python3 "$work/strokes.py" "$work" "$work/picture.png.layout.json" "$work/painted.png" \
  "$work/strokes.json"
check "segment from strokes on the grid" "$lidarshop" segment "$work/scan.ptx" --strokes "$work/strokes.json" \
  -o "$work/mask_grid.png" --overlay none --quiet
check "segment from strokes painted on the render picture" "$lidarshop" segment "$work/scan.ptx" \
  --strokes "$work/painted.png" -o "$work/mask_picture.png" --quiet
cat >"$work/iou.py" <<'PY'
import sys
sys.path.insert(0, sys.argv[1])
import pictures
a, b = pictures.read_png(sys.argv[2]), pictures.read_png(sys.argv[3])
assert a[:2] == b[:2] == (90, 120), (a[:2], b[:2])
both = sum(1 for y in range(120) for x in range(90) if a[3][y][x] and b[3][y][x])
either = sum(1 for y in range(120) for x in range(90) if a[3][y][x] or b[3][y][x])
print(both, either)
assert either > 100 and both / either >= float(sys.argv[4]), (both, either)
PY
check "the two cuts agree (IoU >= 0.99)" python3 "$work/iou.py" "$work" "$work/mask_grid.png" "$work/mask_picture.png" 0.99
# The overlay is in render's layout (the picture painted on), strokes as thin as painted.
cat >"$work/overlay.py" <<'PY'
import sys
sys.path.insert(0, sys.argv[1])
import pictures
o, p = pictures.read_png(sys.argv[2]), pictures.read_png(sys.argv[3])
assert o[:2] == p[:2], (o[:2], p[:2])
green = lambda img: {(x, y) for y in range(img[1]) for x in range(img[0])
                     if img[3][y][3 * x] == 0 and img[3][y][3 * x + 1] == 255 and img[3][y][3 * x + 2] == 0}
assert green(o) == green(p), (len(green(o)), len(green(p)))
PY
check "segment's overlay: render's layout, strokes as painted" python3 "$work/overlay.py" "$work" \
  "$work/mask_picture_overlay.png" "$work/painted.png"

# Any width: render at --width 300, strokes painted there (no layout file beside the strokes): the same cut.
check "render --width 300" "$lidarshop" render "$work/scan.ptx" --channel rgb --width 300 -o "$work/wide.png" --quiet
check "paint on the wide picture" python3 "$work/strokes.py" "$work" "$work/wide.png.layout.json" \
  "$work/painted_wide.png" "$work/strokes_unused.json"
check "segment from strokes on the wide picture" "$lidarshop" segment "$work/scan.ptx" \
  --strokes "$work/painted_wide.png" -o "$work/mask_wide.png" --overlay none --quiet
check "the wide picture's cut agrees too" python3 "$work/iou.py" "$work" "$work/mask_grid.png" "$work/mask_wide.png" 0.99

# A picture of neither size: the error says what fits and how to get a picture to paint on.
check "a wrong-size picture" python3 -c "import sys; sys.path.insert(0, '$work'); import pictures; pictures.write_rgb('$work/wrong.png', 200, 77, {})"
fails_clearly "segment: strokes of the wrong size" \
  "wrong.png.*200 x 77 pixels fits neither .*grid \(90 x 120 cells\).*181 x 120 by default.*lidarshop render .*-o PICTURE.png" \
  "$lidarshop" segment "$work/scan.ptx" --strokes "$work/wrong.png" -o "$work/mask_wrong.png" --quiet
fails_clearly "fill: a mask of the wrong size" "wrong.png.*fits neither" \
  "$lidarshop" fill "$work/scan.ptx" --mask "$work/wrong.png" -o "$work/wrong.ply" --quiet

# A mask painted on the picture: fill fills the cells under it (a rectangle over the box).
cat >"$work/mask.py" <<'PY'
import json, sys
sys.path.insert(0, sys.argv[1])
import pictures
layout = json.load(open(sys.argv[2]))
W, H = layout["picture_width"], layout["picture_height"]
pictures.write_rgb(sys.argv[3], W, H, {(x, y): (255, 255, 255) for x in range(70, 111) for y in range(60, 90)})
PY
check "paint a mask" python3 "$work/mask.py" "$work" "$work/picture.png.layout.json" "$work/hole_painted.png"
check "fill a mask painted on the picture" "$lidarshop" fill "$work/scan.ptx" --mask "$work/hole_painted.png" \
  --method laplace -o "$work/filled.ply" --synthesized-mask "$work/filled_cells.png" --report "$work/fill.json" \
  --quiet
cat >"$work/cells.py" <<'PY'
import json, sys
sys.path.insert(0, sys.argv[1])
import pictures
layout = json.load(open(sys.argv[2]))
W, cols = layout["picture_width"], layout["scan_cols"]
w, h, _, rows = pictures.read_png(sys.argv[3])
# The columns whose centre lies in pixels 70..110 (x of a cell's centre: (c + 0.5) W / cols), rows 60..89.
inside = {(x, y) for y in range(60, 90) for x in range(cols) if 70 <= (x + 0.5) * W / cols < 111}
filled = {(x, y) for y in range(h) for x in range(w) if rows[y][x]}
hole_cells = json.load(open(sys.argv[4]))["hole_cells"]  # filled, or left without a return by the fill's rules
assert filled <= inside and hole_cells == len(inside), (len(filled), hole_cells, len(inside))
PY
check "the filled cells are those under the painted mask" python3 "$work/cells.py" "$work" \
  "$work/picture.png.layout.json" "$work/filled_cells.png" "$work/fill.json"

# A mask painted on the view from the front (orthographic: x right, z up): its layout file says where the
# picture lies in the world (4000 pixels across the ground's 90 m), so the box's front face (x -0.8..0.8, z
# 0..1.2 at y 7.7) is painted from its coordinates; fill fills the box's cells (columns 39-50, rows 64-82 of
# the grid) and nothing else; the same layout file with another scan (its points changed) is refused.
check "render --view front" "$lidarshop" render "$work/scan.ptx" --view front --width 4000 -o "$work/front.png" \
  --quiet
json_check "the front view's layout file" "$work/front.png.layout.json" \
  "d['view'] == 'front' and d['pixel_unit'] == 'm' and d['point_size_px'] == 0 and \
   d['left_m'] < -0.8 and d['top_m'] > 1.1 and d['picture_width'] == 4000"
cat >"$work/front_mask.py" <<'PY'
import json, sys
sys.path.insert(0, sys.argv[1])
import pictures
layout = json.load(open(sys.argv[2]))
W, H = layout["picture_width"], layout["picture_height"]
px = lambda x: int((x - layout["left_m"]) / layout["pixel_width"])
py = lambda z: int((layout["top_m"] - z) / layout["pixel_height"])
pixels = {(x, y): (255, 255, 255) for x in range(px(-0.5), px(0.5) + 1) for y in range(py(1.0), py(0.2) + 1)}
assert len(pixels) > 20, len(pixels)
pictures.write_rgb(sys.argv[3], W, H, pixels)
PY
check "paint a mask on the front view" python3 "$work/front_mask.py" "$work" "$work/front.png.layout.json" \
  "$work/front_painted.png"
check "fill a mask painted on the front view" "$lidarshop" fill "$work/scan.ptx" --mask "$work/front_painted.png" \
  --layout "$work/front.png.layout.json" --method laplace -o "$work/front_filled.ply" \
  --synthesized-mask "$work/front_cells.png" --report "$work/front_fill.json" --quiet
check "the front view's mask holds only box cells" python3 -c "
import json, sys
sys.path.insert(0, '$work')
import pictures
w, h, _, rows = pictures.read_png('$work/front_cells.png')
filled = {(x, y) for y in range(h) for x in range(w) if rows[y][x]}
hole = json.load(open('$work/front_fill.json'))['hole_cells']
assert hole >= 20 and filled and all(39 <= x <= 50 and 64 <= y <= 82 for x, y in filled), (hole, sorted(filled)[:5])
print(hole, len(filled))"
fails_clearly "a front view's layout file of other points" "front.png.layout.json.*drawn of other points" \
  "$lidarshop" fill "$work/filled.ply" --mask "$work/front_painted.png" --layout "$work/front.png.layout.json" \
  -o "$work/front_other.ply" --quiet

# remove from painted strokes; the views before and after around the hole: one camera, the same pixels away
# from the hole's points.
check "remove from strokes painted on the picture" "$lidarshop" remove "$work/scan.ptx" \
  --strokes "$work/painted.png" -o "$work/removed.ptx" --mask-out "$work/hole.png" --quiet
check "view before" "$lidarshop" render "$work/scan.ptx" --orbit 35 --around "$work/hole.png" \
  -o "$work/before.png" --write-camera "$work/camera_before.json" --quiet
check "view after" "$lidarshop" render "$work/removed.ptx" --orbit 35 --around "$work/hole.png" \
  -o "$work/after.png" --write-camera "$work/camera_after.json" --quiet
check "the same camera before and after" cmp "$work/camera_before.json" "$work/camera_after.json"
json_check "the camera file" "$work/camera_before.json" \
  "set(d) == {'eye', 'target', 'up', 'fov_deg', 'width', 'height'} and abs(d['up'][2] - 1) < 1e-6 and \
   d['width'] == 640 and d['height'] == 480"
check "--camera draws the same picture" "$lidarshop" render "$work/scan.ptx" --camera "$work/camera_before.json" \
  -o "$work/before_again.png" --quiet
check "--camera's picture is the same" cmp "$work/before.png" "$work/before_again.png"
cat >"$work/same.py" <<'PY'
import json, math, sys
sys.path.insert(0, sys.argv[1])
import pictures
camera = json.load(open(sys.argv[2]))
before, after = pictures.read_png(sys.argv[3]), pictures.read_png(sys.argv[4])
hole = pictures.read_png(sys.argv[5])
eye, target, up = camera["eye"], camera["target"], camera["up"]
sub = lambda a, b: [a[i] - b[i] for i in range(3)]
dot = lambda a, b: sum(a[i] * b[i] for i in range(3))
cross = lambda a, b: [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
unit = lambda a: [v / math.sqrt(dot(a, a)) for v in a]
forward = unit(sub(target, eye)); right = unit(cross(forward, up)); top = cross(right, forward)
W, H = camera["width"], camera["height"]
focal = 0.5 * W / math.tan(math.radians(camera["fov_deg"]) / 2)
# Where the hole's points (before and after) are drawn: 2 x 2 squares; a 2-pixel margin for rounding.
near = set()
for path in sys.argv[6:8]:
    cols, rows, m, cells = pictures.read_ptx(path)
    for r in range(rows):
        for c in range(cols):
            if not hole[3][r][c] or cells[r][c] is None: continue
            p = [sum(m[i][k] * cells[r][c][k] for k in range(3)) + m[i][3] for i in range(3)]
            d = sub(p, eye); z = dot(d, forward)
            if z < 0.05: continue
            u = math.floor(W / 2 + focal * dot(d, right) / z); v = math.floor(H / 2 - focal * dot(d, top) / z)
            near |= {(u + du, v + dv) for du in range(-3, 4) for dv in range(-3, 4)}
differ = {(x, y) for y in range(H) for x in range(W) if before[3][y][3 * x:3 * x + 3] != after[3][y][3 * x:3 * x + 3]}
assert differ, "the removal does not show"
assert differ <= near, (len(differ - near), sorted(differ - near)[:5])
print(len(differ), len(near))
PY
check "the same pixels away from the hole" python3 "$work/same.py" "$work" "$work/camera_before.json" \
  "$work/before.png" "$work/after.png" "$work/hole.png" "$work/scan.ptx" "$work/removed.ptx"
fails_clearly "render: one viewpoint at a time" "one of --eye, --orbit and --camera" "$lidarshop" render \
  "$work/scan.ptx" --orbit 10 --camera "$work/camera_before.json" -o "$work/x.png"
echo '{"eye": [0, 0, 0], "target": [0, 1, 0], "up": [0, 0, 1], "fov": 40}' >"$work/bad_camera.json"
fails_clearly "render: a camera file with an unknown key" "bad_camera.json.*fov.*unknown key" "$lidarshop" render \
  "$work/scan.ptx" --camera "$work/bad_camera.json" -o "$work/x.png"

# Real data: pumpA (345 x 1074 rays, 0.25 x 0.0675 degrees) with the strokes of docs/results/pictures, painted on
# its default render (1276 x 1074). Written as E57, whose reader fits the grid to the returns: the grid moves
# with the removal, the camera around the hole must not.
pump=$shared/e57/pumpA.e57
pump_strokes=$(dirname "$0")/../docs/results/pictures/pumpA_strokes.png
check "render pumpA" "$lidarshop" render "$pump" --channel rgb -o "$work/pumpA.png" --quiet
json_check "pumpA's layout: square pixels" "$work/pumpA.png.layout.json" \
  "d['picture_width'] == 1276 and d['picture_height'] == 1074 and d['scan_cols'] == 345"
fails_clearly "pumpA: strokes of the grid's height but another width" \
  "fits neither .*pumpA.e57's grid \(345 x 1074 cells\).*1276 x 1074 by default" \
  "$lidarshop" segment "$pump" --strokes "$work/wrong.png" -o "$work/pump_wrong.png" --quiet
check "remove on pumpA from strokes painted on its render" "$lidarshop" remove "$pump" --strokes "$pump_strokes" \
  -o "$work/pump_removed.e57" --mask-out "$work/pump_hole.png" --quiet
check "pumpA before" "$lidarshop" render "$pump" --orbit 30 --around "$work/pump_hole.png" -o "$work/pump_before.png" \
  --write-camera "$work/pump_camera_before.json" --quiet
check "pumpA after" "$lidarshop" render "$work/pump_removed.e57" --orbit 30 --around "$work/pump_hole.png" \
  -o "$work/pump_after.png" --write-camera "$work/pump_camera_after.json" --json "$work/pump_after.json" --quiet
check "pumpA: the same camera before and after" cmp "$work/pump_camera_before.json" "$work/pump_camera_after.json"
json_check "pumpA: up is the floor's normal" "$work/pump_after.json" \
  "d['up_from'] == 'ground' and d['ground']['tilt_deg'] < 5 and d['up_in_world'][2] > 0.99"

echo "paint_cli_test: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
