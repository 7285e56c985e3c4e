#!/usr/bin/env bash
# End to end, `points` (outliers, crop, voxel, normals, planes, clusters, transform, mesh, regions, superpixels,
# sample-mesh) and `register`: every scan keeps its grid.
# Run by ctest as `pointset_cli_test` (tests/cli_fixture.sh says how to run it by hand).
source "$(dirname "$0")/cli_fixture.sh"
make_scan

# points and register (docs/points.md): every scan keeps its grid; clouds for voxel and merge.
check "points outliers" "$lidarshop" points outliers "$work/scan.ptx" -o "$work/clean.ptx" --json "$work/clean.json"
json_check "points outliers summary" "$work/clean.json" "0 < d['output_points'] < d['input_points']"
check "points crop polygon" "$lidarshop" points crop "$work/scan.ptx" -o "$work/crop.ply" \
  --polygon=-3,7,-1,7,-1,9,-3,9 --json "$work/crop.json"
json_check "points crop keeps the box" "$work/crop.json" "100 < d['output_points'] < 2000"
check "points voxel" "$lidarshop" points voxel "$work/scan.ptx" -o "$work/voxel.ply" --voxel 0.2
check "points normals" "$lidarshop" points normals "$work/scan.ptx" -o "$work/normals.ptx" --grid
check "points planes" "$lidarshop" points planes "$work/scan.ptx" -o "$work/planes.ply" --planes 2 --distance 0.02 \
  --json "$work/planes.json"
json_check "points planes: the ground first" "$work/planes.json" \
  "len(d['planes']) == 2 and abs(abs(d['planes'][0]['normal'][2]) - 1) < 1e-3"
check "points planes --hough" "$lidarshop" points planes "$work/scan.ptx" -o "$work/hough.ply" --hough \
  --distance 0.02 --min-inliers 100 --json "$work/hough.json"
json_check "points planes --hough: the ground" "$work/hough.json" "abs(abs(d['planes'][0]['normal'][2]) - 1) < 1e-3"
check "points cluster" "$lidarshop" points cluster "$work/scan.ptx" -o "$work/clusters.ply" --radius 0.3 \
  --json "$work/clusters.json"
check "points transform" "$lidarshop" points transform "$work/scan.ptx" -o "$work/moved.ptx" \
  --matrix 1,0,0,0.05,0,1,0,0.02,0,0,1,0,0,0,0,1
check "register" "$lidarshop" register "$work/scan.ptx" "$work/moved.ptx" -o "$work/registered.ptx" \
  --json "$work/register.json"
json_check "register undoes the move" "$work/register.json" \
  "d['converged'] and abs(d['world_from_scanner'][0][3]) < 1e-3 and abs(d['world_from_scanner'][1][3]) < 1e-3"
check "points mesh" "$lidarshop" points mesh "$work/clean.ptx" -o "$work/grid_mesh.ply" --json "$work/mesh.json"
json_check "points mesh summary" "$work/mesh.json" "d['triangles'] > 1000"
check "points regions" "$lidarshop" points regions "$work/scan.ptx" -o "$work/regions.ply" --min-cells 20 \
  --json "$work/regions.json"
json_check "points regions summary" "$work/regions.json" "d['regions'] >= 3"
check "points superpixels" "$lidarshop" points superpixels "$work/scan.ptx" -o "$work/superpixels.ptx" \
  --superpixel-method graph
check "points sample-mesh" "$lidarshop" points sample-mesh "$work/grid_mesh.ply" -o "$work/mesh_samples.ply" \
  --count 5000 --json "$work/mesh_samples.json"
json_check "points sample-mesh summary" "$work/mesh_samples.json" "d['output_points'] == 5000"
fails_clearly "points: k larger than the cloud" "larger than the cloud" "$lidarshop" points kmeans "$work/scan.ptx" \
  -o "$work/x.ply" --k 100000000
exits_with 2 "points: radius 0 names the flag" "--radius: 0(\.0)? is out of range > 0" "$lidarshop" points outliers \
  "$work/scan.ptx" -o "$work/x.ply" --method radius --radius 0
fails_clearly "points: unknown operation" "unknown operation" "$lidarshop" points smooth "$work/scan.ptx" -o "$work/x.ply"

json_stdout "points --json -" output_points "$lidarshop" points outliers "$work/scan.ptx" -o "$work/j_clean.ptx" --json -
json_stdout "register --json -" converged "$lidarshop" register "$work/scan.ptx" "$work/moved.ptx" \
  -o "$work/j_registered.ptx" --json -

printf '{"planes": {"max_planes": 1}}\n' >"$work/points_options.json"
check "points --options by operation" "$lidarshop" points planes "$work/scan.ptx" -o "$work/j_planes.ply" \
  --options "$work/points_options.json" --distance 0.02 --json "$work/j_planes.json"
json_check "points --options reach the operation" "$work/j_planes.json" \
  "len(d['planes']) == 1 and d['options']['planes']['max_planes'] == 1 and d['options']['planes']['distance_threshold_m'] == 0.02"

exits_with 2 "points: did you mean" "unknown option --std-ration \(did you mean --std-ratio\?\)" \
  "$lidarshop" points outliers "$work/scan.ptx" -o "$work/x.ply" --std-ration 2
help_shows "points help: superpixel methods as words" "slic|graph" "$lidarshop" points

finish
