"""open_result on a result the real CLI wrote: dims, coordinates, units,
shapes and physically sensible values."""

import datetime as dt

import h5py
import numpy as np
import pytest

import inksim

from conftest import TINY_SCENE


def test_identity(tiny, tiny_run):
    assert tiny.path == tiny_run.path
    assert tiny.format_version == 1
    assert isinstance(tiny.version, str) and tiny.version
    assert tiny.config == TINY_SCENE  # the exact text, byte for byte
    assert len(tiny.plan.strip().splitlines()) > 3  # one line per decision
    assert len(tiny.input_hash) == 64
    assert tiny.seed == 3
    assert tiny.grid == (8, 8, 4)
    assert tiny.size_nm == (400.0, 400.0, 400.0)
    assert isinstance(tiny.created, dt.datetime)
    assert tiny.seeds.shape == (2,) and tiny.seeds[0] == 3
    assert "inksim.Result" in repr(tiny)


def test_solves(tiny):
    s = tiny.solves
    assert s["total_reflectance"].dims == ("solve",)
    # 2 wavelengths x (4 angles from above: 0 and 30 deg lit, 8 and 45 deg for the
    # measurement geometries; + 6 from below) x 2 realisations
    assert s.sizes["solve"] == 40
    assert s["wavelength_nm"].attrs["units"] == "nm"
    assert s["polar_deg"].attrs["units"] == "deg"
    assert s["seconds"].attrs["units"] == "s"
    assert set(np.unique(s["wavelength_nm"].values)) == {450.0, 600.0}
    assert set(s["side"].values) == {"above", "below"}
    assert set(s["realisation"].values.tolist()) == {0, 1}
    r, t, a = (s[k].values for k in ("total_reflectance", "total_transmittance", "absorption"))
    for x in (r, t, a):
        assert np.all(np.isfinite(x))
        assert np.all((x >= 0) & (x <= 1))
    np.testing.assert_allclose(r + t + a, 1.0, atol=1e-5)
    np.testing.assert_allclose(r + t + a - 1.0, s["energy_balance"].values, atol=1e-12)
    assert s["r00"].dtype.kind == "c"
    assert set(s["method"].values) <= {"born", "time-marching", "gmres", "bicgstab", "airy"}


def test_orders(tiny):
    o = tiny.orders
    assert o["orders_reflectance"].dims == ("order",)
    assert o.sizes["order"] == int(tiny.solves["n_orders"].sum())
    assert o["orders_theta_deg"].attrs["units"] == "deg"
    assert o["orders_reflectance"].attrs["units"] == "1"
    assert np.all((o["orders_theta_deg"] >= 0) & (o["orders_theta_deg"] < 90))
    for i in range(tiny.solves.sizes["solve"]):
        oi = tiny.orders_of(i)
        assert (oi["solve"] == i).all()
        # the orders add up to the totals
        np.testing.assert_allclose(oi["orders_reflectance"].sum(),
                                   tiny.solves["total_reflectance"][i], rtol=1e-9, atol=1e-15)
        np.testing.assert_allclose(oi["orders_transmittance"].sum(),
                                   tiny.solves["total_transmittance"][i], rtol=1e-9, atol=1e-15)
        assert ((oi["m"] == 0) & (oi["n"] == 0)).sum() == 1


def test_spectra(tiny):
    sp = tiny.spectra
    for k in ("reflectance", "transmittance", "absorption"):
        da = sp[k]
        assert da.dims == ("wavelength_nm", "above_deg")
        assert da.shape == (2, 4)
        assert da.attrs["units"] == "1"
        assert np.all(np.isfinite(da)) and np.all((da >= 0) & (da <= 1))
        assert sp[k + "_se"].shape == (2, 4)  # two realisations
    np.testing.assert_array_equal(sp["wavelength_nm"], [450.0, 600.0])
    np.testing.assert_array_equal(sp["above_deg"], [0.0, 8.0, 30.0, 45.0])
    assert sp["wavelength_nm"].attrs["units"] == "nm"
    assert sp["above_deg"].attrs["units"] == "deg"
    np.testing.assert_allclose(sp["reflectance"] + sp["transmittance"] + sp["absorption"], 1.0, atol=1e-5)
    # the ensemble mean is the mean of the solves from above
    s = tiny.solves
    for w in (450.0, 600.0):
        for p in (0.0, 30.0):
            m = (s["side"] == "above") & (s["wavelength_nm"] == w) & (s["polar_deg"] == p)
            np.testing.assert_allclose(sp["reflectance"].sel(wavelength_nm=w, above_deg=p),
                                       s["total_reflectance"].values[m.values].mean(), rtol=1e-12)


def test_brdf_table(tiny):
    ap = tiny.appearance
    tab = tiny.brdf
    assert tab.dims == ("wavelength_nm", "illumination_deg", "sy", "sx")
    assert tab.attrs["units"] == "sr-1"
    n = tab.sizes["sx"]
    assert tab.sizes["sy"] == n and n % 2 == 1
    cell = ap.attrs["table_cell"]
    np.testing.assert_allclose(tab["sx"], (np.arange(n) - n // 2) * cell)
    assert tab["sx"].attrs["units"] == "1"
    assert tab["theta_deg"].dims == ("sy", "sx") and tab["theta_deg"].attrs["units"] == "deg"
    assert tab["theta_deg"].sel(sx=0.0, sy=0.0) == 0.0
    assert np.isnan(tab["theta_deg"].values[0, 0])  # beyond the horizon
    assert np.all(tab.values >= 0) and np.all(np.isfinite(tab.values))
    assert tiny.btdf.dims == tab.dims
    # power in the table = diffuse (non-specular) reflected orders, mean over realisations
    s = tiny.solves
    for w in tab["wavelength_nm"].values:
        for a in tab["illumination_deg"].values:
            sel = np.flatnonzero(((s["side"] == "above") & (s["wavelength_nm"] == w)
                                  & (s["polar_deg"] == a)).values)
            diffuse = []
            for i in sel:
                o = tiny.orders_of(int(i))
                m = ((o["m"] != 0) | (o["n"] != 0)).values
                diffuse.append(o["orders_reflectance"].values[m].sum())
            p = float(tab.sel(wavelength_nm=w, illumination_deg=a).sum()) * cell ** 2
            np.testing.assert_allclose(p, np.mean(diffuse), rtol=1e-9, atol=1e-15)
    assert ap["brdf_diffuse"].dims == ("wavelength_nm", "illumination_deg", "viewing_deg")
    assert ap["brdf_diffuse"].attrs["units"] == "sr-1"
    assert ap["natural"].dims == ("wavelength_nm", "viewing_deg")


def test_colours(tiny):
    c = tiny.colours
    assert c["natural_lab"].dims == ("viewing_deg", "lab")
    assert list(c["lab"].values) == ["L*", "a*", "b*"]
    assert c["natural_srgb8"].dims == ("viewing_deg", "rgb")
    assert c["natural_srgb8"].dtype == np.uint8
    nv = c.sizes["viewing_deg"]
    assert c["tile_srgb8"].shape == (nv, 1 + tiny.appearance.sizes["illumination_deg"], 3)
    assert c["tile_label"].values[0] == "sky"
    assert np.isnan(c["tile_illumination_deg"].values[0])
    L = c["natural_lab"].sel(lab="L*").values
    assert np.all((L >= 0) & (L <= 100))
    # the sky strip is the tile's first column
    np.testing.assert_array_equal(c["tile_srgb8"].isel(tile_column=0), c["natural_srgb8"])


def test_geometry(tiny):
    g = tiny.geometry
    assert g["centers_nm"].dims == ("sphere", "xyz")
    assert g["centers_nm"].attrs["units"] == "nm"
    assert g["radii_nm"].attrs["units"] == "nm"
    assert list(g["species"].values) == ["p"]
    assert g.sizes["sphere"] > 0
    np.testing.assert_allclose(g["radii_nm"], 50.0)
    c = g["centers_nm"].values
    assert np.all(c >= 0) and np.all(c[:, :2] <= 400.0) and np.all(c[:, 2] <= 400.0)
    assert 0.1 < float(g["achieved_fraction"][0]) < 0.2
    st = tiny.statistics
    assert st["rdf"].dims == ("r",) and st["r"].attrs["units"] == "nm"
    assert st["profile_fraction"].dims == ("z",)
    assert st.sizes["z_edge"] == st.sizes["z"] + 1
    assert st.attrs["min_gap_nm_units"] == "nm"
    re = tiny.realisations
    assert re["seed"].dims == ("realisation",) and re.sizes["realisation"] == 2


def test_pngs(tiny):
    for data in (tiny.tile_png, tiny.picture_png):
        assert data[:8] == b"\x89PNG\r\n\x1a\n"


def test_stored_units_win(tiny, tmp_path):
    """An HDF5 `units` attribute, when the writer adds one, is preferred."""
    p = tmp_path / "with-units.h5"
    p.write_bytes(open(tiny.path, "rb").read())
    with h5py.File(p, "r+") as f:
        f["appearance/wavelengths_nm"].attrs["units"] = "nanometre"
        f["appearance/brdf_table"].attrs["units"] = "1/sr"
    r = inksim.open_result(p)
    assert r.appearance["wavelength_nm"].attrs["units"] == "nanometre"
    assert r.brdf.attrs["units"] == "1/sr"
    assert r.appearance["reflectance"].attrs["units"] == "1"  # the table fills in the rest


def test_missing_file(tmp_path):
    with pytest.raises(FileNotFoundError, match="no such result file"):
        inksim.open_result(tmp_path / "nope.h5")


def test_datatree(tiny):
    xr = pytest.importorskip("xarray")
    if not hasattr(xr, "DataTree"):
        pytest.skip("xarray without DataTree")
    t = tiny.to_datatree()
    assert t["appearance"]["reflectance"].dims == ("wavelength_nm", "above_deg")
    assert t.attrs["seed"] == 3


def _stack_layer(pigment):
    return f"""[[stack]]
[stack.layer]
thickness_nm = 200.0
fragment_nm = [400.0, 400.0]
binder_index = 1.5
[[stack.pigment]]
name = "{pigment}"
material = {{ builtin = "{pigment}" }}
pvc = 0.15
diameter_nm = 100.0

"""


STACK_SCENE = """\
seed = 3
realisations = 2

""" + _stack_layer("yellow") + _stack_layer("blue") + """\
[grid]
cell_nm = 50.0
z_cell_nm = 50.0

[illumination]
wavelengths_nm = [450.0, 600.0]
polar_deg = [0.0]

[appearance]
outputs = ["tile"]

[output]
name = "stack"
"""


def test_stack(binary, tmp_path):
    cfg = tmp_path / "stack.toml"
    cfg.write_text(STACK_SCENE, encoding="utf-8")
    r = inksim.run(cfg, tmp_path / "out").open()
    st = r.stack
    assert st is not None and "stack" in repr(r)
    assert st.sizes["layer"] == 2 and st.sizes["wavelength_nm"] == 2
    assert st["r_down"].dims == ("layer", "wavelength_nm", "node", "node_in")
    assert list(st["layer_pigments"].values) == ["yellow", "blue"]
    # Each layer's columns: what is reflected and transmitted is at most
    # what arrived (the rest is absorbed).
    out = (st["r_down"] + st["t_down"]).sum("node")
    assert float(out.max()) <= 1.0 + 1e-6 and float(out.min()) > 0.0
    # The stack in air conserves energy.
    total = st["reflectance"] + st["transmittance"] + st["absorption"]
    np.testing.assert_allclose(total.values, 1.0, atol=1e-12)
    assert st["reflectance"].attrs["units"] == "1"
    # Its colours are where a single layer's are.
    assert r.appearance["natural"].dims == ("wavelength_nm", "viewing_deg")
