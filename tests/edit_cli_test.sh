#!/usr/bin/env bash
# End to end, the editing commands: `inpaint` (review and resume), `poisson`, `fill`, `remove` (two layers),
# `batch`, their usage errors, --json and --options.
# Run by ctest as `edit_cli_test` (tests/cli_fixture.sh says how to run it by hand).
source "$(dirname "$0")/cli_fixture.sh"
make_scan
make_mask

# Image editing: inpainting and Poisson.
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
# steps (what batch runs per scan): several commands in one process, nothing of one left to the next. The scan
# runs after a step with a 1 MiB memory budget (alone with it, it fails: its triangles need about 5 MiB), and the
# fill reads its --options from a file the last step then writes over (protected for the fill only).
echo '{"method": "laplace"}' >"$work/steps_options.json"
printf '{"steps": [["formats", "--json", "%s", "--max-memory", "1M"], ["scan", "%s", "-o", "%s"],
  ["fill", "%s", "--mask", "%s", "-o", "%s", "--options", "%s"], ["formats", "--json", "%s"]]}' \
  "$work/formats.json" "$work/scene/scene.json" "$work/steps_scan.ptx" "$work/steps_scan.ptx" "$work/mask.png" \
  "$work/steps_filled.ply" "$work/steps_options.json" "$work/steps_options.json" >"$work/steps.json"
check "steps" "$lidarshop" steps "$work/steps.json" --json "$work/steps_report.json" --quiet
json_check "steps report" "$work/steps_report.json" \
  "d['exit'] == 0 and [s['command'] for s in d['steps']] == ['formats', 'scan', 'fill', 'formats'] and \
   all(s['exit'] == 0 and s['seconds'] >= 0 for s in d['steps']) and d['steps'][2]['message'].startswith('lidarshop fill: ')"
json_check "... the last step wrote over the fill's options" "$work/steps_options.json" "'formats' in d"
printf '{"steps": [["formats", "--json", "%s"], ["fill", "%s", "--mask", "%s", "-o", "%s", "--patch-radius", "0"],
  ["formats"]]}' "$work/formats.json" "$work/scan.ptx" "$work/mask.png" "$work/x.ply" >"$work/steps_failing.json"
exits_with 2 "steps: a failing step ends the run with its exit code and message" \
  "^lidarshop fill: --patch-radius: 0 is out of range" \
  "$lidarshop" steps "$work/steps_failing.json" --json "$work/steps_failing_report.json"
json_check "... reported, the steps after it not run" "$work/steps_failing_report.json" \
  "d['exit'] == 2 and [s['exit'] for s in d['steps']] == [0, 2] and \
   d['steps'][1]['message'].startswith('lidarshop fill: --patch-radius: 0 is out of range')"
echo '{"steps": [["formats"], ["batch", "p.json"]]}' >"$work/steps_nested.json"
exits_with 1 "steps: batch cannot be a step" "steps\[1\].*'batch' cannot be a step" \
  "$lidarshop" steps "$work/steps_nested.json"
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
# The flat keys of before are aliases of the nested inpainting (FillOptions::inpaint): --json writes it nested.
json_check "fill --options keys reach the options" "$work/opt.json" \
  "d['options']['inpaint']['patch_radius'] == 3 and d['options']['method'] == 'gradient' and d['options']['inpaint']['acceptance']['band_px'] == 3 and 'patch_radius' not in d['options']"
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
check "E57 -> E57 keeps the second returns" "$lidarshop" convert "$work/two_layers.e57" "$work/two_layers_copy.e57"
cp "$work/last.err" "$work/e57_copy.err"
check "no second returns dropped E57 -> E57" sh -c "grep -q 'wrote .*two_layers_copy.e57' '$work/e57_copy.err' && \
  ! grep -q 'second returns' '$work/e57_copy.err'"
check "the copy still has them (PLY drops them)" "$lidarshop" convert "$work/two_layers_copy.e57" "$work/x2.ply"
cp "$work/last.err" "$work/x2.err"
check "PLY says it drops the second returns" grep -q "x2.ply: the second returns of 1 scan are not written" "$work/x2.err"

json_stdout "inpaint --json -" iterations "$lidarshop" inpaint "$images/lettera/lettera.png" \
  --mask "$images/lettera/lettera_mask.png" -o "$work/j_lettera.png" --search local --json - --quiet
json_stdout "poisson --json -" unknowns "$lidarshop" poisson fill "$images/bungee/bungee.png" \
  --mask "$images/bungee/bungee_mask.png" -o "$work/j_bungee.png" --solver direct --json - --quiet
json_stdout "fill --json -" synthesized_cells "$lidarshop" fill "$work/scan.ptx" --mask "$work/mask.png" \
  -o "$work/j_filled.ply" --method laplace --json - --quiet
json_stdout "remove --json -" cut "$lidarshop" remove "$work/scan.ptx" --strokes "$work/strokes.json" \
  -o "$work/j_removed.ply" --method laplace --json - --quiet

exits_with 2 "inpaint: bad value names the flag" "^lidarshop inpaint: --patch-radius: 0 is out of range \[1, 64\]" \
  "$lidarshop" inpaint "$images/lettera/lettera.png" --mask "$images/lettera/lettera_mask.png" -o "$work/x.png" \
  --patch-radius 0
exits_with 2 "poisson: bad choice names the flag" "--solver: 'cholesky' is not a Poisson solver" \
  "$lidarshop" poisson fill "$images/bungee/bungee.png" --mask "$images/bungee/bungee_mask.png" -o "$work/x.png" \
  --solver cholesky
help_shows "inpaint help: fill order as words" "criminisi|onion-peel|random" "$lidarshop" inpaint

finish
