"""02 — Cut an object out of a scan from a few strokes (graph cuts on colour + depth).

In the editor you paint the strokes; here they are drawn as polylines in grid coordinates ([col, row]).
    PYTHONPATH=build/release/python python3 examples/02_cut_out_an_object.py
"""
import os

import numpy as np

import lidarshop
from _common import mailbox_scene, parse_args

args = parse_args(__doc__)
scan = lidarshop.scan_scene(mailbox_scene(args.small))

# Where is the mailbox? (A synthetic scan knows its labels: 2 = mailbox.) Object strokes across the box and
# down its post; background strokes along the wall above it, the top of the scan and the lawn at the bottom.
rows, cols = np.nonzero(scan.label == 2)
r, c = int(np.median(rows)), int(np.median(cols))
top, bottom, left, right = int(rows.min()), int(rows.max()), int(cols.min()), int(cols.max())
width = right - left
strokes = {"strokes": [
    {"label": "object", "width": 3, "points": [[c - 2, r], [c + 2, r]]},
    {"label": "object", "width": 2, "points": [[c, top + 2], [c, bottom - 3]]},
    {"label": "background", "width": 2, "points": [[left - width, top - 4], [right + width, top - 4]]},
    {"label": "background", "width": 3, "points": [[5, 5], [scan.cols - 6, 5]]},
    {"label": "background", "width": 3, "points": [[5, scan.rows - 6], [scan.cols - 6, scan.rows - 6]]},
]}

options = lidarshop.SegmentOptions(method="two-step")
print(lidarshop.SegmentOptions.__doc__.splitlines()[0])
result = lidarshop.segment(scan, strokes, options)
print(result.summary())

mask = result.mask > 0
truth = scan.label == 2
iou = (mask & truth).sum() / (mask | truth).sum()
print(f"object cells {result.object_cells}, IoU against the truth {iou:.3f}")
assert iou > 0.9

# The object alone as an organized scan: every other cell has no return.
cutout = scan.clone()
cutout.valid = np.where(mask, cutout.valid, 0)
cutout.range = np.where(mask, cutout.range, 0)
cutout.point = np.where(mask[..., None], cutout.point, 0)
path = os.path.join(args.out, "mailbox_object.ply")
lidarshop.write_scan(cutout, path)
print("wrote", path, "with", cutout.count_valid(), "points")
