"""The point-set toolbox on clouds whose answer is known: planes, blobs, outliers, rigid motions."""
import numpy as np
import pytest

import lidarshop
from conftest import small_scene


def rotation_z(deg):
    a = np.radians(deg)
    return np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])


@pytest.fixture
def plane_with_outliers():
    """2,000 points on z = 0.5 (1 mm noise) and 20 points far off it."""
    rng = np.random.default_rng(3)
    plane = np.column_stack([rng.uniform(-2, 2, 2000), rng.uniform(-2, 2, 2000), 0.5 + rng.normal(0, 0.001, 2000)])
    outliers = rng.uniform(-2, 2, (20, 3)) + np.array([0, 0, 3])
    return np.vstack([plane, outliers]).astype(np.float32)


def blobs(rng, centers, n=300, sigma=0.05):
    return np.vstack([rng.normal(c, sigma, (n, 3)) for c in centers]).astype(np.float32)


def test_outlier_filters(plane_with_outliers):
    keep = lidarshop.statistical_outlier_inliers(plane_with_outliers, neighbors=10, std_ratio=2.0)
    assert keep.dtype == bool and keep.shape == (2020,)
    assert not keep[2000:].any()  # every far point removed
    assert keep[:2000].mean() > 0.95
    keep = lidarshop.radius_outlier_inliers(plane_with_outliers, lidarshop.RadiusOutlierOptions(radius_m=0.2))
    assert not keep[2000:].any() and keep[:2000].mean() > 0.99
    with pytest.raises(lidarshop.OptionsError, match="radius_m"):
        lidarshop.radius_outlier_inliers(plane_with_outliers, radius_m=-1)


def test_crop_and_random_sample(plane_with_outliers):
    keep = lidarshop.crop_inliers(plane_with_outliers, box=[[-1, -1, 0], [1, 1, 1]])
    inside = np.all((plane_with_outliers >= [-1, -1, 0]) & (plane_with_outliers <= [1, 1, 1]), axis=1)
    np.testing.assert_array_equal(keep, inside)
    outside = lidarshop.crop_inliers(plane_with_outliers, invert=True, box=[[-1, -1, 0], [1, 1, 1]])
    np.testing.assert_array_equal(outside, ~inside)
    triangle = lidarshop.crop_inliers(plane_with_outliers, polygon=[[0, 0], [2, 0], [0, 2]])
    x, y = plane_with_outliers[:, 0], plane_with_outliers[:, 1]
    np.testing.assert_array_equal(triangle, (x > 0) & (y > 0) & (x + y < 2))
    ranged = lidarshop.crop_inliers(plane_with_outliers, max_range_m=1.0)
    np.testing.assert_array_equal(ranged, np.linalg.norm(plane_with_outliers.astype(np.float64), axis=1) <= 1.0)
    sample = lidarshop.random_sample_inliers(plane_with_outliers, 100, seed=4)
    assert sample.sum() == 100
    np.testing.assert_array_equal(sample, lidarshop.random_sample_inliers(plane_with_outliers, 100, seed=4))
    assert (sample != lidarshop.random_sample_inliers(plane_with_outliers, 100, seed=5)).any()


def test_planes(plane_with_outliers):
    fit = lidarshop.fit_plane_ransac(plane_with_outliers, distance_threshold_m=0.01)
    assert abs(abs(fit.normal[2]) - 1) < 1e-3
    assert abs(abs(fit.offset_m) - 0.5) < 2e-3
    assert len(fit.inliers) >= 1990 and fit.inliers.max() < 2000
    assert fit.rms_m < 0.002
    assert np.abs(fit.distance(plane_with_outliers[:2000])).max() < 0.01
    # Two planes: the floor and a wall x = 1.
    rng = np.random.default_rng(1)
    wall = np.column_stack([np.full(1500, 1.0), rng.uniform(-2, 2, 1500), rng.uniform(0.6, 3, 1500)])
    both = np.vstack([plane_with_outliers[:2000], wall]).astype(np.float32)
    for planes in (lidarshop.detect_planes_ransac(both, max_planes=2, distance_threshold_m=0.01),
                   lidarshop.detect_planes_hough(both, max_planes=2)):
        assert len(planes) == 2
        normals = sorted(np.argmax(np.abs(p.normal)) for p in planes)
        assert normals == [0, 2], [p.normal for p in planes]


def test_clusters_and_kmeans():
    rng = np.random.default_rng(2)
    centers = np.array([[0, 0, 0], [3, 0, 0], [0, 4, 1]])
    points = blobs(rng, centers)
    clusters = lidarshop.euclidean_clusters(points, radius_m=0.3)
    assert clusters.num_clusters == 3 and sorted(clusters.sizes) == [300, 300, 300]
    for i in range(3):
        assert len(set(clusters.labels[i * 300:(i + 1) * 300])) == 1
    km = lidarshop.kmeans(points, lidarshop.KMeansOptions(clusters=3, seed=7))
    found = km.centers[np.argsort(km.centers[:, 0] + 10 * km.centers[:, 1])]
    np.testing.assert_allclose(found, centers[[0, 1, 2]], atol=0.02)
    assert km.labels.shape == (900,) and km.inertia_m2 > 0
    with pytest.raises(lidarshop.OptionsError, match="clusters"):
        lidarshop.kmeans(points, clusters=0)


def test_normals_and_features(plane_with_outliers):
    points = plane_with_outliers[:2000]
    normals, curvature = lidarshop.estimate_normals(points, neighbors=15, viewpoint=[0, 0, 5])
    assert normals.shape == (2000, 3) and curvature.shape == (2000,)
    assert np.median(normals[:, 2]) > 0.999  # up, toward the viewpoint above
    assert np.median(curvature) < 0.01
    features = lidarshop.fpfh(points, 0.4)  # about 60 neighbours each
    assert features.shape == (2000, 33)
    np.testing.assert_allclose(features.sum(axis=1), 300, rtol=1e-3)
    # On a plane every pair has the same angles: each histogram puts its mass in few bins.
    assert np.median(features.max(axis=1)) > 50
    with pytest.raises(ValueError, match="normals: 10 rows for 2000 points"):
        lidarshop.fpfh(points, 0.4, normals=np.zeros((10, 3)))


def test_scan_tools(scan):
    with_normals = lidarshop.scan_normals(scan, window_cells=2)
    up = with_normals.normal[(scan.label == 0) & (scan.valid > 0)]
    assert np.median(up[:, 2]) > 0.98  # the ground faces up (scanner frame = world orientation here)
    # The curvature channel beside it: ~0 on the flat ground, NaN where the ray returned nothing.
    assert with_normals.curvature.dtype == np.float32 and scan.curvature is None
    assert np.nanmedian(with_normals.curvature[(scan.label == 0) & (scan.valid > 0)]) < 1e-3
    assert np.all(np.isnan(with_normals.curvature[scan.valid == 0]))
    for method in ("slic", "graph", "quickshift"):
        labels, count = lidarshop.superpixels(scan, method=method, region_cells=10)
        assert labels.shape == (scan.rows, scan.cols) and count > 10, method
        assert np.all(labels[scan.valid == 0] == -1)
    regions, count = lidarshop.region_growing(scan, 10.0)
    assert regions.shape == (scan.rows, scan.cols) and count >= 3
    # The wall and the ground are separate regions: their largest regions differ.
    wall = np.bincount(regions[(scan.label == 1) & (regions >= 0)]).argmax()
    ground = np.bincount(regions[(scan.label == 0) & (regions >= 0)]).argmax()
    assert wall != ground
    # A Scan passed as points means its valid points in the world frame.
    keep = lidarshop.statistical_outlier_inliers(scan)
    assert keep.shape == (scan.count_valid(),)


def test_icp_and_scan_registration():
    # The box turned 35 degrees shows two faces: they fix x, which the wall and the ground leave free.
    scene = small_scene()
    scene["objects"][2]["rotate_deg"] = [0, 0, 35]
    scan = lidarshop.scan_scene(scene)
    fixed = scan.points(world=True)
    motion = np.eye(4)
    motion[:3, :3] = rotation_z(2.0)
    motion[:3, 3] = [0.05, -0.03, 0.02]
    moving = (fixed.astype(np.float64) @ motion[:3, :3].T + motion[:3, 3]).astype(np.float32)
    result = lidarshop.icp(fixed, moving, max_correspondence_m=0.3)
    assert result.converged or result.iterations > 0
    np.testing.assert_allclose(result.fixed_from_moving @ motion, np.eye(4), atol=5e-3)
    assert result.fitness > 0.9
    # Scans: the moving scan's pose is off by a small motion; registration brings it back.
    moved = lidarshop.transform_scan(scan, motion)
    registered, icp = lidarshop.register_scans(scan, moved, max_correspondence_m=0.3)
    np.testing.assert_allclose(registered.world_from_scanner, scan.world_from_scanner, atol=5e-3)
    assert isinstance(icp, lidarshop.IcpResult)


def test_global_alignment_then_icp():
    """Three boxes seen from all sides, the moving copy turned 60° and shifted: no initial guess needed."""
    rng = np.random.default_rng(5)
    faces = []
    for center, size in [((0, 0, 0.5), (1, 2, 1)), ((3, 1, 0.75), (1.5, 1, 1.5)), ((1, 4, 0.3), (2, 0.6, 0.6))]:
        for _ in range(3000):
            p = rng.uniform(-0.5, 0.5, 3)
            axis = rng.integers(3)
            p[axis] = rng.choice([-0.5, 0.5])
            faces.append(np.array(center) + p * np.array(size))
    fixed = np.array(faces, np.float32)
    motion = np.eye(4)
    motion[:3, :3] = rotation_z(60)
    motion[:3, 3] = [2, -1, 0]
    moving = (fixed.astype(np.float64) @ motion[:3, :3].T + motion[:3, 3]).astype(np.float32)
    coarse = lidarshop.align_globally(fixed, moving, voxel_m=0.1, normal_radius_m=0.25, feature_radius_m=0.5,
                                      seed=3)
    assert coarse.inliers > 10
    fine = lidarshop.icp(fixed, moving, coarse.fixed_from_moving, max_correspondence_m=0.3)
    np.testing.assert_allclose(fine.fixed_from_moving @ motion, np.eye(4), atol=1e-2)


def test_surface_reconstruction():
    rng = np.random.default_rng(6)
    directions = rng.normal(size=(3000, 3))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    points = (directions * 0.5 + [0, 0, 1]).astype(np.float32)
    poisson = lidarshop.reconstruct_surface(points, normals=directions)
    radius = np.linalg.norm(poisson.vertices - [0, 0, 1], axis=1)
    assert len(poisson.triangles) > 300 and np.abs(radius - 0.5).max() < 0.02
    inside = lidarshop.reconstruct_surface(points, viewpoint=[0, 0, 1])  # normals estimated, facing the centre
    assert np.abs(np.linalg.norm(inside.vertices - [0, 0, 1], axis=1) - 0.5).max() < 0.03
    interpolating = lidarshop.reconstruct_surface(points, method="scale-space")
    assert np.abs(np.linalg.norm(interpolating.vertices - [0, 0, 1], axis=1) - 0.5).max() < 1e-5
    with pytest.raises(lidarshop.InputError, match="one plane"):
        lidarshop.reconstruct_surface(np.column_stack([points[:, :2], np.zeros(3000)]))


def street_station(x, y, yaw_deg, seed, passer_by):
    """A street with a facade from a scanner at (x, y), turned yaw_deg; a passer-by (label 10) when asked."""
    objects = [{"primitive": "plane", "size": [80, 80], "translate": [0, 20, 0], "label": 0, "texture": "gravel"},
               {"primitive": "box", "size": [30, 0.5, 8], "translate": [0, 18, 4], "label": 1}]
    if passer_by:
        objects.append({"primitive": "cylinder", "radius": 0.25, "height": 1.75, "translate": [1, 8, 0.875],
                        "label": 10})
    return lidarshop.scan_scene({
        "scanner": {"position": [x, y, 1.6], "rotate_deg": [0, 0, yaw_deg], "azimuth_deg": [-60, 60],
                    "elevation_deg": [-30, 25], "columns": 300, "rows": 140, "max_range": 80,
                    "los_noise_sigma": 0.004, "orthogonal_noise_sigma": 0.002, "seed": seed},
        "objects": objects})


def test_clean_removes_the_passer_by_another_station_saw_through():
    first, second = street_station(0, 0, 0, 3, True), street_station(4, 1, -15, 4, False)
    cleaned, removed, counts = lidarshop.clean([first, second])
    assert len(cleaned) == 2 and len(removed) == 2
    labels = np.asarray(first.label)
    passer_by = labels == 10
    found = removed[0] > 0
    assert found.sum() > 100 and counts[0]["removed"] == found.sum()
    assert (found & passer_by).sum() >= 0.95 * found.sum()  # what went is the passer-by
    assert (found & passer_by).sum() >= 0.9 * passer_by.sum()  # and most of it went
    assert (removed[1] > 0).sum() == 0 and counts[1]["removed"] == 0
    # Station 1 saw through it: every reason is 1 + 1.
    assert set(np.unique(removed[0][found]).tolist()) == {2}
    assert counts[0]["filled"] > 0 and np.asarray(cleaned[0].synthesized).sum() > 0
    with pytest.raises(lidarshop.InputError):
        lidarshop.clean([first])
    with pytest.raises(lidarshop.OptionsError):
        lidarshop.clean([first, second], transients={"min_region_cells": 0})


def test_register_site_brings_spoiled_stations_back():
    # A walled courtyard with boxes at several angles, seen from three stations all around.
    objects = [{"primitive": "plane", "size": [40, 40], "label": 0},
               {"primitive": "box", "size": [30, 0.4, 4], "translate": [0, 12, 2]},
               {"primitive": "box", "size": [30, 0.4, 4], "translate": [0, -12, 2]},
               {"primitive": "box", "size": [0.4, 24, 4], "translate": [15, 0, 2]},
               {"primitive": "box", "size": [0.4, 24, 4], "translate": [-15, 0, 2]},
               {"primitive": "box", "size": [2, 1, 1.5], "rotate_deg": [0, 0, 25], "translate": [-3, 2, 0.75]},
               {"primitive": "box", "size": [1.5, 1.5, 2.5], "rotate_deg": [0, 0, -40], "translate": [4, -1, 1.25]},
               {"primitive": "box", "size": [1, 1, 1], "rotate_deg": [20, 30, 10], "translate": [-9, -4, 1.2]}]
    stations, truth = [], []
    for k, (x, y, yaw) in enumerate([(-8, -6, 10), (0, -7, -20), (7, 5, 160)]):
        scan = lidarshop.scan_scene({
            "scanner": {"position": [x, y, 1.5], "rotate_deg": [0, 0, yaw], "azimuth_deg": [-180, 179.5],
                        "elevation_deg": [-45, 40], "columns": 480, "rows": 120, "max_range": 60,
                        "los_noise_sigma": 0.002, "seed": k + 1},
            "objects": objects})
        truth.append(np.array(scan.world_from_scanner))
        stations.append(scan)
    # Stations 1 and 2 spoiled by 1 degree and 0.2 m.
    for k in (1, 2):
        motion = np.eye(4)
        motion[:3, :3] = rotation_z(1.0 if k == 1 else -1.0)
        motion[:3, 3] = [0.2, -0.1, 0.05] if k == 1 else [-0.15, 0.1, -0.05]
        stations[k] = lidarshop.transform_scan(stations[k], motion)
    registered, per_station, per_pair = lidarshop.register_site(stations, fixed=0)
    assert len(registered) == 3 and len(per_station) == 3 and len(per_pair) >= 2
    for k in range(3):
        error = np.array(registered[k].world_from_scanner)[:3, 3] - truth[k][:3, 3]
        assert np.linalg.norm(error) < 0.005, (k, error)
    assert per_station[1]["moved_m"] > 0.1 and per_station[0]["moved_m"] == 0
    with pytest.raises(lidarshop.OptionsError):  # a site needs two stations
        lidarshop.register_site([stations[0]])


def test_fill_from_stations_takes_what_the_other_station_measured():
    first, second = street_station(0, 0, 0, 3, True), street_station(4, 1, -15, 4, False)
    labels = np.asarray(first.label)
    hole = lidarshop.grow_hole(((labels == 10) & (np.asarray(first.valid) > 0)).astype(np.uint8) * 255, 2)
    filled = lidarshop.fill_from_stations(first, hole, [second])
    hole_cells = int((hole > 0).sum())
    assert filled["hole_cells"] == hole_cells
    assert filled["from_station_cells"] > hole_cells / 2
    assert filled["cells_per_station"] == [filled["from_station_cells"]]
    from_station = filled["from_station"] > 0
    assert from_station.sum() == filled["from_station_cells"]
    assert set(np.unique(filled["from_station"][from_station]).tolist()) == {1}
    scan = filled["scan"]
    assert (np.asarray(scan.from_station) > 0).sum() == filled["from_station_cells"]
    assert (np.asarray(scan.synthesized)[from_station] == 0).all()  # real points, not synthesized
    assert (labels[from_station] == 10).all()
    assert (np.asarray(scan.label)[from_station] != 10).all()
    alone = lidarshop.fill(first, hole)
    assert filled["synthesized_cells"] < alone.synthesized_cells / 2
    with pytest.raises(lidarshop.OptionsError):
        lidarshop.fill_from_stations(first, hole, [second], max_incidence_deg=0)
    removed = lidarshop.remove_object(first, labels_strokes(labels), stations=[second])
    assert removed["filled"]["from_station_cells"] > 0 and removed["cut"].object_cells > 50


def labels_strokes(labels):
    """Strokes: object on the passer-by's middle row, background along the bottom rows."""
    strokes = np.zeros(labels.shape, np.uint8)
    rows, cols = np.nonzero(labels == 10)
    middle = int(np.median(rows))
    on_row = cols[rows == middle]
    strokes[middle, on_row.min() + 1:on_row.max()] = 1
    strokes[-3:, :] = 2
    return strokes
