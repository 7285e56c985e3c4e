"""Shared fixtures: a small synthetic scene (ground, wall, a red box in front) scanned once per session."""
import os

import numpy as np
import pytest

import lidarshop

SOURCE_DIR = os.environ.get(
    "LIDARSHOP_SOURCE_DIR", os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", "..")))


def small_scene(columns=120, rows=80):
    """A box (label 2) standing on a grass ground (label 0) in front of a brick wall (label 1)."""
    return {
        "scanner": {"position": [0, 0, 1.5], "azimuth_deg": [-30, 30], "elevation_deg": [-30, 15],
                    "columns": columns, "rows": rows, "max_range": 60, "los_noise_sigma": 0.002, "seed": 2},
        "objects": [
            {"primitive": "plane", "size": [60, 60], "translate": [0, 15, 0], "label": 0, "texture": "grass"},
            {"primitive": "wall", "size": [20, 0.3, 3], "translate": [0, 9, 0], "label": 1, "texture": "brick",
             "color": [158, 68, 48]},
            {"primitive": "box", "size": [1.2, 1.2, 1.2], "translate": [0, 5, 0.6], "label": 2,
             "color": [40, 60, 200]},
        ],
    }


@pytest.fixture(scope="session")
def scan():
    return lidarshop.scan_scene(small_scene())


def box_strokes(scan):
    """Object strokes on the box's cells (the truth labels), background strokes on the wall and the ground."""
    strokes = np.zeros((scan.rows, scan.cols), np.uint8)
    label = scan.label
    rows, cols = np.nonzero(label == 2)
    r0, c0 = int(np.median(rows)), int(np.median(cols))
    strokes[r0 - 2:r0 + 3, c0 - 2:c0 + 3] = 1
    strokes[(label == 1) & (np.arange(scan.cols)[None, :] % 7 == 0)] = 2
    strokes[(label == 0) & (np.arange(scan.rows)[:, None] % 9 == 0) & (np.abs(np.arange(scan.cols) - c0) > 25)] = 2
    return strokes
