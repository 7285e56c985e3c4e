"""Recolouring from a photo on a synthetic scene: the photo, the camera and the hidden points are known."""
import os
import subprocess

import numpy as np
import pytest

import lidarshop
from conftest import SOURCE_DIR, small_scene


@pytest.fixture(scope="module")
def scene_photo():
    scene = small_scene()
    # A camera 2 m to the right of the scanner, looking at the box: part of the wall behind the box is seen
    # by the scanner but hidden from the camera.
    camera = lidarshop.camera_looking_at([2.0, 0.0, 1.4], [0.0, 5.0, 0.6], 320, 240, 70.0)
    photo = lidarshop.render_photo(scene, camera)
    return scene, camera, photo


def test_camera_forms():
    camera = lidarshop.PinholeCamera(width_px=640, height_px=480, fx_px=500, fy_px=500, cx_px=320, cy_px=240,
                                     distortion={"k1": -0.1, "k2": 0, "k3": 0, "p1": 0, "p2": 0})
    assert camera.k1 == -0.1
    again = lidarshop.PinholeCamera.from_dict(camera.to_dict())
    assert again.to_dict() == camera.to_dict()
    points = np.array([[0.1, -0.2, 3.0], [0.5, 0.3, 2.0], [0.0, 0.0, -1.0]])
    pixels = camera.project(points)
    assert np.isnan(pixels[2]).all()  # behind the camera
    rays = camera.unproject(pixels[:2])
    np.testing.assert_allclose(rays * points[:2, 2:3], points[:2], atol=1e-6)
    with pytest.raises(lidarshop.InputError, match="fx_px"):
        lidarshop.PinholeCamera(width_px=640, height_px=480, fx_px=-1, fy_px=500, cx_px=320, cy_px=240)


def test_resection_recovers_the_camera(scan, scene_photo):
    _, camera, _ = scene_photo
    points = scan.points(world=True)
    pixels = camera.project(points.astype(np.float64))
    inside = np.all(np.isfinite(pixels), axis=1) & (pixels[:, 0] > 0) & (pixels[:, 0] < 320) & \
        (pixels[:, 1] > 0) & (pixels[:, 1] < 240)
    rng = np.random.default_rng(0)
    pick = rng.choice(np.nonzero(inside)[0], 30, replace=False)
    noisy = pixels[pick] + rng.normal(0, 0.3, (30, 2))
    result = lidarshop.resection(noisy, points[pick], width_px=320, height_px=240)
    assert result.num_inliers >= 28 and result.rms_px < 1.0
    assert np.linalg.norm(result.camera.center_in_world - camera.center_in_world) < 0.05
    assert result.inlier.dtype == bool and result.reprojection_error_px.shape == (30,)
    known = lidarshop.resect_with_intrinsics(noisy, points[pick], camera, width_px=320, height_px=240)
    assert np.linalg.norm(known.camera.center_in_world - camera.center_in_world) < 0.05
    with pytest.raises(lidarshop.InputError):
        lidarshop.resection(noisy[:4], points[pick][:4], width_px=320, height_px=240)
    with pytest.raises(lidarshop.OptionsError, match="photo size"):
        lidarshop.resection(noisy, points[pick])


def test_recolor_takes_the_photo_where_seen(scan, scene_photo):
    _, camera, photo = scene_photo
    grey = scan.clone()
    grey.color = np.zeros((scan.rows, scan.cols, 3), np.uint8)
    result = lidarshop.recolor(grey, photo.image, camera)
    assert result.recolored_count > 0 and result.hidden > 0
    # Points by an occluding edge keep their colour (the edge guard): uncertain, neither recoloured nor hidden.
    assert result.recolored_count + result.hidden + result.outside_image + result.uncertain == result.returns
    took = result.recolored > 0
    np.testing.assert_array_equal(result.scan.color[~took & (scan.valid > 0)], 0)  # the rest is unchanged
    # The box seen by the camera takes its blue; the wall cells the box hides from the camera stay black.
    box = took & (scan.label == 2)
    assert box.sum() > 20
    mean = result.scan.color[box].mean(axis=0)
    assert mean[2] > mean[0] and mean[2] > mean[1], mean
    with pytest.raises(ValueError, match="photo"):
        lidarshop.recolor(grey, photo.image[:10], camera)


def test_landmarks_and_photo_pairs():
    rng = np.random.default_rng(1)
    source = rng.uniform(-5, 5, (10, 3))
    angle = np.radians(25)
    rotation = np.array([[np.cos(angle), -np.sin(angle), 0], [np.sin(angle), np.cos(angle), 0], [0, 0, 1]])
    target = 1.5 * source @ rotation.T + [1, 2, 3]
    similarity = lidarshop.align_landmarks(source, target, with_scale=True)
    assert abs(similarity.scale - 1.5) < 1e-9 and similarity.rms_m < 1e-9
    rigid = lidarshop.align_landmarks(source, target)
    assert rigid.scale == pytest.approx(1.0) and rigid.rms_m > 0.1
    a = rng.uniform(0, 500, (20, 2))
    h = np.array([[1.1, 0.05, 10], [-0.02, 0.95, 5], [1e-4, 0, 1]])
    projected = np.column_stack([a, np.ones(20)]) @ h.T
    b = projected[:, :2] / projected[:, 2:]
    model = lidarshop.estimate_homography(a, b, 1.0)
    np.testing.assert_allclose(model.matrix / model.matrix[2, 2], h, rtol=1e-4, atol=1e-6)
    assert model.inlier.all()
    with pytest.raises(lidarshop.InputError):
        lidarshop.estimate_fundamental(a[:5], b[:5], 1.0)


def test_correspondences_by_cell(scan):
    rows, cols = np.nonzero(scan.valid[:, :] > 0)
    pairs = {"pairs": [{"pixel": [10.5 + i, 20.5], "cell": [int(rows[i * 97]), int(cols[i * 97])]} for i in range(6)]}
    parsed = lidarshop.parse_correspondences(pairs, scan)
    assert parsed["kind"] == "pixel-point" and parsed["points"].shape == (6, 3)
    world = scan.world_from_scanner
    point = scan.point[rows[0], cols[0]].astype(np.float64)
    np.testing.assert_allclose(parsed["points"][0], world[:3, :3] @ point + world[:3, 3], atol=1e-5)
    with pytest.raises(lidarshop.InputError, match="cell"):
        lidarshop.parse_correspondences(pairs)  # cells need the scan


def test_photos_stored_in_e57():
    path = os.path.join(SOURCE_DIR, "..", "shared", "data", "e57", "pumpA.e57")
    assert os.path.exists(path), f"{path}: the shared data must be beside the checkout"
    photos = lidarshop.read_e57_photos(path)
    assert len(photos) >= 1
    assert photos[0]["image"].shape == (2304, 3072, 3)


def test_station_colouring_from_e57_images_and_photos(tmp_path):
    """A cube station written by `lidarshop scan --photos cube` (six faces at gains within ±30 %) coloured from its
    own images, then from the same photos and cameras given one by one: the same colours and gains."""
    cli = os.environ.get("LIDARSHOP_CLI")
    assert cli, "LIDARSHOP_CLI (set by ctest) must name the lidarshop executable"
    station = str(tmp_path / "cube.e57")
    subprocess.run([cli, "scan", "parking_lot", "--rows", "100", "--columns", "200", "--seed", "3", "--quiet",
                    "-o", station, "--photos", "cube", "--photo-size", "192"], check=True)
    result = lidarshop.recolor_from_e57_images(station)
    assert result.coloured > 0.8 * result.returns  # the cells no face sees (from 0.15 m above) stay as they were
    assert result.photo_index.shape == result.scan.color.shape[:2] and result.photo_index.dtype == np.uint16
    assert result.gains.shape == (6, 3) and np.all(result.gains[0] == 1)
    assert result.seam_edges > 0 and result.blended > 0
    used = np.unique(result.photo_index[result.photo_index > 0])
    assert len(used) >= 3
    photos = lidarshop.read_e57_photos(station)
    again = lidarshop.recolor_from_photos(lidarshop.read_scan(station), [p["image"] for p in photos],
                                          [p["camera"] for p in photos])
    np.testing.assert_array_equal(again.photo_index, result.photo_index)
    np.testing.assert_array_equal(again.scan.color, result.scan.color)
    np.testing.assert_allclose(again.gains, result.gains)
    # The naive colouring (no gains, no blending) leaves the gains at 1 and the seams unblended.
    naive = lidarshop.recolor_from_photos(lidarshop.read_scan(station), [p["image"] for p in photos],
                                          [p["camera"] for p in photos], equalize_exposure=False,
                                          blend_seams=False, nearest_photo=True)
    assert np.all(naive.gains == 1) and naive.blended == 0
    with pytest.raises(ValueError, match="6 photos but 5 cameras"):
        lidarshop.recolor_from_photos(result.scan, [p["image"] for p in photos], [p["camera"] for p in photos][:5])
    with pytest.raises(lidarshop.InputError, match="no image of scan 0 holds a photo with a camera"):
        lidarshop.recolor_from_e57_images(os.path.join(SOURCE_DIR, "..", "shared", "data", "e57", "pumpA.e57"))


def test_auto_resection_refuses_a_photo_of_nothing_the_scan_holds(scene_photo):
    # The camera without pairs (recolor/auto_resection.h): a photo of the empty sky matches no rendering of the
    # scan, and the function says so instead of returning a camera. (Its accuracy: auto_resection_test.)
    scene, camera, _ = scene_photo
    scan = lidarshop.scan_scene(scene)
    sky = np.zeros((240, 320, 3), dtype=np.uint8)
    with pytest.raises(lidarshop.InputError, match="no rendering of the scan matches"):
        lidarshop.auto_resection(scan, sky, intrinsics=camera)
    options = lidarshop.AutoResectionOptions(rounds=3)
    assert options.to_dict()["rounds"] == 3
