"""05 — Colour a scan from a photo: pick pairs, find the camera, project with occlusion (thesis 3.2).

A photo taken beside the scanner sees the scene from elsewhere: some points the scanner measured are hidden
from the camera (behind the mailbox) and must keep their colour instead of taking the mailbox's.
    PYTHONPATH=build/release/python python3 examples/05_recolor_from_a_photo.py
"""
import os

import numpy as np

import lidarshop
from _common import mailbox_scene, parse_args

args = parse_args(__doc__)
scene = mailbox_scene(args.small)
scan = lidarshop.scan_scene(scene)

# The photo: a synthetic camera 1.2 m right of the scanner looking at the mailbox (a real one would come
# from read_image, or from read_e57_photos for the photos stored in an E57 file).
true_camera = lidarshop.camera_looking_at([1.2, 0.0, 1.3], [0.3, 3.2, 0.9], 640, 480, 60.0)
photo = lidarshop.render_photo(scene, true_camera)
lidarshop.write_image(os.path.join(args.out, "photo.png"), photo.image)

# Pairs "clicked" in the editor: a scan cell and the photo pixel showing the same point (here the true
# projection plus half a pixel of hand error), in the correspondence-file form (docs/recolor.md).
rng = np.random.default_rng(1)
rows, cols = np.nonzero(scan.valid > 0)
pick = rng.choice(len(rows), 400, replace=False)
pairs = []
for i in pick:
    world = scan.world_from_scanner @ np.append(scan.point[rows[i], cols[i]], 1.0)
    u, v = true_camera.project(world[None, :3])[0]
    if np.isfinite(u) and 0 < u < 640 and 0 < v < 480 and photo.label[int(v), int(u)] == scan.label[rows[i], cols[i]]:
        pairs.append({"pixel": [u + rng.normal(0, 0.5), v + rng.normal(0, 0.5)], "cell": [int(rows[i]), int(cols[i])]})
    if len(pairs) == 20:
        break
parsed = lidarshop.parse_correspondences({"pairs": pairs}, scan)
print(f"{len(pairs)} pairs ({parsed['kind']})")

# The camera from the pairs: DLT, RANSAC, then Levenberg-Marquardt.
result = lidarshop.resection(parsed["pixels"], parsed["points"], width_px=640, height_px=480)
print(result.summary())
error_m = np.linalg.norm(result.camera.center_in_world - true_camera.center_in_world)
print(f"camera centre off by {error_m * 1000:.1f} mm")
assert error_m < 0.1
lidarshop.write_camera(os.path.join(args.out, "camera.json"), result.camera)

# Recolour a grey copy: points the camera cannot see keep their grey.
grey = scan.clone()
grey.color = np.full((scan.rows, scan.cols, 3), 128, np.uint8)
coloured = lidarshop.recolor(grey, photo.image, result.camera)
print(coloured.summary())
lidarshop.write_scan(coloured.scan, os.path.join(args.out, "recolored.ply"))

# How often does a recoloured point take the colour of its own object? (The photo knows which object each
# pixel shows.) Without the occlusion test, wall points behind the mailbox would take the mailbox's colour.
took = coloured.recolored > 0
r, c = np.nonzero(took)
world = (scan.point[r, c].astype(np.float64) @ scan.world_from_scanner[:3, :3].T) + scan.world_from_scanner[:3, 3]
pixels = true_camera.project(world)
inside = np.all(np.isfinite(pixels), axis=1)
u = np.clip(pixels[inside, 0].astype(int), 0, 639)
v = np.clip(pixels[inside, 1].astype(int), 0, 479)
agree = (photo.label[v, u] == scan.label[r[inside], c[inside]]).mean()
print(f"recoloured {coloured.recolored_count} points, hidden {coloured.hidden}; "
      f"{agree:.1%} took the colour of their own object")
assert coloured.hidden > 0 and agree > 0.95
