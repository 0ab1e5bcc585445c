"""Matplotlib figures of a result: spectra, BRDF, the stored tile.

Every function returns the :class:`matplotlib.figure.Figure` it drew (a new
one unless axes are passed), with axis labels and units; save it with
``fig.savefig("x.png")``. matplotlib is imported when a function is called,
so ``import inksim`` does not choose a backend.
"""

from __future__ import annotations

import io
from typing import Optional, Sequence

import numpy as np
import xarray as xr

from ._layout import axis_label
from .result import Result

__all__ = ["plot_spectra", "plot_brdf", "show_tile", "brdf_in_plane", "brdf_on_grid"]

_QUANTITIES = [
    ("reflectance", "Reflectance R"),
    ("transmittance", "Transmittance T"),
    ("absorption", "Absorption A"),
]


def _units(da: xr.DataArray, default: Optional[str] = None) -> Optional[str]:
    return da.attrs.get("units", default)


def plot_spectra(result: Result, axes: Optional[Sequence] = None, figsize=(11, 3.6)):
    """Total reflectance, transmittance and absorption against wavelength,
    one line per angle of incidence (error bars: standard errors, when the
    file has them). Returns the figure."""
    import matplotlib.pyplot as plt

    sp = result.spectra
    if axes is None:
        fig, axes = plt.subplots(1, 3, figsize=figsize, sharex=True, constrained_layout=True)
    else:
        fig = axes[0].figure
    wl = sp["wavelength_nm"]
    angles = sp["above_deg"].values
    colours = plt.cm.viridis(np.linspace(0.0, 0.85, max(len(angles), 1)))
    for ax, (name, label) in zip(axes, _QUANTITIES):
        da = sp[name]
        se = sp.get(name + "_se")
        for j, a in enumerate(angles):
            y = da.isel(above_deg=j).values
            kw = dict(color=colours[j], marker="o", ms=4, label=f"θᵢ = {a:g}°")
            if se is not None:
                ax.errorbar(wl.values, y, yerr=se.isel(above_deg=j).values, capsize=3, **kw)
            else:
                ax.plot(wl.values, y, **kw)
        ax.set_xlabel(axis_label("Wavelength λ", _units(wl, "nm")))
        ax.set_ylabel(axis_label(label, _units(da, "1")))
        ax.set_title(label.split()[0])
        ax.grid(True, alpha=0.3)
        lo, hi = np.nanmin(da.values), np.nanmax(da.values)
        pad = max(0.05 * (hi - lo), 0.01)
        ax.set_ylim(max(0.0, lo - pad), min(1.0, hi + pad) if hi <= 1 else hi + pad)
    axes[0].legend(title="incidence", fontsize="small")
    fig.suptitle(f"{_name(result)}: total R, T, A (light from above)")
    return fig


def _name(result: Result) -> str:
    import os

    return os.path.basename(result.path)


def _table(result: Result, which: str) -> xr.DataArray:
    tab = result.brdf if which == "brdf" else result.btdf
    if tab is None:
        raise ValueError(
            f"{result.path}: no {which}_table in /appearance "
            f"(the scene's [appearance] outputs must include \"{which}\")"
        )
    return tab


def _coverage(result: Result) -> np.ndarray:
    """Each table node's share of its kernel above the horizon
    (``/appearance/table_coverage``): the BRDF is the density over it."""
    return np.asarray(result.appearance["table_coverage"].values, dtype=float)


def _interp(density: np.ndarray, cell: float, sx: np.ndarray, sy: np.ndarray) -> np.ndarray:
    """Bilinear interpolation of a node table ``density[j, i]`` at ``(sx, sy)``
    (as the Rust ``AngularTable::density_at``; NaN outside the table)."""
    n = density.shape[-1]
    half = n // 2
    x = np.asarray(sx, dtype=float) / cell + half
    y = np.asarray(sy, dtype=float) / cell + half
    inside = (x >= 0) & (y >= 0) & (x <= n - 1) & (y <= n - 1)
    xc = np.clip(x, 0, n - 1)
    yc = np.clip(y, 0, n - 1)
    i = np.minimum(np.floor(xc).astype(int), n - 2)
    j = np.minimum(np.floor(yc).astype(int), n - 2)
    fx, fy = xc - i, yc - j
    d = density
    v = (d[j, i] * (1 - fx) * (1 - fy) + d[j, i + 1] * fx * (1 - fy)
         + d[j + 1, i] * (1 - fx) * fy + d[j + 1, i + 1] * fx * fy)
    return np.where(inside, v, np.nan)


def _select(tab: xr.DataArray, wavelength: Optional[float], illumination: Optional[float]):
    wl = tab["wavelength_nm"].values
    w = wl[len(wl) // 2] if wavelength is None else float(wavelength)
    t = tab.sel(wavelength_nm=w, method="nearest")
    if illumination is not None:
        t = t.sel(illumination_deg=float(illumination), method="nearest")
    return t


def brdf_in_plane(result: Result, wavelength: Optional[float] = None,
                  illumination: Optional[float] = None, which: str = "brdf",
                  theta_deg: Optional[np.ndarray] = None) -> xr.DataArray:
    """The diffuse BRDF (or BTDF) f = D / C in the plane of incidence (D the
    table's density, C its nodes' coverage above the horizon), read off the
    angular table by bilinear interpolation, over a signed
    viewing angle ``theta_deg`` (positive: specular side, φ = azimuth;
    negative: back towards the source). Dims (illumination_deg, theta_deg)
    or (theta_deg) when one illumination angle is chosen."""
    tab = _select(_table(result, which), wavelength, illumination)
    cell = float(result.appearance.attrs["table_cell"])
    az = np.radians(float(result.appearance.attrs.get("azimuth_deg", 0.0)))
    th = np.linspace(-80.0, 80.0, 321) if theta_deg is None else np.asarray(theta_deg, dtype=float)
    s = np.sin(np.radians(th))
    sx, sy = s * np.cos(az), s * np.sin(az)
    cov = _interp(_coverage(result), cell, sx, sy)
    data = tab.values
    if data.ndim == 2:
        vals = _interp(data, cell, sx, sy) / cov
        dims = ("theta_deg",)
    else:
        vals = np.stack([_interp(data[k], cell, sx, sy) / cov for k in range(data.shape[0])])
        dims = ("illumination_deg", "theta_deg")
    coords = {"theta_deg": ("theta_deg", th, {"units": "deg",
                                              "long_name": "signed viewing angle in the plane of incidence"})}
    if "illumination_deg" in dims:
        coords["illumination_deg"] = tab["illumination_deg"]
    return xr.DataArray(vals, dims=dims, coords=coords, name=f"{which}_in_plane",
                        attrs={"units": tab.attrs.get("units", "sr-1"),
                               "long_name": f"diffuse {which.upper()} f in the plane of incidence",
                               "wavelength_nm": float(tab["wavelength_nm"])})


def brdf_on_grid(result: Result, wavelength: Optional[float] = None,
                 illumination: Optional[float] = None, which: str = "brdf",
                 theta_max_deg: float = 80.0, n_theta: int = 81, n_phi: int = 181) -> xr.DataArray:
    """f = D / C on a regular (θ, φ) grid, for one wavelength and one
    illumination angle (default: the largest)."""
    tab = _table(result, which)
    if illumination is None:
        illumination = float(tab["illumination_deg"].values[-1])
    t = _select(tab, wavelength, illumination)
    cell = float(result.appearance.attrs["table_cell"])
    th = np.linspace(0.0, theta_max_deg, n_theta)
    ph = np.linspace(-180.0, 180.0, n_phi)
    T, P = np.meshgrid(np.radians(th), np.radians(ph), indexing="ij")
    sx, sy = np.sin(T) * np.cos(P), np.sin(T) * np.sin(P)
    vals = _interp(t.values, cell, sx, sy) / _interp(_coverage(result), cell, sx, sy)
    return xr.DataArray(
        vals, dims=("theta_deg", "phi_deg"),
        coords={"theta_deg": ("theta_deg", th, {"units": "deg", "long_name": "polar angle"}),
                "phi_deg": ("phi_deg", ph, {"units": "deg", "long_name": "azimuth"})},
        name=f"{which}_map",
        attrs={"units": t.attrs.get("units", "sr-1"),
               "long_name": f"diffuse {which.upper()} f",
               "wavelength_nm": float(t["wavelength_nm"]),
               "illumination_deg": float(t["illumination_deg"])})


def plot_brdf(result: Result, wavelength: Optional[float] = None,
              illumination: Optional[float] = None, which: str = "brdf", figsize=(11, 4.6)):
    """Two panels for one wavelength (default: the middle one; nearest is
    taken): the diffuse BRDF in the plane of incidence for every
    illumination angle (lines from the table; markers: the stored
    ``brdf_diffuse`` at the viewing angles), and a polar map of the BRDF
    over the hemisphere for one illumination angle (default: the largest)
    with a colour bar. ``which="btdf"`` draws the transmission side.
    Returns the figure."""
    import matplotlib.pyplot as plt

    tab = _table(result, which)
    curve = brdf_in_plane(result, wavelength, None, which)
    grid = brdf_on_grid(result, wavelength, illumination, which)
    lam = curve.attrs["wavelength_nm"]
    units = curve.attrs["units"]
    fig = plt.figure(figsize=figsize, constrained_layout=True)
    ax = fig.add_subplot(1, 2, 1)
    ill = tab["illumination_deg"].values
    colours = plt.cm.viridis(np.linspace(0.0, 0.85, max(len(ill), 1)))
    diffuse_name = f"{which}_diffuse"
    diffuse = result.appearance.get(diffuse_name)
    for k, a in enumerate(ill):
        ax.plot(curve["theta_deg"], curve.isel(illumination_deg=k), color=colours[k],
                label=f"θᵢ = {a:g}°")
        if diffuse is not None:
            pts = diffuse.sel(wavelength_nm=lam).isel(illumination_deg=k)
            ax.plot(pts["viewing_deg"], pts, "o", color=colours[k], ms=5)
        if which == "brdf" and a > 0:
            ax.axvline(a, color=colours[k], ls=":", lw=0.8)
    ax.set_xlabel(axis_label("Viewing angle θ (+: specular side)", "deg"))
    ax.set_ylabel(axis_label(f"{which.upper()} f", units))
    ax.set_xlim(-90, 90)
    ax.set_ylim(bottom=0.0)
    ax.set_xticks(np.arange(-90, 91, 30))
    ax.grid(True, alpha=0.3)
    ax.legend(title="illumination", fontsize="small")
    ax.set_title(f"Plane of incidence, λ = {lam:g} nm\n(dotted: specular direction, not in the diffuse table)",
                 fontsize="medium")

    pax = fig.add_subplot(1, 2, 2, projection="polar")
    phi = np.radians(grid["phi_deg"].values)
    th = grid["theta_deg"].values
    top = float(np.nanmax(grid.values)) if np.isfinite(grid.values).any() else 0.0
    mesh = pax.pcolormesh(phi, th, grid.values, shading="auto", cmap="magma",
                          vmin=0.0, vmax=top if top > 0 else 1.0)
    if top <= 0:
        pax.text(0.5, 0.3, "no diffuse orders\npropagate here", transform=pax.transAxes,
                 ha="center", va="center", color="w", fontsize="small")
    pax.set_theta_zero_location("E")
    pax.set_rlim(0, float(th[-1]))
    ticks = [t for t in (30, 60, 80) if t <= th[-1]]
    pax.set_rticks(ticks)
    pax.set_yticklabels([f"{t}°" for t in ticks], color="w", fontsize="small")
    pax.set_xlabel(axis_label("Azimuth φ", "deg") + "; radius: polar angle θ (°)")
    ia = grid.attrs["illumination_deg"]
    if which == "brdf":
        azd = float(result.appearance.attrs.get("azimuth_deg", 0.0))
        pax.plot([np.radians(azd)], [ia], marker="+", color="c", ms=12, mew=2, ls="none",
                 label="specular")
        pax.legend(loc="upper left", bbox_to_anchor=(-0.2, 1.05), fontsize="small")
    cb = fig.colorbar(mesh, ax=pax, pad=0.06, shrink=0.9)
    cb.set_label(axis_label(f"{which.upper()} f", units))
    pax.set_title(f"Hemisphere, λ = {lam:g} nm, θᵢ = {ia:g}°", fontsize="medium")
    fig.suptitle(f"{_name(result)}: diffuse {which.upper()}")
    return fig


def show_tile(result: Result, ax=None, which: str = "tile", figsize=None):
    """Show the PNG stored in the file: ``which="tile"`` the result tile
    (``/appearance/tile_png``: white-sky strip beside the BRDF square),
    ``"picture"`` the orders picture (``/picture_png``). Returns the figure."""
    import matplotlib.image as mpimg
    import matplotlib.pyplot as plt

    data = result.tile_png if which == "tile" else result.picture_png
    if data is None:
        where = "/appearance/tile_png" if which == "tile" else "/picture_png"
        raise ValueError(f"{result.path}: no {where} in the file")
    img = mpimg.imread(io.BytesIO(data), format="png")
    if ax is None:
        h, w = img.shape[:2]
        if figsize is None:
            scale = 4.0 / max(h, w) * (2.0 if which == "tile" else 2.2)
            figsize = (max(w * scale, 3.0), max(h * scale, 2.0) + 0.4)
        fig, ax = plt.subplots(figsize=figsize, constrained_layout=True)
    else:
        fig = ax.figure
    ax.imshow(img, interpolation="nearest")
    ax.set_xticks([])
    ax.set_yticks([])
    ax.set_title(f"{_name(result)}: {'tile' if which == 'tile' else 'orders picture'}")
    return fig
