"""01 — Scan a synthetic scene and look at the scan as numpy arrays.

    PYTHONPATH=build/release/python python3 examples/01_scan_a_scene.py --out /tmp/lidarshop_examples
"""
import os

import numpy as np

import lidarshop
from _common import mailbox_scene, parse_args

args = parse_args(__doc__)

# A scene is a scene file's path, a dict of the same form, or a built-in scene's name.
print("built-in scenes:", lidarshop.builtin_scenes())
scene = mailbox_scene(args.small)
scan = lidarshop.scan_scene(scene)
print(scan)

# Every channel is an array of the grid's shape, row 0 = the top of the scan, no copy.
valid = scan.valid > 0
print(f"grid {scan.rows} x {scan.cols}, {valid.mean():.1%} of the rays returned")
print(f"range {scan.range[valid].min():.2f} .. {scan.range[valid].max():.2f} m")
for label in np.unique(scan.label[valid]):
    print(f"  label {label}: {np.count_nonzero(scan.label == label)} cells")
print("scanner position in the world:", scan.world_from_scanner[:3, 3])

# Points in the world frame, and the scan written to a file (the format follows the extension).
points = scan.points(world=True)
print("points:", points.shape, "highest z", points[:, 2].max().round(2))
path = os.path.join(args.out, "mailbox.e57")
lidarshop.write_scan(scan, path)
again = lidarshop.read_scan(path)
assert np.array_equal(again.valid, scan.valid)
print("wrote", path)
