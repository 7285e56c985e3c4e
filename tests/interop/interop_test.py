#!/usr/bin/python3
"""Other tools' files through lidarshop: every file of ../shared/data/interop/ (written by PDAL and libE57Format).

  interop_test.py LIDARSHOP DATA_DIR [--table OUT.md]

For each valid file: `info --stats` opens it with the point count the file promises, read here independently
(las_reference.py from the LAS specification, the E57 XML section, PLY/PCD headers, PTS/XYZ lines); `convert`
writes it to every format; the coordinates that come back (through LAS, or XYZ for the other formats) equal an
independent reading of the file to its own resolution, and LAS -> LAS keeps every standard attribute. Each
broken file is refused with exit 1 and a message naming the file. Prints one line per file and the plain
summary line 'N passed, N failed'; --table writes the Markdown table (docs/results/formats/interop.md).
"""
import argparse
import json
import os
import re
import struct
import xml.etree.ElementTree as ET
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from las_reference import read_las  # noqa: E402

TARGETS = ["ptx", "e57", "ply", "pcd", "las", "xyz", "pts"]

# Broken files: refused with exit 1, the message naming the file and containing one of these words.
BROKEN = {
    "e57/libe57_bad-crc.e57": ["CRC", "checksum"],
    "e57/libe57_InvalidCVHeader.e57": ["header", "CompressedVector", "section"],
    # fileOffset 0: the points' section would be the file header (libE57Format's own test expects a throw).
    # libe57_empty.e57 is valid: no data3D, every checksum right (libE57Format opens it: 0 scans, docs/e57.md).
    "e57/libe57_ZeroPointsInvalid.e57": ["section", "compressed vector"],
    "las/1.2-no-points.las": ["truncated"],
    "las/1.2-with-color-clipped.las": ["truncated"],
    "las/garbage_nVariableLength.las": ["truncated"],
    "pcd/missingheader.pcd": ["header", "FIELDS", "VERSION", "DATA"],
    "ply/no_vertex.ply": ["vertex"],
}
# LAZ files and their uncompressed twins (SOURCES.md): the same records, so LAZ -> LAS must give the twin's
# coordinates and attributes. The COPC file holds its twin's points in another order and format: counted only.
LAZ_TWINS = {
    "laz/simple.laz": "las/simple.las",
    "laz/laszip-generated.laz": "las/simple.las",
    "laz/laszip-generated_with2bytespadding.laz": "las/simple.las",
    "laz/liblas-generated.laz": "las/simple.las",
    "laz/simple-laszip-compressor-version-1.2r0.laz": "las/simple.las",
    "laz/autzen_trim.laz": "las/autzen_trim.las",
}
# Valid files lidarshop refuses by design, with the words its message must contain: a z of 1.2 million km
# (PDAL's test of huge values) is past the 10^7 m every reader accepts (hostile-input rule, docs/file-formats.md).
REFUSED_BY_DESIGN = {
    "ply/issue_2421.ply": ["is not a coordinate within 10000000 m"],
}
LAS_ATTRIBUTES = ["return_number", "number_of_returns", "classification", "synthetic", "key_point", "withheld",
                  "overlap", "scan_direction_flag", "edge_of_flight_line", "user_data", "point_source_id",
                  "scan_angle_deg", "gps_time", "rgb", "nir", "intensity"]


def run(args, **kwargs):
    return subprocess.run(args, capture_output=True, text=True, timeout=300, **kwargs)


# ---- independent readings -------------------------------------------------------------------------------

def e57_xml(path):
    """The XML section of an E57 file, its 1024-byte pages' 4-byte CRCs stripped (ASTM E2807 5.2)."""
    data = open(path, "rb").read()
    if len(data) < 48 or data[:8] != b"ASTM-E57":
        raise ValueError("not E57")
    _, _, _, xml_offset, xml_length, page = struct.unpack_from("<IIQQQQ", data, 8)
    logical = bytearray()
    page = page or 1024
    pos = xml_offset
    while len(logical) < xml_length + (xml_offset % page):
        start = pos - pos % page
        logical += data[start:start + page - 4]
        pos = start + page
    skip = xml_offset % page
    return bytes(logical[skip:skip + xml_length]).decode("utf-8", "replace")


def promised_points(rel, path):
    ext = rel.rsplit(".", 1)[-1]
    if rel.endswith(".laz"):
        data = open(path, "rb").read(375)
        count = struct.unpack_from("<I", data, 107)[0]
        if data[25] >= 4 and len(data) >= 255 and struct.unpack_from("<Q", data, 247)[0]:
            count = struct.unpack_from("<Q", data, 247)[0]
        return count
    if ext == "las":
        return read_las(path)["count"]
    if ext == "e57":
        # The recordCount of each data3D entry's `points` only: other CompressedVectors (libE57Format's
        # pointGroupingSchemes groups, extensions) hold no points.
        root = ET.fromstring(e57_xml(path))
        ns = "{http://www.astm.org/COMMIT/E57/2010-e57-v1.0}"
        return sum(int(entry.find(ns + "points").get("recordCount"))
                   for entry in root.iterfind(f"{ns}data3D/{ns}vectorChild"))
    if ext in ("xyz", "pts"):
        return len(text_points(path, ext))
    if ext == "ply":
        head = open(path, "rb").read(4096).split(b"end_header")[0].decode("latin-1")
        found = re.search(r"element vertex (\d+)", head)
        return int(found.group(1)) if found else 0
    if ext == "pcd":
        head = open(path, "rb").read(4096).decode("latin-1")
        return int(re.search(r"^POINTS (\d+)", head, re.M).group(1))
    if ext == "ptx":
        return sum(r * c for r, c, _ in ptx_scans(path))
    raise ValueError(ext)


def text_points(path, ext):
    """Points of an XYZ / PTS file: lines of at least three numbers (a PTS count line has one)."""
    points = []
    for line in open(path, encoding="latin-1"):
        fields = line.replace(",", " ").split()
        if len(fields) < 3 or line.lstrip().startswith(("#", "//")):
            continue
        try:
            points.append([float(f) for f in fields[:3]])
        except ValueError:
            continue
    return np.array(points, dtype=np.float64).reshape(-1, 3)


def ptx_scans(path):
    """(rows, cols, world points with a return) of each scan of a PTX file."""
    lines = open(path, encoding="latin-1").read().split("\n")
    i, scans = 0, []
    while i < len(lines) and lines[i].strip():
        cols, rows = int(lines[i]), int(lines[i + 1])
        m = np.array([[float(v) for v in lines[i + 6 + k].split()] for k in range(4)])
        pts = np.array([[float(v) for v in lines[i + 10 + k].split()[:3]] for k in range(rows * cols)])
        # PTX runs column by column, bottom to top; lidarshop writes clouds row by row from the top row.
        pts = pts[[c * rows + (rows - 1 - r) for r in range(rows) for c in range(cols)]]
        ret = pts[np.any(pts != 0, axis=1)]
        world = ret @ m[:3, :3] + m[3, :3]  # PTX: row vectors times the matrix, translation in the last row
        scans.append((rows, cols, world))
        i += 10 + rows * cols
    return scans


def reference_points(rel, path, warned):
    """World coordinates and their tolerance from an independent reading, or None where none is written."""
    ext = rel.rsplit(".", 1)[-1]
    if ext == "las":
        r = read_las(path)
        return r["xyz"], las_tolerance(r, warned) + 1e-12
    if ext in ("xyz", "pts"):
        pts = text_points(path, ext)
        return pts, text_tolerance(path, pts)
    if ext == "ptx":
        pts = np.concatenate([w for _, _, w in ptx_scans(path)])
        # A rotation printed to 6 decimals is not a rotation: the reader takes the nearest one, which moves
        # points by micrometres (complex-transform.ptx: 4.6e-6 m).
        return pts, max(text_tolerance(path, pts), 1e-5)
    return None


def text_tolerance(path, pts):
    """Half the step a text file prints, or the float step over half the cloud's extent where that is coarser:
    lidarshop holds points as float relative to a local origin (a PTX of georeferenced points 4.6 km wide
    keeps 0.12 mm, not the micrometres it prints)."""
    decimals = max((len(t.split(".")[1]) for t in open(path, encoding="latin-1").read().split()[:200]
                    if "." in t and t.replace(".", "").replace("-", "").isdigit()), default=0)
    half_extent = float((pts.max(0) - pts.min(0)).max()) / 2 if len(pts) else 0.0
    return max(0.5 * 10 ** -decimals, float_step(half_extent)) + 1e-12


def xyz_of_output(path):
    return text_points(path, "xyz")


def same_points(a, b, tol):
    """Point by point, in order: unorganized files keep their order, organized ones are compared in lidarshop's
    row-major order of the returns."""
    if a.shape != b.shape:
        return f"{len(b)} points, expected {len(a)}"
    worst = float(np.abs(a - b).max()) if len(a) else 0.0
    return None if worst <= tol else f"coordinates differ by {worst:.3g} (tolerance {tol:.3g})"


def float_step(value):
    """The spacing of float32 numbers at magnitude `value`."""
    return float(np.spacing(np.float32(abs(value))))


def las_tolerance(r, warned):
    """Half the file's step; where lidarshop warned that float cannot keep the step over the cloud's extent
    (it holds points as float relative to the cloud's centre), half the float step it said it keeps."""
    tolerance = max(r["scale"]) / 2 + 1e-12
    if warned and r["count"]:
        half_extent = float((r["xyz"].max(0) - r["xyz"].min(0)).max()) / 2
        tolerance = max(tolerance, float_step(half_extent))
    return tolerance


def compare_las(original, written, warned):
    """LAS -> LAS: the same coordinates (to the source's step) and every standard attribute."""
    a, b = read_las(original), read_las(written)
    problems = []
    if a["count"] != b["count"]:
        return [f"{b['count']} points written, {a['count']} read"]
    err = same_points(a["xyz"], b["xyz"], las_tolerance(a, warned))
    if err:
        problems.append(err)
    for name in LAS_ATTRIBUTES:
        if name not in a or a[name] is None:
            continue
        if name not in b:
            problems.append(f"{name} not written")
            continue
        va, vb = np.asarray(a[name]), np.asarray(b[name])
        if name == "scan_angle_deg":
            ok = np.allclose(va, vb, atol=0.5 if b["format"] <= 5 or a["format"] <= 5 else 0.003)
        elif name == "gps_time":
            ok = np.array_equal(va, vb, equal_nan=True)
        else:
            ok = np.array_equal(va, vb)
        if not ok:
            problems.append(f"{name} differs")
    if a["extra_bytes"] is not None and (b["extra_bytes"] is None or
                                          not np.array_equal(a["extra_bytes"], b["extra_bytes"])):
        problems.append("extra bytes differ")
    crs = [(u, i) for u, i, _ in a["vlrs"] if u == "LASF_Projection"]
    kept = [(u, i) for u, i, _ in b["vlrs"] if u == "LASF_Projection"]
    if crs != kept:
        problems.append(f"CRS records {crs} written as {kept}")
    return problems


# ---- the run ----------------------------------------------------------------------------------------------

def check_file(lidarshop, rel, path, out_dir):
    row = {"file": rel, "result": "ok", "notes": []}
    ext = rel.rsplit(".", 1)[-1]
    info = run([lidarshop, "info", "--stats", "--json", "-", path])
    if rel in BROKEN or rel in REFUSED_BY_DESIGN:
        words = BROKEN.get(rel) or REFUSED_BY_DESIGN[rel]
        message = info.stderr.strip().splitlines()[-1] if info.stderr.strip() else ""
        row["read"] = "refused"
        row["notes"].append(message.replace(path, os.path.basename(path))[:160])
        if info.returncode != 1:
            row["result"] = f"FAIL: exit {info.returncode}, expected a refusal"
        elif path not in info.stderr:
            row["result"] = "FAIL: the message does not name the file"
        elif not any(w.lower() in info.stderr.lower() for w in words):
            row["result"] = f"FAIL: the message says none of {words}"
        return row
    try:
        promised = promised_points(rel, path)
    except Exception as error:  # the independent reading failed: the test's own problem, say so
        row["result"] = f"FAIL: independent reading: {error}"
        return row
    row["promised"] = promised
    if info.returncode != 0:
        row["result"] = "FAIL: info --stats: " + info.stderr.strip().splitlines()[-1][:200]
        return row
    stats = json.loads(info.stdout)
    warned = "coarser than the file's step" in info.stderr
    if warned:
        row["notes"].append("warned: float keeps less than the file's step over this extent")
    scans = stats["scans"]
    read = sum(s.get("points") if ext == "e57" else (s["cells"] if ext == "ptx" else s["valid"]) for s in scans)
    row["read"] = read
    if read != promised:
        row["result"] = f"FAIL: {read} points read, the file promises {promised}"
    several = len(scans) > 1
    row["convert"] = {}
    for target in TARGETS:
        out = os.path.join(out_dir, f"{os.path.basename(rel)}.{target}")
        args = [lidarshop, "convert", "--quiet", path, out]
        if target == "pcd" and several:
            args += ["--scan", "0"]
        result = run(args)
        if result.returncode != 0 and promised == 0 and ("no point" in result.stderr or "no scan" in result.stderr):
            row["convert"][target] = "nothing to write"
            continue
        if result.returncode != 0:
            row["convert"][target] = "refused"
            row["result"] = f"FAIL: convert to {target}: " + result.stderr.strip().splitlines()[-1][:200]
            continue
        warnings = [w for w in result.stderr.splitlines() if "warning" in w]
        row["convert"][target] = f"ok ({len(warnings)} warnings)" if warnings else "ok"
    # Coordinates (and LAS attributes) against the independent reading (LAZ: of the uncompressed twin).
    twin = os.path.join(os.path.dirname(os.path.dirname(path)), LAZ_TWINS[rel]) if rel in LAZ_TWINS else None
    if (ext == "las" or twin) and promised > 0:
        problems = compare_las(twin or path, os.path.join(out_dir, f"{os.path.basename(rel)}.las"), warned)
        source = "LAZ -> LAS (against the uncompressed twin)" if twin else "LAS -> LAS"
        if problems:
            row["result"] = f"FAIL: {source}: " + "; ".join(problems)
        else:
            row["notes"].append(f"{source}: coordinates and every attribute equal")
    reference = None
    try:
        reference = (reference_points(LAZ_TWINS[rel], twin, warned) if twin else
                     reference_points(rel, path, warned) if promised > 0 else None)
    except Exception as error:
        row["notes"].append(f"no independent coordinates: {error}")
    if reference is not None and not several and row["convert"].get("xyz", "").startswith("ok"):
        points, tol = reference
        err = same_points(points, xyz_of_output(os.path.join(out_dir, f"{os.path.basename(rel)}.xyz")), tol)
        if err:
            row["result"] = "FAIL: through XYZ: " + err
        else:
            row["notes"].append(f"XYZ coordinates within {tol:.2g}")
    return row


def hostile_variants(lidarshop, rel, path, out_dir):
    """Damaged copies of a valid file (cut in half, 16 bytes flipped with a fixed seed, the first 64 bytes
    zeroed): `info --stats` either reads them or refuses them with exit 1 and one line naming the file —
    never a crash, a hang or a second line from a library."""
    data = open(path, "rb").read()
    rng = np.random.default_rng(sum(rel.encode()))  # a fixed seed per file
    flipped = bytearray(data)
    for at in rng.integers(0, len(data), size=16):
        flipped[at] ^= 0xFF
    zeroed = bytes(64) + data[64:]
    problems = []
    base = os.path.basename(rel)
    for name, variant in (("half", data[:len(data) // 2]), ("flipped", bytes(flipped)), ("zeroed", zeroed)):
        variant_path = os.path.join(out_dir, f"{name}_{base}")
        with open(variant_path, "wb") as f:
            f.write(variant)
        try:
            result = run(["prlimit", "--as=4000000000", "--", lidarshop, "info", "--stats", "--max-memory",
                          "1G", "--json", os.devnull, variant_path])
        except subprocess.TimeoutExpired:
            problems.append(f"{name}: hang")
            continue
        errors = [line for line in result.stderr.splitlines() if "warning" not in line]
        if result.returncode not in (0, 1):
            problems.append(f"{name}: exit {result.returncode}")
        elif result.returncode == 1 and (len(errors) != 1 or variant_path not in errors[0]):
            problems.append(f"{name}: the error is not one line naming the file: {errors[:2]}")
    return problems



def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("lidarshop")
    parser.add_argument("data")
    parser.add_argument("--table")
    parser.add_argument("--only", help="a substring of the files to run")
    args = parser.parse_args()
    root = os.path.join(args.data, "interop")
    if not os.path.isdir(root):
        print(f"interop_test: {root} is missing (the shared data must lie beside the checkout)")
        return 1
    files = sorted(os.path.relpath(os.path.join(d, f), root) for d, _, fs in os.walk(root) for f in fs)
    files = [f for f in files if not args.only or args.only in f]
    rows = []
    with tempfile.TemporaryDirectory() as out_dir:
        for rel in files:
            row = check_file(args.lidarshop, rel, os.path.join(root, rel), out_dir)
            damaged = hostile_variants(args.lidarshop, rel, os.path.join(root, rel), out_dir)
            if damaged:
                row["result"] = "FAIL: damaged copies: " + "; ".join(damaged) if row["result"] == "ok" \
                    else row["result"] + "; damaged copies: " + "; ".join(damaged)
            else:
                row["notes"].append("3 damaged copies read or refused cleanly")
            rows.append(row)
            print(f"{rel}: {row['result']}" + (f" ({'; '.join(row['notes'])})" if row["notes"] else ""),
                  flush=True)
    failed = sum(not r["result"].startswith("ok") for r in rows)
    if args.table:
        write_table(rows, args.table)
    print(f"{len(rows) - failed} passed, {failed} failed")
    return 1 if failed else 0


def write_table(rows, path):
    lines = ["# Other tools' files through lidarshop", "",
             "Every file of `../shared/data/interop/` (PDAL's and libE57Format's test data) through "
             "`lidarshop info --stats` and `convert` to every format, checked against an independent reading "
             "(`tests/interop/interop_test.py`, run by ctest as `interop_test`; regenerate with "
             "`/usr/bin/python3 tests/interop/interop_test.py build/release/lidarshop ../shared/data "
             "--table docs/results/formats/interop.md`).", "",
             "| file | promised | read | " + " | ".join(TARGETS) + " | result | notes |",
             "|---|---|---|" + "---|" * len(TARGETS) + "---|---|"]
    for r in rows:
        conv = r.get("convert", {})
        lines.append("| `{}` | {} | {} | {} | {} | {} |".format(
            r["file"], r.get("promised", "—"), r.get("read", "—"),
            " | ".join(conv.get(t, "—") for t in TARGETS), r["result"].replace("|", "/"),
            "; ".join(r["notes"]).replace("|", "/")))
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write("\n".join(lines) + "\n")
    os.replace(tmp, path)


if __name__ == "__main__":
    sys.exit(main())
