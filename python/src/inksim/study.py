"""Reading a merged study (``summary.h5``, written by ``inksim merge``).

``open_study(path)`` takes the summary file or the folder holding it (or a
study output folder with exactly one profile folder inside) and returns a
:class:`Study`: the variant table as an :class:`xarray.Dataset` over
``variant``, with each axis's labels as a coordinate, the axis values where
the sweep file can still be read, and the colours; ``Study.result(name)``
opens one variant's result file.
"""

from __future__ import annotations

import os
from typing import Any, Dict, Iterator, List, Optional

import h5py
import numpy as np
import xarray as xr

from .result import Result, _attrs, _meta, _read, open_result

__all__ = ["Study", "open_study"]


def _find_summary(path: str) -> str:
    if os.path.isfile(path):
        return path
    if os.path.isdir(path):
        direct = os.path.join(path, "summary.h5")
        if os.path.isfile(direct):
            return direct
        subs = sorted(
            os.path.join(path, d, "summary.h5")
            for d in os.listdir(path)
            if os.path.isfile(os.path.join(path, d, "summary.h5"))
        )
        if len(subs) == 1:
            return subs[0]
        if len(subs) > 1:
            raise ValueError(
                f"{path}: several profiles have a summary.h5 ({', '.join(subs)}); pass one of them"
            )
        raise FileNotFoundError(
            f"{path}: no summary.h5 here; run `inksim merge <study.toml>` once every variant is finished"
        )
    raise FileNotFoundError(f"{path}: no such file or folder")


def _generated_label(axis: str, v: Any) -> Optional[str]:
    """The label inksim gives a simple-form axis value (src/study/sweep.rs)."""
    if isinstance(v, bool):
        return f"{axis}-{'true' if v else 'false'}"
    if isinstance(v, str):
        return v
    if isinstance(v, int):
        return f"{axis}{v}"
    if isinstance(v, float):
        if v.is_integer() and abs(v) < 1e15:
            return f"{axis}{int(v)}"
        return f"{axis}{np.format_float_positional(v, trim='-')}"
    return None


def _axis_values(sweep_file: str, base_dirs: List[str]) -> Dict[str, Dict[str, Any]]:
    """label → value for each simple-form axis of the sweep file, when it
    can be found and parsed (needs tomllib, Python ≥ 3.11, or tomli)."""
    try:
        import tomllib  # type: ignore[import-not-found]
    except ImportError:  # pragma: no cover - Python < 3.11
        try:
            import tomli as tomllib  # type: ignore[no-redef]
        except ImportError:
            return {}
    candidates = [sweep_file] if os.path.isabs(sweep_file) else [
        os.path.join(d, sweep_file) for d in [os.getcwd()] + base_dirs]
    for c in candidates:
        if os.path.isfile(c):
            try:
                with open(c, "rb") as fh:
                    doc = tomllib.load(fh)
            except Exception:
                return {}
            break
    else:
        return {}
    out: Dict[str, Dict[str, Any]] = {}
    for ax in doc.get("axis", []):
        name, values = ax.get("name"), ax.get("values")
        if not isinstance(name, str) or not isinstance(values, list):
            continue
        labels = ax.get("labels") or [_generated_label(name, v) for v in values]
        if len(labels) != len(values):
            continue
        out[name] = {lab: v for lab, v in zip(labels, values)
                     if lab is not None and isinstance(v, (int, float, str, bool))}
    return out


class Study:
    """A merged study.

    - ``path``: the summary file, ``dir``: its folder;
    - ``name``, ``profile``, ``sweep_file``: the root attributes;
    - ``table``: Dataset over ``variant`` (coordinate: the variant names)
      with coordinates ``id``, ``seed``, ``has_colour``, one per axis
      holding the labels (``""`` where a variant has none) and, where the
      sweep file is readable, ``<axis>_value``; data variables
      ``mean_reflectance``, ``mean_transmittance``, ``mean_absorption``,
      ``natural_srgb8`` (variant × rgb), ``natural_lab`` (variant × lab;
      NaN without colour) and ``colour_hex``;
    - ``axes``: axis name → its labels in order of first appearance;
    - ``variants``: the names; ``result(name)`` opens a variant's file.
    """

    def __init__(self, path: str):
        self.path = _find_summary(os.fspath(path))
        self.dir = os.path.dirname(os.path.abspath(self.path))
        with h5py.File(self.path, "r") as f:
            self.attrs: Dict[str, Any] = _attrs(f)
            names = [str(x) for x in _read(f["name"])]
            n = len(names)
            d = ("variant",)
            coords: Dict[str, xr.Variable] = {
                "variant": xr.Variable(d, np.asarray(names, dtype=object),
                                       attrs=_meta("study/name", f["name"])),
            }
            for k in ("id", "seed", "has_colour"):
                if k in f:
                    coords[k] = xr.Variable(d, _read(f[k]), attrs=_meta("study/" + k, f[k]))
            axes: Dict[str, List[str]] = {}
            if "labels" in f:
                for a in f["labels"].keys():
                    labs = [str(x) for x in _read(f["labels"][a])]
                    coords[a] = xr.Variable(d, np.asarray(labs, dtype=object),
                                            attrs={"long_name": f"label on axis {a}"})
                    seen: List[str] = []
                    for lab in labs:
                        if lab and lab not in seen:
                            seen.append(lab)
                    axes[a] = seen
            data: Dict[str, xr.Variable] = {}
            for k in ("mean_reflectance", "mean_transmittance", "mean_absorption"):
                if k in f:
                    data[k] = xr.Variable(d, _read(f[k]), attrs=_meta("study/" + k, f[k]))
            if "natural_srgb8" in f:
                data["natural_srgb8"] = xr.Variable(("variant", "rgb"), _read(f["natural_srgb8"]),
                                                    attrs=_meta("study/natural_srgb8", f["natural_srgb8"]))
        self.axes = axes
        # Colours in CIELAB from the variant files (the summary has sRGB only).
        lab = np.full((n, 3), np.nan)
        for i, name in enumerate(names):
            p = self.variant_path(name)
            if not os.path.isfile(p):
                continue
            try:
                with h5py.File(p, "r") as vf:
                    if "appearance/natural_lab" in vf:
                        lab[i] = vf["appearance/natural_lab"][0]
            except OSError:
                pass
        data["natural_lab"] = xr.Variable(("variant", "lab"), lab, attrs=_meta("study/natural_lab"))
        if "natural_srgb8" in data:
            has = coords["has_colour"].values if "has_colour" in coords else np.ones(n)
            rgb = data["natural_srgb8"].values
            hexes = ["#%02x%02x%02x" % tuple(int(c) for c in rgb[i]) if has[i] else ""
                     for i in range(n)]
            data["colour_hex"] = xr.Variable(d, np.asarray(hexes, dtype=object),
                                             attrs={"long_name": "sRGB colour as hex (\"\": none)"})
        values = _axis_values(str(self.attrs.get("sweep_file", "")),
                              [self.dir, os.path.dirname(self.dir), os.path.dirname(os.path.dirname(self.dir))]) \
            if self.attrs.get("sweep_file") else {}
        if values:  # axes in sweep-file order (HDF5 lists the labels group by name)
            order = [a for a in values if a in self.axes] + [a for a in self.axes if a not in values]
            self.axes = {a: self.axes[a] for a in order}
        for a, mapping in values.items():
            if a not in coords:
                continue
            labs = coords[a].values
            vals = [mapping.get(lab) for lab in labs]
            if all(v is None or (isinstance(v, (int, float)) and not isinstance(v, bool))
                   for v in vals):
                arr = np.asarray([np.nan if v is None else v for v in vals], dtype=float)
            else:
                arr = np.asarray(vals, dtype=object)
            coords[a + "_value"] = xr.Variable(d, arr, attrs={"long_name": f"value on axis {a}"})
        coords["rgb"] = xr.Variable(("rgb",), np.asarray(["R", "G", "B"], dtype=object))
        coords["lab"] = xr.Variable(("lab",), np.asarray(["L*", "a*", "b*"], dtype=object))
        self.table = xr.Dataset(data, coords=coords,
                                attrs={k: v for k, v in self.attrs.items()})

    @property
    def name(self) -> Optional[str]:
        return self.attrs.get("study")

    @property
    def profile(self) -> Optional[str]:
        return self.attrs.get("profile")

    @property
    def sweep_file(self) -> Optional[str]:
        return self.attrs.get("sweep_file")

    @property
    def variants(self) -> List[str]:
        return [str(v) for v in self.table["variant"].values]

    def variant_path(self, name: str) -> str:
        return os.path.join(self.dir, "variants", f"{name}.h5")

    def result(self, name: str) -> Result:
        """Open one variant's result file."""
        if name not in self.variants:
            raise KeyError(f"{name}: not a variant of study {self.name} ({', '.join(self.variants)})")
        return open_result(self.variant_path(name))

    def results(self) -> Iterator[Result]:
        for v in self.variants:
            yield self.result(v)

    def grid(self, var: str = "mean_reflectance") -> xr.DataArray:
        """``table[var]`` with one dimension per axis (labels as coordinates);
        NaN where a combination has no variant."""
        axes = [a for a in self.axes if a in self.table.coords]
        da = self.table[var].drop_vars([c for c in self.table[var].coords
                                        if c not in axes + ["variant"]])
        return da.set_index(variant=axes).unstack("variant")

    def __repr__(self) -> str:
        axes = "; ".join(f"{a}: {', '.join(ls)}" for a, ls in self.axes.items())
        return (f"<inksim.Study {self.name!r} profile {self.profile!r}, "
                f"{len(self.variants)} variants ({axes}) at {self.path}>")


def open_study(path: "os.PathLike[str] | str") -> Study:
    """Open a merged study: ``summary.h5`` or the folder that holds it."""
    return Study(os.fspath(path))
