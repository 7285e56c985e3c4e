#!/usr/bin/python3
"""Side by side: lidarshop `points` against Open3D (Debian python3-open3d 0.16) and PCL 1.13 on one 1 M-point
cloud.

Usage: /usr/bin/python3 bench/pointset_peers.py LIDARSHOP_BINARY WORK_DIR [POINTS] [--pcl build/release/bench/pcl_peers]
Prints a markdown table: seconds of each tool (lidarshop: the operation alone, from its --json summary, without
reading and writing; Open3D: the call alone; PCL: the calls alone, timed inside bench/pcl_peers.cc) and how well
the answers agree. The cloud: a 40 m x 40 m ground (5 mm noise), four boxes, 3 % uniform outliers, seeded.
Poisson runs on a closed surface instead (a torus, POINTS / 20 points, at most 50 k, 1 mm noise, exact normals):
the scene is open and Poisson closes every surface; the agreement is each mesh's distance to the true torus.
Without --pcl (PCL not installed: bench/pcl_peers is built only when CMake finds PCL) the PCL column is left out.
"""
import argparse
import json
import subprocess
import time

import numpy as np
import open3d as o3d

parser = argparse.ArgumentParser()
parser.add_argument("lidarshop")
parser.add_argument("work")
parser.add_argument("points", type=int, nargs="?", default=1_000_000)
parser.add_argument("--pcl", help="bench/pcl_peers (built when CMake finds PCL)")
args = parser.parse_args()
lidarshop, work, count = args.lidarshop, args.work, args.points
rng = np.random.default_rng(17)
TORUS_R, TORUS_r = 2.0, 0.7


def make_torus(n):
    """n points on a torus (uniform by area, by rejection), 1 mm noise along the exact outward normals."""
    u, v = [], []
    while len(u) < n:
        a, b = rng.uniform(0, 2 * np.pi, 2 * n), rng.uniform(0, 2 * np.pi, 2 * n)
        keep = rng.uniform(0, 1, 2 * n) < (TORUS_R + TORUS_r * np.cos(b)) / (TORUS_R + TORUS_r)
        u.extend(a[keep])
        v.extend(b[keep])
    u, v = np.array(u[:n]), np.array(v[:n])
    normal = np.c_[np.cos(v) * np.cos(u), np.cos(v) * np.sin(u), np.sin(v)]
    centre = np.c_[TORUS_R * np.cos(u), TORUS_R * np.sin(u), np.zeros(n)]
    points = centre + (TORUS_r + rng.normal(0, 0.001, n))[:, None] * normal
    return points.astype(np.float32), normal.astype(np.float32)


def torus_distance(vertices):
    """|distance| of each vertex to the true torus, metres."""
    v = np.asarray(vertices, dtype=np.float64)
    return np.abs(np.hypot(np.hypot(v[:, 0], v[:, 1]) - TORUS_R, v[:, 2]) - TORUS_r)


def distance_text(vertices, triangles):
    d = torus_distance(vertices)
    return f"{triangles} triangles, median {np.median(d) * 1000:.2f} mm, 99 % {np.percentile(d, 99) * 1000:.2f} mm"


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
points = xyz(read_ply(path))  # exactly what every tool reads
points.tofile(f"{work}/points.f32")
torus_points, torus_normals = make_torus(min(50_000, count // 20))
torus_path = f"{work}/torus.ply"
torus = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(torus_points.astype(np.float64)))
torus.normals = o3d.utility.Vector3dVector(torus_normals.astype(np.float64))
o3d.io.write_point_cloud(torus_path, torus)
torus_read = read_ply(torus_path)
np.c_[xyz(torus_read), torus_read["nx"], torus_read["ny"], torus_read["nz"]].astype(np.float32).tofile(
    f"{work}/torus.f32")
pcl = {}
if args.pcl:
    out = subprocess.run([args.pcl, f"{work}/points.f32", work, f"{work}/torus.f32"], check=True,
                         capture_output=True, text=True)
    pcl = json.loads(out.stdout)
    assert pcl["points"] == len(points)
rows = []  # (tool, lidarshop s, Open3D s, PCL s, agreement)

# Normals from the 20 nearest points.
t = time.perf_counter()
cloud.estimate_normals(o3d.geometry.KDTreeSearchParamKNN(20))
o3d_s = time.perf_counter() - t
summary = run(["normals", path, "-o", f"{work}/normals.ply", "--neighbors", "20"])
ours = read_ply(f"{work}/normals.ply")
ours_n = np.c_[ours["nx"], ours["ny"], ours["nz"]]
o3d_n = np.asarray(cloud.normals)


def angle_text(a, b, name):
    angle = np.degrees(np.arccos(np.clip(np.abs(np.sum(a * b, axis=1)), 0, 1)))
    return f"to {name}'s: median {np.median(angle):.2g}°, {np.mean(angle < 1) * 100:.2f} % under 1°"


agreement = "ours " + angle_text(ours_n, o3d_n, "Open3D")
if pcl:
    pcl_n = np.fromfile(f"{work}/pcl_normals.f32", dtype=np.float32).reshape(-1, 3)
    agreement += "; ours " + angle_text(ours_n, pcl_n, "PCL")
rows.append(("normals (k = 20)", summary["seconds"], o3d_s, pcl.get("normals_s"), agreement))

# Statistical outlier removal, k = 20, 2 σ.
t = time.perf_counter()
_, kept = cloud.remove_statistical_outlier(20, 2.0)
o3d_s = time.perf_counter() - t
summary = run(["outliers", path, "-o", f"{work}/clean.ply", "--neighbors", "20", "--std-ratio", "2"])
ours_kept = key_set(xyz(read_ply(f"{work}/clean.ply")))
o3d_kept = key_set(points[np.asarray(kept)])
agreement = (f"kept {len(ours_kept)} / {len(o3d_kept)}" + (f" / {pcl['kept']}" if pcl else "") +
             f"; Jaccard ours–Open3D {jaccard(ours_kept, o3d_kept):.4f}")
if pcl:
    pcl_kept = key_set(points[np.fromfile(f"{work}/pcl_kept.i32", dtype=np.int32)])
    agreement += f", ours–PCL {jaccard(ours_kept, pcl_kept):.4f}, Open3D–PCL {jaccard(o3d_kept, pcl_kept):.4f}"
rows.append(("statistical outliers (k = 20, 2 σ)", summary["seconds"], o3d_s, pcl.get("outliers_s"), agreement))

# RANSAC plane, 1 cm, 1000 hypotheses.
t = time.perf_counter()
plane, inliers = cloud.segment_plane(0.01, 3, 1000)
o3d_s = time.perf_counter() - t
summary = run(["planes", path, "-o", f"{work}/planes.ply", "--distance", "0.01", "--iterations", "1000"])
ours = read_ply(f"{work}/planes.ply")
ours_in = key_set(xyz(ours)[ours["label"] == 0])
o3d_in = key_set(points[np.asarray(inliers)])
n_ours = np.array(summary["planes"][0]["normal"])


def plane_angle(a, b):
    a, b = np.array(a[:3]) / np.linalg.norm(a[:3]), np.array(b[:3]) / np.linalg.norm(b[:3])
    return np.degrees(np.arccos(min(1.0, abs(np.dot(a, b)))))


agreement = (f"normal angle to Open3D's {plane_angle(n_ours, plane):.3f}°" +
             (f", to PCL's {plane_angle(n_ours, pcl['plane']):.3f}°" if pcl else "") +
             f"; inliers {len(ours_in)} / {len(o3d_in)}" + (f" / {pcl['plane_inliers']}" if pcl else "") +
             f", Jaccard ours–Open3D {jaccard(ours_in, o3d_in):.4f}")
if pcl:
    pcl_in = key_set(points[np.fromfile(f"{work}/pcl_plane.i32", dtype=np.int32)])
    agreement += f", ours–PCL {jaccard(ours_in, pcl_in):.4f}"
rows.append(("RANSAC plane (1 cm, ≤ 1000 hypotheses)", summary["seconds"], o3d_s, pcl.get("plane_s"), agreement))

# Euclidean clustering (ours) vs DBSCAN with min_points 1 (the same connected components).
t = time.perf_counter()
labels = np.asarray(cloud.cluster_dbscan(eps=0.1, min_points=1))
o3d_s = time.perf_counter() - t
summary = run(["cluster", path, "-o", f"{work}/clusters.ply", "--radius", "0.1"])
rows.append(("Euclidean clustering (Open3D: DBSCAN min 1; r = 10 cm)", summary["seconds"], o3d_s,
             pcl.get("cluster_s"),
             f"clusters {summary['clusters']} / {labels.max() + 1}" + (f" / {pcl['clusters']}" if pcl else "") +
             f"; largest {summary['cluster_sizes'][0]} / {np.bincount(labels[labels >= 0]).max()}" +
             (f" / {pcl['largest_cluster']}" if pcl else "")))

# Voxel subsampling, 5 cm.
t = time.perf_counter()
down = cloud.voxel_down_sample(0.05)
o3d_s = time.perf_counter() - t
summary = run(["voxel", path, "-o", f"{work}/voxel.ply", "--voxel", "0.05"])
agreement = f"{summary['output_points']} / {len(down.points)}" + (f" / {pcl['voxels']}" if pcl else "") + " points"
if pcl:  # PCL's grid is aligned to multiples of the leaf size: numpy counts the same occupied voxels
    agreement += f" (numpy, PCL's grid: {len(np.unique(np.floor(points / np.float32(0.05)).astype(np.int64), axis=0))})"
rows.append(("voxel subsampling (5 cm)", summary["seconds"], o3d_s, pcl.get("voxel_s"), agreement))

# Poisson reconstruction on the torus with its exact normals: lidarshop (CGAL, Delaunay refinement), Open3D
# (Kazhdan's PoissonRecon, depth 8), PCL (its older copy of PoissonRecon, depth 8).
t = time.perf_counter()
o3d_mesh, _ = o3d.geometry.TriangleMesh.create_from_point_cloud_poisson(torus, depth=8)
o3d_s = time.perf_counter() - t
summary = run(["mesh", torus_path, "-o", f"{work}/torus_mesh.ply", "--method", "poisson"])
assert summary["normals"] == "input"
agreement = ("distance to the torus: ours " + distance_text(xyz(read_ply(f"{work}/torus_mesh.ply")), summary["triangles"]) +
             "; Open3D " + distance_text(np.asarray(o3d_mesh.vertices), len(o3d_mesh.triangles)))
if pcl:
    agreement += "; PCL " + distance_text(
        np.fromfile(f"{work}/pcl_poisson_vertices.f32", dtype=np.float32).reshape(-1, 3), pcl["poisson_triangles"])
rows.append((f"Poisson reconstruction ({len(torus_points) // 1000} k-point torus, depth 8)", summary["seconds"], o3d_s,
             pcl.get("poisson_s"), agreement))

print(f"{len(points)} points\n")
print("| tool | lidarshop s | Open3D 0.16 s |" + (" PCL 1.13 s |" if pcl else "") + " agreement |")
print("|---|---|---|" + ("---|" if pcl else "") + "---|")
for name, ours_s, o3d_s, pcl_s, agreement in rows:
    print(f"| {name} | {ours_s:.3f} | {o3d_s:.3f} |" + (f" {pcl_s:.3f} |" if pcl else "") + f" {agreement} |")
