"""04 — Verify an object pose against a scan: consistency and confidence (thesis ch. 4).

A detector proposes "a mailbox is here"; the scan says whether that can be (no measured point behind the
model's surface) and how much of it was seen.
    PYTHONPATH=build/release/python python3 examples/04_verify_a_pose.py
"""
import numpy as np

import lidarshop
from _common import mailbox_scene, parse_args

args = parse_args(__doc__)
scene = mailbox_scene(args.small)
scan = lidarshop.scan_scene(scene)

model = lidarshop.make_primitive("mailbox")  # the model in its own frame (or lidarshop.read_mesh("m.obj"))
print(model)
x, y, z = next(o for o in scene["objects"] if o["name"] == "mailbox")["translate"]

print(f"{'pose':>24} {'consistency':>12} {'confidence':>11}")
results = {}
for name, dx, dy, yaw in [("true", 0, 0, 0), ("10 cm right", 0.1, 0, 0), ("turned 90 deg", 0, 0, 90),
                          ("1 m nearer", 0, -1.0, 0), ("behind the wall", 0, 4.0, 0)]:
    pose = lidarshop.pose_from_xyz_yaw(x + dx, y + dy, z, yaw)
    result = lidarshop.verify_pose(model, scan, pose, allowance_m=0.05, sigma_m=0.02)
    results[name] = result
    print(f"{name:>24} {result.consistency:12.3f} {result.confidence:11.3f}")

# The true pose is consistent and well seen; a pose in front of what was measured is inconsistent (the rays
# went through it), and one hidden behind the wall was not seen at all.
assert results["true"].consistency > 0.95
assert results["1 m nearer"].consistency < results["true"].consistency
assert results["behind the wall"].confidence < results["true"].confidence
