"""An effect paint's result (configs/metallic.toml) read by open_result:
the multi-angle colours with their geometries, the flop index, the sparkle
figures and the BRDF, with units, on the axes the file labels."""

import numpy as np
import pytest

import inksim

from conftest import REPO


@pytest.fixture(scope="module")
def metallic(binary, tmp_path_factory):
    src = REPO / "configs" / "metallic.toml"
    if not src.is_file():
        pytest.skip(f"{src}: not found (tests run from an inksim checkout)")
    out = tmp_path_factory.mktemp("paint") / "out"
    return inksim.open_result(inksim.run(src, out).path)


def test_multiangle_colours(metallic):
    assert metallic.attrs["kind"] == "paint"
    assert metallic.solves.sizes["solve"] == 0
    m = metallic.multiangle
    assert m.sizes["geometry"] == 11
    assert list(m["illumination_deg"].values[:6]) == [45.0] * 6
    assert list(m["aspecular_deg"].values[:6]) == [-15.0, 15.0, 25.0, 45.0, 75.0, 110.0]
    assert m["lab"].dims == ("geometry", "lab")
    assert m.attrs["illuminant"] == "D65" and m.attrs["observer_deg"] == 10
    lightness = m["lch"].values[:, 0]
    assert np.all(np.isfinite(m["xyz"].values))
    # A metallic is lightest near the mirror direction and dark far from it.
    assert lightness[1] > lightness[3] > lightness[5]
    fi = float(m["flop_index"])
    assert fi > 5.0
    assert m["flop_index"].attrs["units"] == "1"
    assert f"flop index {fi:.2f}" in repr(metallic)


def test_sparkle_and_brdf(metallic):
    s = metallic.sparkle
    assert list(s["illumination_deg"].values) == [15.0, 45.0, 75.0]
    assert s["glints_per_mm2"].attrs["units"] == "mm-2"
    assert np.all(s["glints_per_mm2"].values > 0)
    assert float(s["graininess"]) > 0
    p = metallic.paint
    assert p["brdf"].dims == ("wavelength_nm", "direction_deg", "view_deg")
    assert p["brdf"].attrs["units"] == "sr-1"
    assert p.sizes["wavelength_nm"] == 31
    assert np.all(np.isfinite(p["brdf"].values)) and np.all(p["brdf"].values >= 0)
    albedo = p["albedo"].values
    assert np.all((albedo > 0) & (albedo < 1))


def test_views_in_the_plane(metallic):
    v = metallic.paint["view_deg"].values
    # Light's side negative, mirror side positive, the normal once and as +0.
    assert np.all(np.diff(v) > 0)
    assert np.count_nonzero(v == 0.0) == 1 and not np.signbit(v[v == 0.0][0])
    assert v[0] == -v[-1]
