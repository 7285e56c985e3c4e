#!/usr/bin/env python3
"""Smoke run of the evaluations on random scenes (the ctest `random_eval_smoke_test`).

Runs `segment_eval --random-seeds` and `fill_eval --random-seeds` on a few small random scenes
(scanner/random_scene.h) and checks their reports: one row per seed with the target, numbers in their ranges
(IoU in [0, 1], RMSE >= 0, floating share in [0, 100] %), and a distribution table whose mean lies between its
5th and 95th percentile bounds and whose worst seed is one of the rows. The numbers themselves are measured, not
asserted: docs/results/random_scenes.md has them for seeds 1..100.
Usage: python3 tests/random_eval_smoke_test.py SEGMENT_EVAL FILL_EVAL
"""
import os
import re
import subprocess
import sys
import tempfile

SEEDS = (1, 5)  # seeds 1..5
SIZE = ("--random-columns", "240", "--random-rows", "180")


def table_rows(text, header_start):
    """The data rows (lists of cells) of the markdown table whose header starts with `header_start`."""
    lines = text.splitlines()
    for i, line in enumerate(lines):
        if line.startswith(header_start):
            rows = []
            for row in lines[i + 2:]:
                if not row.startswith("|"):
                    break
                rows.append([c.strip() for c in row.strip().strip("|").split("|")])
            return rows
    raise AssertionError(f"no table starting with {header_start!r} in the report:\n{text}")


def run(program, out_dir, name):
    path = os.path.join(out_dir, name + ".md")
    args = [program, "--random-seeds", f"{SEEDS[0]}..{SEEDS[1]}", *SIZE, "--markdown", path]
    done = subprocess.run(args, capture_output=True, text=True, timeout=120)
    if done.returncode != 0:
        raise AssertionError(f"{' '.join(args)} failed ({done.returncode}):\n{done.stdout}\n{done.stderr}")
    with open(path, encoding="utf-8") as f:
        return f.read()


def check_rows(rows, columns, ranges):
    seeds = list(range(SEEDS[0], SEEDS[1] + 1))
    assert [int(r[0]) for r in rows] == seeds, f"rows are not one per seed {seeds}: {rows}"
    for row in rows:
        assert len(row) == columns, row
        assert re.fullmatch(r"[a-z_]+( \*)?", row[1]), f"target kind {row[1]!r}"
        for index, (lo, hi) in ranges.items():
            value = float(row[index])
            assert lo <= value <= hi, f"seed {row[0]}: column {index} = {value} outside [{lo}, {hi}]"


def main():
    if len(sys.argv) != 3:
        print(__doc__)
        return 2
    segment_eval, fill_eval = sys.argv[1:]
    seeds = set(range(SEEDS[0], SEEDS[1] + 1))
    with tempfile.TemporaryDirectory() as out_dir:
        segment = run(segment_eval, out_dir, "segment")
        rows = table_rows(segment, "| seed | target |")
        check_rows(rows, 7, {2: (0.1, 1000), 3: (1, 1e6), 4: (0, 1), 5: (0, 1), 6: (0, 600)})
        dist = table_rows(segment, "| method | mean IoU |")
        assert [r[0] for r in dist] == ["two-step", "grabcut"], dist
        for r in dist:
            mean, p5 = float(r[1]), float(r[2])
            worst, seed = re.fullmatch(r"([0-9.]+) \((\d+)\)", r[3]).groups()
            assert int(seed) in seeds and float(worst) <= p5 + 1e-9 <= mean + 1e-3, r
            assert abs(float(worst) - min(float(x[4 if r[0] == "two-step" else 5]) for x in rows)) < 1e-3, r

        fill = run(fill_eval, out_dir, "fill")
        rows = table_rows(fill, "| seed | target |")
        check_rows(rows, 10, {2: (0.1, 1000), 3: (1, 1e6), 4: (0, 1e6), 5: (0, 1e6), 6: (0, 1e6),
                              7: (0, 100), 8: (0, 100), 9: (0, 600)})
        dist = table_rows(fill, "| measure (lower is better) |")
        assert len(dist) == 5, dist
        for r in dist:
            mean, p5, p95 = float(r[1]), float(r[2]), float(r[3])
            worst, seed = re.fullmatch(r"([0-9.]+) \((\d+)\)", r[4]).groups()
            assert int(seed) in seeds, r
            assert p5 <= mean + 0.01 and mean <= p95 + 0.01 and p95 <= float(worst) + 0.01, r
    print(f"random_eval_smoke_test: segment_eval and fill_eval reports on seeds {SEEDS[0]}..{SEEDS[1]} are sane")
    return 0


if __name__ == "__main__":
    sys.exit(main())
