#!/usr/bin/env bash
# End to end, filling from other stations (docs/stations.md "Filling from other stations"): the hatchback of the
# built-in site removed from station 0 with the real points station 2 measured behind it (the car had left by
# then), `fill --stations` and `remove --stations` with their masks and JSON, the from_station channel in E57 and
# LAS and PTX's warning, and `clean` filling from the other stations first.
# Run by ctest as `from_stations_cli_test` (tests/cli_fixture.sh says how to run it by hand).
source "$(dirname "$0")/cli_fixture.sh"

check "scan the built-in site" "$lidarshop" scan parking_lot_stations --rows 160 --columns 320 -o "$work/site.e57" \
  --labels "$work/labels.png" --quiet

# The hatchback's cells of station 0 grown by 2 cells: the hole; and strokes on it and on the ground.
check "the hatchback's hole and strokes" python3 -c "
import json, sys; sys.path.insert(0, sys.argv[1]); import png_grey as png
labels = png.read(sys.argv[2]); h, w = len(labels), len(labels[0])
car = {(r, c) for r in range(h) for c in range(w) if labels[r][c] == 3}
assert len(car) > 200, len(car)
hole = [[255 if any((r + dr, c + dc) in car for dr in range(-2, 3) for dc in range(-2, 3)) else 0 for c in range(w)]
        for r in range(h)]
png.write(sys.argv[3], hole)
rows = sorted(r for r, c in car); r0 = rows[len(rows) // 2]; cols = sorted(c for r, c in car if r == r0)
json.dump({'strokes': [{'label': 'object', 'width': 3, 'points': [[cols[2], r0], [cols[-3], r0]]},
                       {'label': 'background', 'width': 2, 'points': [[5, h - 4], [w - 5, h - 4]]}]},
          open(sys.argv[4], 'w'))
" "$(dirname "$0")" "$work/labels_0.png" "$work/hole.png" "$work/strokes.json"

check "fill from station 2" "$lidarshop" fill "$work/site.e57#0" --mask "$work/hole.png" --stations "$work/site.e57#2" \
  -o "$work/filled.e57" --from-stations-mask "$work/from.png" --synthesized-mask "$work/synth.png" \
  --json "$work/fill.json" --quiet
json_check "part of the hole comes from station 2 (its real points), the rest is synthesized" "$work/fill.json" \
  "d['from_station_cells'] > d['hole_cells'] / 5 and d['synthesized_cells'] < d['hole_cells'] and \
   d['stations'][0]['from_station_cells'] == d['from_station_cells'] and d['stations'][0]['scan'] == 0 and \
   d['options']['from_stations']['check_free_space'] == True"
check "fill alone, for comparison" "$lidarshop" fill "$work/site.e57#0" --mask "$work/hole.png" -o "$work/alone.e57" \
  --json "$work/alone.json" --quiet
check "the synthesized share shrinks" python3 -c "
import json, sys; a = json.load(open(sys.argv[1])); s = json.load(open(sys.argv[2]))
assert s['synthesized_cells'] < 0.8 * a['synthesized_cells'], (s['synthesized_cells'], a['synthesized_cells'])
" "$work/alone.json" "$work/fill.json"
check "the masks: from-station and synthesized cells apart, inside the hole" python3 -c "
import json, sys; sys.path.insert(0, sys.argv[1]); import png_grey as png
hole, from_, synth = png.read(sys.argv[2]), png.read(sys.argv[3]), png.read(sys.argv[4]); d = json.load(open(sys.argv[5]))
cells = [(r, c) for r in range(len(hole)) for c in range(len(hole[0]))]
assert sum(1 for r, c in cells if from_[r][c]) == d['from_station_cells']
assert sum(1 for r, c in cells if synth[r][c]) == d['synthesized_cells']
assert not any(from_[r][c] and synth[r][c] for r, c in cells)
assert not any((from_[r][c] or synth[r][c]) and not hole[r][c] for r, c in cells)
" "$(dirname "$0")" "$work/hole.png" "$work/from.png" "$work/synth.png" "$work/fill.json"
check "E57 keeps the from_station channel" sh -c "'$lidarshop' info '$work/filled.e57' | grep -q from_station"
check "LAS keeps it as user data" "$lidarshop" convert "$work/filled.e57" "$work/filled.las" --quiet
check "PLY keeps it" "$lidarshop" convert "$work/filled.e57" "$work/filled.ply" --quiet
check "PLY's header lists it" sh -c "'$lidarshop' info '$work/filled.ply' | grep -q from_station"
check "PTX cannot: it says so, naming the channel" sh -c \
  "'$lidarshop' fill '$work/site.e57#0' --mask '$work/hole.png' --stations '$work/site.e57#2' -o '$work/filled.ptx' \
   2>&1 | grep -q 'without the from_station channel'"

check "remove from strokes with stations 1 and 2" "$lidarshop" remove "$work/site.e57#0" --strokes "$work/strokes.json" \
  --stations "$work/site.e57" -o "$work/removed.e57" --from-stations-mask "$work/removed_from.png" \
  --json "$work/remove.json" --quiet
json_check "remove: the site's other two stations, station 0 itself left out" "$work/remove.json" \
  "len(d['fill']['stations']) == 2 and [s['scan'] for s in d['fill']['stations']] == [1, 2] and \
   d['fill']['from_station_cells'] > 0 and d['cut']['object_cells'] > 100"
check "the removed car is not painted back from station 1, where it stands" python3 -c "
import json, sys; d = json.load(open(sys.argv[1]))
s1 = d['fill']['stations'][0]
assert s1['object_cells'] > 50, s1
" "$work/remove.json"

exits_with 2 "--from-stations-mask needs --stations" "--from-stations-mask needs --stations" "$lidarshop" fill \
  "$work/site.e57#0" --mask "$work/hole.png" -o "$work/x.e57" --from-stations-mask "$work/x.png"
fails_clearly "a station file that is only the scan itself" "no station other than the scan" "$lidarshop" fill \
  "$work/site.e57#0" --mask "$work/hole.png" -o "$work/x.e57" --stations "$work/site.e57#0"

check "clean fills from the other stations first" "$lidarshop" clean "$work/site.e57" --out "$work/clean" \
  --json "$work/clean.json" --quiet
json_check "clean: the sedan's hole at station 2 partly from stations 0 and 1" "$work/clean.json" \
  "d['stations'][2]['removed'] > 100 and d['stations'][2]['from_station'] > 0"

finish
