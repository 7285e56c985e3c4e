"""Scans as numpy arrays: shapes, dtypes, no copies, setting channels, files."""
import copy

import numpy as np
import pytest

import lidarshop


def test_channel_shapes_and_dtypes(scan):
    assert (scan.rows, scan.cols) == (80, 120)
    expected = {"range": (np.float32, ()), "point": (np.float32, (3,)), "direction": (np.float32, (3,)),
                "valid": (np.uint8, ()), "intensity": (np.float32, ()), "color": (np.uint8, (3,)),
                "label": (np.int32, ()), "normal": (np.float32, (3,)), "true_range": (np.float32, ())}
    for name, (dtype, tail) in expected.items():
        array = getattr(scan, name)
        assert array.dtype == dtype, name
        assert array.shape == (80, 120) + tail, name
    assert scan.world_from_scanner.shape == (4, 4)
    assert scan.world_from_scanner.dtype == np.float64
    np.testing.assert_allclose(scan.world_from_scanner[:3, 3], [0, 0, 1.5])
    assert scan.synthesized is None  # optional channel absent in a fresh scan
    assert scan.count_valid() == int((scan.valid > 0).sum())
    assert 0 < scan.count_valid() < scan.num_cells
    # The range is the length of the point where valid, 0 elsewhere.
    valid = scan.valid > 0
    np.testing.assert_allclose(np.linalg.norm(scan.point[valid], axis=1), scan.range[valid], rtol=1e-5)
    assert np.all(scan.range[~valid] == 0)
    assert scan.points().shape == (scan.count_valid(), 3)


def test_arrays_share_the_scans_memory(scan):
    work = scan.clone()
    view = work.range
    assert not view.flags["OWNDATA"] and view.flags["WRITEABLE"]
    r, c = np.argwhere(work.valid > 0)[0]
    view[r, c] = 123.5
    assert work.range[r, c] == np.float32(123.5)  # seen through a new view: the same memory
    assert scan.range[r, c] != np.float32(123.5)  # clone() copied
    work.color[0, 0] = (1, 2, 3)
    assert tuple(work.color[0, 0]) == (1, 2, 3)
    pose = work.world_from_scanner
    pose[0, 3] = 7.0
    assert work.world_from_scanner[0, 3] == 7.0
    # A view outlives the scan it came from.
    fresh = scan.clone()
    kept = fresh.range
    del fresh
    assert kept.sum() == pytest.approx(scan.range.sum(), rel=1e-6)
    # copy.copy is deep (a Scan copies its channels in Python).
    other = copy.copy(scan)
    other.range[r, c] = -1
    assert scan.range[r, c] != -1


def test_set_channels_from_numpy(scan):
    work = scan.clone()
    new_range = np.full((work.rows, work.cols), 2.0)  # float64 is converted to the channel's float32
    work.range = new_range
    assert work.range.dtype == np.float32 and np.all(work.range == 2.0)
    work.synthesized = np.zeros((work.rows, work.cols), bool)
    assert work.synthesized.dtype == np.uint8
    mask = np.zeros((work.rows, work.cols), bool)
    mask[3, 4] = True
    work.synthesized = mask
    assert work.synthesized[3, 4] == 255  # True becomes the project's 255
    work.label = None
    assert work.label is None
    with pytest.raises(ValueError, match=r"Scan.range: expected an array of shape \(80, 120\), got shape \(3, 3\)"):
        work.range = np.zeros((3, 3))
    with pytest.raises(ValueError, match="cannot be None"):
        work.valid = None
    work.world_from_scanner = np.eye(4) * 1.0
    with pytest.raises(ValueError, match="4 x 4"):
        work.world_from_scanner = np.eye(3)


def test_new_scan():
    scan = lidarshop.Scan(4, 5, with_color=True)
    assert scan.range.shape == (4, 5) and scan.color.shape == (4, 5, 3) and scan.count_valid() == 0


def test_intensity_is_none_when_the_file_has_none(tmp_path):
    path = tmp_path / "plain.pcd"
    path.write_text("# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 2\n"
                    "HEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\nDATA ascii\n1 2 3\n2 3 4\n")
    scan = lidarshop.read_scan(str(path))
    assert scan.intensity is None and not scan.has_intensity
    assert "intensity" not in scan.channel_names()
    assert scan.count_valid() == 2
    lidarshop.write_scan(scan, str(tmp_path / "copy.ply"))
    assert lidarshop.read_scan(str(tmp_path / "copy.ply")).intensity is None
    # Setting an intensity adds the channel; None removes it again.
    scan.intensity = np.full((scan.rows, scan.cols), 0.25)
    assert scan.has_intensity and scan.intensity.dtype == np.float32
    scan.intensity = None
    assert scan.intensity is None
    assert lidarshop.Scan(2, 3, with_intensity=False).intensity is None
    assert lidarshop.Scan(2, 3).intensity.shape == (2, 3)


@pytest.mark.parametrize("extension", ["ptx", "e57", "pcd", "ply"])
def test_write_read_round_trip(scan, tmp_path, extension):
    path = tmp_path / f"box.{extension}"
    lidarshop.write_scan(scan, str(path))
    back = lidarshop.read_scan(str(path))
    assert (back.rows, back.cols) == (scan.rows, scan.cols)
    np.testing.assert_array_equal(back.valid > 0, scan.valid > 0)
    valid = scan.valid > 0
    np.testing.assert_allclose(back.range[valid], scan.range[valid], atol=2e-3)
    np.testing.assert_allclose(back.world_from_scanner, scan.world_from_scanner, atol=1e-9)
    if extension != "ptx":
        np.testing.assert_array_equal(back.color[valid], scan.color[valid])


@pytest.mark.parametrize("extension", ["las", "xyz", "pts"])
def test_point_formats_keep_the_world_points(scan, tmp_path, extension):
    path = tmp_path / f"box.{extension}"
    lidarshop.write_scan(scan, str(path))
    back = lidarshop.read_scan(str(path))
    valid = scan.valid > 0
    assert (back.rows, back.cols) == (1, int(valid.sum()))  # the points alone, in row-major order

    def world(s, mask):
        return s.point[mask] @ s.world_from_scanner[:3, :3].T + s.world_from_scanner[:3, 3]

    np.testing.assert_allclose(world(back, back.valid > 0), world(scan, valid), atol=1e-4)
    np.testing.assert_array_equal(back.color[0], scan.color[valid])


def test_read_scan_header_agrees_with_the_scan(scan, tmp_path):
    path = str(tmp_path / "scan.e57")
    lidarshop.write_scan(scan, path)
    header = lidarshop.read_scan_header(path)
    assert header["format"] == "e57"
    assert list(header)[:2] == ["file", "format"]
    entry = header["scans"][0]
    assert (entry["rows"], entry["cols"]) == (scan.rows, scan.cols)
    assert entry["organized"] is True
    assert "valid" not in entry  # the points are not read


def test_bad_files_raise_input_error(tmp_path):
    bad = tmp_path / "bad.ptx"
    bad.write_text("12\nnot a number\n")
    with pytest.raises(lidarshop.InputError, match="bad.ptx"):
        lidarshop.read_scan(str(bad))
    with pytest.raises(ValueError):  # InputError is a ValueError ...
        lidarshop.read_scan(str(bad))
    with pytest.raises(OSError):  # ... and an OSError
        lidarshop.read_scan(str(tmp_path / "missing.e57"))
    with pytest.raises(lidarshop.InputError, match="unknown scan format"):
        lidarshop.write_scan(lidarshop.Scan(2, 2), str(tmp_path / "scan.asc"))


def test_builtin_scenes_and_dict_scenes():
    names = lidarshop.builtin_scenes()
    assert "mailbox" in names and "parking_lot" in names
    scene = lidarshop.builtin_scene("mailbox")
    scene["scanner"]["columns"], scene["scanner"]["rows"] = 60, 40
    small = lidarshop.scan_scene(scene)
    assert (small.rows, small.cols) == (40, 60)
    assert set(np.unique(small.label[small.valid > 0])) <= {0, 1, 2}
    with pytest.raises(lidarshop.InputError, match="no built-in scene 'nope'"):
        lidarshop.builtin_scene("nope")
    scene["objects"][0]["size"] = [-1, 60]
    with pytest.raises(lidarshop.InputError, match="size"):
        lidarshop.scan_scene(scene)


def test_read_scans_gives_a_sites_stations_with_their_poses(tmp_path):
    # The built-in site on a coarse grid: three stations, the late sedan (label 7) at station 2 only.
    site = lidarshop.builtin_scene("parking_lot_stations")
    for station in site["stations"]:
        station["columns"], station["rows"] = 120, 70
    stations = lidarshop.scan_stations(site)
    assert [s.name for s in stations] == ["station0", "station1", "station2"]
    assert [bool((s.label[s.valid > 0] == 7).any()) for s in stations] == [False, False, True]
    for extension in ["e57", "ptx"]:
        path = str(tmp_path / f"site.{extension}")
        lidarshop.write_scan(stations, path)
        back = lidarshop.read_scans(path)
        assert len(back) == 3, extension
        for i, (read, written) in enumerate(zip(back, stations)):
            assert (read.rows, read.cols) == (written.rows, written.cols)
            np.testing.assert_allclose(read.world_from_scanner, written.world_from_scanner, atol=1e-9)
            np.testing.assert_array_equal(read.valid > 0, written.valid > 0)
            if extension == "e57":
                assert read.name == f"station{i}"
        # Where each stands (x = 0, -8, +8 m) and looks (yaw 0, -30, +30 degrees).
        for read, x, yaw in zip(back, [0, -8, 8], [0, -30, 30]):
            pose = read.world_from_scanner
            assert pose[0, 3] == pytest.approx(x)
            assert np.degrees(np.arctan2(-pose[0, 1], pose[1, 1])) == pytest.approx(yaw)
    # One scanner: one scan.
    mailbox = lidarshop.builtin_scene("mailbox")
    mailbox["scanner"]["columns"], mailbox["scanner"]["rows"] = 60, 40
    assert len(lidarshop.scan_stations(mailbox)) == 1
