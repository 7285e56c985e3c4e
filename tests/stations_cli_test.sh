#!/usr/bin/env bash
# End-to-end test of sites of several stations (issue 31, docs/stations.md): `scan` of a scene with
# "stations" into one E57 / PTX or one file per station (--split), labels per station, `info` listing the
# stations, FILE#N and --scan N reading one station, and `register` of a whole site against the scene's true
# poses. Single-station scenes keep their outputs. Run by ctest as `stations_cli_test` (tests/cli_fixture.sh says
# how to run it by hand).
source "$(dirname "$0")/cli_fixture.sh"

small=(--rows 120 --columns 240)

# A site into one E57: one data3D per station, named and posed.
check "scan a site" "$lidarshop" scan parking_lot_stations "${small[@]}" -o "$work/site.e57" \
  --labels "$work/L.png" --json "$work/scan.json" -q
json_check "scan json lists 3 stations" "$work/scan.json" \
  "len(d['stations']) == 3 and [s['name'] for s in d['stations']] == ['station0', 'station1', 'station2'] \
   and d['stations'][1]['position'] == [-8, 2, 1.6] and d['rays'] == 3 * 120 * 240 \
   and d['returns'] == sum(s['returns'] for s in d['stations']) \
   and d['stations'][2]['labels_color'].endswith('L_2_color.png') and 'labels' not in d"
json_check "the hatchback left, a sedan came" "$work/scan.json" \
  "[s['objects'] for s in d['stations']] == [7, 7, 7]"
for i in 0 1 2; do
  check "labels of station $i" test -s "$work/L_$i.png"
  check "label colours of station $i" test -s "$work/L_${i}_color.png"
done
check "no labels for the site as a whole" test ! -e "$work/L.png"
check "info site" "$lidarshop" info "$work/site.e57" --json "$work/info.json" -q
json_check "info lists the stations and their poses" "$work/info.json" \
  "len(d['scans']) == 3 and [s['name'] for s in d['stations']] == ['station0', 'station1', 'station2'] \
   and all(abs(a - b) < 1e-6 for a, b in zip(d['stations'][2]['position'], [8, 2, 1.6])) \
   and abs(d['stations'][2]['heading_deg'] - 30) < 1e-6 and abs(d['stations'][1]['heading_deg'] + 30) < 1e-6"
check "info FILE#N" "$lidarshop" info "$work/site.e57#2" --json "$work/info2.json" -q
json_check "info FILE#N shows that scan alone" "$work/info2.json" \
  "len(d['scans']) == 1 and d['scans'][0]['name'] == 'station2' and 'stations' not in d"
fails_clearly "FILE#N out of range" "scan 3 is out of range.*holds 3 scan" \
  "$lidarshop" render "$work/site.e57#3" -o "$work/r.png"
check "render FILE#N" "$lidarshop" render "$work/site.e57#1" -o "$work/r1.png" -q
check "render --scan N" "$lidarshop" render "$work/site.e57" --scan 1 -o "$work/r1b.png" -q
check "FILE#N and --scan N draw the same" cmp "$work/r1.png" "$work/r1b.png"
check "convert FILE#N" "$lidarshop" convert "$work/site.e57#2" "$work/s2.ptx" -q
check "info of the converted station" "$lidarshop" info "$work/s2.ptx" --json "$work/s2.json" -q
json_check "one station converted" "$work/s2.json" "len(d['scans']) == 1 and 'stations' not in d"
fails_clearly "FILE#N is protected from outputs" "overwrite|input" \
  "$lidarshop" convert "$work/site.e57#0" "$work/site.e57"

# PTX holds several scans in order; --split writes one file per station; PCD needs --split.
check "scan a site to PTX" "$lidarshop" scan parking_lot_stations "${small[@]}" -o "$work/site.ptx" -q
check "info site.ptx" "$lidarshop" info "$work/site.ptx" --json "$work/ptx.json" -q
json_check "PTX holds the three stations" "$work/ptx.json" "len(d['scans']) == 3 and len(d['stations']) == 3"
check "scan --split" "$lidarshop" scan parking_lot_stations "${small[@]}" -o "$work/split.ptx" --split -q
for i in 0 1 2; do check "split station $i" test -s "$work/split_$i.ptx"; done
check "no unsplit file" test ! -e "$work/split.ptx"
check "PTX station 1 = split_1.ptx" "$lidarshop" info "$work/split_1.ptx" --json "$work/split1.json" -q
json_check "split station at its pose" "$work/split1.json" \
  "all(abs(a - b) < 1e-6 for a, b in zip([r[3] for r in d['scans'][0]['world_from_scanner'][:3]], [-8, 2, 1.6]))"
fails_clearly "PCD holds one scan" "--split" \
  "$lidarshop" scan parking_lot_stations "${small[@]}" -o "$work/site.pcd"
check "PCD --split" "$lidarshop" scan parking_lot_stations "${small[@]}" -o "$work/site.pcd" --split -q
check "PCD station 2" test -s "$work/site_2.pcd"

# One station: outputs as before (no stations in the JSON, no _N files, the scan unnamed).
check "scan one station" "$lidarshop" scan parking_lot "${small[@]}" -o "$work/one.e57" --labels "$work/one.png" \
  --json "$work/one_scan.json" -q
check "one station's labels" test -s "$work/one.png"
check "no _0 labels" test ! -e "$work/one_0.png"
json_check "no stations for one station" "$work/one_scan.json" "'stations' not in d"
check "info one" "$lidarshop" info "$work/one.e57" --json "$work/one.json" -q
json_check "one scan, no stations" "$work/one.json" "len(d['scans']) == 1 and 'stations' not in d"

# Register a site: stations 1 and 2 moved off their poses come back.
check "spoil station 1" "$lidarshop" points transform "$work/site.e57#1" -o "$work/station1.e57" \
  --matrix "0.3,-0.2,0.1,1.0" -q
check "spoil station 2" "$lidarshop" points transform "$work/site.e57#2" -o "$work/station2.e57" \
  --matrix "-0.25,0.3,0.05,-1.2" -q
mkdir -p "$work/registered"
check "register a site" "$lidarshop" register "$work/site.e57#0" "$work/station1.e57" "$work/station2.e57" \
  -o "$work/registered" --json "$work/register.json" -q
json_check "site JSON: stations and pairs" "$work/register.json" \
  "len(d['stations']) == 3 and d['stations'][0]['fixed'] and len(d['pairs']) >= 2 \
   and all('rms_m' in p and 'graph_translation_m' in p for p in d['pairs']) \
   and all('rms_m' in s for s in d['stations'])"
for i in 1 2; do
  check "registered station $i" "$lidarshop" info "$work/registered/station$i.e57" --json "$work/reg$i.json" -q
done
cat >"$work/pose_error.py" <<'PY'
import json, math, sys
truth = json.load(open(sys.argv[1]))["scans"][int(sys.argv[3])]["world_from_scanner"]
moved = json.load(open(sys.argv[2]))["scans"][0]["world_from_scanner"]
dt = math.sqrt(sum((truth[r][3] - moved[r][3]) ** 2 for r in range(3)))
trace = sum(sum(truth[i][k] * moved[i][k] for i in range(3)) for k in range(3))
angle = math.degrees(math.acos(max(-1.0, min(1.0, (trace - 1) / 2))))
print(f"station {sys.argv[3]}: {dt * 1000:.2f} mm, {angle:.4f} deg")
assert dt < 0.01 and angle < 0.05, (dt, angle)
PY
for i in 1 2; do
  check "station $i back at its true pose" python3 "$work/pose_error.py" "$work/info.json" "$work/reg$i.json" "$i"
done
fails_clearly "site output must be a folder" "folder" \
  "$lidarshop" register "$work/site.e57#0" "$work/station1.e57" "$work/station2.e57" -o "$work/x.e57"

finish
