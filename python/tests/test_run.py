"""inksim.run: results, errors, and the example script."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

import inksim

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "plot_demo.py"


def test_scene_run(tiny_run):
    assert tiny_run.kind == "scene"
    assert os.path.isabs(tiny_run.path) and tiny_run.path.endswith("tiny.h5")
    assert os.path.isfile(tiny_run.path)
    assert "results:" in tiny_run.stdout


def test_missing_config(binary, tmp_path):
    with pytest.raises(FileNotFoundError, match="nope.toml: no such scene or study file"):
        inksim.run(tmp_path / "nope.toml")


def test_bad_config(binary, tmp_path):
    p = tmp_path / "bad.toml"
    p.write_text("seed = 1\n[layer]\nthickness_nm = 400.0\n", encoding="utf-8")
    with pytest.raises(inksim.InksimError, match=r"failed \(exit 1\): error: .*bad.toml") as e:
        inksim.run(p, tmp_path / "out")
    assert e.value.returncode == 1
    assert "fragment_nm" in str(e.value)


def test_binary_from_env(monkeypatch, tmp_path):
    monkeypatch.setenv("INKSIM_BIN", str(tmp_path / "no-such-inksim"))
    with pytest.raises(inksim.InksimNotFound, match="INKSIM_BIN"):
        inksim.find_binary()


def test_example_script(tiny, tmp_path):
    if not EXAMPLE.is_file():
        pytest.skip("examples/ not shipped here")
    out = tmp_path / "plots"
    p = subprocess.run([sys.executable, str(EXAMPLE), tiny.path, "--out", str(out)],
                       capture_output=True, text=True, env={**os.environ, "MPLBACKEND": "Agg"})
    assert p.returncode == 0, p.stderr
    for name in ("tiny-spectra.png", "tiny-brdf.png", "tiny-tile.png"):
        assert (out / name).stat().st_size > 1000, name
