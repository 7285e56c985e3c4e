#!/usr/bin/python3
"""Side by side: lidarshop `points` against Open3D (Debian python3-open3d 0.16) on one 1 M-point cloud.

Usage: /usr/bin/python3 bench/pointset_peers.py LIDARSHOP_BINARY WORK_DIR [POINTS]
Prints a markdown table: seconds of each tool (lidarshop: the operation alone, from its --json summary, without
reading and writing; Open3D: the call alone) and how well the answers agree. The cloud: a 40 m x 40 m ground
(5 mm noise), four boxes, 3 % uniform outliers, seeded.
"""
import json
import subprocess
import sys
import time

import numpy as np
import open3d as o3d

lidarshop, work = sys.argv[1], sys.argv[2]
count = int(sys.argv[3]) if len(sys.argv) > 3 else 1_000_000
rng = np.random.default_rng(17)


def make_cloud(n):
    n_out = int(0.03 * n)
    n_box = int(0.25 * n)
    n_ground = n - n_out - n_box
    ground = np.c_[rng.uniform(-20, 20, (n_ground, 2)), rng.normal(0, 0.005, n_ground)]
    boxes = []
    per = n_box // 4
    for b, (cx, cy) in enumerate([(-6, 5), (4, 8), (8, -5), (-5, -7)]):
        face = rng.integers(0, 5, per)  # 4 sides and the top of a 2 m cube
        u, v = rng.uniform(-1, 1, per), rng.uniform(0, 2, per)
        x = np.where(face == 0, -1, np.where(face == 1, 1, u))
        y = np.where(face == 2, -1, np.where(face == 3, 1, np.where(face < 2, u, rng.uniform(-1, 1, per))))
        z = np.where(face == 4, 2.0, v)
        x = np.where(face == 4, rng.uniform(-1, 1, per), x)
        boxes.append(np.c_[x + cx, y + cy, z])
    outliers = np.c_[rng.uniform(-20, 20, (n_out, 2)), rng.uniform(0, 6, n_out)]
    return np.vstack([ground] + boxes + [outliers])[:n].astype(np.float32)


def read_ply(path):
    """Binary little-endian PLY vertices as a structured numpy array (lidarshop's extra fields included)."""
    with open(path, "rb") as f:
        fields, n = [], 0
        types = {"float": "<f4", "double": "<f8", "int": "<i4", "uint": "<u4", "uchar": "u1", "short": "<i2",
                 "ushort": "<u2", "char": "i1", "int32": "<i4", "float32": "<f4", "uint8": "u1"}
        in_vertex = False
        while True:
            line = f.readline().decode().strip()
            if line.startswith("element"):
                in_vertex = line.split()[1] == "vertex"
                if in_vertex:
                    n = int(line.split()[2])
            elif line.startswith("property") and in_vertex:
                _, t, name = line.split()
                fields.append((name, types[t]))
            elif line == "end_header":
                break
        return np.frombuffer(f.read(np.dtype(fields).itemsize * n), dtype=np.dtype(fields), count=n)


def run(args):
    out = subprocess.run([lidarshop, "points"] + args + ["--json", "-"], check=True, capture_output=True, text=True)
    return json.loads(out.stdout)


def xyz(a):
    return np.ascontiguousarray(np.c_[a["x"], a["y"], a["z"]].astype(np.float32))


def key_set(points):
    return set(map(bytes, np.ascontiguousarray(points, dtype=np.float32)))


def jaccard(a, b):
    return len(a & b) / max(1, len(a | b))


points = make_cloud(count)
cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(points.astype(np.float64)))
path = f"{work}/cloud.ply"
o3d.io.write_point_cloud(path, o3d.geometry.PointCloud(o3d.utility.Vector3dVector(points.astype(np.float64))))
points = xyz(read_ply(path))  # exactly what both tools read
rows = []

# Normals from the 20 nearest points.
t = time.perf_counter()
cloud.estimate_normals(o3d.geometry.KDTreeSearchParamKNN(20))
o3d_s = time.perf_counter() - t
summary = run(["normals", path, "-o", f"{work}/normals.ply", "--neighbors", "20"])
ours = read_ply(f"{work}/normals.ply")
ours_n = np.c_[ours["nx"], ours["ny"], ours["nz"]]
o3d_n = np.asarray(cloud.normals)
angle = np.degrees(np.arccos(np.clip(np.abs(np.sum(ours_n * o3d_n, axis=1)), 0, 1)))
rows.append(("normals (k = 20)", summary["seconds"], o3d_s,
             f"angle to Open3D's: median {np.median(angle):.2g}°, {np.mean(angle < 1) * 100:.2f} % under 1°"))

# Statistical outlier removal, k = 20, 2 σ.
t = time.perf_counter()
_, kept = cloud.remove_statistical_outlier(20, 2.0)
o3d_s = time.perf_counter() - t
summary = run(["outliers", path, "-o", f"{work}/clean.ply", "--neighbors", "20", "--std-ratio", "2"])
ours_kept = key_set(xyz(read_ply(f"{work}/clean.ply")))
o3d_kept = key_set(points[np.asarray(kept)])
rows.append(("statistical outliers (k = 20, 2 σ)", summary["seconds"], o3d_s,
             f"kept {len(ours_kept)} vs {len(o3d_kept)}; Jaccard of the kept sets {jaccard(ours_kept, o3d_kept):.4f}"))

# RANSAC plane, 1 cm, 1000 hypotheses.
t = time.perf_counter()
plane, inliers = cloud.segment_plane(0.01, 3, 1000)
o3d_s = time.perf_counter() - t
summary = run(["planes", path, "-o", f"{work}/planes.ply", "--distance", "0.01", "--iterations", "1000"])
ours = read_ply(f"{work}/planes.ply")
ours_in = key_set(xyz(ours)[ours["label"] == 0])
o3d_in = key_set(points[np.asarray(inliers)])
n_ours = np.array(summary["planes"][0]["normal"])
plane_angle = np.degrees(np.arccos(min(1.0, abs(np.dot(n_ours, np.array(plane[:3]) / np.linalg.norm(plane[:3]))))))
rows.append(("RANSAC plane (1 cm, ≤ 1000 hypotheses)", summary["seconds"], o3d_s,
             f"normal angle {plane_angle:.3f}°; inliers {len(ours_in)} vs {len(o3d_in)}, Jaccard "
             f"{jaccard(ours_in, o3d_in):.4f}"))

# Euclidean clustering (ours) vs DBSCAN with min_points 1 (the same connected components).
t = time.perf_counter()
labels = np.asarray(cloud.cluster_dbscan(eps=0.1, min_points=1))
o3d_s = time.perf_counter() - t
summary = run(["cluster", path, "-o", f"{work}/clusters.ply", "--radius", "0.1"])
rows.append(("Euclidean clustering / DBSCAN min 1 (r = 10 cm)", summary["seconds"], o3d_s,
             f"{summary['clusters']} clusters vs {labels.max() + 1}; largest {summary['cluster_sizes'][0]} vs "
             f"{np.bincount(labels[labels >= 0]).max()}"))

# Voxel subsampling, 5 cm.
t = time.perf_counter()
down = cloud.voxel_down_sample(0.05)
o3d_s = time.perf_counter() - t
summary = run(["voxel", path, "-o", f"{work}/voxel.ply", "--voxel", "0.05"])
rows.append(("voxel subsampling (5 cm)", summary["seconds"], o3d_s,
             f"{summary['output_points']} vs {len(down.points)} points"))

# Poisson reconstruction: Open3D only (lidarshop has none yet).
t = time.perf_counter()
o3d.geometry.TriangleMesh.create_from_point_cloud_poisson(cloud, depth=8)
rows.append(("Poisson reconstruction (depth 8)", None, time.perf_counter() - t, "not in lidarshop yet"))

print(f"{len(points)} points\n")
print("| tool | lidarshop s | Open3D 0.16 s | agreement |")
print("|---|---|---|---|")
for name, ours_s, o3d_s, agreement in rows:
    ours_text = "—" if ours_s is None else f"{ours_s:.3f}"
    print(f"| {name} | {ours_text} | {o3d_s:.3f} | {agreement} |")
