"""The Mitsuba 3 export, read by Mitsuba 3 itself (skipped without it).

`inksim export <result.h5> --mitsuba` writes `<name>.bsdf` and inksim's own
evaluations of the BRDF at directions between the file's grid nodes
(`<name>-bsdf-samples.csv`); Mitsuba's `measured` plugin, in its spectral
variant, must give the same numbers within the interpolation error of its
table (measured: max 0.8 %, median 0.2 % on this scene).
"""

import importlib.util
import subprocess
from pathlib import Path

import pytest

from conftest import REPO

mi = pytest.importorskip("mitsuba")


def _check_module():
    path = REPO / "scripts" / "mitsuba_check.py"
    if not path.is_file():
        pytest.skip(f"{path}: not found (tests run from an inksim checkout)")
    spec = importlib.util.spec_from_file_location("mitsuba_check", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_mitsuba_evaluates_the_export_as_inksim_does(binary, tiny_run):
    h5 = Path(tiny_run.path)
    subprocess.run([*binary, "export", str(h5), "--mitsuba"], check=True, capture_output=True)
    bsdf = h5.with_suffix(".bsdf")
    samples = h5.parent / f"{h5.stem}-bsdf-samples.csv"
    check = _check_module()
    rows = check.compare(bsdf, samples, "scalar_spectral")
    s = check.summary(rows)
    # Two wavelengths x 160 directions, every one above the horizon.
    assert s["n"] == 320
    assert all(r[1] > 0 for r in rows)
    assert s["max_relative_error"] < 0.02, s
    assert s["median_relative_error"] < 0.005, s
