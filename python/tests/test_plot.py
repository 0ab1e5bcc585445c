"""The plotting helpers make figures with labelled axes (Agg backend)."""

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

import inksim  # noqa: E402


def test_plot_spectra(tiny, tmp_path):
    fig = inksim.plot_spectra(tiny)
    axes = fig.axes
    assert len(axes) == 3
    for ax, q in zip(axes, ("Reflectance", "Transmittance", "Absorption")):
        assert ax.get_xlabel() == "Wavelength λ (nm)"
        assert ax.get_ylabel().startswith(q)
        assert len(ax.get_lines()) >= 2  # one per angle (error bars add more)
    assert axes[0].get_legend() is not None
    fig.savefig(tmp_path / "s.png")
    assert (tmp_path / "s.png").stat().st_size > 1000
    plt.close(fig)


def test_plot_brdf(tiny, tmp_path):
    fig = inksim.plot_brdf(tiny, wavelength=600)
    curve, polar, cbar = fig.axes
    assert curve.get_xlabel().endswith("(°)")
    assert curve.get_ylabel() == "BRDF f (sr⁻¹)"
    assert polar.name == "polar"
    assert "°" in polar.get_xlabel()
    assert cbar.get_ylabel() == "BRDF f (sr⁻¹)"  # the colour bar
    assert "600 nm" in polar.get_title()
    fig.savefig(tmp_path / "b.png")
    plt.close(fig)
    fig = inksim.plot_brdf(tiny, wavelength=450, which="btdf")
    assert fig.axes[1].name == "polar" and "BTDF" in fig.axes[2].get_ylabel()
    plt.close(fig)


def test_in_plane_matches_stored(tiny):
    """The curve read off the table agrees with the stored brdf_diffuse."""
    ap = tiny.appearance
    for w in ap["wavelength_nm"].values:
        c = inksim.brdf_in_plane(tiny, w, theta_deg=ap["viewing_deg"].values)
        assert c.dims == ("illumination_deg", "theta_deg")
        assert c.attrs["units"] == "sr-1"
        np.testing.assert_allclose(c.values, ap["brdf_diffuse"].sel(wavelength_nm=w).values,
                                   rtol=1e-9, atol=1e-15)
    m = inksim.brdf_on_grid(tiny)
    assert m.dims == ("theta_deg", "phi_deg") and np.all(np.isfinite(m)) and np.all(m >= 0)


def test_show_tile(tiny):
    fig = inksim.show_tile(tiny)
    (ax,) = fig.axes
    (img,) = ax.get_images()
    assert img.get_array().shape[2] in (3, 4)
    assert ax.get_title().endswith("tile")
    plt.close(fig)
    fig = inksim.show_tile(tiny, which="picture")
    assert fig.axes[0].get_images()
    plt.close(fig)


def test_no_table(tiny, tmp_path):
    import h5py

    p = tmp_path / "no-table.h5"
    p.write_bytes(open(tiny.path, "rb").read())
    with h5py.File(p, "r+") as f:
        del f["appearance/btdf_table"]
    r = inksim.open_result(p)
    with pytest.raises(ValueError, match="btdf"):
        inksim.plot_brdf(r, which="btdf")
