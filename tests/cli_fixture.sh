# The set-up every end-to-end test of one command group shares (tests/*_cli_test.sh): the binary and the shared
# data, a scratch folder, the check helpers, the small scene of docs/scene-format.md and the inputs made from it.
# Each test sources this file and builds only the inputs it uses, so the tests are independent and run in
# parallel (ctest -j).
#
# The binary and the data come from the environment that ctest sets (LIDARSHOP_CLI, LIDARSHOP_SHARED_DATA); by
# hand: LIDARSHOP_CLI=build/release/lidarshop LIDARSHOP_SHARED_DATA=../shared/data bash tests/scan_cli_test.sh
set -uo pipefail
lidarshop=${LIDARSHOP_CLI:-}
shared=${LIDARSHOP_SHARED_DATA:-}
if [ ! -x "$lidarshop" ] || [ ! -d "$shared" ]; then
  echo "$(basename "$0"): set LIDARSHOP_CLI to the lidarshop binary and LIDARSHOP_SHARED_DATA to the shared data" \
    "(got '$lidarshop' and '$shared')" >&2
  exit 2
fi
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
images=$shared/images
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
passed=0
failed=0
# shellcheck source=check_lib.sh
source "$(dirname "${BASH_SOURCE[0]}")/check_lib.sh"

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

picture_size() {  # picture_size FILE.png: "width height" from the PNG header
  python3 -c "import struct,sys; d=open(sys.argv[1],'rb').read(24); print(*struct.unpack('>II', d[16:24]))" "$1"
}

finish() {  # the last line of every test: the counts, and the exit status
  echo "$passed passed, $failed failed"
  [ "$failed" -eq 0 ]
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

# segment: the sphere (label 1) from JSON strokes in grid coordinates. Its centre (2, 10, 1) seen from (0, 0, 1.5)
# is at azimuth atan2(2, 10) = 11.31 deg and elevation atan2(-0.5, sqrt(104)) = -2.81 deg: column
# (11.31 + 45) / 90 * 179 = 112, image row (30 + 2.81) / 60 * 119 = 65 (row 0 = top).
cat >"$work/strokes.json" <<'JSON'
{"strokes": [{"label": "object", "width": 3, "points": [[110, 65], [114, 65]]},
             {"label": "background", "width": 2, "points": [[5, 115], [175, 115]]}]}
JSON

# The inputs made from the scene, each by the function named after it. A test calls the ones it uses; a failure
# to make one is a failed check (the checks that use it then fail too, and say so).
make_scan() {  # $work/scan.ptx (+ labels.png, labels_color.png, mesh.ply) and $valid, its returns
  check "fixture: scan the scene" "$lidarshop" scan "$work/scene/scene.json" -o "$work/scan.ptx" \
    --labels "$work/labels.png" --mesh "$work/mesh.ply" --quiet
  "$lidarshop" info --stats "$work/scan.ptx" >"$work/info.json" 2>/dev/null
  valid=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['scans'][0]['valid'])" "$work/info.json" \
    2>/dev/null || echo -1)
}
make_labels_ply() {  # $work/scan_labels.ply: the scan with the synthetic scanner's labels and normals
  check "fixture: scan to PLY" "$lidarshop" scan "$work/scene/scene.json" -o "$work/scan_labels.ply" --quiet
}
make_mask() {  # $work/mask.png: the sphere cut from the strokes (needs make_scan)
  check "fixture: segment the sphere" "$lidarshop" segment "$work/scan.ptx" --strokes "$work/strokes.json" \
    -o "$work/mask.png" --overlay none --quiet
}
make_box() {  # $work/box.obj: the scene's box (label 2) as a model, centred on its origin
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
}
