#!/usr/bin/env bash
# #35 items 4 and 5 end to end: every command ends with one summary line on stderr (not with -q), warnings about
# a result that looks wrong are on stderr and in --json's "warnings", errors stay one line; every command takes
# -q and --max-memory; --scan is the scan index everywhere (--scan-index kept); every option is in --help;
# batch steps take the last scan as their input. Run by ctest as `summary_cli_test`.
# Usage: summary_cli_test.sh LIDARSHOP_BINARY
set -uo pipefail
lidarshop=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
passed=0
failed=0
# shellcheck source=check_lib.sh
source "$(dirname "$0")/check_lib.sh"

summary_line() {  # summary_line NAME COMMAND_NAME COMMAND...: succeeds, stderr ends with "lidarshop CMD: ... (T s)"
  local name=$1 command=$2
  shift 2
  if "$@" >"$work/last.out" 2>"$work/last.err" &&
    tail -n 1 "$work/last.err" | grep -qE "^lidarshop $command: .+ \([0-9]+\.[0-9]{2} s\)$" &&
    [ "$(grep -cE "^lidarshop $command: .+ \([0-9]+\.[0-9]{2} s\)$" "$work/last.err")" -eq 1 ]; then
    passed=$((passed + 1))
    # The same with -q: no summary line.
    if "$@" -q >"$work/quiet.out" 2>"$work/quiet.err" && ! grep -qE "\([0-9]+\.[0-9]{2} s\)$" "$work/quiet.err"; then
      passed=$((passed + 1))
    else
      failed=$((failed + 1))
      echo "FAILED: $name -q: a summary line or a failure:"
      sed 's/^/  | /' "$work/quiet.err" | head -10
    fi
  else
    failed=$((failed + 1))
    echo "FAILED: $name: expected success and one summary line 'lidarshop $command: ... (T s)' last, got:"
    sed 's/^/  | /' "$work/last.err" | head -10
  fi
}

png() {  # png FILE WIDTH HEIGHT VALUE: a grey PNG of one value
  python3 - "$@" <<'PY'
import struct, sys, zlib
path, width, height, value = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4])
raw = b"".join(b"\x00" + bytes([value]) * width for _ in range(height))
chunk = lambda kind, data: struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
open(path, "wb").write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0))
                       + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))
PY
}

# The scene of cli_test.sh without its mesh: a sphere (label 1) and a box on grass.
cat >"$work/scene.json" <<'JSON'
{"scanner": {"position": [0, 0, 1.5], "rotate_deg": [0, 0, 0],
             "azimuth_deg": [-45, 45], "elevation_deg": [-30, 30], "columns": 180, "rows": 120,
             "max_range": 100, "los_noise_sigma": 0.0, "orthogonal_noise_sigma": 0.0, "seed": 1},
 "objects": [
   {"primitive": "plane", "size": [200, 200], "translate": [0, 0, 0], "label": 0, "texture": "grass"},
   {"primitive": "sphere", "radius": 1.0, "translate": [2, 10, 1], "label": 1, "color": [200, 40, 40]},
   {"primitive": "box", "size": [1, 0.6, 1.2], "translate": [-2, 8, 0.6], "label": 2}]}
JSON
cat >"$work/strokes.json" <<'JSON'
{"strokes": [{"label": "object", "width": 3, "points": [[110, 65], [114, 65]]},
             {"label": "background", "width": 2, "points": [[5, 115], [175, 115]]}]}
JSON
cat >"$work/cam.json" <<'JSON'
{"width_px": 320, "height_px": 240, "fx_px": 260, "fy_px": 260, "cx_px": 160, "cy_px": 120,
 "world_from_camera": [[1, 0, 0, 1], [0, 0, 1, -0.5], [0, -1, 0, 1.6], [0, 0, 0, 1]]}
JSON
python3 - "$work" <<'PY'
import json, sys
pairs = []
for x, y, z in [[-2.5, 7.7, 0.05], [-1.5, 7.7, 0.05], [-2.5, 7.7, 1.15], [-1.5, 7.7, 1.15], [2, 9, 1],
                [4, 11.9, 2.9], [0, 5, 0], [3, 6, 0], [-3, 12, 0], [1, 20, 0], [-1.6, 7.7, 0.6], [2.5, 9.2, 1.3]]:
    d = y + 0.5
    pairs.append({"pixel": [160 + 260 * (x - 1) / d, 120 - 260 * (z - 1.6) / d], "point": [x, y, z]})
json.dump({"image_size_px": [320, 240], "pairs": pairs}, open(sys.argv[1] + "/pairs.json", "w"))
json.dump({"pairs": [{"source": [0, 0, 0], "target": [1, 2, 3]}, {"source": [1, 0, 0], "target": [2, 2, 3]},
                     {"source": [0, 1, 0], "target": [1, 3, 3]}, {"source": [0, 0, 1], "target": [1, 2, 4]}]},
          open(sys.argv[1] + "/landmarks.json", "w"))
PY
png "$work/empty.png" 180 120 0
python3 - "$work" <<'PY'
import struct, sys, zlib
# A 20 x 16 hole on the grass below the sphere.
width, height = 180, 120
rows = [bytes(255 if 100 <= c < 120 and 95 <= r < 111 else 0 for c in range(width)) for r in range(height)]
chunk = lambda kind, data: struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
open(sys.argv[1] + "/hole.png", "wb").write(
    b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0))
    + chunk(b"IDAT", zlib.compress(b"".join(b"\x00" + row for row in rows))) + chunk(b"IEND", b""))
PY

# One summary line per command (and none with -q).
summary_line "scan" scan "$lidarshop" scan "$work/scene.json" -o "$work/scan.ptx"
summary_line "info" info "$lidarshop" info "$work/scan.ptx"
summary_line "info --stats" info "$lidarshop" info "$work/scan.ptx" --stats
summary_line "convert" convert "$lidarshop" convert "$work/scan.ptx" "$work/scan.ply"
summary_line "render" render "$lidarshop" render "$work/scan.ptx" -o "$work/range.png"
summary_line "render --orbit" render "$lidarshop" render "$work/scan.ptx" -o "$work/orbit.png" --orbit 20
summary_line "segment" segment "$lidarshop" segment "$work/scan.ptx" --strokes "$work/strokes.json" \
  -o "$work/mask.png" --json "$work/segment.json"
json_check "segment --json has an empty warnings list on a good cut" "$work/segment.json" \
  "d['warnings'] == [] and d['object_cells'] > 0 and 'options' in d"
summary_line "fill" fill "$lidarshop" fill "$work/scan.ptx" --mask "$work/hole.png" -o "$work/filled.ply" \
  --method laplace --json "$work/fill.json"
json_check "fill --json has an empty warnings list" "$work/fill.json" "d['warnings'] == [] and d['hole_cells'] == 320"
summary_line "remove" remove "$lidarshop" remove "$work/scan.ptx" --strokes "$work/strokes.json" \
  -o "$work/removed.ply" --json "$work/remove.json"
json_check "remove --json has the warnings lists" "$work/remove.json" \
  "d['warnings'] == [] and d['cut']['warnings'] == [] and d['fill']['warnings'] == []"
summary_line "points" points "$lidarshop" points outliers "$work/scan.ptx" -o "$work/clean.ptx"
summary_line "points voxel" points "$lidarshop" points voxel "$work/scan.ptx" -o "$work/voxel.ply"
summary_line "photo" photo "$lidarshop" photo "$work/scene.json" --camera "$work/cam.json" -o "$work/photo.png"
summary_line "resection" resection "$lidarshop" resection --correspondences "$work/pairs.json" \
  -o "$work/cam_out.json" --json "$work/resection.json"
json_check "resection --json: warnings next to the errors" "$work/resection.json" \
  "d['warnings'] == [] and d['rms_px'] < 0.01"
summary_line "recolor" recolor "$lidarshop" recolor "$work/scan.ptx" --photo "$work/photo.png" \
  --camera "$work/cam.json" -o "$work/recolored.ply" --json "$work/recolor.json"
json_check "recolor --json: warnings and the disagreement" "$work/recolor.json" \
  "d['warnings'] == [] and 0 <= d['disagreement'] < 0.5 and d['recolored'] > 0"
summary_line "align" align "$lidarshop" align --correspondences "$work/landmarks.json" -o "$work/T.txt" \
  --json "$work/align.json"
summary_line "register" register "$lidarshop" register "$work/scan.ptx" "$work/scan.ptx" -o "$work/registered.ply"
summary_line "poisson" poisson "$lidarshop" poisson fill "$work/range.png" --mask "$work/hole.png" \
  -o "$work/poisson.png"
# A result that looks wrong says so: an empty fill mask (#35: it exited 0 without a word).
check "fill with an empty mask succeeds" "$lidarshop" fill "$work/scan.ptx" --mask "$work/empty.png" \
  -o "$work/copy.ply" --json "$work/empty_fill.json" -q
cp "$work/last.err" "$work/empty_fill.err"
check "... and warns on stderr (one line), also with -q" \
  grep -qx "lidarshop fill: warning: the hole mask is empty .*" "$work/empty_fill.err"
check "... and says nothing else with -q" test "$(wc -l <"$work/empty_fill.err")" -eq 1
json_check "... and in --json's warnings" "$work/empty_fill.json" \
  "len(d['warnings']) == 1 and 'empty' in d['warnings'][0] and d['hole_cells'] == 0"

# -q and --max-memory on every command (info, images, align and serve refused them).
for command in demo scan info convert render verify sweep segment inpaint poisson fill remove resection recolor \
  images align photo points register serve; do
  check "$command --help lists -q and --max-memory" sh -c "'$lidarshop' $command --help | grep -q -- '-q,--quiet' \
    && '$lidarshop' $command --help | grep -q -- '--max-memory'"
done
check "info -q --max-memory" "$lidarshop" info "$work/scan.ptx" -q --max-memory 2G --json "$work/info.json"
check "... says nothing" test ! -s "$work/last.err"
check "align -q --max-memory" "$lidarshop" align --correspondences "$work/landmarks.json" -o "$work/T2.txt" \
  --json "$work/align2.json" -q --max-memory 512M
fails_clearly "a bad --max-memory is one line" "max-memory" "$lidarshop" info "$work/scan.ptx" --max-memory lots
# Every option in --help: resection --intrinsics worked but was hidden.
check "resection --help lists --intrinsics" sh -c "'$lidarshop' resection --help | grep -q -- '--intrinsics'"

# --scan is the scan index everywhere; --scan-index stays; messages name the flag typed.
check "segment --scan 0" "$lidarshop" segment "$work/scan.ptx" --strokes "$work/strokes.json" -o "$work/m2.png" \
  --scan 0 -q
check "segment --scan-index 0 (the older name)" "$lidarshop" segment "$work/scan.ptx" \
  --strokes "$work/strokes.json" -o "$work/m3.png" --scan-index 0 -q
for command in fill remove recolor; do
  check "$command --help lists --scan and --scan-index" sh -c "'$lidarshop' $command --help | grep -q -- '--scan ' \
    && '$lidarshop' $command --help | grep -q -- '--scan-index'"
done
fails_clearly "fill --scan out of range names --scan" "^lidarshop fill: --scan 3 is out of range" \
  "$lidarshop" fill "$work/scan.ptx" --mask "$work/hole.png" -o "$work/x.ply" --scan 3
fails_clearly "fill --scan-index out of range names --scan-index" "^lidarshop fill: --scan-index 3 is out of range" \
  "$lidarshop" fill "$work/scan.ptx" --mask "$work/hole.png" -o "$work/x.ply" --scan-index 3
fails_clearly "recolor --scan out of range" "^lidarshop recolor: --scan 2 is out of range" \
  "$lidarshop" recolor "$work/scan.ptx" --photo "$work/photo.png" --camera "$work/cam.json" -o "$work/x.ply" --scan 2

# batch: a render step in the middle hands the scan on, not its picture.
if "$lidarshop" batch --help >/dev/null 2>&1; then
  printf '{"steps": [{"command": "fill", "options": {"method": "laplace"}, "mask": "%s", "output": "{name}_filled.ply"},
    {"command": "render", "output": "{name}_filled.png"},
    {"command": "convert", "output": "{name}.pcd"}]}' "$work/hole.png" >"$work/pipeline.json"
  check "batch with a render step in the middle" "$lidarshop" batch "$work/pipeline.json" "$work/scan.ptx" \
    --out "$work/batch" --serial -q
  check "... says nothing with -q" test ! -s "$work/last.err"
  json_check "... every step ran" "$work/batch/summary.json" "d['done'] == 1 and d['failed'] == 0"
  check "... the picture is there" test -s "$work/batch/scan_filled.png"
  check "info on the converted scan" sh -c "'$lidarshop' info --stats '$work/batch/scan.pcd' >'$work/batch_info.json'"
  json_check "... it is the filled scan (synthesized points), not the picture" "$work/batch_info.json" \
    "'synthesized' in d['scans'][0]['channels'] and d['scans'][0]['rows'] == 120"
fi

# Start-up: OpenCV's codecs (Debian links them to GDAL and ~120 more libraries) load with the first picture
# (util/plugin.h), not with every command.
check "the executable does not link OpenCV's codecs nor GDAL" \
  sh -c "! ldd '$lidarshop' | grep -qE 'libopencv_imgcodecs|libopencv_ximgproc|libgdal'"
check "... which load when a picture is written" "$lidarshop" render "$work/scan.ptx" -o "$work/again.png" -q

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
