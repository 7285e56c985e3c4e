"""06 — Point-set tools and registration: the ground plane, the objects on it, a second scan aligned.

    PYTHONPATH=build/release/python python3 examples/06_points_and_registration.py
"""
import numpy as np

import lidarshop
from _common import mailbox_scene, parse_args

args = parse_args(__doc__)
scene = mailbox_scene(args.small)
scan = lidarshop.scan_scene(scene)
points = scan.points(world=True)  # (N, 3), world frame
print(f"{len(points)} points")

# The lawn is the largest plane: z = 0.
ground = lidarshop.fit_plane_ransac(points, distance_threshold_m=0.02, seed=1)
print(ground)
assert abs(abs(ground.normal[2]) - 1) < 0.01 and abs(ground.offset_m) < 0.02

# What stands on it, in clusters (the wall and the mailbox), after thinning and outlier removal.
above = np.ones(len(points), bool)
above[ground.inliers] = False
standing = lidarshop.voxel_downsample(points[above], 0.05)
standing = standing[lidarshop.statistical_outlier_inliers(standing, neighbors=10, std_ratio=3.0)]
clusters = lidarshop.euclidean_clusters(standing, radius_m=0.15, min_points=20)
print(f"{clusters.num_clusters} objects standing on the ground, sizes {sorted(clusters.sizes, reverse=True)}")
for label in range(clusters.num_clusters):
    members = standing[clusters.labels == label]
    low, high = members.min(axis=0), members.max(axis=0)
    print(f"  {label}: x {low[0]:+.2f}..{high[0]:+.2f}  y {low[1]:.2f}..{high[1]:.2f}  height {high[2]:.2f} m")
assert clusters.num_clusters >= 2

# A second scan from another position, with its pose off by 3 degrees and 10 cm (as from a rough GNSS /
# compass set-up); register_scans corrects it against the first.
scene["scanner"]["position"] = [-1.5, -0.5, 1.5]
second = lidarshop.scan_scene(scene)
error = np.eye(4)
a = np.radians(3)
error[:3, :3] = [[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]]
error[:3, 3] = [0.1, -0.05, 0.02]
rough = lidarshop.transform_scan(second, error)
registered, icp = lidarshop.register_scans(scan, rough, max_correspondence_m=0.5)
print(icp)
before = np.linalg.norm(rough.world_from_scanner[:3, 3] - second.world_from_scanner[:3, 3])
after = np.linalg.norm(registered.world_from_scanner[:3, 3] - second.world_from_scanner[:3, 3])
print(f"scanner position off by {before * 1000:.0f} mm before, {after * 1000:.1f} mm after registration")
assert after < 0.02
