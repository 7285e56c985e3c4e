#!/usr/bin/python3
"""E57 checked by a decoder that is not lidarshop's (tests/interop/e57_decode.py, written from ASTM E2807).

usage: e57_interop_test.py LIDARSHOP SHARED_DATA_DIR [TABLE.md]

1. What lidarshop writes: a built-in scene scanned to PTX (text: the truth, cell by cell) and converted to E57.
   The independent decoder must find one record per return and nothing else in `points` (a reader that
   ignores cartesianInvalidState sees no junk), every record at its PTX cell's coordinates (bit for bit), the
   scan's angular grid in lidarshop's extension `angularGrid` (an azimuth per column, an elevation per row, which
   every return lies on within its noise), no no-return ray stored beside it (they are the grid's), and `info`
   must count what the decoder counts. The same for pumpA converted E57 -> E57 (155,201 returns, a grid of 1074
   rows and 345 columns, no ray in the extension).
2. `images --extract` writes the stored blobs byte for byte, with the stored format's extension.
3. Every E57 of SHARED_DATA_DIR/interop/e57: the valid ones open with `info --stats` with the decoder's point
   count and bounds and convert to every format with that count; the broken ones are refused with exit 1
   and one line naming the file. The table of results is printed (and written to TABLE.md when given).
"""

import json
import os
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import e57_decode as dec  # noqa: E402

LIDARSHOP, SHARED = sys.argv[1], sys.argv[2]
TABLE = sys.argv[3] if len(sys.argv) > 3 else None
FORMATS = ["ptx", "e57", "ply", "pcd", "las", "xyz", "pts"]
failures = []


def check(condition, what):
    if not condition:
        failures.append(what)
        print("FAILED:", what)
    return condition


def run(*args):
    return subprocess.run([LIDARSHOP, *map(str, args)], capture_output=True, text=True)


def info(path, stats=True):
    r = run("info", *(["--stats"] if stats else []), path, "--compact")
    if r.returncode != 0:
        return None, r
    return json.loads(r.stdout), r


def angular_grid(scan):
    """(azimuth per column, elevation per row) of lidarshop:angularGrid under a data3D entry; None if absent."""
    for child in scan["entry"]:
        if child.tag == "{http://lidarshop.dev/e57/1.0}angularGrid":
            return tuple(np.array([float(v.text) for v in dec._child(child, name)]) for name in ("azimuth", "elevation"))
    return None


def check_grid(scan, rows, cols, what):
    """The stored grid has the scan's shape, and the records lie on their cells' grid rays (lidarshop's frame:
    azimuth from +y towards +x, elevation up): RMS angle under 3/4 of the grid's larger step (pumpA's fit misses its returns by 1.5 mrad RMS; a wrong grid or a flipped axis is many steps off)."""
    grid = angular_grid(scan)
    if not check(grid is not None, f"{what}: lidarshop:angularGrid is present"):
        return
    azimuth, elevation = grid
    check(len(azimuth) == cols and len(elevation) == rows, f"{what}: the grid is {len(elevation)} x {len(azimuth)}")
    f = scan["fields"]
    valid = dec.valid_mask(scan)
    x, y, z = (f[k][valid].astype(np.float64) for k in ("cartesianX", "cartesianY", "cartesianZ"))
    a, e = azimuth[f["columnIndex"][valid].astype(int)], elevation[f["rowIndex"][valid].astype(int)]
    ray = np.vstack([np.cos(e) * np.sin(a), np.cos(e) * np.cos(a), np.sin(e)])
    p = np.vstack([x, y, z])
    angle = np.arccos(np.clip(np.sum(ray * p, axis=0) / np.linalg.norm(p, axis=0), -1, 1))
    rms = float(np.sqrt(np.mean(angle ** 2)))
    step = max(np.median(np.abs(np.diff(azimuth))), np.median(np.abs(np.diff(elevation))))
    check(rms < 0.75 * step,
          f"{what}: the returns on their grid rays (RMS {rms:.2e} rad, max {np.max(angle):.2e}, step {step:.2e})")


def extension_points(e57, scan):
    """The CompressedVector of lidarshop:noReturnDirections under a data3D entry, decoded; None if absent."""
    for child in scan["entry"]:
        if child.tag == "{http://lidarshop.dev/e57/1.0}noReturnDirections":
            return dec.read_compressed_vector("", e57.logical, dec._child(child, "points"))
    return None


def read_ptx(path):
    """(rows, cols, xyz as float32 array of cols*rows x 3 in file order: columns, each bottom to top)."""
    lines = open(path).read().split("\n")
    cols, rows = int(lines[0]), int(lines[1])
    xyz = np.array([[np.float32(v) for v in line.split()[:3]] for line in lines[10:10 + rows * cols]],
                   dtype=np.float32)
    return rows, cols, xyz


def check_our_file(work):
    ptx, e57_path = os.path.join(work, "s.ptx"), os.path.join(work, "s.e57")
    r = run("scan", "parking_lot", "-o", ptx, "--rows", 48, "--columns", 96, "--quiet")
    if not check(r.returncode == 0, f"scan parking_lot: {r.stderr}"):
        return
    check(run("convert", ptx, e57_path, "--quiet").returncode == 0, "convert ptx -> e57")
    rows, cols, xyz = read_ptx(ptx)
    returns = np.any(xyz != 0, axis=1)
    f = dec.decode(e57_path)
    check(len(f.scans) == 1, "one scan")
    s = f.scans[0]
    n = s["record_count"]
    fields = s["fields"]
    print(f"ours: {rows} x {cols} grid, {returns.sum()} returns, {n} records")
    check(0 < returns.sum() < rows * cols, "the synthetic scan has returns and no-return cells")
    check(n == returns.sum(), f"one record per return: {n} records, {returns.sum()} returns")
    x, y, z = (fields[k].astype(np.float32) for k in ("cartesianX", "cartesianY", "cartesianZ"))
    state = fields.get("cartesianInvalidState", np.zeros(n))
    row, col = fields["rowIndex"].astype(int), fields["columnIndex"].astype(int)
    line = col * rows + (rows - 1 - row)  # PTX: columns, each listed bottom to top; E57 row 0 = top
    # No record of an empty cell at non-zero coordinates with a valid state (what a naive reader would show).
    junk = (state == 0) & ~returns[line] & ((x != 0) | (y != 0) | (z != 0))
    check(not junk.any(), f"{junk.sum()} records of empty cells at non-zero coordinates with a valid state")
    check(np.all(state == 0), "every record is a return")
    same = (x == xyz[line, 0]) & (y == xyz[line, 1]) & (z == xyz[line, 2])
    check(same.all(), f"{(~same).sum()} records differ from their PTX cell")
    check(len(set(line.tolist())) == n, "one record per cell")
    for k in (0, n // 3, n - 1):  # a few known points, spelled out
        print(f"  record {k}: row {row[k]} col {col[k]} = ({x[k]}, {y[k]}, {z[k]}); PTX {xyz[line[k]].tolist()}")
    # The rays of the empty cells are the grid's: the grid in lidarshop's extension, no ray stored beside it.
    check_grid(s, rows, cols, "ours")
    check(extension_points(f, s) is None, "no lidarshop:noReturnDirections: every ray is the grid's")
    header, _ = info(e57_path, stats=False)
    stats, _ = info(e57_path)
    check(header["scans"][0]["points"] == n, f"info counts {header['scans'][0]['points']} points, decoder {n}")
    check(stats["scans"][0]["valid"] == n, f"info --stats: {stats['scans'][0]['valid']} returns, decoder {n}")


def check_pump(work):
    pump = os.path.join(SHARED, "e57", "pumpA.e57")
    copy = os.path.join(work, "pumpA.e57")
    check(run("convert", pump, copy, "--quiet").returncode == 0, "convert pumpA.e57 -> e57")
    a, b = dec.decode(pump).scans[0], dec.decode(copy)
    s = b.scans[0]
    valid = int(dec.valid_mask(a).sum())
    print(f"pumpA: {a['record_count']} records ({valid} valid) -> {s['record_count']} records")
    check(s["record_count"] == valid == 155201, "pumpA copy: one record per return")
    check_grid(s, 1074, 345, "pumpA copy")
    check(extension_points(b, s) is None, "pumpA copy: no ray in lidarshop:noReturnDirections")
    for axis in ("cartesianX", "cartesianY", "cartesianZ"):  # the same points (as float32), any order
        check(np.allclose(np.sort(a["fields"][axis][dec.valid_mask(a)]), np.sort(s["fields"][axis]),
                          atol=1e-6), f"pumpA copy: {axis} as in the original")
    header, _ = info(copy, stats=False)
    check(header["scans"][0]["points"] == 155201, "info counts pumpA's 155,201 points")
    # images --extract: the stored bytes, byte for byte, named after the stored format.
    folder = os.path.join(work, "images")
    for path in (pump, os.path.join(SHARED, "e57", "tiny_pc_and_images.e57")):
        r = run("images", path, "--extract", folder)
        if not check(r.returncode == 0, f"images --extract {path}: {r.stderr}"):
            continue
        listed = json.loads(r.stdout)["images"]
        stored = dec.decode(path).images
        for i, image in enumerate(listed):
            out = image.get("extracted")
            if not image["decoded"]:
                check(out is None, f"{path} image {i}: an undecodable blob is not extracted")
                continue
            want = ".jpg" if stored[i]["encoding"] == "jpeg" else ".png"
            check(out is not None and out.endswith(want), f"{path} image {i}: extracted as {want}: {out}")
            if out is not None:
                got = open(out, "rb").read()
                check(got == stored[i]["blob"], f"{path} image {i}: {len(got)} bytes extracted, blob has "
                      f"{len(stored[i]['blob'])}, equal: {got == stored[i]['blob']}")


def world_bounds(scan):
    mask = dec.valid_mask(scan)
    x, y, z = (v[mask] for v in dec.cartesian(scan))
    keep = (x != 0) | (y != 0) | (z != 0)  # our reader's rule: a point at the origin is no return
    if not keep.any():
        return None, 0
    wx, wy, wz = dec.world(scan, x[keep], y[keep], z[keep])
    return (np.array([wx.min(), wy.min(), wz.min()]), np.array([wx.max(), wy.max(), wz.max()])), int(keep.sum())


def check_interop(work):
    folder = os.path.join(SHARED, "interop", "e57")
    rows = []
    for name in sorted(os.listdir(folder)):
        path = os.path.join(folder, name)
        try:
            f = dec.decode(path)
            error = None
        except dec.E57Error as e:
            f, error = None, str(e)
        if error is not None:  # broken: refused, exit 1, one line naming the file
            r = run("info", "--stats", path)
            c = run("convert", path, os.path.join(work, "x.ply"), "--quiet")
            message = r.stderr.strip()
            ok = (r.returncode == 1 and c.returncode == 1 and name in message and len(message.split("\n")) == 1)
            check(ok, f"{name}: broken ({error}) must be refused with exit 1 naming the file: got "
                      f"{r.returncode} / {c.returncode}: {message}")
            rows.append((name, "-", "-", "refused: " + message.replace(path, name).replace("|", "/")))
            continue
        promised = sum(s["record_count"] for s in f.scans)
        expected = []
        for s in f.scans:
            bounds, count = world_bounds(s)
            expected.append((bounds, count))
        stats, r = info(path)
        if not check(stats is not None, f"{name}: info --stats: {r.stderr}"):
            rows.append((name, promised, "-", "info failed: " + r.stderr.strip()))
            continue
        read = sum(s.get("valid", 0) for s in stats["scans"])
        ok = check(read == sum(c for _, c in expected) == promised, f"{name}: {read} read, {promised} promised")
        for i, (bounds, count) in enumerate(expected):
            got = stats["scans"][i].get("bounds")
            if bounds is None:
                ok &= check(got is None, f"{name} scan {i}: no bounds expected")
                continue
            tolerance = 1e-5 + 1e-6 * np.abs(np.concatenate(bounds))  # float32 points, rounded JSON
            diff = np.abs(np.concatenate([np.array(got["min"]) - bounds[0], np.array(got["max"]) - bounds[1]]))
            ok &= check(np.all(diff <= tolerance), f"{name} scan {i}: bounds {got} vs decoder {bounds}")
        results = []
        for fmt in FORMATS:
            out = os.path.join(work, f"{os.path.splitext(name)[0]}.{fmt}")
            if promised == 0 and fmt != "e57":
                # A valid file without points (no data3D, a data3D of 0 records, photos only): only E57 holds
                # an empty scan; the other formats refuse with exit 1 and one line.
                c = run("convert", path, out, "--quiet")
                message = c.stderr.strip()
                ok &= check(c.returncode == 1 and len(message.split("\n")) == 1 and "to write" in message
                            and not os.path.exists(out), f"{name} -> {fmt}: exit {c.returncode}: {message}")
                continue
            # PCD holds one scan: a file of several is written scan by scan (--scan K).
            parts = [[]] if fmt != "pcd" or len(f.scans) < 2 else [["--scan", k] for k in range(len(f.scans))]
            n = 0
            for k, extra in enumerate(parts):
                part = out if not extra else out.replace(".pcd", f"_{k}.pcd")
                c = run("convert", path, part, "--quiet", *extra)
                if not check(c.returncode == 0, f"{name} -> {fmt} {extra}: {c.stderr.strip()}"):
                    n = None
                    break
                back, rb = info(part)
                if not check(back is not None, f"{name} -> {fmt}: info: {rb.stderr.strip()}"):
                    n = None
                    break
                n += sum(s.get("valid", 0) for s in back["scans"])
            ok &= check(n == promised, f"{name} -> {fmt}: {n} points read back, {promised} promised")
            if n != promised:
                results.append(f"{fmt}: {n}")
            elif len(parts) > 1:
                results.append(f"{fmt}: one file per scan")
        rows.append((name, promised, read,
                     ("ok: info --stats, bounds, " + ("E57 (the other formats refuse: no point to write)"
                                                       if promised == 0 else "all 7 formats")
                      if ok else "FAILED") +
                     (" (" + ", ".join(results) + ")" if results else "")))
    table = ["| file | points promised | points read | result |", "|---|---|---|---|"]
    table += [f"| {a} | {b} | {c} | {d} |" for a, b, c, d in rows]
    print("\n".join(table))
    if TABLE:
        open(TABLE, "w").write("\n".join(table) + "\n")


def main():
    with tempfile.TemporaryDirectory(prefix="lidarshop_e57_interop_") as work:
        check_our_file(work)
        check_pump(work)
        check_interop(work)
    if failures:
        print(f"{len(failures)} checks failed")
        return 1
    print("all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
