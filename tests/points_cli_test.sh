#!/usr/bin/env bash
# End-to-end test of `lidarshop points mesh` (grid mesh, Poisson, scale-space) and of the curvature channel
# that `points normals` writes (docs/points.md), with answers known from the geometry: a sphere's mesh lies on
# the sphere, a limited grid mesh has no longer edge, a plane has no curvature. Run by ctest as
# `points_cli_test`. Usage: points_cli_test.sh LIDARSHOP_BINARY
set -uo pipefail
lidarshop=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
passed=0
failed=0
# shellcheck source=check_lib.sh
source "$(dirname "$0")/check_lib.sh"

# ply_check NAME FILE PYTHON_EXPRESSION: on `v` (the vertex properties, name -> list) and `f` (the faces,
# lists of vertex indices) of a PLY file (ascii or binary little-endian).
cat >"$work/ply.py" <<'PY'
import math, struct, sys
TYPES = {"char": "b", "int8": "b", "uchar": "B", "uint8": "B", "short": "h", "int16": "h", "ushort": "H",
         "uint16": "H", "int": "i", "int32": "i", "uint": "I", "uint32": "I", "float": "f", "float32": "f",
         "double": "d", "float64": "d"}
def read(path):
    data = open(path, "rb").read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    elements, fmt = [], None
    for line in data[:end].decode().splitlines():
        w = line.split()
        if w[0] == "format": fmt = w[1]
        elif w[0] == "element": elements.append((w[1], int(w[2]), []))
        elif w[0] == "property": elements[-1][2].append(w[1:])
    out, pos = {}, end
    tokens = data[end:].split() if fmt == "ascii" else None
    t = 0
    for name, count, props in elements:
        rows = []
        for _ in range(count):
            row = []
            for p in props:
                if p[0] == "list":
                    if tokens is not None:
                        n = int(tokens[t]); row.append([int(x) for x in tokens[t + 1:t + 1 + n]]); t += 1 + n
                    else:
                        n = struct.unpack_from("<" + TYPES[p[1]], data, pos)[0]; pos += struct.calcsize(TYPES[p[1]])
                        c = TYPES[p[2]]; row.append(list(struct.unpack_from("<%d%s" % (n, c), data, pos)))
                        pos += n * struct.calcsize(c)
                elif tokens is not None:
                    row.append(float(tokens[t])); t += 1
                else:
                    row.append(struct.unpack_from("<" + TYPES[p[0]], data, pos)[0]); pos += struct.calcsize(TYPES[p[0]])
            rows.append(row)
        out[name] = {p[-1]: [r[i] for r in rows] for i, p in enumerate(props)}
    return out
ply = read(sys.argv[1])
v = ply.get("vertex", {})
f = ply.get("face", {}).get("vertex_indices", ply.get("face", {}).get("vertex_index", []))
assert eval(sys.argv[2]), "expression false"
PY
ply_check() {
  check "$1" python3 "$work/ply.py" "$2" "$3"
}

# A sphere of radius 1 around (1, 2, 3) as an ASCII PLY cloud (Fibonacci lattice, outward normals), the same
# without normals around (0.2, -0.1, 0.3) (the origin, where a plain cloud's scanner is, inside: estimated
# normals face it), and a flat square (all points on one plane).
python3 - "$work" <<'PY'
import math, sys
def sphere(path, centre, normals, count=3000):
    with open(path, "w") as out:
        out.write("ply\nformat ascii 1.0\nelement vertex %d\nproperty float x\nproperty float y\nproperty float z\n" % count)
        if normals: out.write("property float nx\nproperty float ny\nproperty float nz\n")
        out.write("end_header\n")
        for i in range(count):
            z = 1 - 2 * (i + 0.5) / count
            phi = math.pi * (1 + 5 ** 0.5) * (i + 0.5)
            rho = math.sqrt(1 - z * z)
            n = (rho * math.cos(phi), rho * math.sin(phi), z)
            p = [centre[k] + n[k] for k in range(3)]
            out.write(" ".join("%.7f" % x for x in (p + list(n) if normals else p)) + "\n")
sphere(sys.argv[1] + "/sphere.ply", (1, 2, 3), True)
sphere(sys.argv[1] + "/sphere_bare.ply", (0.2, -0.1, 0.3), False)
with open(sys.argv[1] + "/flat.ply", "w") as out:
    out.write("ply\nformat ascii 1.0\nelement vertex 400\nproperty float x\nproperty float y\nproperty float z\nend_header\n")
    for i in range(400):
        out.write("%g %g 0\n" % (i % 20 * 0.1, i // 20 * 0.1))
PY

# mesh --method poisson: the cloud's own normals; every vertex within 2 % of the radius of the centre.
on_sphere() {  # on_sphere CX CY CZ TOLERANCE: a python expression over v
  echo "len(v['x']) > 100 and max(abs(math.dist((x, y, z), ($1, $2, $3)) - 1) for x, y, z in zip(v['x'], v['y'], v['z'])) < $4"
}
check "mesh --method poisson" "$lidarshop" points mesh "$work/sphere.ply" -o "$work/poisson.ply" --method poisson \
  --json "$work/poisson.json"
json_check "mesh poisson summary" "$work/poisson.json" \
  "d['method'] == 'poisson' and d['normals'] == 'input' and d['triangles'] > 300 and d['vertices'] > 150 and d['input_points'] == 3000 \
   and 'surface' in d['options'] and 'mesh' not in d['options'] and d['options']['surface']['method'] == 'poisson'"
ply_check "poisson vertices lie on the sphere" "$work/poisson.ply" "$(on_sphere 1 2 3 0.02)"
# Closed: every edge is shared by exactly two triangles.
ply_check "poisson mesh is closed" "$work/poisson.ply" \
  "(lambda e: len(f) > 300 and all(c == 2 for c in e.values()))(__import__('collections').Counter(tuple(sorted((t[i], t[(i + 1) % 3]))) for t in f for i in range(3)))"
check "mesh poisson with estimated normals" "$lidarshop" points mesh "$work/sphere_bare.ply" \
  -o "$work/poisson_bare.ply" --method poisson --neighbors 12 --json "$work/poisson_bare.json"
json_check "estimated normals are said so" "$work/poisson_bare.json" \
  "d['normals'] == 'estimated' and d['options']['surface']['normal_neighbors'] == 12"
ply_check "poisson from estimated normals lies on the sphere" "$work/poisson_bare.ply" "$(on_sphere 0.2 -0.1 0.3 0.02)"
check "mesh poisson is deterministic" "$lidarshop" points mesh "$work/sphere.ply" -o "$work/poisson2.ply" \
  --method poisson
check "same mesh twice" cmp "$work/poisson.ply" "$work/poisson2.ply"
# --keep-within trims: a distance under the point spacing (6.5 cm) drops the triangles with a vertex far from
# every input point.
check "mesh poisson --keep-within" "$lidarshop" points mesh "$work/sphere.ply" -o "$work/trimmed.ply" \
  --method poisson --keep-within 0.03 --json "$work/trimmed.json"
check "keep-within drops triangles" python3 -c "import json,sys; a=json.load(open(sys.argv[1])); \
b=json.load(open(sys.argv[2])); assert b['triangles'] < a['triangles']" "$work/poisson.json" "$work/trimmed.json"

# mesh --method scale-space: interpolating, so the vertices are input points (on the sphere to float precision).
check "mesh --method scale-space" "$lidarshop" points mesh "$work/sphere_bare.ply" -o "$work/scale.ply" \
  --method scale-space --json "$work/scale.json"
json_check "scale-space summary" "$work/scale.json" "d['method'] == 'scale-space' and d['triangles'] > 1000"
ply_check "scale-space vertices are the points" "$work/scale.ply" "$(on_sphere 0.2 -0.1 0.3 1e-5)"

# The scan's own grid mesh of a scanned scene (a ground and a sphere), and --max-edge.
cat >"$work/scene.json" <<'JSON'
{"scanner": {"position": [0, 0, 1.5], "rotate_deg": [0, 0, 0],
             "azimuth_deg": [-40, 40], "elevation_deg": [-40, 10], "columns": 160, "rows": 100,
             "max_range": 60, "los_noise_sigma": 0.0, "orthogonal_noise_sigma": 0.0, "seed": 1},
 "objects": [
   {"primitive": "plane", "size": [200, 200], "translate": [0, 0, 0], "label": 0},
   {"primitive": "sphere", "radius": 1.0, "translate": [0.5, 6, 1], "label": 1}]}
JSON
check "scan the scene" "$lidarshop" scan "$work/scene.json" -o "$work/scan.ptx"
check "mesh (grid)" "$lidarshop" points mesh "$work/scan.ptx" -o "$work/grid.ply" --json "$work/grid.json"
json_check "grid mesh summary" "$work/grid.json" \
  "d['method'] == 'grid' and d['triangles'] > 10000 and 'mesh' in d['options'] and 'surface' not in d['options']"
check "mesh (grid) --max-edge 0.1" "$lidarshop" points mesh "$work/scan.ptx" -o "$work/grid_short.ply" \
  --max-edge 0.1 --json "$work/grid_short.json"
check "max-edge drops the long triangles of the far ground" python3 -c "import json,sys; \
a=json.load(open(sys.argv[1])); b=json.load(open(sys.argv[2])); assert 1000 < b['triangles'] < a['triangles']; \
assert b['options']['mesh']['max_edge_m'] == 0.1" "$work/grid.json" "$work/grid_short.json"
ply_check "no edge longer than 0.1 m" "$work/grid_short.ply" \
  "max(math.dist(*[(v['x'][t[i]], v['y'][t[i]], v['z'][t[i]]) for i in (k, (k + 1) % 3)]) for t in f for k in range(3)) <= 0.1 + 1e-6"
fails_clearly "a plain cloud has no grid mesh" "no grid\): use --method poisson or scale-space" \
  "$lidarshop" points mesh "$work/sphere.ply" -o "$work/x.ply"
fails_clearly "mesh: unknown method" "mesh takes grid, poisson or scale-space" \
  "$lidarshop" points mesh "$work/sphere.ply" -o "$work/x.ply" --method marching-cubes
fails_clearly "mesh: points on one plane" "on one plane" \
  "$lidarshop" points mesh "$work/flat.ply" -o "$work/x.ply" --method scale-space
fails_clearly "mesh: a mesh needs .ply" "as \.ply" \
  "$lidarshop" points mesh "$work/sphere.ply" -o "$work/x.pcd" --method poisson

# Curvature beside the normals: k nearest and grid, in PLY and PCD. The ground is a plane (curvature ~0),
# the sphere's surface variation is larger.
check "normals write curvature (PLY)" "$lidarshop" points normals "$work/scan.ptx" -o "$work/normals.ply"
ply_check "curvature field: ~0 on the ground, more on the sphere" "$work/normals.ply" \
  "(lambda g, s: len(g) > 1000 and len(s) > 100 and sorted(g)[len(g) // 2] < 1e-5 and sorted(s)[len(s) // 2] > 2e-4)(\
[c for c, z, y in zip(v['curvature'], v['z'], v['y']) if z < 0.01 and y < 4], \
[c for c, z, y, x in zip(v['curvature'], v['z'], v['y'], v['x']) if math.dist((x, y, z), (0.5, 6, 1)) < 1.01])"
ply_check "curvature in [0, 1/3]" "$work/normals.ply" "all(0 <= c <= 1 / 3 + 1e-6 for c in v['curvature'])"
check "normals --grid write curvature (PCD)" "$lidarshop" points normals "$work/scan.ptx" -o "$work/normals.pcd" --grid
check "PCD has the curvature field" grep -qa "^FIELDS .* normal_z curvature" "$work/normals.pcd"
# Reading the PCD keeps the channel: a crop that keeps every point writes it again, as PLY.
check "PCD curvature reads back" "$lidarshop" points crop "$work/normals.pcd" -o "$work/normals_again.ply" \
  --box -100,-100,-100,100,100,100
ply_check "the curvature survives PCD -> PLY" "$work/normals_again.ply" \
  "len(v['curvature']) > 10000 and sum(1 for c in v['curvature'] if c >= 0) > 10000"

echo "points_cli_test: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
