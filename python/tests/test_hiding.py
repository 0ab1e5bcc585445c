"""Hiding power over a hiding chart, read back from a result the real CLI
wrote: the contrast ratio and Kubelka's S and K with their standard errors
and units, consistent with the colours over both halves."""

import numpy as np
import pytest

import inksim

from conftest import TINY_SCENE

CHART_SCENE = TINY_SCENE.replace('name = "tiny"', 'name = "chart"') + """
[substrate]
kind = "chart"
white_albedo = 0.8
"""


@pytest.fixture(scope="module")
def chart(binary, tmp_path_factory):
    d = tmp_path_factory.mktemp("chart")
    p = d / "chart.toml"
    p.write_text(CHART_SCENE, encoding="utf-8")
    return inksim.open_result(inksim.run(p, d / "out").path)


def test_no_chart_no_hiding(tiny):
    assert tiny.hiding is None
    assert tiny.contrast_ratio is None


def test_hiding_datasets_units_and_shapes(chart):
    h = chart.hiding
    assert set(h["geometry"].values) == {"45/0", "d/8 SCI", "d/8 SCE"}
    assert h["contrast_ratio"].dims == ("geometry",)
    assert h["s_per_um"].dims == ("geometry", "wavelength_nm")
    assert list(h["wavelength_nm"].values) == [450.0, 600.0]
    assert h["s_per_um"].attrs["units"] == "um-1"
    assert h["k_y_per_um"].attrs["units"] == "um-1"
    assert h["contrast_ratio"].attrs["units"] == "1"
    assert "contrast ratio" in h["contrast_ratio"].attrs["long_name"]
    # Two realisations: the contrast ratio and the values at Y have finite
    # standard errors; per wavelength a value (or its error) is NaN where a
    # realisation's reflectances admit no Kubelka layer (here the weakly
    # scattering layer's d/8 SCE over black is nearly 0).
    for name in ("contrast_ratio", "s_y_per_um", "k_y_per_um"):
        assert np.all(np.isfinite(h[name + "_se"].values)), name
        assert np.all(h[name + "_se"].values >= 0), name
    sci = h.sel(geometry="d/8 SCI")
    for name in ("s_per_um", "k_per_um", "r_inf"):
        assert np.all(np.isfinite(sci[name].values)), name
        assert np.all(np.isfinite(sci[name + "_se"].values)), name
    np.testing.assert_allclose(h["y_ground"].values, 80.0, rtol=0, atol=1e-9)
    np.testing.assert_allclose(h["ground_reflectance"].values, 0.8, rtol=0, atol=0)


def test_contrast_ratio_is_the_ratio_of_the_luminance_factors(chart):
    h = chart.hiding
    cr = h["y_black"].values / h["y_white"].values
    np.testing.assert_allclose(h["contrast_ratio"].values, cr, rtol=1e-12)
    assert np.all((cr > 0) & (cr < 1))
    value, se = chart.contrast_ratio
    sci = h.sel(geometry="d/8 SCI")
    assert value == float(sci["contrast_ratio"]) and se == float(sci["contrast_ratio_se"])


def test_kubelka_values_agree_with_each_other(chart):
    h = chart.hiding
    # K = S (a - 1) = S (K/S), and K/S = (1 - R_inf)^2 / (2 R_inf).
    np.testing.assert_allclose(h["k_per_um"], h["s_per_um"] * h["k_over_s"], rtol=1e-10)
    r = h["r_inf"].values
    np.testing.assert_allclose(h["k_over_s"].values, (1 - r) ** 2 / (2 * r), rtol=1e-8)
    kmax = h["k_over_s"].max("wavelength_nm").values
    np.testing.assert_allclose(h["k_over_s_max"].values, kmax, rtol=0)
