#!/usr/bin/env bash
# End to end, `clean`: two registered stations of a street, a passer-by at the first only. Its points are removed
# from the first station and filled, nothing from the second; the removed masks say which station saw through.
# Run by ctest as `clean_cli_test` (tests/cli_fixture.sh says how to run it by hand).
source "$(dirname "$0")/cli_fixture.sh"

station() {  # station N X Y YAW_DEG EXTRA_OBJECTS: scans $work/stN.e57
  cat >"$work/site$1.json" <<JSON
{"scanner": {"position": [$2, $3, 1.6], "rotate_deg": [0, 0, $4], "azimuth_deg": [-60, 60],
             "elevation_deg": [-30, 25], "columns": 420, "rows": 190, "max_range": 80,
             "los_noise_sigma": 0.004, "orthogonal_noise_sigma": 0.002, "seed": $((7 + $1))},
 "objects": [{"primitive": "plane", "size": [80, 80], "translate": [0, 20, 0], "label": 0, "texture": "gravel"},
             {"primitive": "box", "size": [30, 0.5, 8], "translate": [0, 18, 4], "label": 1}$5]}
JSON
  check "scan station $1" "$lidarshop" scan "$work/site$1.json" -o "$work/st$1.e57" --quiet
}
station 0 0 0 0 ', {"primitive": "cylinder", "radius": 0.25, "height": 1.75, "translate": [1, 8, 0.875], "label": 10}'
station 1 4 1 -15 ''

check "clean two stations" "$lidarshop" clean "$work/st0.e57" "$work/st1.e57" --out "$work/clean" --removed-masks \
  --json "$work/clean.json" --quiet
json_check "the passer-by is removed from station 0 and filled, nothing from station 1" "$work/clean.json" \
  "d['stations'][0]['removed'] > 300 and d['stations'][0]['filled'] + d['stations'][0]['from_station'] > 300 and \
   d['stations'][0]['from_station'] > 0 and d['stations'][1]['removed'] == 0 \
   and d['removed'] == d['stations'][0]['removed'] and d['options']['transients']['min_region_cells'] == 12"
check "each station written under its own name, with its removed mask" test -s "$work/clean/st0.e57" \
  -a -s "$work/clean/st1.e57" -a -s "$work/clean/st0_removed.png" -a -s "$work/clean/st1_removed.png"
check "the cleaned station holds filled points (synthesized or from the other station)" sh -c \
  "'$lidarshop' info '$work/clean/st0.e57' | grep -qE 'synthesized|from_station'"
fails_clearly "clean: one station is not enough" "two stations" "$lidarshop" clean "$work/st0.e57" --out "$work/one"
exits_with 2 "clean: a bad value names the flag" "--min-region: 0 is out of range" "$lidarshop" clean \
  "$work/st0.e57" "$work/st1.e57" --out "$work/bad" --min-region 0
fails_clearly "clean: an --out that cannot be a folder" "cannot create the folder" "$lidarshop" clean \
  "$work/st0.e57" "$work/st1.e57" --out "$work/st0.e57/inside"
fails_clearly "clean: never onto an input" "st0.e57" "$lidarshop" clean "$work/st0.e57" "$work/st1.e57" --out "$work"

# The built-in site: the hatchback stands at stations 0 and 1 (each confirms the other: kept), the sedan (label 7)
# at station 2 only (stations 0 and 1 see through it: removed from station 2).
check "scan the built-in site" "$lidarshop" scan parking_lot_stations --rows 160 --columns 320 -o "$work/site.e57" \
  --labels "$work/site_labels.png" --quiet
check "clean the site" "$lidarshop" clean "$work/site.e57" --out "$work/site_clean" --removed-masks \
  --json "$work/site_clean.json" --quiet
json_check "the sedan goes from station 2, nothing much from 0 and 1" "$work/site_clean.json" \
  "len(d['stations']) == 3 and d['stations'][2]['removed'] > 100 and \
   d['stations'][0]['removed'] < 20 and d['stations'][1]['removed'] < 20"
check "what was removed from station 2 is the sedan" python3 -c "
import sys; sys.path.insert(0, sys.argv[3]); from png_grey import read as png
removed, labels = png(sys.argv[1]), png(sys.argv[2])
cells = [labels[r][c] for r in range(len(removed)) for c in range(len(removed[0])) if removed[r][c]]
sedan = sum(1 for l in cells if l == 7)
assert cells and sedan >= 0.9 * len(cells), (len(cells), sedan)
" "$work/site_clean/site_2_removed.png" "$work/site_labels_2.png" "$(dirname "$0")"

finish
