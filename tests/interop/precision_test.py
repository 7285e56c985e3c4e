#!/usr/bin/python3
"""Survey coordinates through every format and every edit, to the file's resolution.

  precision_test.py LIDARSHOP

A synthetic scan is given a pose 5,000 km from the origin (UTM-like: easting 500 km, northing 5,000 km) with
`points transform`. Its PTX (scanner-frame points + the pose) is read here independently into world
coordinates (numpy, double). Then:
  * through every format (PTX, E57, PLY, PCD, LAS, XYZ, PTS) and back to XYZ, every point comes back within
    0.1 mm of the independent reading (LAS: within half of its 0.1 mm step);
  * fill, remove, segment --object and register write PTX whose unchanged cells are the input's, to the digit,
    and whose pose is the input's (register: the pose it reports, applied in double).
Prints one line per check and 'N passed, N failed'.
"""
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

EASTING, NORTHING, HEIGHT = 500000.0, 5000000.0, 100.0
SCENE = {
    "scanner": {"position": [0, 0, 1.5], "azimuth_deg": [-45, 45], "elevation_deg": [-30, 30], "columns": 180,
                "rows": 120, "max_range": 100, "los_noise_sigma": 0.002, "orthogonal_noise_sigma": 0.001,
                "seed": 3},
    "objects": [
        {"primitive": "plane", "size": [200, 200], "translate": [0, 0, 0], "label": 0, "texture": "grass"},
        {"primitive": "sphere", "radius": 1.0, "translate": [2, 10, 1], "label": 1, "color": [200, 40, 40]},
        {"primitive": "box", "size": [1, 0.6, 1.2], "translate": [-2, 8, 0.6], "label": 2}]}
# The sphere (column 112, image row 65) and the ground below it, as in tests/cli_fixture.sh.
STROKES = {"strokes": [{"label": "object", "width": 3, "points": [[110, 65], [114, 65]]},
                       {"label": "background", "width": 2, "points": [[5, 115], [175, 115]]}]}

results = []


def check(name, ok, detail=""):
    results.append(ok)
    print(f"{'ok' if ok else 'FAIL'}: {name}" + (f" ({detail})" if detail else ""), flush=True)


def run(*args):
    result = subprocess.run([str(a) for a in args], capture_output=True, text=True, timeout=600)
    if result.returncode != 0:
        raise RuntimeError(f"{' '.join(map(str, args))}: {result.stderr.strip()[-300:]}")
    return result


def read_ptx(path):
    """[(cells as text lines, 4x4 matrix as text, world points (rows*cols x 3, NaN without a return))]."""
    lines = open(path).read().split("\n")
    i, scans = 0, []
    while i < len(lines) and lines[i].strip():
        cols, rows = int(lines[i]), int(lines[i + 1])
        matrix_text = lines[i + 6:i + 10]
        m = np.array([[float(v) for v in line.split()] for line in matrix_text])
        cells = lines[i + 10:i + 10 + rows * cols]
        pts = np.array([[float(v) for v in c.split()[:3]] for c in cells])
        world = pts @ m[:3, :3] + m[3, :3]
        world[np.all(pts == 0, axis=1)] = np.nan
        # PTX runs column by column, bottom to top; lidarshop writes clouds row by row from the top row.
        order = [c * rows + (rows - 1 - r) for r in range(rows) for c in range(cols)]
        world = world[order]
        scans.append((cells, matrix_text, world, m))
        i += 10 + rows * cols
    return scans


def read_xyz(path):
    return np.array([[float(v) for v in line.split()[:3]] for line in open(path) if len(line.split()) >= 3])


def main():
    lidarshop = os.path.abspath(sys.argv[1])
    with tempfile.TemporaryDirectory() as work:
        def path(name):
            return os.path.join(work, name)
        json.dump(SCENE, open(path("scene.json"), "w"))
        json.dump(STROKES, open(path("strokes.json"), "w"))
        run(lidarshop, "scan", path("scene.json"), "-o", path("local.ptx"), "--quiet")
        matrix = f"1,0,0,{EASTING},0,1,0,{NORTHING},0,0,1,{HEIGHT},0,0,0,1"
        run(lidarshop, "points", "transform", path("local.ptx"), "-o", path("utm.ptx"), f"--matrix={matrix}")
        (cells, matrix_text, world, m), = read_ptx(path("utm.ptx"))
        check("the pose is 5,000 km out", abs(m[3, 1] - NORTHING) < 1e-6, f"translation {m[3, :3]}")
        reference = world[~np.isnan(world[:, 0])]
        check("the scan has returns", len(reference) > 10000, f"{len(reference)} points")

        # Every format, then XYZ.
        for fmt in ["ptx", "e57", "ply", "pcd", "las", "xyz", "pts"]:
            out = path(f"through.{fmt}")
            run(lidarshop, "convert", "--quiet", path("utm.ptx"), out)
            run(lidarshop, "convert", "--quiet", out, path(f"back_{fmt}.xyz"))
            got = read_xyz(path(f"back_{fmt}.xyz"))
            if got.shape != reference.shape:
                check(f"{fmt}: every point back", False, f"{len(got)} of {len(reference)}")
                continue
            worst = float(np.abs(got - reference).max())
            tolerance = 0.5e-4 + 1e-6 if fmt == "las" else 1e-4
            check(f"{fmt}: world coordinates 5,000 km out within {tolerance * 1000:.2f} mm", worst <= tolerance,
                  f"worst {worst * 1000:.4f} mm")

        # Edits: the cells they do not change come back to the digit, with the same pose.
        run(lidarshop, "segment", path("utm.ptx"), "--strokes", path("strokes.json"), "-o", path("mask.png"),
            "--object", path("object.ptx"), "--quiet")
        run(lidarshop, "fill", path("utm.ptx"), "--mask", path("mask.png"), "-o", path("filled.ptx"), "--quiet")
        run(lidarshop, "remove", path("utm.ptx"), "--strokes", path("strokes.json"), "-o", path("removed.ptx"),
            "--quiet")
        for name in ["object", "filled", "removed"]:
            (out_cells, out_matrix, out_world, _), = read_ptx(path(f"{name}.ptx"))
            same = [a == b for a, b in zip(cells, out_cells) if b.split()[:3] != ["0", "0", "0"]]
            changed = sum(not s for s in same)
            kept = sum(same)
            check(f"{name}: the pose is the input's, to the digit", out_matrix == matrix_text)
            # segment --object keeps a subset of cells unchanged; fill and remove change only the hole.
            limit = 0 if name == "object" else 0.2 * len(reference)
            check(f"{name}: unchanged cells are the input's, to the digit", kept > 100 and changed <= limit,
                  f"{kept} identical, {changed} changed")
        # Synthesized points into XYZ, which cannot mark them: a warning with their number by default;
        # --drop-synthesized leaves them out, --synthesized-mask records them on the grid.
        run(lidarshop, "fill", path("utm.ptx"), "--mask", path("mask.png"), "-o", path("filled.ply"), "--quiet")
        warned = run(lidarshop, "convert", path("filled.ply"), path("all.xyz")).stderr
        run(lidarshop, "convert", path("filled.ply"), path("kept.xyz"), "--drop-synthesized",
            "--synthesized-mask", path("synthesized.png"), "--json", path("convert.json"), "--quiet")
        left_out = json.load(open(path("convert.json")))["synthesized_left_out"]
        all_points, kept_points = len(read_xyz(path("all.xyz"))), len(read_xyz(path("kept.xyz")))
        check("XYZ: the warning says how many synthesized points go unmarked",
              f"{left_out} synthesized points are written without their flag" in warned, warned.strip()[-200:])
        check("--drop-synthesized leaves exactly those out", left_out > 0 and kept_points == all_points - left_out,
              f"{all_points} points, {kept_points} kept, {left_out} left out")
        png = open(path("synthesized.png"), "rb").read()
        width, height = int.from_bytes(png[16:20], "big"), int.from_bytes(png[20:24], "big")
        check("--synthesized-mask is a picture of the grid", (width, height) == (180, 120),
              f"{width} x {height}")
        # register: a copy moved by 5 cm comes back; its points are untouched, its pose moves in double.
        run(lidarshop, "points", "transform", path("utm.ptx"), "-o", path("moved.ptx"),
            "--matrix=1,0,0,0.05,0,1,0,0.02,0,0,1,0,0,0,0,1")
        run(lidarshop, "register", path("utm.ptx"), path("moved.ptx"), "-o", path("registered.ptx"), "--json",
            path("register.json"))
        (reg_cells, _, reg_world, _), = read_ptx(path("registered.ptx"))
        check("register: the points are the input's, to the digit", reg_cells == cells)
        valid = ~np.isnan(world[:, 0])
        worst = float(np.abs(reg_world[valid] - world[valid]).max())
        check("register: 5,000 km out, the registered scan lies on the fixed one within 1 mm", worst < 1e-3,
              f"worst {worst * 1000:.3f} mm")
    failed = results.count(False)
    print(f"{len(results) - failed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
