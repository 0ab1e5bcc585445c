#!/usr/bin/env python3
"""A small flake solved by wave optics against the fast effect-paint model's
specular lobe, with and without its diffraction term (docs/VALIDATION.md,
"A small flake in wave optics").

A level aluminium disc (diameter D, 100 nm thick) in a medium of index 1,
one per periodic cell of side L (the scene is an explicit structure: a
cylinder along z), lit at 0° and 45°, solved by `inksim run`. The lattice's
reflected orders sample the flake's far field: order (m, n) collects the
power of its cell of in-plane directions, side λ/L in sin. Against it:

- Kirchhoff's aperture: the orders' powers in proportion to Airy's pattern
  |2 J1(x)/x|², x = π D |(m, n)| / L (independent of this code);
- the fast model's lobe: a Gaussian of the deviation with
  σ = √2 λ/(π n D), spread over the flakes' normals as σ_d/μ at incidence
  cosine μ (optics::flakes::normals, `Orientation::at_incidence`); a normal
  tilted by δ moves the reflected direction's in-plane sin by 2 cos θ δ, so
  the lobe is σ wide in sin at every angle; integrated over each order's
  cell;
- the same lobe with the normals' spread of normal incidence at every
  angle ("one spread"), cos θ as wide in sin at incidence θ;
- no diffraction: all of the flakes' light in the specular order.

Prints, per wavelength and angle, the share of the reflected power in the
orders with |(m, n)| ≤ r.

Usage: python3 scripts/flake_diffraction.py [--inksim target/release/inksim]
       [--diameter-nm 2000] [--cell-nm 4000] [--out runs/flake-diffraction]
Needs numpy and h5py (the Python package's environment, .venv). A 2 µm flake
in a 4 µm cell takes about 20 min on 2 cores (six solves of 1300–1900
BiCGStab iterations); `--diameter-nm 1000 --cell-nm 2000` about 1 min.
"""
import argparse
import math
import os
import subprocess

import h5py
import numpy as np

SCENE = """seed = 1
realisations = 1
[layer]
thickness_nm = 300.0
fragment_nm = [{cell}, {cell}]
binder_index = 1.0
[structure]
kind = "primitives"
[[structure.primitive]]
shape = {{ kind = "cylinder", center_nm = [{half}, {half}, 150.0], radius_nm = {radius}, length_nm = 100.0, axis = "z" }}
material = {{ library = "aluminium" }}
[grid]
cell_nm = 25.0
z_cell_nm = 10.0
[illumination]
wavelengths_nm = [450.0, 550.0, 650.0]
polar_deg = [0.0, 45.0]
[solver]
tolerance = 1e-6
[output]
dir = "{out}"
name = "flake"
[appearance]
outputs = []
"""


def j1(x):
    """Bessel J1 by its integral (trapezoidal on a period: spectrally exact)."""
    t = np.linspace(0.0, math.pi, 401)
    return np.trapezoid(np.cos(t - x * np.sin(t)), t) / math.pi


def airy(x):
    return 1.0 if x == 0 else (2.0 * j1(x) / x) ** 2


def gaussian_cells(orders, lam, cell, sigma):
    """A Gaussian of the in-plane sin (σ per axis) integrated over each
    order's square cell of side λ/L, normalised over the orders."""
    half = lam / (2.0 * cell)
    share = lambda a: 0.5 * (
        math.erf((a + half) / (sigma * math.sqrt(2.0)))
        - math.erf((a - half) / (sigma * math.sqrt(2.0)))
    )
    p = np.array([share(m * lam / cell) * share(n * lam / cell) for m, n in orders])
    return p / p.sum()


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--inksim", default="target/release/inksim")
    ap.add_argument("--diameter-nm", type=float, default=2000.0)
    ap.add_argument("--cell-nm", type=float, default=4000.0)
    ap.add_argument("--out", default="runs/flake-diffraction")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    scene = os.path.join(a.out, "flake.toml")
    with open(scene, "w") as f:
        f.write(
            SCENE.format(
                cell=a.cell_nm,
                half=a.cell_nm / 2,
                radius=a.diameter_nm / 2,
                out=os.path.abspath(a.out),
            )
        )
    result = os.path.join(a.out, "flake.h5")
    if not os.path.exists(result):
        subprocess.run([a.inksim, "run", scene], check=True)
    d, cell = a.diameter_nm, a.cell_nm
    print(f"aluminium disc {d:.0f} nm across, 100 nm thick, one per {cell:.0f} nm cell, in n = 1")
    print("share of the reflected power in the orders with |(m, n)| <= r\n")
    print("| λ nm | θ | r | wave | Kirchhoff (Airy) | fast lobe (σ_d/μ) | one spread | no diffraction |")
    print("|---|---|---|---|---|---|---|---|")
    with h5py.File(result) as h:
        for key in sorted(h["solves"].keys()):
            g = h["solves"][key]
            lam = float(g.attrs["wavelength_nm"])
            theta = math.radians(float(g.attrs["polar_deg"]))
            orders = [tuple(int(v) for v in mn) for mn in np.array(g["orders_mn"])]
            wave = np.array(g["orders_reflectance"])
            wave = wave / wave.sum()
            kirchhoff = np.array([airy(math.pi * d * math.hypot(m, n) / cell) for m, n in orders])
            kirchhoff /= kirchhoff.sum()
            sigma_dev = math.sqrt(2.0) * lam / (math.pi * d)
            fast = gaussian_cells(orders, lam, cell, sigma_dev)
            one = gaussian_cells(orders, lam, cell, sigma_dev * math.cos(theta))
            radius = np.array([math.hypot(m, n) for m, n in orders])
            for r in [0.0, 1.0, 1.5, 2.0, 3.0]:
                sel = radius <= r + 1e-9
                print(
                    f"| {lam:.0f} | {math.degrees(theta):.0f}° | {r:g} | {wave[sel].sum():.3f} "
                    f"| {kirchhoff[sel].sum():.3f} | {fast[sel].sum():.3f} | {one[sel].sum():.3f} | 1.000 |"
                )


if __name__ == "__main__":
    main()
