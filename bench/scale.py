#!/usr/bin/env python3
"""The scaling benchmark of issue #34: every command of a session on the built-in parking lot at growing sizes.

    /usr/bin/python3 bench/scale.py [--sizes 1,4,16] [--work DIR] [--markdown FILE] [--binary PATH]

Sizes are in millions of rays (a square grid: 4 = 2000 x 2000). For each size the script scans the parking lot to
E57 and then runs, each as its own process under /usr/bin/time (wall seconds and peak resident memory):
`info --stats`, `render`, `segment` (two strokes made from the scanner's labels on the hatchback), `fill` (the same
200 x 200-cell hole at every size, centred on the hatchback), `remove` (the same strokes) and `convert` to LAS.
Then the editor (`--editor`, the default when web/dist is built and node and chromium are there): web/e2e/station.mjs
serves the station and opens it in Debian's chromium, and the table gives how long `serve` took to read it, the
first picture after page open and its bytes, the bytes of the whole opening (pictures and 3-D points up to the
refined level), the server's peak memory at the first picture, the first stroke -> cut -> picture and the first
picture after opening the station again in the running server.
The last table gives each command's cost exponent k (time ~ rays^k, a least-squares fit of log time on log rays
over the sizes run). The machine's CPU and load are printed with the results: read the times of one run as
ratios. A command that fails (the memory budget refusing it) is reported in the table with its message. Needs
the built CLI (build/release/lidarshop, or --binary) and its Python module (build/release/python); 100 M rays
need about 15 GB of memory for `remove` and about 7 GB of disk.
"""
import argparse
import json
import math
import os
import pathlib
import subprocess
import sys
import time

REPO = pathlib.Path(__file__).resolve().parent.parent
CLI = REPO / "build" / "release" / "lidarshop"
sys.path.insert(0, str(REPO / "build" / "release" / "python"))

TARGET_LABEL = 3  # the hatchback of data/scenes/parking_lot.json
HOLE_CELLS = 200  # the side of the fill's square hole, cells, at every size


def cpu_model():
    for line in pathlib.Path("/proc/cpuinfo").read_text().splitlines():
        if line.startswith("model name"):
            return line.split(":", 1)[1].strip()
    return "unknown"


def cpu_flags():
    for line in pathlib.Path("/proc/cpuinfo").read_text().splitlines():
        if line.startswith("flags"):
            flags = line.split(":", 1)[1].split()
            return "AVX-512" if "avx512f" in flags else ("AVX2" if "avx2" in flags else "no AVX2")
    return "unknown"


def timed(args, log, required=False):
    """Runs the command under /usr/bin/time; returns (wall seconds, peak resident MB, None), or with the reason
    in place of None when the command failed (a refusal by the memory budget is a result of the benchmark;
    `required` commands raise instead)."""
    stats = log.with_suffix(".time")
    command = ["/usr/bin/time", "-f", "%e %M", "-o", str(stats), str(CLI)] + [str(a) for a in args]
    with open(log, "w") as out:
        result = subprocess.run(command, stdout=out, stderr=subprocess.STDOUT)
    wall_s, peak_kb = stats.read_text().split()[-2:]
    if result.returncode != 0:
        if required:
            raise RuntimeError(f"{' '.join(command)} failed (exit {result.returncode}); see {log}")
        last = (log.read_text().strip().splitlines() or [""])[-1]
        return float(wall_s), float(peak_kb) / 1024.0, f"exit {result.returncode}: {last[:160]}"
    return float(wall_s), float(peak_kb) / 1024.0, None


def strokes_and_hole(labels_png, strokes_json, hole_png):
    """Two strokes from the labels (object: across the target's upper third; background: the row under it) and a
    HOLE_CELLS square hole centred on the target, in grid coordinates."""
    import numpy as np
    import lidarshop

    labels = np.asarray(lidarshop.read_image(str(labels_png)))
    rows, cols = np.nonzero(labels == TARGET_LABEL)
    if rows.size == 0:
        raise RuntimeError(f"{labels_png}: no cell of label {TARGET_LABEL}")
    top, bottom, left, right = (int(v) for v in (rows.min(), rows.max(), cols.min(), cols.max()))
    # Across the body, well inside it: a 3-cell-wide stroke along the roof line also paints the facade seen
    # above the car, which then belongs to the object.
    object_row = int(top + 0.6 * (bottom - top))
    on_object = np.nonzero(labels[object_row] == TARGET_LABEL)[0]
    quarter = (on_object.max() - on_object.min()) // 4
    background_row = min(int(bottom) + max(3, (bottom - top) // 10), labels.shape[0] - 1)
    strokes = [
        {"label": "object", "width": 3,
         "points": [[int(on_object.min() + quarter), object_row], [int(on_object.max() - quarter), object_row]]},
        {"label": "background", "width": 3,
         "points": [[int(left), background_row], [int(right), background_row]]},
    ]
    strokes_json.write_text(json.dumps({"strokes": strokes}))
    hole = np.zeros(labels.shape, dtype=np.uint8)
    centre_row, centre_col = int(rows.mean()), int(cols.mean())
    r0 = max(0, centre_row - HOLE_CELLS // 2)
    c0 = max(0, centre_col - HOLE_CELLS // 2)
    hole[r0:r0 + HOLE_CELLS, c0:c0 + HOLE_CELLS] = 255
    lidarshop.write_image(str(hole_png), hole)


def editor_missing():
    """Why the editor cannot be measured here, or None."""
    if not (REPO / "web" / "dist" / "index.html").exists():
        return "web/dist not built (cd web && npm ci && npm run build)"
    if not (REPO / "web" / "node_modules" / "playwright-core").exists():
        return "web/node_modules missing (cd web && npm ci)"
    if not pathlib.Path(os.environ.get("CHROMIUM", "/usr/bin/chromium")).exists():
        return "no chromium (apt-get install chromium)"
    return None


def run_editor(scan, folder):
    """web/e2e/station.mjs on the station: its JSON line (the numbers it measured), or {"failed": reason}."""
    log = folder / "editor.log"
    command = ["node", "e2e/station.mjs", str(CLI), str(folder / "editor"), "--station", str(scan)]
    with open(log, "w") as out:
        result = subprocess.run(command, cwd=REPO / "web", stdout=out, stderr=subprocess.STDOUT)
    lines = [line for line in log.read_text().splitlines() if line.startswith("e2e station: {")]
    if result.returncode != 0 or not lines:
        last = (log.read_text().strip().splitlines() or [""])[-1]
        return {"failed": f"exit {result.returncode}: {last[:160]}"}
    return json.loads(lines[-1][len("e2e station: "):])


def run_size(millions, work, editor):
    side = int(round(math.sqrt(millions * 1e6)))
    folder = work / f"{millions}M"
    folder.mkdir(parents=True, exist_ok=True)
    scan = folder / "scan.e57"
    row = {"rays": side * side, "side": side}
    budget = ["--max-memory", "20G"]
    row["scan"] = timed(["scan", "parking_lot", "--columns", side, "--rows", side, "-o", scan,
                         "--labels", folder / "labels.png", "-q"] + budget, folder / "scan.log", required=True)
    row["e57_mb"] = scan.stat().st_size / 1e6
    strokes, hole = folder / "strokes.json", folder / "hole.png"
    strokes_and_hole(folder / "labels.png", strokes, hole)
    row["info --stats"] = timed(["info", scan, "--stats", "--json", folder / "info.json", "-q"] + budget,
                                folder / "info.log")
    row["render"] = timed(["render", scan, "--channel", "rgb", "-o", folder / "render.png", "-q"] + budget,
                          folder / "render.log")
    row["segment"] = timed(["segment", scan, "--strokes", strokes, "-o", folder / "mask.png", "--overlay", "none",
                            "--json", folder / "segment.json", "-q"] + budget, folder / "segment.log")
    row["fill"] = timed(["fill", scan, "--mask", hole, "-o", folder / "filled.e57", "--json",
                         folder / "fill.json", "-q"] + budget, folder / "fill.log")
    row["remove"] = timed(["remove", scan, "--strokes", strokes, "-o", folder / "removed.e57", "--json",
                           folder / "remove.json", "-q"] + budget, folder / "remove.log")
    row["convert to LAS"] = timed(["convert", scan, folder / "scan.las", "-q"] + budget, folder / "convert.log")
    if editor:
        row["editor"] = run_editor(scan, folder)
    for name in ("filled.e57", "removed.e57", "scan.las"):
        (folder / name).unlink(missing_ok=True)
    return row


COMMANDS = ["scan", "info --stats", "render", "segment", "fill", "remove", "convert to LAS"]


def fit_exponent(rows, command):
    points = [(math.log(r["rays"]), math.log(max(r[command][0], 1e-3))) for r in rows if r[command][2] is None]
    if len(points) < 2:
        return float("nan")
    mean_x = sum(x for x, _ in points) / len(points)
    mean_y = sum(y for _, y in points) / len(points)
    sxx = sum((x - mean_x) ** 2 for x, _ in points)
    sxy = sum((x - mean_x) * (y - mean_y) for x, y in points)
    return sxy / sxx


def markdown(rows, load_before, load_after):
    lines = [f"Machine: {cpu_model()} ({cpu_flags()}), {os.cpu_count()} cores; load average "
             f"{load_before:.1f} before, {load_after:.1f} after.", "",
             "Wall seconds / peak resident MB of each command, each its own process:", ""]
    lines.append("| rays | grid | E57 MB | " + " | ".join(COMMANDS) + " |")
    lines.append("|---" * (3 + len(COMMANDS)) + "|")
    for r in rows:
        cells = [f"{r[c][0]:.2f} s / {r[c][1]:.0f} MB" + (f" (failed, {r[c][2]})" if r[c][2] else "")
                 for c in COMMANDS]
        lines.append(f"| {r['rays'] / 1e6:.0f} M | {r['side']} × {r['side']} | {r['e57_mb']:.0f} | "
                     + " | ".join(cells) + " |")
    lines += ["", "Peak memory per ray, bytes:", "", "| rays | " + " | ".join(COMMANDS) + " |",
              "|---" * (1 + len(COMMANDS)) + "|"]
    for r in rows:
        lines.append(f"| {r['rays'] / 1e6:.0f} M | "
                     + " | ".join(f"{r[c][1] * 1048576 / r['rays']:.0f}" for c in COMMANDS) + " |")
    lines += ["", "Cost exponent k (time ∝ rays^k, fitted over the sizes above):", "",
              "| " + " | ".join(COMMANDS) + " |", "|---" * len(COMMANDS) + "|",
              "| " + " | ".join(f"{fit_exponent(rows, c):.2f}" for c in COMMANDS) + " |"]
    if any("editor" in r for r in rows):
        lines += editor_markdown(rows)
    return "\n".join(lines) + "\n"


def seconds(value):
    return "–" if value is None else f"{value:.2f} s"


def editor_markdown(rows):
    lines = ["", "The editor (web/e2e/station.mjs: `serve STATION`, the page opened in chromium):", "",
             "| rays | serve reads | first picture | its bytes | opening's bytes (refined points) | points held "
             "/ budget | serve's peak at the first picture | stroke -> cut -> picture | opened again: read, "
             "first picture |", "|---" * 9 + "|"]
    for r in rows:
        e = r.get("editor")
        if e is None:
            continue
        if "failed" in e:
            lines.append(f"| {r['rays'] / 1e6:.0f} M | failed: {e['failed']} |" + " |" * 7)
            continue
        cut = next((x for x in e.get("edits", []) if "first cut" in x.get("what", "")), {})
        peak = e.get("first_picture_serve_peak_kib")
        lines.append(
            f"| {r['rays'] / 1e6:.0f} M | {e['serve_read_s']:.2f} s | {e['first_picture_s']:.2f} s | "
            f"{e['first_picture_bytes']:,} B | {e['open_bytes']:,} B | {e['points_held']:,} / {e['point_budget']:,} | "
            + (f"{peak / 1024:.0f} MB ({peak * 1024 / r['rays']:.0f} bytes a ray)" if peak else "–")
            + f" | {seconds(cut.get('picture_s'))} | {e['reopen_read_s']:.2f} s, "
            f"{e['reopen_first_picture_s']:.2f} s |")
    return lines


def main():
    global CLI
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sizes", default="1,4,16", help="millions of rays, comma-separated (default 1,4,16)")
    parser.add_argument("--work", default="/tmp/lidarshop_scale", help="working folder (large files)")
    parser.add_argument("--markdown", help="also write the tables to this file")
    parser.add_argument("--editor", choices=["auto", "yes", "no"], default="auto",
                        help="measure the editor with web/e2e/station.mjs (auto: when it can run here)")
    parser.add_argument("--binary", default=str(CLI),
                        help="the lidarshop executable to measure (default build/release/lidarshop)")
    args = parser.parse_args()
    CLI = pathlib.Path(args.binary)
    if not CLI.exists():
        sys.exit(f"{CLI} not found: build it first (bash scripts/build.sh)")
    missing = editor_missing()
    if args.editor == "yes" and missing:
        sys.exit(f"scale: the editor cannot be measured: {missing}")
    editor = args.editor == "yes" or (args.editor == "auto" and missing is None)
    if not editor:
        print(f"scale: the editor is not measured ({missing or '--editor no'})", file=sys.stderr)
    work = pathlib.Path(args.work)
    load_before = os.getloadavg()[0]
    rows = []
    for size in args.sizes.split(","):
        started = time.time()
        rows.append(run_size(int(size), work, editor))
        print(f"scale: {size} M rays done in {time.time() - started:.0f} s", file=sys.stderr)
    text = markdown(rows, load_before, os.getloadavg()[0])
    print(text)
    if args.markdown:
        pathlib.Path(args.markdown).write_text(text)


if __name__ == "__main__":
    main()
