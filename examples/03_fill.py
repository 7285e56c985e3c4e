"""03 — Remove an object and fill the surface behind it (gradient-domain patches + Poisson).

    PYTHONPATH=build/release/python python3 examples/03_fill.py
"""
import os

import numpy as np

import lidarshop
from _common import mailbox_scene, parse_args

args = parse_args(__doc__)
scan = lidarshop.scan_scene(mailbox_scene(args.small))

# The hole: the mailbox's cells grown by 2 (mixed pixels at its silhouette belong to neither surface).
hole = lidarshop.grow_hole((scan.label == 2).astype(np.uint8), 2)

# Options are Python objects with the library's own docs, units and ranges.
options = lidarshop.FillOptions(patch_radius=4, method="gradient")
options.poisson.solver = "direct"
print(lidarshop.FillOptions.patch_radius.__doc__)
print(options.to_dict()["method"], options.poisson)

result = lidarshop.fill(scan, hole, options)
print(result.summary())
filled = result.scan
print(f"hole {result.hole_cells} cells: {result.synthesized_cells} synthesized, "
      f"{result.no_return_cells} without a return, {result.timings.total_s:.2f} s")

# Behind the mailbox there is wall and lawn: the filled ranges are farther than the mailbox was.
was_mailbox = (scan.label == 2) & (filled.synthesized > 0)
print(f"median range where the mailbox was: {np.median(scan.range[was_mailbox]):.2f} m -> "
      f"{np.median(filled.range[was_mailbox]):.2f} m")
assert np.median(filled.range[was_mailbox]) > np.median(scan.range[was_mailbox])

# Synthesized cells are flagged in the file too (E57 extension field lidarshop:synthesized).
path = os.path.join(args.out, "mailbox_filled.e57")
lidarshop.write_scan(filled, path)
print("wrote", path)

# The same in one call: strokes -> cut -> fill.
rows, cols = np.nonzero(scan.label == 2)
strokes = np.zeros((scan.rows, scan.cols), np.uint8)
strokes[int(np.median(rows)), int(np.median(cols))] = 1
strokes[:3, :] = 2
strokes[-3:, :] = 2
removed = lidarshop.remove_object(scan, strokes, lidarshop.RemoveOptions(margin_cells=2))
print("remove_object:", removed.cut.object_cells, "object cells,", removed.fill.synthesized_cells, "synthesized")
