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
  "d['stations'][0]['removed'] > 300 and d['stations'][0]['filled'] > 300 and d['stations'][1]['removed'] == 0 \
   and d['removed'] == d['stations'][0]['removed'] and d['options']['transients']['min_region_cells'] == 12"
check "each station written under its own name, with its removed mask" test -s "$work/clean/st0.e57" \
  -a -s "$work/clean/st1.e57" -a -s "$work/clean/st0_removed.png" -a -s "$work/clean/st1_removed.png"
check "the cleaned station holds synthesized points" sh -c \
  "'$lidarshop' info '$work/clean/st0.e57' | grep -q synthesized"
fails_clearly "clean: one station is not enough" "two stations" "$lidarshop" clean "$work/st0.e57" --out "$work/one"
exits_with 2 "clean: a bad value names the flag" "--min-region: 0 is out of range" "$lidarshop" clean \
  "$work/st0.e57" "$work/st1.e57" --out "$work/bad" --min-region 0
fails_clearly "clean: never onto an input" "st0.e57" "$lidarshop" clean "$work/st0.e57" "$work/st1.e57" --out "$work"

finish
