"""``inksim match`` and ``inksim fit-material`` results read by open_match
and open_fit: the recipes on their pigment and geometry axes, each
recipe's unknowns with standard errors and flags, the fitted constants
with theirs; and a file of the wrong kind refused with one clear error."""

import subprocess

import numpy as np
import pytest

import inksim

from conftest import REPO


def _run(binary, command, config, out):
    src = REPO / "configs" / config
    if not src.is_file():
        pytest.skip(f"{src}: not found (tests run from an inksim checkout)")
    subprocess.run([*binary, command, str(src), "--output-dir", str(out)],
                   check=True, capture_output=True, text=True)


@pytest.fixture(scope="module")
def match(binary, tmp_path_factory):
    out = tmp_path_factory.mktemp("match")
    _run(binary, "match", "match-red-tint.toml", out)
    return inksim.open_match(out / "match-red-tint.h5")


@pytest.fixture(scope="module")
def fit(binary, tmp_path_factory):
    out = tmp_path_factory.mktemp("fit")
    _run(binary, "fit-material", "fit-red.toml", out)
    return inksim.open_fit(out / "fit-red.h5")


def test_recipes_on_their_axes(match):
    r = match.recipes
    assert r["pvc"].dims == ("recipe", "pigment")
    assert r["de00"].dims == ("recipe", "geometry")
    assert list(r["geometry"].values) == list(match.target["geometry"].values)
    assert r["thickness_nm"].attrs["units"] == "nm"
    assert len(match) == r.sizes["recipe"]
    # The best recipe first, and it is the one the file says reached the tolerance.
    assert list(r["rank"].values) == sorted(r["rank"].values)
    assert bool(match.attrs["reached"]) == bool(r["reached"].values[0])
    assert np.all(r["de00"].values[0] <= r["de00"].values[-1] + 1e-12)
    assert "match_toml" in match.attrs and "[target]" in match.attrs["match_toml"]


def test_one_recipe_in_full(match):
    best = match.recipe(0)
    used = [p for p, v in zip(match.recipes["pigment"].values, match.recipes["pvc"].values[0]) if v > 0]
    assert sorted(best["unknown"].values) == sorted(used)
    assert best["value"].dims == ("unknown",) and best["standard_error"].dims == ("unknown",)
    assert best["correlation"].dims == ("unknown", "unknown_2")
    np.testing.assert_allclose(np.diag(best["correlation"].values), 1.0)
    assert best["reflectance_factor"].dims == ("wavelength_nm",)
    assert "recipe" in repr(match) or "ΔE00" in repr(match)


def test_fitted_constants(fit):
    c = fit.constants
    assert c["k"].dims == ("wavelength_nm",) and c["wavelength_nm"].attrs["units"] == "nm"
    assert np.all(c["k"].values >= 0) and np.all(c["k_se"].values > 0)
    assert fit.residuals.dims == ("wavelength_nm", "reading")
    assert fit.drawdowns["thickness_nm"].attrs["units"] == "nm"
    # The residuals are at the stated noise: RMS within a factor 2 of it.
    rms = float(np.sqrt(np.mean(fit.residuals.values ** 2)))
    assert 0.5 * fit.attrs["noise_reflectance"] < rms < 2 * fit.attrs["noise_reflectance"], rms


def test_a_file_of_another_kind_is_refused(match, fit, tmp_path):
    with pytest.raises(ValueError, match="not an `inksim match` result"):
        inksim.open_match(fit.path)
    with pytest.raises(ValueError, match="not an `inksim fit-material` result"):
        inksim.open_fit(match.path)
    with pytest.raises(FileNotFoundError):
        inksim.open_match(tmp_path / "missing.h5")
