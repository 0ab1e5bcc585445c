"""Results of ``inksim match`` (recipes for a target colour) and
``inksim fit-material`` (a colourant's constants from drawdowns), read into
xarray on the axes the files label (docs/MATCH.md).

>>> m = inksim.open_match("runs/match-red-tint/match-red-tint.h5")
>>> m.recipes["pvc"].sel(recipe=0)        # the best recipe's PVC per pigment
>>> m.recipe(1)                            # rank 1's unknowns with s.e. and flags
>>> m.verified[0][["de00", "de00_se"]]    # the wave verification, step by step
>>> f = inksim.open_fit("runs/fit-red/fit-red.h5")
>>> f.constants[["k", "k_se"]]             # k(λ) with its standard error
"""

import os
from typing import Any, Dict, List

import h5py
import numpy as np
import xarray as xr

from .result import _attrs, _dims, _var


def _dataset(f: h5py.File, group: str, coords_from: h5py.Group) -> xr.Dataset:
    """The datasets of ``group`` as variables; the 1-D datasets of
    ``coords_from`` whose name is their own axis as coordinates. A square
    matrix on one axis twice (a correlation) gets ``<axis>_2`` as its second
    axis name."""
    g = f[group] if group else f
    data: Dict[str, xr.Variable] = {}
    for k, ds in g.items():
        if not isinstance(ds, h5py.Dataset):
            continue
        key = f"{group}/{k}" if group else k
        dims = _dims(key, ds.shape, ds)
        if len(dims) == 2 and dims[0] == dims[1]:
            dims = (dims[0], f"{dims[1]}_2")
        v = _var(key, ds, dims)
        if group == "" and v.dims == (k,):
            continue  # an axis: a coordinate below
        data[k] = v
    dims = {d for v in data.values() for d in v.dims}
    coords = {}
    for k, ds in coords_from.items():
        if isinstance(ds, h5py.Dataset) and k in dims and ds.ndim == 1:
            coords[k] = _var(k, ds, (k,))
    return xr.Dataset(data, coords=coords, attrs=_attrs(g))


class MatchResult:
    """One ``inksim match`` result file.

    - ``attrs``: the run's settings and outcome (objective, tolerance,
      illuminant, observer, model, whether the tolerance was reached, the
      exact match file as ``match_toml``, version);
    - ``target``: the target's CIELAB per geometry and its noise;
    - ``palette``: the pigments and their PVC bounds;
    - ``recipes``: every recipe's PVC per pigment, thickness and ΔE00 per
      geometry with its standard error from the target's noise
      (``de00_se``), on a ``recipe`` axis (0 the best); for an effect paint
      (``attrs["kind"] == "effect"``) its flake ``concentration`` and
      ``coating_nm`` per ``flake_layer`` and ``flop_index``,
      with the target's ``flop_index`` in ``target.attrs``;
    - ``recipe(i)``: recipe ``i``'s unknowns with standard errors,
      correlations and flags, its CIELAB and reflectance factor;
    - ``verified``: with ``[match.verify]``, one dataset per verified recipe
      on a ``step`` axis (0 the fast model's recipe, k after k corrections):
      its PVC per pigment, the wave solution's CIELAB with standard error,
      the fast model's CIELAB of the same recipe, ΔE00 to the target and the
      fast model's error, each step's result file; attributes ``rank``,
      ``verified`` and ``outcome``. ``verify_fidelity`` says what the wave
      solver solved at (None without a verification).
    """

    def __init__(self, path: str):
        self.path = path
        with h5py.File(path, "r") as f:
            if "recipes" not in f or "target" not in f:
                raise ValueError(f"{path}: not an `inksim match` result (no /recipes, /target)")
            self.attrs: Dict[str, Any] = _attrs(f)
            self.target = _dataset(f, "target", f)
            self.palette = _dataset(f, "palette", f)
            self.recipes = _dataset(f, "recipes", f)
            self._recipes: List[xr.Dataset] = [
                _dataset(f, f"recipes/{name}", f)
                for name in sorted(k for k in f["recipes"] if isinstance(f["recipes"][k], h5py.Group))
            ]
            self.verified: List[xr.Dataset] = []
            self.verify_fidelity = None
            if "verify" in f:
                self.verify_fidelity = _attrs(f["verify"]).get("fidelity")
                for name in sorted(f["verify"]):
                    g = f["verify"][name]
                    if isinstance(g, h5py.Group):
                        ds = _dataset(f, f"verify/{name}", f)
                        self.verified.append(ds.set_coords("step") if "step" in ds else ds)

    def recipe(self, i: int) -> xr.Dataset:
        """Recipe ``i`` (0 the best) in full."""
        return self._recipes[i]

    def __len__(self) -> int:
        return len(self._recipes)

    def __repr__(self) -> str:
        lines = [f"<inksim.MatchResult {os.path.basename(self.path)}: {len(self)} recipe(s), "
                 f"objective {self.attrs.get('objective')}, reached {bool(self.attrs.get('reached'))}>"]
        for i in range(len(self)):
            parts = []
            if "pvc" in self.recipes:
                pvc = self.recipes["pvc"].isel(recipe=i)
                parts += [f"{p} {float(v):.4f}" for p, v in zip(pvc["pigment"].values, pvc.values) if v > 0]
            if "concentration" in self.recipes:  # an effect paint's flakes
                c = self.recipes["concentration"].isel(recipe=i)
                t = self.recipes["coating_nm"].isel(recipe=i)
                for layer, cv, tv in zip(c["flake_layer"].values, c.values, t.values):
                    parts.append(f"{layer} flakes {float(cv):.4f}"
                                 + ("" if np.isnan(tv) else f", coating {float(tv):.1f} nm"))
            used = ", ".join(parts)
            de = self.recipes["de00"].isel(recipe=i).values
            lines.append(f"  {i}: {used}; ΔE00 {', '.join(f'{x:.2f}' for x in de)}")
        return "\n".join(lines)


class FitResult:
    """One ``inksim fit-material`` result file.

    - ``attrs``: the fit's settings and outcome (pigment, unknowns, fitted
      diameter with its s.e., χ² and degrees of freedom, residual RMS,
      the exact fit file as ``fit_toml``, input hashes, version);
    - ``constants``: n and k per wavelength with standard errors, their
      correlation, flags and residual RMS;
    - ``residuals``: per wavelength and drawdown reading;
    - ``drawdowns``: each reading's PVC, white PVC and thickness.
    """

    def __init__(self, path: str):
        self.path = path
        with h5py.File(path, "r") as f:
            if "n" not in f or "k" not in f or "drawdowns" not in f:
                raise ValueError(f"{path}: not an `inksim fit-material` result (no /n, /k, /drawdowns)")
            self.attrs = _attrs(f)
            root = _dataset(f, "", f)
            self.constants = root[[v for v in root.data_vars if "reading" not in root[v].dims]]
            self.residuals = root["residuals"]
            self.drawdowns = _dataset(f, "drawdowns", f)

    def __repr__(self) -> str:
        k = self.constants["k"]
        return (f"<inksim.FitResult {os.path.basename(self.path)}: {self.attrs.get('pigment')}, "
                f"{k.sizes['wavelength_nm']} wavelengths, unknowns {self.attrs.get('unknowns')}, "
                f"χ² {float(self.attrs.get('chi2', np.nan)):.1f} on {self.attrs.get('dof')} dof>")


def open_match(path: "os.PathLike[str] | str") -> MatchResult:
    """Read an ``inksim match`` result (``<name>.h5``)."""
    p = os.fspath(path)
    if not os.path.exists(p):
        raise FileNotFoundError(f"{p}: no such match result")
    return MatchResult(p)


def open_fit(path: "os.PathLike[str] | str") -> FitResult:
    """Read an ``inksim fit-material`` result (``<name>.h5``)."""
    p = os.fspath(path)
    if not os.path.exists(p):
        raise FileNotFoundError(f"{p}: no such fit result")
    return FitResult(p)
