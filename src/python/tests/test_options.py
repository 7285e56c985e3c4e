"""Options objects generated from the library's descriptions: attributes, keywords, dicts, errors, docs."""
import copy
import pickle

import pytest

import lidarshop

# Every generated options class (the classes with from_dict); the list below must all be there.
OPTION_CLASSES = [getattr(lidarshop, name) for name in dir(lidarshop)
                  if hasattr(getattr(lidarshop, name), "from_dict") and hasattr(getattr(lidarshop, name), "fields")]
EXPECTED = {"FillOptions", "RemoveOptions", "SegmentOptions", "InpaintOptions", "PoissonOptions",
            "AcceptanceOptions", "CutWeights", "MeanTestOptions", "HistogramTestOptions", "ScannerOptions",
            "VerifyOptions", "ModelOptions", "SweepOptions", "ResectionOptions", "RecolorOptions",
            "StatisticalOutlierOptions", "RadiusOutlierOptions", "CropOptions", "RansacPlaneOptions",
            "HoughPlaneOptions", "EuclideanClusterOptions", "KMeansOptions", "NormalOptions",
            "RegionGrowingOptions", "SuperpixelOptions", "IcpOptions", "GlobalAlignOptions", "PhotoOptions",
            "PtxReadOptions", "E57WriteOptions", "PointViewOptions", "PictureLayoutOptions"}


def test_every_described_struct_is_a_class():
    assert EXPECTED <= {cls.__name__ for cls in OPTION_CLASSES}


def test_keywords_and_attributes():
    options = lidarshop.FillOptions(patch_radius=6, method="laplace")
    assert options.patch_radius == 6 and options.method == "laplace"
    assert lidarshop.FillOptions().method == "gradient"  # the library's default
    options.seed = 2**63 + 5  # uint64 keeps its full range
    assert options.seed == 2**63 + 5
    options.color_weight = 2  # an int for a double field
    assert options.color_weight == 2.0 and isinstance(options.color_weight, float)
    # Nested structs are objects of their own class, views into the parent.
    assert isinstance(options.poisson, lidarshop.PoissonOptions)
    options.poisson.tolerance = 1e-4
    assert options.poisson.tolerance == 1e-4
    assert options.to_dict()["poisson"]["tolerance"] == 1e-4
    options.acceptance.mean.enabled = False
    # acceptance is an alias of inpaint.acceptance (FillOptions nests its inpainting): to_dict() is nested.
    assert options.to_dict()["inpaint"]["acceptance"]["mean"]["enabled"] is False
    assert options.inpaint.acceptance.mean.enabled is False and "acceptance" not in options.to_dict()
    options.patch_radius = 6
    assert options.inpaint.patch_radius == 6 and "patch_radius" not in lidarshop.FillOptions.fields
    options.poisson = lidarshop.PoissonOptions(max_levels=3)
    assert options.poisson.max_levels == 3
    options.poisson = {"solver": "multigrid"}  # a dict sets the keys it names
    assert options.poisson.solver == "multigrid" and options.poisson.max_levels == 3
    nested = lidarshop.RemoveOptions(fill=lidarshop.FillOptions(patch_radius=3), margin_cells=5)
    assert nested.fill.patch_radius == 3 and nested.margin_cells == 5


@pytest.mark.parametrize("cls", OPTION_CLASSES)
def test_dict_round_trip_is_exact(cls):
    default = cls()
    data = default.to_dict()
    assert list(data) == cls.fields
    assert cls.from_dict(data) == default
    # Change every field the way the JSON would and come back exactly.
    changed = cls.from_dict(data)
    for key, value in data.items():
        if isinstance(value, bool):
            setattr(changed, key, not value)
        elif isinstance(value, float) and value != 0:
            try:
                setattr(changed, key, value * 0.75)
            except lidarshop.OptionsError:
                pass
    again = cls.from_dict(changed.to_dict())
    assert again == changed and again.to_dict() == changed.to_dict()
    assert cls(**changed.to_dict()) == changed
    assert pickle.loads(pickle.dumps(changed)) == changed
    assert copy.deepcopy(changed) == changed


def test_errors_carry_the_library_messages():
    with pytest.raises(lidarshop.OptionsError, match=r"patch_radius: 0 is out of range \[1, 15\]"):
        lidarshop.FillOptions(patch_radius=0)
    options = lidarshop.FillOptions()
    with pytest.raises(ValueError, match=r"patch_radius: 40 is out of range \[1, 15\]"):
        options.patch_radius = 40
    assert options.patch_radius == 4  # unchanged
    with pytest.raises(lidarshop.OptionsError, match=r"'magic' is not a fill method: gradient\|laplace"):
        options.method = "magic"
    with pytest.raises(lidarshop.OptionsError, match="patch_radus: unknown option \\(did you mean .patch_radius.\\?\\)"):
        lidarshop.FillOptions(patch_radus=3)
    with pytest.raises(lidarshop.OptionsError, match="patch_radius: expected a whole number"):
        lidarshop.FillOptions.from_dict({"patch_radius": 2.5})
    with pytest.raises(lidarshop.OptionsError, match=r"poisson\.tolerance"):
        lidarshop.FillOptions.from_dict({"poisson": {"tolerance": 2.0}})
    with pytest.raises(lidarshop.OptionsError, match="expected true or false"):
        options.inverse_range = "yes"
    with pytest.raises(AttributeError, match="FillOptions has no field 'patch_radus' \\(did you mean 'patch_radius'\\?\\)"):
        options.patch_radus = 3  # no silent new attributes
    assert issubclass(lidarshop.OptionsError, ValueError)


def test_docs_and_repr_come_from_the_descriptions():
    doc = lidarshop.FillOptions.patch_radius.__doc__
    assert "Alias of inpaint.patch_radius" in doc and "[px]" in doc and "[1, 15]" in doc and "default 4" in doc
    assert "gradient" in lidarshop.FillOptions.method.__doc__ and "laplace" in lidarshop.FillOptions.method.__doc__
    assert "patch_radius:" in lidarshop.FillOptions.__doc__
    text = repr(lidarshop.FillOptions(method="telea"))
    assert text.startswith("FillOptions(method='telea', inpaint=InpaintOptions(patch_radius=4")
    assert "poisson=PoissonOptions(" in text


def test_results_are_read_only(scan):
    import numpy as np
    hole = np.zeros((scan.rows, scan.cols), bool)
    hole[10:14, 10:14] = True
    result = lidarshop.fill(scan, hole, method="laplace")
    with pytest.raises(AttributeError):
        result.hole_cells = 3
    assert result.to_dict()["hole_cells"] == 16
