#!/usr/bin/env bash
# End to end, `scan` and the usage of the command: PTX, labels, mesh, the summary line, built-in and random
# scenes, the scene example of docs/scene-format.md, --json, --options and bad values.
# Run by ctest as `scan_cli_test` (tests/cli_fixture.sh says how to run it by hand).
source "$(dirname "$0")/cli_fixture.sh"

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

json_stdout "scan --json -" returns "$lidarshop" scan "$work/scene/scene.json" -o "$work/j_scan.ptx" --rows 40 \
  --columns 60 --json - --quiet
json_stdout "scan --json - has its options" options "$lidarshop" scan "$work/scene/scene.json" -o "$work/j_scan.ptx" \
  --rows 40 --columns 60 --json - --quiet

# --options FILE: the scanner options by key; flags win.
printf '{"rows": 30, "seed": 7}\n' >"$work/scanner_options.json"
check "scan --options overrides the scene's scanner" "$lidarshop" scan "$work/scene/scene.json" -o "$work/j_scan2.ptx" \
  --options "$work/scanner_options.json" --columns 50 --json "$work/j_scan.json" --quiet
json_check "scan --options and flags reach the scanner" "$work/j_scan.json" \
  "d['rows'] == 30 and d['columns'] == 50 and d['options']['seed'] == 7 and d['options']['azimuth_min_deg'] == -45"

# Bad values exit 2 naming the flag the user typed.
exits_with 2 "scan: bad value names the flag" "^lidarshop scan: --rows: 1 is out of range >= 2" \
  "$lidarshop" scan "$work/scene/scene.json" -o "$work/x.ptx" --rows 1

finish
