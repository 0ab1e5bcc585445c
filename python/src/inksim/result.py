"""Reading one inksim result file (``<name>.h5``) into labelled arrays.

``open_result(path)`` reads the whole file at once (result files are small:
the largest arrays are the particle set and the per-solve orders) and closes
it, so the returned :class:`Result` holds no open HDF5 handle. Each part of
the file is an :class:`xarray.Dataset` whose variables keep their HDF5 names
and carry ``units`` and ``long_name`` attributes; dimensions are those the
file labels (HDF5 dimension labels), else those of the layout in
docs/FORMAT.md (see :mod:`inksim._layout`).
"""

from __future__ import annotations

import datetime as _dt
import os
from typing import Any, Dict, List, Optional

import h5py
import numpy as np
import xarray as xr

from ._layout import DERIVED, LAYOUT, lookup, units_of

__all__ = ["Result", "open_result"]

_LAB = ["L*", "a*", "b*"]
_RGB = ["R", "G", "B"]
_XYZ = ["x", "y", "z"]


def _py(v: Any) -> Any:
    """HDF5 attribute value as plain Python (str for strings, numbers, arrays)."""
    if isinstance(v, bytes):
        return v.decode("utf-8")
    if isinstance(v, np.ndarray):
        if v.dtype.kind in ("S", "O"):
            return [x.decode("utf-8") if isinstance(x, bytes) else x for x in v.tolist()]
        return v
    if isinstance(v, np.generic):
        return v.item()
    return v


def _attrs(obj: h5py.HLObject) -> Dict[str, Any]:
    return {k: _py(obj.attrs[k]) for k in obj.attrs.keys()}


def _read(ds: h5py.Dataset) -> np.ndarray:
    if h5py.check_string_dtype(ds.dtype) is not None:
        return np.asarray(ds.asstr()[()], dtype=object)
    return ds[()]


# HDF5 dimension-scale bookkeeping (the H5DS API's attributes): the axes
# are read from them (``_dims``), they are not metadata of the values.
_SCALE_ATTRS = {"CLASS", "NAME", "REFERENCE_LIST", "DIMENSION_LIST", "DIMENSION_LABELS"}


def _meta(key: str, ds: Optional[h5py.Dataset] = None) -> Dict[str, str]:
    """``units`` (stored attribute first, then the layout table),
    ``long_name`` (the table's, else the stored ``description``) and the
    dataset's other attributes."""
    stored = ds.attrs.get("units") if ds is not None else None
    out: Dict[str, str] = {}
    u = units_of(key, stored)
    if u is not None:
        out["units"] = u
    try:
        out["long_name"] = lookup(key)[2]
    except KeyError:
        if ds is not None and "description" in ds.attrs:
            out["long_name"] = _py(ds.attrs["description"])
    if ds is not None:
        for k in ds.attrs.keys():
            if k != "units" and k not in _SCALE_ATTRS:
                out.setdefault(k, _py(ds.attrs[k]))
    return out


def _stored_dims(ds: Optional[h5py.Dataset]) -> Optional[tuple]:
    """The axis names the file gives (HDF5 dimension labels), when every
    axis of ``ds`` has one."""
    if ds is None or ds.ndim == 0:
        return None
    labels = tuple(d.label for d in ds.dims)
    return labels if all(labels) else None


def _dims(key: str, shape: tuple, ds: Optional[h5py.Dataset] = None) -> tuple:
    """Axis names: the file's dimension labels first, then the layout table's."""
    stored = _stored_dims(ds)
    if stored is not None and len(stored) == len(shape):
        return stored
    try:
        dims = lookup(key)[0]
    except KeyError:
        dims = ()
    if len(dims) != len(shape):
        base = key.rsplit("/", 1)[-1]
        dims = tuple(f"{base}_dim{i}" for i in range(len(shape)))
    return dims


def _var(key: str, ds: h5py.Dataset, dims: Optional[tuple] = None) -> xr.Variable:
    data = _read(ds)
    if dims is None:
        dims = _dims(key, data.shape, ds)
    return xr.Variable(dims, data, attrs=_meta(key, ds))


def _coord(key: str, data, dims) -> xr.Variable:
    return xr.Variable(dims, np.asarray(data), attrs=_meta(key))


def _derived(name: str, dims, data) -> xr.Variable:
    units, long_name = DERIVED[name]
    return xr.Variable(dims, np.asarray(data), attrs={"units": units, "long_name": long_name})


class Result:
    """One result file, read into labelled arrays.

    Attributes (all plain Python or xarray; ``None`` where the file has no
    such part):

    - ``path``: the file; ``attrs``: the root attributes;
    - ``version`` (``inksim_version``), ``format_version``, ``config_path``,
      ``input_hash``, ``seed``, ``created`` (UTC datetime), ``grid`` (nx, ny,
      nz), ``size_nm`` (Lx, Ly, H);
    - ``config``: the exact scene TOML text; ``plan``: the run's plan text;
    - ``solves``: Dataset over ``solve`` (one per ``/solves/NNNN``): the
      group attributes, with coordinates ``equation`` (``helmholtz`` |
      ``maxwell``) and ``polarisation`` (``unpolarised``, ``s``, ``p``, or
      ``none`` for the scalar wave; the keyword of the stored text). A
      file written before these attributes were stored holds only
      Helmholtz solves: ``equation`` reads ``helmholtz`` and
      ``polarisation`` ``none`` there. ``total_reflectance``,
      ``total_transmittance``, ``absorption``, ``energy_balance`` are the
      solve's (for Maxwell's unpolarised light the mean of s and p); the
      same with suffix ``_s`` / ``_p`` are each polarisation's own, NaN
      where the solve has no such polarisation (Helmholtz, a Maxwell
      run of the other one, or natural light solved as one random-phase
      state, whose relative phase of p to s is ``random_phase_deg``, NaN
      elsewhere);
    - ``orders``: Dataset over ``order``, every propagating order of every
      solve (coordinate ``solve`` says which), ``orders_of(i)`` one solve's:
      ``orders_reflectance``, ``orders_transmittance`` and, per
      polarisation, ``orders_reflectance_s`` / ``_p``,
      ``orders_transmittance_s`` / ``_p`` (NaN where absent);
    - ``spectra``: reflectance, transmittance, absorption over
      (``wavelength_nm``, ``above_deg``);
    - ``appearance``: the whole ``/appearance`` group, ``brdf`` /
      ``btdf``: the angular tables with their node directions;
    - ``colours``: CIELAB and sRGB8 of the tile and under natural light;
    - ``geometry``, ``statistics``, ``realisations`` (and ``seeds``);
    - ``tile_png``, ``picture_png``: the stored PNG bytes.
    - ``stack``: ``/stack`` of a stack combined layer by layer, else None.
    - an effect paint's result (``kind`` ``"paint"`` in ``attrs``; no
      solves, orders or appearance): ``paint``, ``/paint`` as a Dataset
      (``brdf`` over ``wavelength_nm``, ``direction_deg``, ``view_deg``;
      ``mirror_reflectance``, ``albedo``, ``fourier_terms``);
      ``multiangle``, a Dataset over ``geometry`` (``illumination_deg``,
      ``aspecular_deg`` as coordinates; ``lab``, ``lch``, ``xyz``,
      ``reflectance_factor``, ``flop_index``; ``illuminant`` and
      ``observer_deg`` in ``attrs``); ``sparkle``, over
      ``sparkle_illumination_deg`` (``glints_per_mm2``,
      ``glints_per_cell``, ``glint_reflectance`` and the scalars
      ``viewing_distance_mm``, ``cell_area_mm2``, ``flakes_per_mm2``,
      ``graininess``), None without flakes.
    - ``hiding``: over a hiding chart (``substrate.kind = "chart"``),
      ``/appearance/hiding`` as a Dataset over ``geometry`` (``45/0``,
      ``d/8 SCI``, ``d/8 SCE``): ``contrast_ratio``, ``y_black``,
      ``y_white``, ``y_ground``, Kubelka's ``r_inf_y``, ``s_y_per_um``,
      ``k_y_per_um`` (µm⁻¹), ``k_over_s_y`` from the luminance factors,
      ``k_over_s_max`` and ``k_over_s_max_wavelength_nm``, and over
      (``geometry``, ``wavelength_nm``) ``r_inf``, ``s_per_um``,
      ``k_per_um``, ``k_over_s`` and the white half's
      ``ground_reflectance``; each with its ``*_se`` standard error where
      the file has one (NaN elsewhere), units in ``attrs``. ``contrast_ratio``
      (d/8 SCI where measured) is the shortcut to its value and error.
    """

    def __init__(self, path: "os.PathLike[str] | str"):
        self.path = os.fspath(path)
        with h5py.File(self.path, "r") as f:
            self.attrs: Dict[str, Any] = _attrs(f)
            self.config: Optional[str] = _read(f["config"]).item() if "config" in f else None
            self.plan: Optional[str] = _read(f["plan"]).item() if "plan" in f else None
            self.solves = _read_solves(f)
            self.orders = _read_orders(f)
            self.appearance = _read_appearance(f) if "appearance" in f else None
            self.geometry = _read_geometry(f) if "geometry" in f else None
            self.statistics = (
                _read_statistics(f) if "geometry/statistics" in f else None
            )
            self.realisations = _read_realisations(f) if "realisations" in f else None
            self.stack = _read_stack(f) if "stack" in f else None
            self.paint = _read_paint(f) if "paint" in f else None
            self.multiangle = _read_group(f, "paint/multiangle") if "paint/multiangle" in f else None
            self.sparkle = _read_group(f, "paint/sparkle") if "paint/sparkle" in f else None
            self.hiding = _read_hiding(f) if "appearance/hiding" in f else None
            self.picture_png: Optional[bytes] = (
                f["picture_png"][()].tobytes() if "picture_png" in f else None
            )
            self.tile_png: Optional[bytes] = (
                f["appearance/tile_png"][()].tobytes() if "appearance/tile_png" in f else None
            )

    # --- identity -------------------------------------------------------
    @property
    def version(self) -> Optional[str]:
        return self.attrs.get("inksim_version")

    @property
    def format_version(self) -> Optional[int]:
        return self.attrs.get("format_version")

    @property
    def config_path(self) -> Optional[str]:
        return self.attrs.get("config_path")

    @property
    def input_hash(self) -> Optional[str]:
        return self.attrs.get("input_hash")

    @property
    def seed(self) -> Optional[int]:
        return self.attrs.get("seed")

    @property
    def created(self) -> Optional[_dt.datetime]:
        t = self.attrs.get("created_unix_s")
        if t is None:
            return None
        return _dt.datetime.fromtimestamp(int(t), tz=_dt.timezone.utc)

    @property
    def grid(self) -> Optional[tuple]:
        g = self.attrs.get("grid")
        return None if g is None else tuple(int(x) for x in g)

    @property
    def size_nm(self) -> Optional[tuple]:
        s = self.attrs.get("size_nm")
        return None if s is None else tuple(float(x) for x in s)

    @property
    def seeds(self) -> Optional[np.ndarray]:
        """Seed of every realisation (``/realisations/seed``)."""
        return None if self.realisations is None else self.realisations["seed"].values

    # --- derived views -------------------------------------------------
    def orders_of(self, solve: int) -> xr.Dataset:
        """The propagating orders of one solve (index into ``solves``)."""
        return self.orders.isel(order=np.flatnonzero(self.orders["solve"].values == solve))

    @property
    def spectra(self) -> xr.Dataset:
        """Total reflectance, transmittance and absorption over
        (``wavelength_nm``, ``above_deg``), with ``*_se`` standard errors
        when the file has them. From ``/appearance`` when present, else
        the mean over realisations of the solves from above."""
        names = ["reflectance", "transmittance", "absorption"]
        if self.appearance is not None and "reflectance" in self.appearance:
            keep = [n for n in self.appearance.data_vars
                    if n in names or n in [x + "_se" for x in names]]
            ds = self.appearance[keep]
            return ds.drop_vars([c for c in ds.coords if c not in ("wavelength_nm", "above_deg")])
        s = self.solves
        above = s.isel(solve=np.flatnonzero(s["side"].values == "above"))
        wl = np.unique(above["wavelength_nm"].values)
        pol = np.unique(above["polar_deg"].values)
        out = {}
        for n, src in zip(names, ["total_reflectance", "total_transmittance", "absorption"]):
            a = np.full((wl.size, pol.size), np.nan)
            for i, w in enumerate(wl):
                for j, p in enumerate(pol):
                    m = (above["wavelength_nm"].values == w) & (above["polar_deg"].values == p)
                    if m.any():
                        a[i, j] = above[src].values[m].mean()
            out[n] = xr.Variable(("wavelength_nm", "above_deg"), a,
                                 attrs=_meta("appearance/" + n))
        return xr.Dataset(out, coords={
            "wavelength_nm": _coord("appearance/wavelengths_nm", wl, ("wavelength_nm",)),
            "above_deg": _coord("appearance/above_deg", pol, ("above_deg",)),
        })

    @property
    def brdf(self) -> Optional[xr.DataArray]:
        """``brdf_table`` (density per projected solid angle, sr⁻¹; f = density / ``table_coverage``) over (wavelength_nm,
        illumination_deg, sy, sx) with node directions ``sx``, ``sy``,
        ``theta_deg``, ``phi_deg``."""
        if self.appearance is None or "brdf_table" not in self.appearance:
            return None
        return self.appearance["brdf_table"]

    @property
    def btdf(self) -> Optional[xr.DataArray]:
        if self.appearance is None or "btdf_table" not in self.appearance:
            return None
        return self.appearance["btdf_table"]

    @property
    def colours(self) -> Optional[xr.Dataset]:
        """CIELAB and sRGB8 of the tile cells and under natural light."""
        if self.appearance is None:
            return None
        keep = [n for n in ("natural_lab", "natural_srgb8", "tile_lab", "tile_srgb8")
                if n in self.appearance]
        if not keep:
            return None
        return self.appearance[keep]

    @property
    def contrast_ratio(self) -> Optional[tuple]:
        """``(CR, standard error)`` over a hiding chart in d/8 SCI (ISO
        6504-3's geometry; else the first geometry measured); the error is
        NaN where the file has none. None without a chart."""
        if self.hiding is None:
            return None
        geoms = list(self.hiding["geometry"].values)
        g = "d/8 SCI" if "d/8 SCI" in geoms else geoms[0]
        h = self.hiding.sel(geometry=g)
        return float(h["contrast_ratio"]), float(h["contrast_ratio_se"])

    def to_datatree(self):
        """All parts as one ``xarray.DataTree`` (needs xarray ≥ 2024.10)."""
        try:
            from xarray import DataTree
        except ImportError as e:  # pragma: no cover - depends on xarray version
            raise ImportError("Result.to_datatree needs xarray >= 2024.10 (xarray.DataTree)") from e
        root = xr.Dataset(attrs={k: (v if not isinstance(v, np.ndarray) else v.tolist())
                                 for k, v in self.attrs.items()})
        root.attrs["config"] = self.config or ""
        root.attrs["plan"] = self.plan or ""
        parts = {"/": root, "/solves": self.solves, "/orders": self.orders}
        for name in ("appearance", "geometry", "statistics", "realisations", "stack", "hiding"):
            v = getattr(self, name)
            if v is not None:
                parts["/" + name] = v
        return DataTree.from_dict(parts)

    def __repr__(self) -> str:
        lines = [f"<inksim.Result {self.path}>",
                 f"  inksim {self.version}, format {self.format_version}, seed {self.seed}, "
                 f"grid {self.grid}, size_nm {self.size_nm}",
                 f"  solves: {self.solves.sizes.get('solve', 0)}, orders: {self.orders.sizes.get('order', 0)}"]
        if self.appearance is not None:
            lines.append("  appearance: " + ", ".join(f"{k} {v}" for k, v in self.appearance.sizes.items()))
        if self.geometry is not None:
            lines.append("  geometry: " + ", ".join(f"{k} {v}" for k, v in self.geometry.sizes.items()))
        if self.multiangle is not None:
            fi = self.multiangle.get("flop_index")
            lines.append(f"  paint: {self.multiangle.sizes.get('geometry', 0)} multi-angle geometries"
                         + (f", flop index {float(fi):.2f}" if fi is not None else ""))
        if self.stack is not None:
            lines.append("  stack: " + ", ".join(f"{k} {v}" for k, v in self.stack.sizes.items()))
        return "\n".join(lines)


def open_result(path: "os.PathLike[str] | str") -> Result:
    """Read an inksim result file (``<name>.h5``) into a :class:`Result`."""
    p = os.fspath(path)
    if not os.path.exists(p):
        raise FileNotFoundError(f"{p}: no such result file")
    return Result(p)


# --- readers ---------------------------------------------------------------

_SOLVE_COORDS = ["wavelength_nm", "polar_deg", "azimuth_deg", "side", "realisation", "method",
                 "equation", "polarisation"]
_TOTALS = ["total_reflectance", "total_transmittance", "absorption", "energy_balance"]
# Maxwell: each polarisation solved, its totals beside their mean.
_POLARISED_TOTALS = [f"{t}_{p}" for t in _TOTALS for p in ("s", "p")]
_SOLVE_VARS = _TOTALS + _POLARISED_TOTALS + [
    "random_phase_deg", "r00", "t00", "iterations", "operator_applications", "residual", "seconds", "note"]
_SOLVE_TEXT = ("side", "method", "note", "equation", "polarisation")
# What a solve group without the attribute holds: files written before
# ``equation`` and ``polarisation`` were stored are all scalar (Helmholtz).
_SOLVE_TEXT_DEFAULT = {"equation": "helmholtz", "polarisation": "none"}
_ORDER_EFFICIENCIES = ["orders_reflectance", "orders_transmittance"]
_ORDER_VARS = _ORDER_EFFICIENCIES + [f"{n}_{p}" for n in _ORDER_EFFICIENCIES for p in ("s", "p")]


def _polarisation_keyword(text: str) -> str:
    """The keyword of a stored ``polarisation`` attribute: ``unpolarised``
    (stored as ``unpolarised: the mean of s and p solved apart``), ``s``,
    ``p``, or ``none`` (stored as ``none (scalar wave: …)``)."""
    return text.split(":", 1)[0].split("(", 1)[0].strip()


def _solve_groups(f: h5py.File) -> List[h5py.Group]:
    if "solves" not in f:
        return []
    return [f["solves"][k] for k in sorted(f["solves"].keys())]


def _read_solves(f: h5py.File) -> xr.Dataset:
    groups = _solve_groups(f)
    cols: Dict[str, list] = {k: [] for k in _SOLVE_COORDS + _SOLVE_VARS}
    n_orders = []
    for g in groups:
        a = _attrs(g)
        for k in cols:
            v = a.get(k)
            if k in ("r00", "t00"):
                v = complex(v[0], v[1]) if v is not None else complex(np.nan, np.nan)
            elif v is None:
                v = _SOLVE_TEXT_DEFAULT.get(k, "") if k in _SOLVE_TEXT else np.nan
            elif k == "polarisation":
                v = _polarisation_keyword(v)
            cols[k].append(v)
        n_orders.append(g["orders_mn"].shape[0] if "orders_mn" in g else 0)
    n = len(groups)
    dims = ("solve",)
    coords = {"solve": xr.Variable(dims, np.arange(n), attrs={"long_name": "solve index (/solves/NNNN)"})}
    data = {}
    for k in _SOLVE_COORDS + _SOLVE_VARS:
        vals = cols[k]
        if k in _SOLVE_TEXT:
            arr = np.asarray(vals, dtype=object) if n else np.zeros(0, dtype=object)
        elif k in ("r00", "t00"):
            arr = np.asarray(vals, dtype=complex)
        elif k in ("realisation", "iterations", "operator_applications") and all(
                isinstance(v, (int, np.integer)) for v in vals):
            arr = np.asarray(vals, dtype=np.int64)
        else:
            arr = np.asarray(vals, dtype=float)
        var = xr.Variable(dims, arr, attrs=_meta(f"solves/*@{k}"))
        (coords if k in _SOLVE_COORDS else data)[k] = var
    data["n_orders"] = xr.Variable(dims, np.asarray(n_orders, dtype=np.int64),
                                   attrs={"long_name": "propagating orders of the solve"})
    return xr.Dataset(data, coords=coords)


def _read_orders(f: h5py.File) -> xr.Dataset:
    groups = _solve_groups(f)
    parts: Dict[str, list] = {k: [] for k in ["solve", "m", "n", "orders_theta_deg", "orders_phi_deg"]
                              + _ORDER_VARS + ["wavelength_nm", "polar_deg", "side"]}
    for i, g in enumerate(groups):
        if "orders_mn" not in g:
            continue
        mn = g["orders_mn"][()].reshape(-1, 2)
        k = mn.shape[0]
        parts["solve"].append(np.full(k, i))
        parts["m"].append(mn[:, 0])
        parts["n"].append(mn[:, 1])
        for name in ["orders_theta_deg", "orders_phi_deg"] + _ORDER_VARS:
            parts[name].append(g[name][()] if name in g else np.full(k, np.nan))
        a = _attrs(g)
        parts["wavelength_nm"].append(np.full(k, a.get("wavelength_nm", np.nan)))
        parts["polar_deg"].append(np.full(k, a.get("polar_deg", np.nan)))
        parts["side"].append(np.full(k, a.get("side", ""), dtype=object))

    def cat(name, dtype=None):
        if parts[name]:
            return np.concatenate(parts[name])
        return np.zeros(0, dtype=dtype or float)

    d = ("order",)
    coords = {
        "solve": xr.Variable(d, cat("solve", np.int64), attrs={"long_name": "solve index"}),
        "m": xr.Variable(d, cat("m", np.int32), attrs={"long_name": "order index m (along x)"}),
        "n": xr.Variable(d, cat("n", np.int32), attrs={"long_name": "order index n (along y)"}),
        "wavelength_nm": xr.Variable(d, cat("wavelength_nm"), attrs=_meta("solves/*@wavelength_nm")),
        "polar_deg": xr.Variable(d, cat("polar_deg"), attrs=_meta("solves/*@polar_deg")),
        "side": xr.Variable(d, cat("side", object), attrs=_meta("solves/*@side")),
        "orders_theta_deg": xr.Variable(d, cat("orders_theta_deg"), attrs=_meta("solves/*/orders_theta_deg")),
        "orders_phi_deg": xr.Variable(d, cat("orders_phi_deg"), attrs=_meta("solves/*/orders_phi_deg")),
    }
    data = {
        name: xr.Variable(d, cat(name), attrs=_meta("solves/*/" + name))
        for name in _ORDER_VARS
    }
    return xr.Dataset(data, coords=coords)


def _read_appearance(f: h5py.File) -> xr.Dataset:
    g = f["appearance"]
    axes = {
        "wavelengths_nm": "wavelength_nm",
        "above_deg": "above_deg",
        "illumination_deg": "illumination_deg",
        "viewing_deg": "viewing_deg",
        "below_deg": "below_deg",
    }
    coords: Dict[str, xr.Variable] = {}
    for src, dim in axes.items():
        if src in g:
            coords[dim] = _var("appearance/" + src, g[src], (dim,))
    attrs = _attrs(g)
    data: Dict[str, xr.Variable] = {}
    for name in g.keys():
        if name in axes or name == "tile_png" or not isinstance(g[name], h5py.Dataset):
            continue
        data[name] = _var("appearance/" + name, g[name])
    # Table node directions: s = (i - N//2) * cell (rows j along s_y).
    table = next((data[n] for n in ("brdf_table", "btdf_table") if n in data), None)
    if table is not None and "table_cell" in attrs:
        nn = table.shape[-1]
        s = (np.arange(nn) - nn // 2) * float(attrs["table_cell"])
        coords["sx"] = _derived("sx", ("sx",), s)
        coords["sy"] = _derived("sy", ("sy",), s)
        sx, sy = np.meshgrid(s, s)  # [j, i]
        rho = np.hypot(sx, sy)
        with np.errstate(invalid="ignore"):
            theta = np.where(rho <= 1.0, np.degrees(np.arcsin(np.minimum(rho, 1.0))), np.nan)
        coords["theta_deg"] = _derived("theta_deg", ("sy", "sx"), theta)
        coords["phi_deg"] = _derived("phi_deg", ("sy", "sx"), np.degrees(np.arctan2(sy, sx)))
    if any("tile_column" in v.dims for v in data.values()) and "illumination_deg" in coords:
        ill = coords["illumination_deg"].values
        coords["tile_illumination_deg"] = _derived(
            "tile_illumination_deg", ("tile_column",), np.concatenate([[np.nan], ill]))
        coords["tile_label"] = xr.Variable(
            ("tile_column",),
            np.asarray(["sky"] + [f"{a:g}°" for a in ill], dtype=object),
            attrs={"long_name": "tile column: the sky strip, then the illumination angle"})
    if any("lab" in v.dims for v in data.values()):
        coords["lab"] = xr.Variable(("lab",), np.asarray(_LAB, dtype=object))
    if any("rgb" in v.dims for v in data.values()):
        coords["rgb"] = xr.Variable(("rgb",), np.asarray(_RGB, dtype=object))
    ds = xr.Dataset(data, coords=coords)
    for k, v in attrs.items():
        ds.attrs[k] = v
        u = units_of("appearance@" + k)
        if u is not None:
            ds.attrs[k + "_units"] = u
    return ds


# Datasets of each /appearance/hiding/<geometry> group, by their axes.
_HIDING_SCALARS = ["contrast_ratio", "y_black", "y_white", "y_ground", "r_inf_y",
                   "s_y_per_um", "k_y_per_um", "k_over_s_y", "k_over_s_max",
                   "k_over_s_max_wavelength_nm"]
_HIDING_SPECTRA = ["r_inf", "s_per_um", "k_per_um", "k_over_s", "ground_reflectance"]


def _read_hiding(f: h5py.File) -> xr.Dataset:
    """``/appearance/hiding`` (docs/FORMAT.md) over ``geometry`` (and
    ``wavelength_nm``); a standard error the file lacks reads NaN."""
    hg = f["appearance/hiding"]
    groups = [hg[k] for k in hg.keys()]
    geometry = [_py(g.attrs["geometry"]) for g in groups]
    wl = f["appearance/wavelengths_nm"][()]
    data: Dict[str, xr.Variable] = {}

    def column(name: str, shape: tuple):
        first = next((g[name] for g in groups if name in g), None)
        out = np.full((len(groups),) + shape, np.nan)
        for i, g in enumerate(groups):
            if name in g:
                out[i] = np.asarray(g[name][()], dtype=float).reshape(shape)
        attrs = {} if first is None else _meta("appearance/hiding/" + name, first)
        return out, attrs

    for base, shape, dims in ([(n, (), ("geometry",)) for n in _HIDING_SCALARS]
                              + [(n, (wl.size,), ("geometry", "wavelength_nm"))
                                 for n in _HIDING_SPECTRA]):
        for name in (base, base + "_se"):
            if name.endswith("_se") and (base.startswith("y_") or base.endswith("_nm")
                                         or base == "ground_reflectance"):
                continue
            values, attrs = column(name, shape)
            if not attrs and name.endswith("_se"):
                attrs = dict(data[base].attrs)
                attrs["long_name"] = "standard error of " + attrs.get("long_name", base)
            data[name] = xr.Variable(dims, values, attrs=attrs)
    coords = {
        "geometry": xr.Variable(("geometry",), np.asarray(geometry, dtype=object)),
        "wavelength_nm": _coord("appearance/wavelengths_nm", wl, ("wavelength_nm",)),
    }
    return xr.Dataset(data, coords=coords, attrs=_attrs(hg))


def _read_group(f: h5py.File, name: str) -> xr.Dataset:
    """The datasets of group ``name`` (not its subgroups or PNG bytes), on
    the axes the file labels; 1-D datasets named after their own axis are
    coordinates, and so are those along ``geometry``'s angles."""
    g = f[name]
    data: Dict[str, xr.Variable] = {}
    coords: Dict[str, xr.Variable] = {}
    for k, ds in g.items():
        if not isinstance(ds, h5py.Dataset) or k.endswith("_png"):
            continue
        v = _var(f"{name}/{k}", ds)
        own_axis = v.dims == (k,) or (k == "illumination_deg" and v.ndim == 1)
        if own_axis or (v.dims == ("geometry",) and k == "aspecular_deg"):
            coords[k if v.dims != (k,) else v.dims[0]] = v
        else:
            data[k] = v
    return xr.Dataset(data, coords=coords, attrs=_attrs(g))


def _read_paint(f: h5py.File) -> xr.Dataset:
    """``/paint`` of an effect paint's result (docs/FORMAT.md)."""
    return _read_group(f, "paint")


def _read_stack(f: h5py.File) -> xr.Dataset:
    """``/stack`` of a stack combined layer by layer (docs/FORMAT.md): the
    adding method's directions, the stack's R, T, A in air, and each layer's
    flux matrices with a leading ``layer`` axis (``r_down``, ``t_down``,
    ``r_up``, ``t_up``: layer x wavelength x node (out) x node_in)."""
    g = f["stack"]
    coords = {
        "layer": _var("stack/layer_thickness_nm", g["layer_thickness_nm"], ("layer",)),
        "node": _var("stack/binder_polar_deg", g["binder_polar_deg"], ("node",)),
        "wavelength_nm": _var("stack/wavelengths_nm", g["wavelengths_nm"], ("wavelength_nm",)),
        "above_deg": _var("stack/above_deg", g["above_deg"], ("above_deg",)),
    }
    data: Dict[str, xr.Variable] = {}
    for name in g.keys():
        ds = g[name]
        if isinstance(ds, h5py.Dataset) and name not in (
            "layer_thickness_nm", "binder_polar_deg", "wavelengths_nm", "above_deg"
        ):
            data[name] = _var("stack/" + name, ds)
    layers = sorted((k for k in g.keys() if k.startswith("layer") and isinstance(g[k], h5py.Group)),
                    key=lambda k: int(k[len("layer"):]))
    for m in ("r_down", "t_down", "r_up", "t_up"):
        parts = [g[k][m] for k in layers]
        if parts:
            first = _var(f"stack/{layers[0]}/{m}", parts[0])
            stacked = np.stack([p[()] for p in parts])
            data[m] = xr.Variable(("layer",) + first.dims, stacked, attrs=first.attrs)
    return xr.Dataset(data, coords=coords, attrs=_attrs(g))


def _read_geometry(f: h5py.File) -> xr.Dataset:
    g = f["geometry"]
    data: Dict[str, xr.Variable] = {}
    coords: Dict[str, xr.Variable] = {}
    for name in g.keys():
        if not isinstance(g[name], h5py.Dataset):
            continue
        v = _var("geometry/" + name, g[name])
        if name == "species_names":
            coords["species"] = v
        else:
            data[name] = v
    if "centers_nm" in data:
        coords["xyz"] = xr.Variable(("xyz",), np.asarray(_XYZ, dtype=object))
    ds = xr.Dataset(data, coords=coords)
    for k, v in _attrs(g).items():
        ds.attrs[k] = v
        u = units_of("geometry@" + k)
        if u is not None:
            ds.attrs[k + "_units"] = u
    return ds


def _read_statistics(f: h5py.File) -> xr.Dataset:
    g = f["geometry/statistics"]
    data: Dict[str, xr.Variable] = {}
    coords: Dict[str, xr.Variable] = {}
    for name in g.keys():
        v = _var("geometry/statistics/" + name, g[name])
        if name == "rdf_r_nm":
            coords["r"] = v
        elif name == "profile_z_nm":
            coords["profile_z_nm"] = v
            e = v.values
            if e.size >= 2:
                coords["z"] = xr.Variable(("z",), 0.5 * (e[1:] + e[:-1]),
                                          attrs={"units": v.attrs.get("units", "nm"),
                                                 "long_name": "z bin centre"})
        else:
            data[name] = v
    if "species_names" in f["geometry"]:
        coords["species"] = _var("geometry/species_names", f["geometry/species_names"])
    ds = xr.Dataset(data, coords=coords)
    for k, v in _attrs(g).items():
        ds.attrs[k] = v
        u = units_of("geometry/statistics@" + k)
        if u is not None:
            ds.attrs[k + "_units"] = u
    return ds


def _read_realisations(f: h5py.File) -> xr.Dataset:
    g = f["realisations"]
    data = {}
    for name in g.keys():
        if isinstance(g[name], h5py.Dataset) and ("realisations/" + name) in LAYOUT:
            data[name] = _var("realisations/" + name, g[name])
    ds = xr.Dataset(data)
    n = max([v.shape[0] for v in data.values()] + [0])
    return ds.assign_coords(realisation=("realisation", np.arange(n)))
