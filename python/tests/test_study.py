"""open_study on the tiny study (configs/study-tiny.toml) run and merged by
the real CLI."""

import os
import sys

import numpy as np
import pytest

import inksim


def test_open_forms(study, study_run):
    assert study_run.kind == "study"
    assert study_run.path.endswith(os.path.join("quick", "summary.h5"))
    by_dir = inksim.open_study(os.path.dirname(study_run.path))
    # the study's output folder, holding one profile folder
    by_root = inksim.open_study(os.path.dirname(os.path.dirname(study_run.path)))
    assert by_dir.variants == by_root.variants == study.variants
    with pytest.raises(FileNotFoundError, match="summary.h5"):
        inksim.open_study(os.path.dirname(os.path.dirname(os.path.dirname(study_run.path))))


def test_table(study):
    assert study.name == "tiny" and study.profile == "quick"
    assert study.variants == ["red_d100", "red_d150", "yellow_d100", "yellow_d150"]
    t = study.table
    assert t["mean_reflectance"].dims == ("variant",)
    assert t["mean_reflectance"].attrs["units"] == "1"
    assert list(t["pigment"].values) == ["red", "red", "yellow", "yellow"]
    assert list(t["d"].values) == ["d100", "d150", "d100", "d150"]
    assert study.axes == {"d": ["d100", "d150"], "pigment": ["red", "yellow"]}
    if study.table.get("d_value") is not None:  # sweep file read: its axis order
        assert list(study.axes) == ["pigment", "d"]
    r, tr, a = (t[k].values for k in ("mean_reflectance", "mean_transmittance", "mean_absorption"))
    for x in (r, tr, a):
        assert np.all(np.isfinite(x)) and np.all((x >= 0) & (x <= 1))
    np.testing.assert_allclose(r + tr + a, 1.0, atol=1e-5)
    assert t["natural_srgb8"].dims == ("variant", "rgb") and t["natural_srgb8"].dtype == np.uint8
    assert t["natural_lab"].dims == ("variant", "lab") and np.all(np.isfinite(t["natural_lab"]))
    assert all(h.startswith("#") and len(h) == 7 for h in t["colour_hex"].values)
    assert len(set(t["id"].values)) == 4


def test_axis_values(study):
    if sys.version_info < (3, 11):
        pytest.importorskip("tomli")
    np.testing.assert_array_equal(study.table["d_value"], [100.0, 150.0, 100.0, 150.0])
    assert list(study.table["pigment_value"].values) == ["red", "red", "yellow", "yellow"]


def test_grid_and_results(study):
    g = study.grid("mean_reflectance")
    assert set(g.dims) == {"d", "pigment"} and g.shape == (2, 2)
    r = study.result("yellow_d150")
    assert r.grid == (8, 8, 4)
    s = r.solves
    above = (s["side"] == "above").values
    np.testing.assert_allclose(g.sel(pigment="yellow", d="d150"),
                               s["total_reflectance"].values[above].mean(), rtol=1e-12)
    # the summary's colour is the first viewing angle's colour under natural light
    np.testing.assert_array_equal(study.table["natural_srgb8"].sel(variant="yellow_d150"),
                                  r.colours["natural_srgb8"].isel(viewing_deg=0))
    with pytest.raises(KeyError, match="not a variant"):
        study.result("blue_d100")
