#!/usr/bin/env python3
"""Reference per-order efficiencies of y-invariant lamellar gratings from an
independent rigorous coupled-wave code (grcwa, PyPI), for tests/rcwa.rs.

For a grating whose permittivity depends on x only, the scalar Helmholtz
equation solved by inksim is exactly TE Maxwell (E along the stripes, y), so
grcwa's s-polarised (E along y for azimuth 0) order efficiencies are the
reference. With --polarisation p the script writes the TM counterpart
(grcwa's p polarisation at azimuth 0: E in the x-z plane of incidence, H
along y), a reference for the vector Maxwell solver. The stripe spans the
whole slab thickness.

Usage (in a venv with `pip install grcwa numpy`):
    python scripts/rcwa_reference.py [--polarisation s] [--out tests/fixtures/lamellar_rcwa.json]
    python scripts/rcwa_reference.py --polarisation p [--out tests/fixtures/lamellar_rcwa_p.json]
(About 2 minutes for s and 4 for p on 2 cores.)

What it does:
1. Checks grcwa against the exact Airy formula for homogeneous slabs (real
   and absorbing, normal and oblique; in p also at the binder's Brewster
   angle, where R vanishes, and Fresnel half-spaces) and aborts if they
   differ by more than 1e-10 (s) or 1e-9 (p).
2. For each grating case, solves with an increasing number of Fourier orders
   and a fine sampling of the unit cell, stores the finest result, and as the
   reference's own uncertainty the largest per-order change between the two
   finest truncations and under doubling the cell sampling.

TM factorisation (p only). At azimuth 0 (ky = 0) grcwa's layer matrix
M = ep2 kp - k k^T is block diagonal: the first nG x nG block,
w^2 [eps] - kx^2, is TE; the second, [eps] (w^2 - kx [eps]^-1 kx), is TM
(the excitation's p amplitude enters the second half of grcwa's amplitude
vector). grcwa (0.1.2, fft_funs.Epsilon_fft) fills both blocks of ep2 with
the Toeplitz matrix [eps] of Fourier coefficients (Laurent's rule) and uses
inv([eps]) for eps_zz^-1. The latter is right (Ez is tangential to the
stripe walls) but the former multiplies Ex, which is normal to the walls and
discontinuous there, so Li's inverse rule [1/eps]^-1 is the correct
factorisation (L. Li, JOSA A 13, 1870 (1996)); with Laurent's rule TM
converges only as 1/(number of orders). In p the script therefore replaces
the TM block of ep2 by inv([1/eps]) (a few lines below, everything else is
grcwa's) and stores those results; as an independent cross-check it also
runs grcwa as shipped and records how far it is from the reference, and how
far its Richardson extrapolation in 1/N is.

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
import grcwa.rcwa
from grcwa.fft_funs import get_conv

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


def _case(name, n, polar, period=1000.0, x0=0.0, width=400.0):
    return {"name": name, "wavelength_nm": 550.0, "period_nm": period,
            "thickness_nm": 1000.0, "stripe_x0_nm": x0, "stripe_width_nm": width,
            "stripe_n": n, "polar_deg": polar}


# p polarisation: the three s cases plus more angles and a lossless
# high-index (rutile-like) stripe. Edges on multiples of 50 nm.
CASES_P = CASES + [
    _case("weak_oblique60", [1.4, 0.3], 60.0),
    _case("strong_normal", [2.0, 0.8], 0.0),
    _case("strong_oblique45", [2.0, 0.8], 45.0),
    _case("rutile_normal", [2.7, 0.0], 0.0, x0=250.0, width=500.0),
    _case("rutile_oblique30", [2.7, 0.0], 30.0, x0=250.0, width=500.0),
]

# Sampling of the unit cell handed to grcwa (points per nm of period) and
# the Fourier truncations per period (grcwa's nG, the number of x orders
# kept; the actual count is odd, +-m pairs). grcwa solves a 2nG x 2nG
# eigenproblem (both polarisations), so nG ~ 800 already takes minutes.
SAMPLES_PER_NM = 4
SAMPLING_CHECK_ORDERS = 201
TRUNCATIONS = {1000.0: [51, 101, 201, 401], 4000.0: [101, 201, 401, 801]}
# p only: grcwa as shipped (Laurent's rule for the TM block), the cross-check.
LAURENT_TRUNCATIONS = {1000.0: [201, 401], 4000.0: [401, 801]}

_GRCWA_EPSILON_FFT = grcwa.rcwa.Epsilon_fft


def _epsilon_fft_inverse_rule(dN, eps_grid, G):
    """grcwa's Epsilon_fft with the TM block of ep2 (rows/columns nG:, the
    one multiplying Ex, normal to the stripe walls) by Li's inverse rule,
    inv([1/eps]). The TE block and inv([eps]) for eps_zz are grcwa's."""
    epinv, ep2 = _GRCWA_EPSILON_FFT(dN, eps_grid, G)
    n = G.shape[0]
    ep2 = ep2.copy()
    ep2[n:, n:] = np.linalg.inv(get_conv(dN, 1.0 / eps_grid, G))
    return epinv, ep2


def solve(eps_slab, wavelength, period, thickness, polar_deg, n_orders,
          eps_cell=None, polarisation="s", rule="grcwa", substrate=False):
    """grcwa at azimuth 0: polarisation "s" (E along y) or "p" (H along y).
    Lengths in nm.

    eps_cell: sampled permittivity of one period along x (None: uniform
    slab of eps_slab). rule: "grcwa" (as shipped, Laurent's rule) or
    "inverse" (Li's inverse rule for the TM block; does not touch TE).
    substrate: half-space of eps_slab below z = 0 instead of a slab
    (uniform only). Returns (orders m, R_m, T_m, total R, total T)."""
    # A 1-D grating in a 2-D code: the second lattice vector is so short
    # that its reciprocal orders never enter the circular truncation.
    obj = grcwa.obj(n_orders, [period, 0.0], [0.0, period * 1e-4],
                    1.0 / wavelength, np.radians(polar_deg), 0.0, verbose=0)
    obj.Add_LayerUniform(0.0, 1.0)
    if substrate:
        obj.Add_LayerUniform(0.0, eps_slab)
    else:
        if eps_cell is None:
            obj.Add_LayerUniform(thickness, eps_slab)
        else:
            obj.Add_LayerGrid(thickness, len(eps_cell), 1)
        obj.Add_LayerUniform(0.0, 1.0)
    obj.Init_Setup(Gmethod=0)
    if eps_cell is not None:
        grcwa.rcwa.Epsilon_fft = {"grcwa": _GRCWA_EPSILON_FFT,
                                  "inverse": _epsilon_fft_inverse_rule}[rule]
        try:
            obj.GridLayer_geteps(np.asarray(eps_cell, dtype=complex))
        finally:
            grcwa.rcwa.Epsilon_fft = _GRCWA_EPSILON_FFT
    assert np.all(obj.G[:, 1] == 0), "y orders entered the truncation"
    if polarisation == "s":
        obj.MakeExcitationPlanewave(0.0, 0.0, 1.0, 0.0, order=0)
    else:
        obj.MakeExcitationPlanewave(1.0, 0.0, 0.0, 0.0, order=0)
    r, t = obj.RT_Solve(normalize=1, byorder=1)
    return obj.G[:, 0].copy(), np.real(r), np.real(t), float(np.sum(r)), float(np.sum(t))


def solve_te(*args, **kwargs):
    return solve(*args, polarisation="s", **kwargs)


def airy(eps, wavelength, thickness, polar_deg, polarisation="s", substrate=False):
    """Exact R, T of a slab of eps in vacuum, or (substrate=True) of the
    vacuum | eps half-space interface, in s (E along y; the scalar wave) or
    p (H along y) polarisation.

    The tangential field (Ey in s, Hy in p) is continuous with its
    derivative over the admittance p = kz (s) or kz/eps (p), so the
    interface coefficients are r12 = (p1 - p2)/(p1 + p2), t12 = 2 p1/(p1 + p2)
    and the flux is Re(p) |field|^2."""
    k0 = 2 * np.pi / wavelength
    kap = k0 * np.sin(np.radians(polar_deg))
    g = np.sqrt(complex(k0 * k0 * eps - kap * kap))
    if g.imag < 0:
        g = -g
    p1 = np.sqrt(complex(k0 * k0 - kap * kap))
    p2 = g if polarisation == "s" else g / eps
    r12 = (p1 - p2) / (p1 + p2)
    t12 = 2 * p1 / (p1 + p2)
    if substrate:
        return abs(r12) ** 2, (p2.real / p1.real) * abs(t12) ** 2
    t21 = 2 * p2 / (p1 + p2)
    e = np.exp(2j * g * thickness)
    den = 1 - r12 * r12 * e
    r = r12 * (1 - e) / den
    t = t12 * t21 * np.exp(1j * g * thickness) / den
    return abs(r) ** 2, abs(t) ** 2


def check_airy():
    worst = 0.0
    checks = []
    for eps, polar in [(BINDER_N**2, 0.0), (BINDER_N**2, 30.0),
                       ((1.4 + 0.3j) ** 2, 30.0), ((2 + 0.8j) ** 2, 60.0)]:
        _, _, _, r, t = solve_te(eps, 550.0, 1000.0, 1000.0, polar, 21)
        r0, t0 = airy(eps, 550.0, 1000.0, polar)
        err = max(abs(r - r0), abs(t - t0))
        worst = max(worst, err)
        checks.append({"eps": [eps.real, eps.imag] if isinstance(eps, complex) else [eps, 0.0],
                       "polar_deg": polar, "R": r, "T": t, "R_airy": r0, "T_airy": t0})
    if worst > 1e-10:
        sys.exit(f"grcwa disagrees with the Airy slab by {worst:.3e}; not TE?")
    return worst, checks


BREWSTER_DEG = float(np.degrees(np.arctan(BINDER_N)))


def check_airy_tm():
    """grcwa p against airy(..., "p"): slabs as a uniform layer and as a (uniform)
    grid layer through the inverse-rule path, and half-spaces."""
    worst = 0.0
    checks = []
    slabs = [(BINDER_N**2, 0.0), (BINDER_N**2, 30.0), (BINDER_N**2, BREWSTER_DEG),
             ((1.4 + 0.3j) ** 2, 30.0), ((2 + 0.8j) ** 2, 60.0), (2.7**2, 45.0)]
    runs = [("slab", "uniform_layer", e, a) for e, a in slabs]
    runs += [("slab", "grid_layer_inverse_rule", e, a) for e, a in slabs]
    runs += [("half_space", "uniform_layer", e, a) for e, a in
             [(BINDER_N**2, BREWSTER_DEG), (BINDER_N**2, 60.0), ((2 + 0.8j) ** 2, 45.0)]]
    for kind, layer, eps, polar in runs:
        eps = complex(eps)
        cell = np.full(20, eps) if layer.startswith("grid") else None
        _, _, _, r, t = solve(eps, 550.0, 1000.0, 1000.0, polar, 21, eps_cell=cell,
                              polarisation="p", rule="inverse",
                              substrate=kind == "half_space")
        r0, t0 = airy(eps, 550.0, 1000.0, polar, "p", substrate=kind == "half_space")
        err = max(abs(r - r0), abs(t - t0))
        worst = max(worst, err)
        checks.append({"geometry": kind, "layer": layer, "eps": [eps.real, eps.imag],
                       "polar_deg": polar, "R": r, "T": t, "R_airy": r0, "T_airy": t0})
    brewster = max(abs(c["R"]) for c in checks if c["polar_deg"] == BREWSTER_DEG)
    if worst > 1e-9 or brewster > 1e-9:
        sys.exit(f"grcwa p disagrees with the Airy/Fresnel formulas by {worst:.3e} "
                 f"(R at Brewster {brewster:.3e}); not TM?")
    return worst, brewster, checks


def propagating(wavelength, period, polar_deg, m):
    k0 = 2 * np.pi / wavelength
    kx = k0 * np.sin(np.radians(polar_deg)) + 2 * np.pi * m / period
    return abs(kx) < k0


def _orders(lam, period, polar, sol):
    m, r, t = sol[:3]
    keep = [i for i in range(len(m)) if propagating(lam, period, polar, m[i])]
    return sorted((int(m[i]), float(r[i]), float(t[i])) for i in keep)


def _max_diff(a, b):
    return max(max(abs(x[1] - y[1]), abs(x[2] - y[2])) for x, y in zip(a, b))


def grating(case, polarisation="s"):
    lam, period, h = case["wavelength_nm"], case["period_nm"], case["thickness_nm"]
    x0, w = case["stripe_x0_nm"], case["stripe_width_nm"]
    n_s = complex(*case["stripe_n"])
    # s: grcwa as shipped; p: Li's inverse rule (see the docstring)
    rule = "grcwa" if polarisation == "s" else "inverse"

    def sampled(per_nm):
        nx = int(round(period * per_nm))
        x = (np.arange(nx) + 0.5) * period / nx
        cell = np.full(nx, BINDER_N**2, dtype=complex)
        cell[(x >= x0) & (x < x0 + w)] = n_s * n_s
        return cell

    def run(n_orders, cell, rule=rule):
        return solve(None, lam, period, h, case["polar_deg"], n_orders, cell,
                     polarisation=polarisation, rule=rule)

    cell = sampled(SAMPLES_PER_NM)
    nx = len(cell)
    # grcwa takes the Fourier coefficients of the sampled cell (a DFT), which
    # differ from the exact stripe's by O((m/nx)^2): measure the effect by
    # doubling the sampling at a moderate truncation.
    coarse = run(SAMPLING_CHECK_ORDERS, cell)
    fine = run(SAMPLING_CHECK_ORDERS, sampled(2 * SAMPLES_PER_NM))
    sampling_change = float(max(np.max(np.abs(coarse[1] - fine[1])),
                                np.max(np.abs(coarse[2] - fine[2]))))
    runs = []
    for n_orders in TRUNCATIONS[period]:
        t0 = time.time()
        m, r, t, rt, tt = run(n_orders, cell)
        orders = _orders(lam, period, case["polar_deg"], (m, r, t))
        runs.append({"n_orders": int(len(m)), "orders": orders, "R": rt, "T": tt,
                     "seconds": time.time() - t0})
    last, prev = runs[-1], runs[-2]
    change = _max_diff(last["orders"], prev["orders"])
    out = {
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
    if polarisation == "s":
        return out
    # Sanity: flux balance when lossless, mirror symmetry at normal incidence.
    ref = last["orders"]
    sanity = {}
    if n_s.imag == 0.0:
        sanity["energy_balance_error"] = abs(last["R"] + last["T"] - 1.0)
        if sanity["energy_balance_error"] > 1e-6:
            sys.exit(f"{case['name']}: R+T-1 = {sanity['energy_balance_error']:.2e}")
    if case["polar_deg"] == 0.0:
        by_m = {o[0]: o for o in ref}
        sanity["max_mirror_asymmetry"] = max(
            max(abs(by_m[k][1] - by_m[-k][1]), abs(by_m[k][2] - by_m[-k][2])) for k in by_m)
        if sanity["max_mirror_asymmetry"] > 1e-8:
            sys.exit(f"{case['name']}: R_m != R_-m by {sanity['max_mirror_asymmetry']:.2e}")
    out["sanity"] = sanity
    # Cross-check: grcwa as shipped (Laurent's rule), error ~ c/N, and its
    # Richardson extrapolation from the two truncations.
    laurent = []
    for n_orders in LAURENT_TRUNCATIONS[period]:
        t0 = time.time()
        sol = run(n_orders, cell, rule="grcwa")
        laurent.append((int(len(sol[0])), _orders(lam, period, case["polar_deg"], sol),
                        sol[3], sol[4], time.time() - t0))
    (n1, o1, *_), (n2, o2, *_) = laurent[-2], laurent[-1]
    extrap = [(a[0], (n2 * b[1] - n1 * a[1]) / (n2 - n1), (n2 * b[2] - n1 * a[2]) / (n2 - n1))
              for a, b in zip(o1, o2)]
    out["laurent_check"] = {
        "truncations": [{"n_orders": q[0], "total_R": q[2], "total_T": q[3],
                         "R0": dict((o[0], o[1]) for o in q[1])[0],
                         "T0": dict((o[0], o[2]) for o in q[1])[0],
                         "max_diff_vs_reference": _max_diff(q[1], ref),
                         "seconds": q[4]} for q in laurent],
        "richardson_max_diff_vs_reference": _max_diff(extrap, ref),
    }
    # The inverse rule acts on the TM block only: TE must be unchanged.
    te = [solve(None, lam, period, h, case["polar_deg"], 51, cell, polarisation="s", rule=q)
          for q in ("grcwa", "inverse")]
    out["sanity"]["te_change_from_inverse_rule"] = float(
        max(np.max(np.abs(te[0][1] - te[1][1])), np.max(np.abs(te[0][2] - te[1][2]))))
    if out["sanity"]["te_change_from_inverse_rule"] > 1e-12:
        sys.exit(f"{case['name']}: the inverse-rule patch changed TE")
    return out


DEFAULT_OUT = {"s": "tests/fixtures/lamellar_rcwa.json", "p": "tests/fixtures/lamellar_rcwa_p.json"}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--polarisation", choices=["s", "p"], default="s",
                    help="s: TE, E along y (default); p: TM, H along y")
    ap.add_argument("--out", default=None,
                    help="default: " + ", ".join(f"{k}: {v}" for k, v in DEFAULT_OUT.items()))
    args = ap.parse_args()
    pol = args.polarisation
    out_path = args.out or DEFAULT_OUT[pol]
    start = time.time()
    if pol == "s":
        worst, checks = check_airy()
        print(f"Airy check: max |dR|,|dT| = {worst:.2e}")
    else:
        worst, brewster, checks = check_airy_tm()
        print(f"Airy/Fresnel check (p): max |dR|,|dT| = {worst:.2e}, R at Brewster {brewster:.1e}")
    cases = []
    for case in (CASES if pol == "s" else CASES_P):
        c = grating(case, pol)
        print(f"{c['name']}: {len(c['orders'])} propagating orders, R={c['total_R']:.6f} "
              f"T={c['total_T']:.6f}, change vs previous truncation {c['max_change_vs_previous_truncation']:.1e}, "
              f"with doubled cell sampling {c['max_change_with_doubled_sampling']:.1e}")
        for q in c["convergence"]:
            print(f"   nG={q['n_orders']:4d} R0={q['R0']:.8f} T0={q['T0']:.8f} ({q['seconds']:.1f} s)")
        if pol == "p":
            lc = c["laurent_check"]
            for q in lc["truncations"]:
                print(f"   grcwa as shipped nG={q['n_orders']:4d} R0={q['R0']:.8f} T0={q['T0']:.8f} "
                      f"max diff {q['max_diff_vs_reference']:.1e} ({q['seconds']:.1f} s)")
            print(f"   Richardson-extrapolated, max diff {lc['richardson_max_diff_vs_reference']:.1e}; "
                  f"sanity {c['sanity']}")
        cases.append(c)
    if pol == "s":
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
    else:
        out = {
            "generator": "scripts/rcwa_reference.py",
            "generator_args": "--polarisation p",
            "package": "grcwa",
            "package_version": version("grcwa"),
            "numpy_version": np.__version__,
            "python_version": platform.python_version(),
            "polarisation": "TM (grcwa p polarisation, azimuth 0: E in the x-z plane of incidence, "
                            "H along y, the stripe axis)",
            "geometry": "vacuum | slab 0<=z<=H of binder with one full-height stripe x0<=x<x0+width | vacuum; "
                        "light from above, incidence in the x-z plane",
            "cell_sampling": f"unit cell sampled at {SAMPLES_PER_NM} points per nm (cell midpoints)",
            "truncations_by_period_nm": {str(k): v for k, v in TRUNCATIONS.items()},
            "laurent_truncations_by_period_nm": {str(k): v for k, v in LAURENT_TRUNCATIONS.items()},
            "factorisation": "grcwa 0.1.2 (fft_funs.Epsilon_fft) builds the in-plane permittivity ep2 from the "
                             "Toeplitz matrix [eps] (Laurent's rule) in both blocks and eps_zz^-1 as inv([eps]); "
                             "it has no inverse rule. At azimuth 0 the TM block of its layer matrix is "
                             "[eps](w^2 - kx inv([eps]) kx); the [eps] factor multiplies Ex, normal to the stripe "
                             "walls, where Li's inverse rule inv([1/eps]) is correct (L. Li, JOSA A 13, 1870, 1996). "
                             "The stored results replace that block by inv([1/eps]) (everything else is grcwa's); "
                             "laurent_check records grcwa as shipped, which converges only as 1/N.",
            "convergence_note": "orders: finest truncation with the inverse rule; max_change_vs_previous_truncation "
                                "is the largest per-order |dR|,|dT| between the two finest truncations, "
                                "max_change_with_doubled_sampling the same for doubling the cell sampling at "
                                f"{SAMPLING_CHECK_ORDERS} orders (together: the reference's uncertainty). "
                                "laurent_check: grcwa as shipped (Laurent's rule) at two truncations, its largest "
                                "per-order difference from the reference, and that of the Richardson extrapolation "
                                "(N2 f(N2) - N1 f(N1))/(N2 - N1) assuming error ~ 1/N. sanity: |R+T-1| (lossless "
                                "cases), max |R_m - R_-m|, |T_m - T_-m| (normal incidence), and the change of TE "
                                "results by the inverse-rule patch at 51 orders (must be 0).",
            "airy_check": {"max_error": worst, "R_at_brewster_max": brewster,
                           "brewster_deg": BREWSTER_DEG, "cases": checks},
            "cases": cases,
        }
    with open(out_path, "w") as f:
        json.dump(out, f, indent=1)
        f.write("\n")
    print(f"wrote {out_path} ({time.time() - start:.0f} s)")


if __name__ == "__main__":
    main()
