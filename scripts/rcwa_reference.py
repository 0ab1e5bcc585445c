#!/usr/bin/env python3
"""Reference per-order efficiencies of y-invariant lamellar gratings from an
independent rigorous coupled-wave code (grcwa, PyPI), for tests/rcwa.rs.

For a grating whose permittivity depends on x only, the scalar Helmholtz
equation solved by inksim is exactly TE Maxwell (E along the stripes, y), so
grcwa's s-polarised (E along y for azimuth 0) order efficiencies are the
reference. The stripe spans the whole slab thickness.

Usage (in a venv with `pip install grcwa numpy`):
    python scripts/rcwa_reference.py [--out tests/fixtures/lamellar_rcwa.json]

What it does:
1. Checks grcwa in s polarisation against the exact Airy formula for
   homogeneous slabs (real and absorbing, normal and oblique) and aborts if
   they differ by more than 1e-10.
2. For each grating case, solves with an increasing number of Fourier orders
   and a fine sampling of the unit cell, stores the finest result, and as the
   reference's own uncertainty the largest per-order change between the two
   finest truncations and under doubling the cell sampling.

Conventions (docs/METHOD.md §4): incidence from above in the x-z plane at polar
angle theta; order m has kappa_m = k0 sin(theta) + 2 pi m / period;
R_m, T_m are power efficiencies normalised by the incident flux.
Efficiencies do not depend on where the stripe sits in the cell, so the
stripe's position in grcwa's sampled cell is irrelevant; the Rust test puts
it at [x0, x0 + width) on its own grid.
"""
import argparse
import json
import platform
import sys
import time
from importlib.metadata import version

import numpy as np
import grcwa

grcwa.set_backend("numpy")

BINDER_N = 1.558

CASES = [
    {
        "name": "weak_normal",
        "wavelength_nm": 550.0,
        "period_nm": 1000.0,
        "thickness_nm": 1000.0,
        "stripe_x0_nm": 0.0,
        "stripe_width_nm": 400.0,
        "stripe_n": [1.4, 0.3],
        "polar_deg": 0.0,
    },
    {
        "name": "weak_oblique30",
        "wavelength_nm": 550.0,
        "period_nm": 1000.0,
        "thickness_nm": 1000.0,
        "stripe_x0_nm": 0.0,
        "stripe_width_nm": 400.0,
        "stripe_n": [1.4, 0.3],
        "polar_deg": 30.0,
    },
    {
        "name": "strong_period4um",
        "wavelength_nm": 550.0,
        "period_nm": 4000.0,
        "thickness_nm": 1000.0,
        "stripe_x0_nm": 0.0,
        "stripe_width_nm": 400.0,
        "stripe_n": [2.0, 0.8],
        "polar_deg": 0.0,
    },
]

# Sampling of the unit cell handed to grcwa (points per nm of period) and
# the Fourier truncations per period (grcwa's nG, the number of x orders
# kept; the actual count is odd, +-m pairs). grcwa solves a 2nG x 2nG
# eigenproblem (both polarisations), so nG ~ 800 already takes minutes.
SAMPLES_PER_NM = 4
SAMPLING_CHECK_ORDERS = 201
TRUNCATIONS = {1000.0: [51, 101, 201, 401], 4000.0: [101, 201, 401, 801]}


def solve_te(eps_slab, wavelength, period, thickness, polar_deg, n_orders,
             eps_cell=None):
    """grcwa, s polarisation, azimuth 0 (E along y). Lengths in nm.

    eps_cell: sampled permittivity of one period along x (None: uniform
    slab of eps_slab). Returns (orders m, R_m, T_m, total R, total T)."""
    # A 1-D grating in a 2-D code: the second lattice vector is so short
    # that its reciprocal orders never enter the circular truncation.
    obj = grcwa.obj(n_orders, [period, 0.0], [0.0, period * 1e-4],
                    1.0 / wavelength, np.radians(polar_deg), 0.0, verbose=0)
    obj.Add_LayerUniform(0.0, 1.0)
    if eps_cell is None:
        obj.Add_LayerUniform(thickness, eps_slab)
    else:
        obj.Add_LayerGrid(thickness, len(eps_cell), 1)
    obj.Add_LayerUniform(0.0, 1.0)
    obj.Init_Setup(Gmethod=0)
    if eps_cell is not None:
        obj.GridLayer_geteps(np.asarray(eps_cell, dtype=complex))
    assert np.all(obj.G[:, 1] == 0), "y orders entered the truncation"
    obj.MakeExcitationPlanewave(0.0, 0.0, 1.0, 0.0, order=0)
    r, t = obj.RT_Solve(normalize=1, byorder=1)
    return obj.G[:, 0].copy(), np.real(r), np.real(t), float(np.sum(r)), float(np.sum(t))


def airy_te(eps, wavelength, thickness, polar_deg):
    """Exact |r|^2, |t|^2 of a slab in vacuum (scalar wave = TE)."""
    k0 = 2 * np.pi / wavelength
    kap = k0 * np.sin(np.radians(polar_deg))
    g = np.sqrt(complex(k0 * k0 * eps - kap * kap))
    if g.imag < 0:
        g = -g
    b = np.sqrt(complex(k0 * k0 - kap * kap))
    rho = (g - b) / (g + b)
    e = np.exp(2j * g * thickness)
    a = 2 * b / ((g + b) * (1 - rho * rho * e))
    return abs(a * (1 + rho * e) - 1) ** 2, abs(a * np.exp(1j * g * thickness) * (1 + rho)) ** 2


def check_airy():
    worst = 0.0
    checks = []
    for eps, polar in [(BINDER_N**2, 0.0), (BINDER_N**2, 30.0),
                       ((1.4 + 0.3j) ** 2, 30.0), ((2 + 0.8j) ** 2, 60.0)]:
        _, _, _, r, t = solve_te(eps, 550.0, 1000.0, 1000.0, polar, 21)
        r0, t0 = airy_te(eps, 550.0, 1000.0, polar)
        err = max(abs(r - r0), abs(t - t0))
        worst = max(worst, err)
        checks.append({"eps": [eps.real, eps.imag] if isinstance(eps, complex) else [eps, 0.0],
                       "polar_deg": polar, "R": r, "T": t, "R_airy": r0, "T_airy": t0})
    if worst > 1e-10:
        sys.exit(f"grcwa disagrees with the Airy slab by {worst:.3e}; not TE?")
    return worst, checks


def propagating(wavelength, period, polar_deg, m):
    k0 = 2 * np.pi / wavelength
    kx = k0 * np.sin(np.radians(polar_deg)) + 2 * np.pi * m / period
    return abs(kx) < k0


def grating(case):
    lam, period, h = case["wavelength_nm"], case["period_nm"], case["thickness_nm"]
    x0, w = case["stripe_x0_nm"], case["stripe_width_nm"]
    n_s = complex(*case["stripe_n"])

    def sampled(per_nm):
        nx = int(round(period * per_nm))
        x = (np.arange(nx) + 0.5) * period / nx
        cell = np.full(nx, BINDER_N**2, dtype=complex)
        cell[(x >= x0) & (x < x0 + w)] = n_s * n_s
        return cell

    cell = sampled(SAMPLES_PER_NM)
    nx = len(cell)
    # grcwa takes the Fourier coefficients of the sampled cell (a DFT), which
    # differ from the exact stripe's by O((m/nx)^2): measure the effect by
    # doubling the sampling at a moderate truncation.
    coarse = solve_te(None, lam, period, h, case["polar_deg"], SAMPLING_CHECK_ORDERS, cell)
    fine = solve_te(None, lam, period, h, case["polar_deg"], SAMPLING_CHECK_ORDERS,
                    sampled(2 * SAMPLES_PER_NM))
    sampling_change = float(max(np.max(np.abs(coarse[1] - fine[1])),
                                np.max(np.abs(coarse[2] - fine[2]))))
    runs = []
    for n_orders in TRUNCATIONS[period]:
        t0 = time.time()
        m, r, t, rt, tt = solve_te(None, lam, period, h, case["polar_deg"], n_orders, cell)
        keep = [i for i in range(len(m)) if propagating(lam, period, case["polar_deg"], m[i])]
        orders = sorted((int(m[i]), float(r[i]), float(t[i])) for i in keep)
        runs.append({"n_orders": int(len(m)), "orders": orders, "R": rt, "T": tt,
                     "seconds": time.time() - t0})
    last, prev = runs[-1], runs[-2]
    change = max(max(abs(a[1] - b[1]), abs(a[2] - b[2]))
                 for a, b in zip(last["orders"], prev["orders"]))
    return {
        **case,
        "binder_n": BINDER_N,
        "eps_binder": BINDER_N**2,
        "eps_stripe": [(n_s * n_s).real, (n_s * n_s).imag],
        "cell_samples": nx,
        "n_orders": last["n_orders"],
        "orders": [{"m": o[0], "R": o[1], "T": o[2]} for o in last["orders"]],
        "total_R": last["R"],
        "total_T": last["T"],
        "absorption": 1.0 - last["R"] - last["T"],
        "max_change_vs_previous_truncation": change,
        "max_change_with_doubled_sampling": sampling_change,
        "convergence": [{"n_orders": q["n_orders"], "total_R": q["R"], "total_T": q["T"],
                         "R0": dict((o[0], o[1]) for o in q["orders"])[0],
                         "T0": dict((o[0], o[2]) for o in q["orders"])[0],
                         "seconds": q["seconds"]} for q in runs],
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default="tests/fixtures/lamellar_rcwa.json")
    args = ap.parse_args()
    worst, checks = check_airy()
    print(f"Airy check: max |dR|,|dT| = {worst:.2e}")
    cases = []
    for case in CASES:
        c = grating(case)
        print(f"{c['name']}: {len(c['orders'])} propagating orders, R={c['total_R']:.6f} "
              f"T={c['total_T']:.6f}, change vs previous truncation {c['max_change_vs_previous_truncation']:.1e}, "
              f"with doubled cell sampling {c['max_change_with_doubled_sampling']:.1e}")
        for q in c["convergence"]:
            print(f"   nG={q['n_orders']:4d} R0={q['R0']:.8f} T0={q['T0']:.8f} ({q['seconds']:.1f} s)")
        cases.append(c)
    out = {
        "generator": "scripts/rcwa_reference.py",
        "package": "grcwa",
        "package_version": version("grcwa"),
        "numpy_version": np.__version__,
        "python_version": platform.python_version(),
        "polarisation": "TE (grcwa s polarisation, azimuth 0: E along y, the stripe axis)",
        "geometry": "vacuum | slab 0<=z<=H of binder with one full-height stripe x0<=x<x0+width | vacuum; "
                    "light from above, incidence in the x-z plane",
        "cell_sampling": f"unit cell sampled at {SAMPLES_PER_NM} points per nm (cell midpoints)",
        "truncations_by_period_nm": {str(k): v for k, v in TRUNCATIONS.items()},
        "convergence_note": "orders: finest truncation; max_change_vs_previous_truncation is the largest "
                            "per-order |dR|,|dT| between the two finest truncations, "
                            "max_change_with_doubled_sampling the same for doubling the cell sampling at "
                            f"{SAMPLING_CHECK_ORDERS} orders (together: the reference's uncertainty)",
        "airy_check": {"max_error": worst, "cases": checks},
        "cases": cases,
    }
    with open(args.out, "w") as f:
        json.dump(out, f, indent=1)
        f.write("\n")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
