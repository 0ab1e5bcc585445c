"""Shared fixtures: real results made by the inksim CLI in a temporary folder.

Every test here needs the inksim binary (``INKSIM_BIN``, ``inksim`` on PATH,
or ``cargo run`` in the checkout); without one the tests are skipped.
"""

import os
import shutil
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import pytest  # noqa: E402

import inksim  # noqa: E402

REPO = Path(__file__).resolve().parents[2]

# The smallest scene shape, copied from configs/study-tiny.toml's base: a
# 400 nm fragment on an 8 x 8 x 4 grid, two wavelengths. Two angles, two
# realisations (standard errors) and every table, so each part of the file
# is there; runs in well under a second.
TINY_SCENE = """\
seed = 3
realisations = 2

[layer]
thickness_nm = 400.0
fragment_nm = [400.0, 400.0]
pvc = 0.15

[[pigment]]
name = "p"
material = { builtin = "red" }
diameter_nm = 100.0

[grid]
cell_nm = 50.0
z_cell_nm = 100.0

[illumination]
wavelengths_nm = [450.0, 600.0]
polar_deg = [0.0, 30.0]

[solver]
tolerance = 1e-6

[appearance]
outputs = ["brdf", "btdf", "tile"]

[output]
name = "tiny"
"""


@pytest.fixture(scope="session")
def binary():
    try:
        return inksim.find_binary()
    except inksim.InksimNotFound as e:
        pytest.skip(f"no inksim binary: {e}")


@pytest.fixture(scope="session")
def scene_file(tmp_path_factory):
    d = tmp_path_factory.mktemp("scene")
    p = d / "tiny.toml"
    p.write_text(TINY_SCENE, encoding="utf-8")
    return p


@pytest.fixture(scope="session")
def tiny_run(binary, scene_file):
    out = scene_file.parent / "out"
    return inksim.run(scene_file, out)


@pytest.fixture(scope="session")
def tiny(tiny_run):
    return inksim.open_result(tiny_run.path)


@pytest.fixture(scope="session")
def study_run(binary, tmp_path_factory):
    src = REPO / "configs" / "study-tiny.toml"
    if not src.is_file():
        pytest.skip(f"{src}: not found (tests run from an inksim checkout)")
    d = tmp_path_factory.mktemp("study")
    sweep = d / "study-tiny.toml"
    shutil.copyfile(src, sweep)
    return inksim.run(sweep, d / "runs", cwd=d)


@pytest.fixture(scope="session")
def study(study_run):
    return inksim.open_study(study_run.path)
