#!/usr/bin/env python3
"""The scalar equation's error in layers with grains: the same layers (same
seeds, so the same fragments) solved with solver.equation = "helmholtz" and
"maxwell" on paper of albedo 0.9, and the CIEDE2000 difference of their mean
colours per measurement geometry (D50, 2°), with its standard error from the
realisations' paired differences. Writes a Markdown table to stdout.

The fidelity is fixed below (1 µm layer, 1 × 1 µm fragments, 25 nm cells,
20 nm z cells, 400–700 nm every 30 nm, tolerance 1e-4). Both equations see
the same discretised layer, volume-averaged voxels included
(grid.voxel_permittivity = "average"), so the table measures the model error
at that fidelity; the discretisation's own error (docs/ACCURACY.md) largely
cancels in the difference.

With --compare voxels it measures instead what Maxwell's anisotropic cut
voxels (the default of a Maxwell run) change against volume averaging on
the same fragments: both runs in Maxwell, "average" against "anisotropic".

Usage: python3 scripts/model_error_grains.py [--inksim target/release/inksim]
       [--realisations 3] [--pigments red,blue,yellow] [--pvc 0.15,0.3,0.5]
       [--diameters 100,200,300]
Needs numpy and h5py (pip install numpy h5py). The default grid of 27 layers
takes about half an hour on a 2-core machine."""
import argparse
import os
import subprocess
import sys
import tempfile

import h5py
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from model_error_surfaces import de00  # noqa: E402  (one CIEDE2000, checked there)

SCENE = """seed = {seed}
realisations = {realisations}
[layer]
thickness_nm = 1000.0
fragment_nm = [1000.0, 1000.0]
binder_index = 1.558
[[pigment]]
name = "ink"
material = {{ builtin = "{pigment}" }}
pvc = {pvc}
diameter_nm = {diameter}
[grid]
cell_nm = 25.0
z_cell_nm = 20.0
voxel_permittivity = "{voxels}"

[illumination]
wavelength_range_nm = {{ start = 400.0, stop = 700.0, step = 30.0 }}
polar_deg = [0.0]
[solver]
equation = "{equation}"
tolerance = 1e-4
[substrate]
kind = "paper"
albedo = 0.9
[output]
dir = "{out}"
name = "r"
[appearance]
outputs = ["tile"]
quadrature_points = 4
"""

GEOMETRIES = {"45/0": "45_0", "d/8 SCI": "d8_sci", "d/8 SCE": "d8_sce"}


def realisation_labs(inksim, work, equation, voxels="average", **kw):
    """CIELAB of every realisation per geometry, (R, 3) each."""
    out = os.path.join(work, "{pigment}-{pvc}-{diameter}-".format(**kw)
                       + equation + "-" + voxels)
    scene = os.path.join(work, "scene.toml")
    with open(scene, "w") as f:
        f.write(SCENE.format(equation=equation, voxels=voxels, out=out, **kw))
    subprocess.run([inksim, "run", scene], check=True, capture_output=True)
    with h5py.File(os.path.join(out, "r.h5"), "r") as f:
        return {g: f[f"appearance/measured/{k}/lab_realisations"][()].reshape(-1, 3)
                for g, k in GEOMETRIES.items()}


def difference(h, m):
    """ΔE00 between the mean colours and its standard error: the paired
    differences' covariance over √R, propagated linearly through ΔE00 at the
    Maxwell colour (numerical gradient)."""
    mh, mm = h.mean(axis=0), m.mean(axis=0)
    d = de00(*mh, *mm)
    r = len(h)
    cov = np.cov((m - h).T) / r
    grad = np.zeros(3)
    for i in range(3):
        step = np.zeros(3)
        step[i] = 1e-4
        grad[i] = (de00(*mh, *(mm + step)) - de00(*mh, *(mm - step))) / 2e-4
    return d, float(np.sqrt(max(grad @ cov @ grad, 0.0)))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--inksim", default="target/release/inksim")
    ap.add_argument("--realisations", type=int, default=3)
    ap.add_argument("--pigments", default="red,blue,yellow")
    ap.add_argument("--pvc", default="0.15,0.3,0.5")
    ap.add_argument("--diameters", default="100,200,300")
    ap.add_argument("--compare", choices=["equations", "voxels"], default="equations")
    args = ap.parse_args()
    if args.compare == "equations":
        runs = (("helmholtz", "average"), ("maxwell", "average"))
        title = "Helmholtz → Maxwell"
    else:
        runs = (("maxwell", "average"), ("maxwell", "anisotropic"))
        title = "average → anisotropic"
    print("| pigment | PVC | diameter | " + " | ".join(GEOMETRIES)
          + f" | L* 45/0, {title} |")
    print("|---|---|---|" + "---|" * len(GEOMETRIES) + "---|")
    with tempfile.TemporaryDirectory() as work:
        for pigment in args.pigments.split(","):
            for pvc in (float(p) for p in args.pvc.split(",")):
                for diameter in (float(d) for d in args.diameters.split(",")):
                    kw = dict(pigment=pigment, pvc=pvc, diameter=diameter, seed=20240601,
                              realisations=args.realisations)
                    h = realisation_labs(args.inksim, work, *runs[0], **kw)
                    m = realisation_labs(args.inksim, work, *runs[1], **kw)
                    cells = []
                    for g in GEOMETRIES:
                        d, se = difference(h[g], m[g])
                        cells.append(f"{d:.2f} ± {se:.2f}")
                    print(f"| {pigment} | {round(pvc * 100)} % | {diameter:.0f} nm | "
                          + " | ".join(cells)
                          + f" | {h['45/0'][:, 0].mean():.2f} → {m['45/0'][:, 0].mean():.2f} |",
                          flush=True)


if __name__ == "__main__":
    main()
