"""Segment, fill, remove, inpaint, Poisson and verify on synthetic data whose truth is known."""
import time

import numpy as np
import pytest

import lidarshop
from conftest import box_strokes


def test_segment_from_strokes(scan):
    strokes = box_strokes(scan)
    result = lidarshop.segment(scan, strokes)
    assert result.mask.shape == (scan.rows, scan.cols) and result.mask.dtype == np.uint8
    truth = scan.label == 2
    mask = result.mask > 0
    iou = (mask & truth).sum() / (mask | truth).sum()
    assert iou > 0.8, iou
    assert result.object_cells == int(mask.sum())
    assert result.timings.total_s > 0
    assert result.to_dict()["object_cells"] == result.object_cells
    # Options as keywords, as an object and as a dict give the same cut.
    by_keyword = lidarshop.segment(scan, strokes, method="depth")
    by_object = lidarshop.segment(scan, strokes, lidarshop.SegmentOptions(method="depth"))
    by_dict = lidarshop.segment(scan, strokes, {"method": "depth"})
    np.testing.assert_array_equal(by_keyword.mask, by_object.mask)
    np.testing.assert_array_equal(by_keyword.mask, by_dict.mask)


def test_segment_errors(scan):
    with pytest.raises(lidarshop.InputError, match="object"):
        lidarshop.segment(scan, np.zeros((scan.rows, scan.cols), np.uint8))
    with pytest.raises(ValueError, match=r"strokes: expected an array of shape \(80, 120\)"):
        lidarshop.segment(scan, np.zeros((5, 5), np.uint8))
    with pytest.raises(lidarshop.OptionsError, match="sigma_scale"):
        lidarshop.segment(scan, box_strokes(scan), sigma_scale=-1)


def test_segment_from_json_strokes(scan):
    rows, cols = np.nonzero(scan.label == 2)
    r, c = int(np.median(rows)), int(np.median(cols))
    strokes = {"strokes": [{"label": "object", "width": 3, "points": [[c - 2, r], [c + 2, r]]},
                           {"label": "background", "width": 2, "points": [[2, 2], [scan.cols - 3, 2]]},
                           {"label": "background", "width": 2,
                            "points": [[2, scan.rows - 3], [scan.cols - 3, scan.rows - 3]]}]}
    result = lidarshop.segment(scan, strokes)
    assert result.mask[r, c] == 255


def test_fill_gives_synthesized_cells(scan):
    hole = lidarshop.grow_hole((scan.label == 2).astype(np.uint8), 2) > 0
    result = lidarshop.fill(scan, hole, lidarshop.FillOptions(patch_radius=3))
    filled = result.scan
    assert result.hole_cells == int(hole.sum())
    assert result.synthesized_cells > 0.8 * result.hole_cells
    assert result.synthesized_cells + result.no_return_cells == result.hole_cells
    assert filled.synthesized.shape == (scan.rows, scan.cols)
    assert int((filled.synthesized > 0).sum()) == result.synthesized_cells
    assert np.all(filled.synthesized[~hole] == 0)
    # Outside the hole every cell is a bit-exact copy; inside, the box is gone: the ranges reach the wall or
    # the ground behind it, farther than the box.
    np.testing.assert_array_equal(filled.range[~hole], scan.range[~hole])
    inside = hole & (result.filled > 0) & (scan.label == 2)
    assert np.median(filled.range[inside]) > np.median(scan.range[inside]) + 1.0
    assert result.timings.total_s > 0 and result.to_dict()["timings"]["total_s"] > 0
    assert "synthesized" in result.summary() or result.summary()


def test_fill_window_applied_equals_fill(scan):
    hole = lidarshop.grow_hole((scan.label == 2).astype(np.uint8), 2) > 0
    options = lidarshop.FillOptions(patch_radius=3, window_margin=0.5, window_min_margin_cells=4,
                                    window_min_known_ratio=1.0)
    whole = lidarshop.fill(scan, hole, options)
    windowed = lidarshop.fill_window(scan, hole, options)
    shape = (windowed.window_rows, windowed.window_cols)
    assert shape[0] * shape[1] < scan.rows * scan.cols
    assert windowed.scan.range.shape == shape and windowed.filled.shape == shape
    assert windowed.synthesized_cells == whole.synthesized_cells
    applied = scan.clone()
    lidarshop.apply_fill(windowed, applied)
    np.testing.assert_array_equal(applied.range, whole.scan.range)
    np.testing.assert_array_equal(applied.synthesized, whole.scan.synthesized)
    np.testing.assert_array_equal(applied.color, whole.scan.color)
    assert not np.array_equal(applied.range, scan.range)  # the clone changed, the fixture did not


def test_remove_object(scan):
    result = lidarshop.remove_object(scan, box_strokes(scan), margin_cells=1)
    assert result.cut.object_cells > 0
    assert result.hole.shape == (scan.rows, scan.cols)
    assert result.fill.synthesized_cells > 0
    assert (result.scan.synthesized > 0).sum() == result.fill.synthesized_cells
    assert result.behind is None


def test_inpaint_and_poisson():
    rows, cols = 40, 50
    y, x = np.mgrid[0:rows, 0:cols]
    image = np.dstack([x * 2.0, y * 3.0, np.full((rows, cols), 50.0)]).astype(np.float32)
    hole = np.zeros((rows, cols), np.uint8)
    hole[15:22, 20:28] = 255
    result = lidarshop.poisson_fill(image, hole)
    assert result.image.shape == (rows, cols, 3)
    # A linear ramp is harmonic: the membrane fill reproduces it.
    np.testing.assert_allclose(result.image[hole > 0], image[hole > 0], atol=1e-3)
    # The numbers are the described result's, as the CLI's poisson --json writes them.
    assert list(result.to_dict()) == list(lidarshop.PoissonResult.fields)
    assert result.operation == "fill" and result.unknowns == int((hole > 0).sum()) and result.channels == 3
    grey = (x % 10 < 5).astype(np.float32) * 100
    painted = lidarshop.inpaint(grey, hole, lidarshop.InpaintOptions(patch_radius=3))
    assert painted.image.shape == (rows, cols)
    assert painted.hole_pixels == int((hole > 0).sum())
    assert np.all((painted.fill_iteration >= 0) == (hole > 0))
    assert painted.complete and "review" not in painted.to_dict()  # review: only when a fill stopped for one
    assert list(painted.to_dict()) == [key for key in lidarshop.InpaintResult.fields if key != "review"]
    assert painted.review is None  # an optional part holding nothing reads as None
    np.testing.assert_array_equal(painted.image[hole == 0], grey[hole == 0])
    gx = np.zeros_like(grey)
    gy = np.zeros_like(grey)
    flat = lidarshop.reconstruct_from_gradients(np.full((rows, cols), 5.0), gx, gy, hole, solver="direct")
    np.testing.assert_allclose(flat.image, 5.0, atol=1e-9)
    with pytest.raises(lidarshop.OptionsError, match="patch_radius"):
        lidarshop.inpaint(grey, hole, patch_radius=0)


def test_one_angle_convention():
    # R = Rz(yaw) Ry(pitch) Rx(roll), roll applied first: the same matrix from both functions and from the
    # elementary rotations written out here.
    def rx(a):
        c, s = np.cos(np.radians(a)), np.sin(np.radians(a))
        return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])

    def ry(a):
        c, s = np.cos(np.radians(a)), np.sin(np.radians(a))
        return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])

    def rz(a):
        c, s = np.cos(np.radians(a)), np.sin(np.radians(a))
        return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])

    yaw, pitch, roll = 35.0, -20.0, 12.0
    expected = rz(yaw) @ ry(pitch) @ rx(roll)
    np.testing.assert_allclose(lidarshop.rotation_from_euler_degrees([roll, pitch, yaw]), expected, atol=1e-12)
    pose = lidarshop.pose_from_xyz_yaw(1, 2, 3, yaw, pitch, roll)
    np.testing.assert_allclose(pose[:3, :3], expected, atol=1e-12)
    np.testing.assert_array_equal(pose[:3, 3], [1, 2, 3])


def test_verify_pose(scan):
    box = lidarshop.make_primitive("box", {"size": [1.2, 1.2, 1.2]})
    assert box.vertices.shape[1] == 3 and box.triangles.shape[1] == 3
    truth = lidarshop.pose_from_xyz_yaw(0, 5, 0.6, 0)
    right = lidarshop.verify_pose(box, scan, truth, allowance_m=0.05, sigma_m=0.05)
    assert right.consistency > 0.95 and right.confidence > 0.1
    # In front of the box: the rays that returned from the box went through it.
    floating = lidarshop.verify_pose(box, [scan], lidarshop.pose_from_xyz_yaw(0, 3, 0.6, 0), allowance_m=0.05)
    assert floating.consistency < 0.5
    # Hidden behind the wall: consistent (nothing contradicts it) but not seen at all.
    hidden = lidarshop.verify_pose(box, [scan], lidarshop.pose_from_xyz_yaw(0, 11, 0.6, 0), allowance_m=0.05)
    assert hidden.consistency > 0.95 and hidden.confidence < 0.01
    # Many poses at once: the same numbers as one by one.
    many = lidarshop.verify_pose(box, [scan], np.stack([truth, lidarshop.pose_from_xyz_yaw(0, 3, 0.6, 0)]),
                                 allowance_m=0.05)
    assert len(many) == 2
    assert many[1].consistency == floating.consistency and many[1].confidence == floating.confidence
    with pytest.raises(lidarshop.OptionsError, match="sigma"):
        lidarshop.verify_pose(box, scan, truth, sigma=1)
    # A model in millimetres: model_scale, or the scale in the pose, gives the numbers of the model in metres.
    box_mm = lidarshop.make_primitive("box", {"size": [1200.0, 1200.0, 1200.0]})
    by_option = lidarshop.verify_pose(box_mm, scan, truth, allowance_m=0.05, sigma_m=0.05,
                                      model_options={"model_scale": 0.001})
    scaled_pose = truth.copy()
    scaled_pose[:3, :3] *= 0.001
    in_pose = lidarshop.verify_pose(box_mm, scan, scaled_pose, allowance_m=0.05, sigma_m=0.05)
    for result in (by_option, in_pose):
        assert result.consistency == pytest.approx(right.consistency, abs=1e-3)
        assert result.confidence == pytest.approx(right.confidence, abs=1e-3)


def test_long_calls_release_the_gil(scan):
    """Python threads run while a fill runs: the binding releases the GIL around the library call."""
    import threading

    hole = lidarshop.grow_hole((scan.label == 2).astype(np.uint8), 2) > 0
    span = {}

    def work():
        span["start"] = time.monotonic()
        for _ in range(10):
            lidarshop.fill(scan, hole, patch_radius=3)
        span["end"] = time.monotonic()

    ticks = []
    thread = threading.Thread(target=work)
    thread.start()
    while thread.is_alive():
        ticks.append(time.monotonic())
        time.sleep(0.001)
    thread.join()
    length = span["end"] - span["start"]
    middle = [t for t in ticks if span["start"] + 0.25 * length < t < span["start"] + 0.75 * length]
    assert len(middle) > 10, (length, len(middle))


def test_point_set_tools(scan):
    points = scan.points()
    coarse = lidarshop.voxel_downsample(points, 0.5)
    assert coarse.dtype == np.float32 and coarse.shape[1] == 3 and 0 < len(coarse) < len(points)
    cells = {tuple(c) for c in np.floor((points - points.min(axis=0)) / 0.5).astype(int)}
    assert len(coarse) == len(cells)  # one point per occupied voxel
    with pytest.raises(lidarshop.OptionsError, match="voxel_m"):
        lidarshop.voxel_downsample(points, 0)
    shift = np.eye(4)
    shift[:3, 3] = [1, 2, 3]
    moved = lidarshop.transform_scan(scan, shift)
    np.testing.assert_allclose(moved.world_from_scanner[:3, 3], [1, 2, 4.5])
    np.testing.assert_array_equal(moved.point, scan.point)
    with pytest.raises(lidarshop.OptionsError):
        lidarshop.transform_scan(scan, np.diag([2.0, 2, 2, 1]))


def test_sweep_finds_the_box(scan):
    box = lidarshop.make_primitive("box", {"size": [1.2, 1.2, 1.2]})
    grid = dict(x_min_m=-1.5, x_max_m=1.5, y_min_m=3.5, y_max_m=6.5, step_m=0.5, z_m=0.6, yaws_deg=[0, 45],
                min_comparable_pairs=20, min_confidence=0.2)
    options = lidarshop.SweepOptions(**grid)
    result = lidarshop.sweep(box, scan, options, verify_options={"allowance_m": 0.05, "sigma_m": 0.05})
    assert len(result.xs_m) == 7 and len(result.ys_m) == 7 and list(result.yaws_deg) == [0, 45]
    assert result.confidence_map.shape == (7, 7)
    assert len(result.poses["x_m"]) == 7 * 7 * 2
    assert len(result.detections) >= 1
    best = result.detections[0]
    assert abs(best.x_m) < 0.15 and abs(best.y_m - 5) < 0.15, best
    # The grid pose at the truth gives what verify_pose gives there.
    index = (list(result.ys_m).index(5.0) * 7 + list(result.xs_m).index(0.0)) * 2
    alone = lidarshop.verify_pose(box, scan, lidarshop.pose_from_xyz_yaw(0, 5, 0.6, 0), allowance_m=0.05,
                                  sigma_m=0.05)
    assert result.poses["confidence"][index] == pytest.approx(alone.confidence, abs=1e-12)
    picture = result.heat_map("consistency", 0.75)
    assert picture.ndim == 3 and picture.shape[2] == 3 and picture.dtype == np.uint8
    # The coarse-to-fine search (the default) verifies only the poses that can pass; the CSV lists those.
    assert result.csv().count("\n") == 1 + int(result.poses["evaluated"].sum())
    assert result.evaluated_poses == int(result.poses["evaluated"].sum())
    skipped = result.poses["evaluated"] == 0
    assert np.all(result.poses["confidence_bound"][skipped] <= 0.2)
    full = lidarshop.sweep(box, scan, lidarshop.SweepOptions(**grid, search="full"),
                           verify_options={"allowance_m": 0.05, "sigma_m": 0.05})
    assert full.evaluated_poses == 98 and full.csv().count("\n") == 99
    assert [(d.x_m, d.y_m, d.yaw_deg, d.confidence) for d in full.detections] == \
        [(d.x_m, d.y_m, d.yaw_deg, d.confidence) for d in result.detections]
    with pytest.raises(lidarshop.OptionsError, match="step_m"):
        lidarshop.sweep(box, scan, step_m=0)
    with pytest.raises(lidarshop.OptionsError, match="consistency\\|confidence"):
        result.heat_map("consistancy")
