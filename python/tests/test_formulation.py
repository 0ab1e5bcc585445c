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
def effect(binary, tmp_path_factory):
    out = tmp_path_factory.mktemp("effect")
    _run(binary, "match", "match-pearl.toml", out)
    return inksim.open_match(out / "match-pearl.h5")


@pytest.fixture(scope="module")
def fit(binary, tmp_path_factory):
    out = tmp_path_factory.mktemp("fit")
    _run(binary, "fit-material", "fit-red.toml", out)
    return inksim.open_fit(out / "fit-red.h5")


def test_recipes_on_their_axes(match):
    r = match.recipes
    assert r["pvc"].dims == ("recipe", "pigment")
    assert r["de00"].dims == ("recipe", "geometry")
    # Each ΔE00 with its standard error from the target's noise (0.05 per L*, a*, b*).
    assert r["de00_se"].dims == ("recipe", "geometry")
    assert np.all((r["de00_se"].values > 0.0) & (r["de00_se"].values < 0.2))
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


def test_effect_paint_match(effect):
    """The pearl example: its target was made from flakes at 0.03 with a 132 nm coating."""
    assert effect.attrs["kind"] == "effect" and bool(effect.attrs["reached"])
    r = effect.recipes
    assert r["concentration"].dims == ("recipe", "flake_layer")
    assert list(r["flake_layer"].values) == ["basecoat"]
    assert r["coating_nm"].attrs["units"] == "nm"
    assert r["de00"].dims == ("recipe", "geometry") and r["de00_se"].dims == ("recipe", "geometry")
    assert list(r["geometry"].values) == ["45as-15", "45as15", "45as25", "45as45", "45as75", "45as110"]
    assert abs(float(r["concentration"].values[0, 0]) - 0.03) < 3e-4
    assert abs(float(r["coating_nm"].values[0, 0]) - 132.0) < 1.0
    assert np.all(r["de00"].values[0] < 0.1)
    assert abs(float(r["flop_index"].values[0]) - effect.target.attrs["flop_index"]) < 0.05
    best = effect.recipe(0)
    assert list(best["unknown"].values) == ["basecoat.flakes concentration", "basecoat.flakes coating_nm"]
    assert best["lab_all"].dims == ("multi_angle_geometry", "lab") and best.sizes["multi_angle_geometry"] == 11
    assert "coating 132" in repr(effect)


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


def test_a_verified_match_on_its_step_axis(binary, tmp_path):
    """A match with ``[match.verify]`` (dissolved dyes: the wave solution in
    closed form, so it runs in a second): ``verified`` has one dataset per
    verified recipe on its ``step`` axis, the wave colour with units."""
    palette = ('[[palette]]\nname = "red"\nmaterial = { builtin = "red" }\n'
               'shape = { kind = "molecular" }\npvc_range = [0.0, 0.3]\n')
    text = (
        '[match]\nname = "v"\ntolerance_de00 = 0.3\nmax_colourants = 1\n'
        '[match.verify]\nmax_steps = 2\nwavelength_step_nm = 30.0\n'
        '[target]\nkind = "lab"\nilluminant = "D65"\nobserver_deg = 10\n'
        'colour = [{ geometry = "45/0", lab = [60.0, 40.0, 10.0] }]\n'
        '[base.layer]\nthickness_nm = 1000.0\nfragment_nm = [2000.0, 2000.0]\nbinder_index = 1.5\n'
        '[base.grid]\ncell_nm = 50.0\n'
        '[base.illumination]\nwavelengths_nm = [430.0, 700.0]\npolar_deg = [0.0]\n'
        '[base.substrate]\nkind = "white"\nalbedo = 0.85\n' + palette)
    cfg = tmp_path / "v.toml"
    cfg.write_text(text)
    out = tmp_path / "out"
    subprocess.run([*binary, "match", str(cfg), "--output-dir", str(out)],
                   check=True, capture_output=True, text=True)
    m = inksim.open_match(out / "v.h5")
    assert len(m.verified) == 1 and "equation" in m.verify_fidelity
    v = m.verified[0]
    assert v["lab"].dims == ("step", "geometry", "lab")
    assert v["de00"].dims == ("step", "geometry")
    assert v["pvc"].dims == ("step", "pigment")
    assert list(v["step"].values) == list(range(v.sizes["step"]))
    assert v.attrs["rank"] == 1 and "outcome" in v.attrs
    assert np.all(np.isfinite(v["de00"].values))
