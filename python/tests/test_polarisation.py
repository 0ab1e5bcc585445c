"""Maxwell results: each polarisation's totals and order efficiencies beside
their mean, the ``equation`` and ``polarisation`` of every solve, and what a
Helmholtz file (with or without those attributes) reads as."""

import shutil

import h5py
import numpy as np
import pytest

import inksim

# The tiny scene in Maxwell: one wavelength, normal and oblique incidence
# (at 40° a layer reflects s clearly more than p), no appearance products,
# so the file holds the two solves from above and nothing else.
MAXWELL_SCENE = """\
seed = 3

[layer]
thickness_nm = 400.0
fragment_nm = [400.0, 400.0]
pvc = 0.15

[[pigment]]
name = "p"
material = {{ builtin = "red" }}
diameter_nm = 100.0

[grid]
cell_nm = 50.0
z_cell_nm = 100.0

[illumination]
wavelengths_nm = [450.0]
polar_deg = [0.0, 40.0]
polarisation = "{polarisation}"

[solver]
equation = "maxwell"
tolerance = 1e-8

[appearance]
outputs = []

[output]
name = "maxwell-{polarisation}"
"""

TOTALS = ["total_reflectance", "total_transmittance", "absorption", "energy_balance"]
ORDERS = ["orders_reflectance", "orders_transmittance"]
SUFFIXED = [f"{n}_{p}" for n in TOTALS for p in "sp"]
SUFFIXED_ORDERS = [f"{n}_{p}" for n in ORDERS for p in "sp"]


@pytest.fixture(scope="module")
def maxwell(binary, tmp_path_factory):
    """Results of the scene in unpolarised light, s alone and p alone."""
    d = tmp_path_factory.mktemp("maxwell")
    out = {}
    for pol in ("unpolarised", "s", "p"):
        cfg = d / f"maxwell-{pol}.toml"
        cfg.write_text(MAXWELL_SCENE.format(polarisation=pol), encoding="utf-8")
        out[pol] = inksim.run(cfg, d / "out").open()
    return out


def _oblique(r):
    """Index of the solve at 40°."""
    (i,) = np.flatnonzero(r.solves["polar_deg"].values == 40.0)
    return int(i)


def test_maxwell_unpolarised_keeps_s_and_p(maxwell):
    r = maxwell["unpolarised"]
    s = r.solves
    assert s.sizes["solve"] == 2
    assert list(s["equation"].values) == ["maxwell", "maxwell"]
    assert list(s["polarisation"].values) == ["unpolarised", "unpolarised"]
    assert "equation" in s.coords and "polarisation" in s.coords
    for name in TOTALS:
        sv, pv = s[name + "_s"].values, s[name + "_p"].values
        assert s[name + "_s"].dims == ("solve",)
        assert s[name + "_s"].attrs["units"] == "1"
        assert "s-polarised" in s[name + "_s"].attrs["long_name"]
        assert "p-polarised" in s[name + "_p"].attrs["long_name"]
        assert np.all(np.isfinite(sv)) and np.all(np.isfinite(pv))
        # natural light is the mean of the two powers
        np.testing.assert_allclose(0.5 * (sv + pv), s[name].values, rtol=1e-12, atol=0)
    for name in ("total_reflectance", "total_transmittance", "absorption"):
        for p in "sp":
            x = s[f"{name}_{p}"].values
            assert np.all((x > 0) & (x < 1)), (name, p, x)
    for p in "sp":
        np.testing.assert_allclose(
            s[f"total_reflectance_{p}"] + s[f"total_transmittance_{p}"] + s[f"absorption_{p}"],
            1.0, atol=1e-6)

    # At 40° s is reflected more than p (Fresnel), so reading one
    # polarisation's numbers under the other's name shows here.
    i = _oblique(r)
    assert float(s["total_reflectance_s"][i]) > float(s["total_reflectance_p"][i]) + 0.05
    assert float(s["total_transmittance_s"][i]) < float(s["total_transmittance_p"][i]) - 0.05

    o = r.orders
    for name in ORDERS:
        for p in "sp":
            v = o[f"{name}_{p}"]
            assert v.dims == ("order",)
            assert v.attrs["units"] == "1"
            assert f"{p}-polarised" in v.attrs["long_name"]
            assert np.all(np.isfinite(v.values))
        np.testing.assert_allclose(0.5 * (o[name + "_s"] + o[name + "_p"]), o[name],
                                   rtol=1e-12, atol=0)
    for k in range(s.sizes["solve"]):
        ok = r.orders_of(k)
        for p in "sp":
            # each polarisation's orders add up to its own totals
            np.testing.assert_allclose(ok[f"orders_reflectance_{p}"].sum(),
                                       s[f"total_reflectance_{p}"][k], rtol=1e-9)
            np.testing.assert_allclose(ok[f"orders_transmittance_{p}"].sum(),
                                       s[f"total_transmittance_{p}"][k], rtol=1e-9)
    spec = r.orders_of(i)
    spec = spec.isel(order=np.flatnonzero((spec["m"] == 0) & (spec["n"] == 0)))
    assert float(spec["orders_reflectance_s"][0]) > float(spec["orders_reflectance_p"][0]) + 0.05


@pytest.mark.parametrize("pol,other", [("s", "p"), ("p", "s")])
def test_maxwell_one_polarisation(maxwell, pol, other):
    r, both = maxwell[pol], maxwell["unpolarised"]
    s, o = r.solves, r.orders
    assert list(s["equation"].values) == ["maxwell", "maxwell"]
    assert list(s["polarisation"].values) == [pol, pol]
    np.testing.assert_array_equal(s["polar_deg"], both.solves["polar_deg"])
    for name in TOTALS:
        # its own numbers are the solve's, and those of the same
        # polarisation solved for natural light
        np.testing.assert_array_equal(s[f"{name}_{pol}"], s[name])
        np.testing.assert_allclose(s[f"{name}_{pol}"], both.solves[f"{name}_{pol}"],
                                   rtol=1e-12, atol=1e-15)
        assert np.all(np.isnan(s[f"{name}_{other}"].values))
    assert o.sizes["order"] == both.orders.sizes["order"] > 0
    for name in ORDERS:
        np.testing.assert_array_equal(o[f"{name}_{pol}"], o[name])
        np.testing.assert_allclose(o[f"{name}_{pol}"], both.orders[f"{name}_{pol}"],
                                   rtol=1e-12, atol=1e-15)
        assert np.all(np.isnan(o[f"{name}_{other}"].values))


def test_polarisations_missing_in_some_solves(maxwell, tmp_path):
    """The NaN of a solve without a polarisation lands on that solve and
    its orders only."""
    r = maxwell["unpolarised"]
    p = tmp_path / "part.h5"
    shutil.copyfile(r.path, p)
    with h5py.File(p, "r+") as f:
        g = f["solves/0001"]
        for name in TOTALS:
            del g.attrs[name + "_p"]
        for name in ORDERS:
            del g[name + "_p"]
    q = inksim.open_result(p)
    s, o = q.solves, q.orders
    for name in TOTALS:
        np.testing.assert_array_equal(s[name + "_s"], r.solves[name + "_s"])
        assert np.isfinite(s[name + "_p"][0]) and np.isnan(s[name + "_p"][1])
        assert s[name + "_p"][0] == r.solves[name + "_p"][0]
    in1 = o["solve"].values == 1
    assert in1.any() and (~in1).any()
    for name in ORDERS:
        np.testing.assert_array_equal(o[name + "_s"], r.orders[name + "_s"])
        assert np.all(np.isnan(o[name + "_p"].values[in1]))
        np.testing.assert_array_equal(o[name + "_p"].values[~in1],
                                      r.orders[name + "_p"].values[~in1])


def _helmholtz_reads_as_scalar(r):
    s, o = r.solves, r.orders
    assert set(s["equation"].values) == {"helmholtz"}
    assert set(s["polarisation"].values) == {"none"}
    for name in SUFFIXED:
        assert s[name].dims == ("solve",) and s[name].attrs["units"] == "1"
        assert np.all(np.isnan(s[name].values)), name
    for name in SUFFIXED_ORDERS:
        assert o[name].sizes["order"] == o.sizes["order"] > 0
        assert np.all(np.isnan(o[name].values)), name
    for name in TOTALS:
        assert np.all(np.isfinite(s[name].values))
    for name in ORDERS:
        assert np.all(np.isfinite(o[name].values))


def test_helmholtz(tiny):
    with h5py.File(tiny.path, "r") as f:
        g = f["solves/0000"]
        assert g.attrs["equation"] == "helmholtz"
        assert g.attrs["polarisation"].startswith("none")
        assert "total_reflectance_s" not in g.attrs and "orders_reflectance_s" not in g
    _helmholtz_reads_as_scalar(tiny)


def test_helmholtz_without_the_attributes(tiny, tmp_path):
    """A file written before ``equation`` and ``polarisation`` were stored."""
    p = tmp_path / "old.h5"
    shutil.copyfile(tiny.path, p)
    with h5py.File(p, "r+") as f:
        for g in f["solves"].values():
            del g.attrs["equation"]
            del g.attrs["polarisation"]
    _helmholtz_reads_as_scalar(inksim.open_result(p))


@pytest.fixture(scope="module")
def ensemble(binary, tmp_path_factory):
    """The scene with two realisations: natural light by default as one
    random-phase solve per incidence, and as s and p solved apart."""
    d = tmp_path_factory.mktemp("ensemble")
    out = {}
    for how in ("auto", "two-solves"):
        text = MAXWELL_SCENE.format(polarisation="unpolarised").replace(
            "seed = 3", "seed = 3\nrealisations = 2").replace(
            'equation = "maxwell"', f'equation = "maxwell"\nnatural_light = "{how}"').replace(
            'name = "maxwell-unpolarised"', f'name = "ensemble-{how}"')
        cfg = d / f"ensemble-{how}.toml"
        cfg.write_text(text, encoding="utf-8")
        out[how] = inksim.run(cfg, d / "out").open()
    return out


def test_random_phase_natural_light(ensemble):
    """One solve per incidence at a relative phase of its own; its powers
    are natural light's plus an s-p cross term bounded by Cauchy-Schwarz
    (|cross| <= sqrt(X_s X_p)) against the same layers solved in s and p."""
    r, two = ensemble["auto"], ensemble["two-solves"]
    s, t = r.solves, two.solves
    assert s.sizes["solve"] == t.sizes["solve"] == 4
    assert set(s["polarisation"].values) == {"unpolarised"}
    assert set(s["equation"].values) == {"maxwell"}
    phase = s["random_phase_deg"].values
    assert s["random_phase_deg"].attrs["units"] == "deg"
    assert np.all((phase >= -180) & (phase <= 180)) and len(set(phase)) == 4
    assert np.all(np.isnan(t["random_phase_deg"].values))
    for name in SUFFIXED:
        assert np.all(np.isnan(s[name].values)), name
    np.testing.assert_allclose(
        s["total_reflectance"] + s["total_transmittance"] + s["absorption"], 1.0, atol=1e-6)
    # half the solves: each incidence's iterations are one solve's
    assert s["iterations"].sum() < 0.75 * t["iterations"].sum()
    np.testing.assert_array_equal(s["realisation"], t["realisation"])
    np.testing.assert_array_equal(s["polar_deg"], t["polar_deg"])
    largest = 0.0
    for name in ("total_reflectance", "total_transmittance", "absorption"):
        xs, xp = t[name + "_s"].values, t[name + "_p"].values
        cross = s[name].values - 0.5 * (xs + xp)
        assert np.all(np.abs(cross) <= np.sqrt(xs * xp) + 1e-6), name
        largest = max(largest, float(np.abs(cross).max()))
    assert largest > 1e-6  # the phase is really there to average out


def test_maxwell_notes_count_the_anisotropic_cut_voxels(maxwell):
    """A Maxwell solve of grains says in its note how many voxels a grain
    surface cuts and took as anisotropic (grid.voxel_permittivity = "auto");
    the same grains in Helmholtz have no tensor part."""
    import re
    for note in maxwell["unpolarised"].solves["note"].values:
        m = re.search(r"tensor ε: (\d+) cut voxels anisotropic, (\d+) crystal-grain voxels", str(note))
        assert m, note
        assert int(m.group(1)) > 0 and int(m.group(2)) == 0
