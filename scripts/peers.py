#!/usr/bin/env python3
"""inksim side by side with two public peers on one problem (docs/PEERS.md).

Problem: a y-invariant lamellar grating at normal incidence. lambda = 550 nm,
period 4 um, a 1 um binder slab (n = 1.558) with one 0.4 um wide stripe of
n = 2 + 0.8i through its full thickness, vacuum above and below. For a
y-invariant structure the scalar Helmholtz equation is exactly TE Maxwell
(E along y), so all three codes solve the same problem.

1. RCWA (grcwa 0.1.2, PyPI), s polarisation, at increasing numbers of Fourier
   orders; the finest truncation is the reference (as scripts/rcwa_reference.py,
   whose 799-order result in tests/fixtures/lamellar_rcwa.json is cross-checked).
2. inksim: examples/lamellar.rs (built with cargo, run once per grid and
   method so that its CPU time can be measured per solve).
3. macromax 0.2.2 (PyPI): the convergent Born series of Osnabrugge et al.
   2016, scalar, on a 2-D (z, x) grid, periodic in x (period 4 um: its FFT
   grid is the period), with its `LinearBound` absorbing layers at both
   z ends (the z direction is periodic too, so the two layers are adjacent
   through the wrap and must absorb what leaves the cell).

How order efficiencies are taken from macromax's field
------------------------------------------------------
The z axis runs downward: [top absorbing layer b][vacuum gap g][slab H]
[vacuum gap g][bottom absorbing layer b]. The source is one grid plane of
constant amplitude at depth b + 120 nm (it radiates a plane wave down to the
slab and one up into the top layer). The field is sampled on two lines of
grid points: z_R = 200 nm above the slab (between source and slab) and
z_T = 200 nm below it. A second solve with the slab removed (same grid,
source and layers: the "calibration" run) gives the incident field u_inc.
With F_m(u) = (1/N_x) sum_j u(x_j) exp(-2 pi i m x_j / period) (numpy's FFT,
order m at index m mod N_x):
    r_m = F_m(u(z_R) - u_inc(z_R)) / F_0(u_inc(z_R)),
    t_m = F_m(u(z_T)) / F_0(u_inc(z_T)),
    R_m = |r_m|^2 Re(k_zm)/k0,  T_m = |t_m|^2 Re(k_zm)/k0,
    k_zm = sqrt(k0^2 - (2 pi m / period)^2).
For propagating orders the distance from the line to the slab only changes
the phase of r_m, t_m; evanescent orders are excluded by the Fourier
projection. Normalising by the calibration run removes the source's
discretisation (its amplitude is ~ dz / (2 k0) up to the grid's band limit)
and the layers' effect on the incident wave itself; what remains of the
layers is their reflection of the scattered orders (worst for the steep
orders: m = +-7 travels at 74 deg from the normal here).

Timing: every code runs on one thread (RAYON_NUM_THREADS=1 for inksim;
OpenBLAS/FFTW threads = 1 for grcwa and macromax: macromax otherwise sets
its thread count to os.cpu_count(), which on a loaded 2-core machine made
each iteration ~20x slower). Reported: wall seconds of the solve (with
inksim's: solve + order efficiencies; macromax's: solve only, the
calibration run listed separately) and CPU seconds.

Usage (venv with `pip install macromax grcwa==0.1.2 numpy pyfftw`; pyfftw is
macromax's own recommended FFT backend):
    python scripts/peers.py                # the table of docs/PEERS.md (~5 min)
    python scripts/peers.py --quick        # coarse settings only (~1 min)
Options: --rcwa-orders 101,201,401 (truncations, finest = reference),
--inksim-cells 40,20,10,5, --mm "dx:bound:kmax[,...]" macromax settings,
--mm-tol 1e-6, --threads 1.
"""
import os

# One thread everywhere, before numpy is imported (see Timing above).
for _v in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_v] = "1"
os.cpu_count = lambda: 1  # macromax's numpy backend sizes its FFTW/BLAS threads by this

import argparse
import json
import logging
import resource
import subprocess
import sys
import time
from importlib.metadata import version
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
LAMBDA = 550.0
PERIOD = 4000.0
THICKNESS = 1000.0
STRIPE_X0 = 0.0
STRIPE_W = 400.0
N_BINDER = 1.558
N_STRIPE = 2.0 + 0.8j
ORDERS = list(range(-3, 4))
K0 = 2 * np.pi / LAMBDA


def cpu_self():
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def cpu_children():
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


# ---------------------------------------------------------------- RCWA ----

def rcwa(n_orders, samples_per_nm=4):
    """grcwa, s polarisation (E along y), normal incidence. Returns
    ({m: (R, T)} for propagating m, wall s, cpu s)."""
    import grcwa
    grcwa.set_backend("numpy")
    nx = int(round(PERIOD * samples_per_nm))
    x = (np.arange(nx) + 0.5) * PERIOD / nx
    cell = np.full(nx, N_BINDER**2, dtype=complex)
    cell[(x >= STRIPE_X0) & (x < STRIPE_X0 + STRIPE_W)] = N_STRIPE**2
    t0, c0 = time.time(), cpu_self()
    # 1-D grating in a 2-D code: the second lattice vector is so short that
    # its reciprocal orders never enter the truncation.
    obj = grcwa.obj(n_orders, [PERIOD, 0.0], [0.0, PERIOD * 1e-4], 1.0 / LAMBDA, 0.0, 0.0, verbose=0)
    obj.Add_LayerUniform(0.0, 1.0)
    obj.Add_LayerGrid(THICKNESS, nx, 1)
    obj.Add_LayerUniform(0.0, 1.0)
    obj.Init_Setup(Gmethod=0)
    obj.GridLayer_geteps(cell)
    assert np.all(obj.G[:, 1] == 0), "y orders entered the truncation"
    obj.MakeExcitationPlanewave(0.0, 0.0, 1.0, 0.0, order=0)
    r, t = obj.RT_Solve(normalize=1, byorder=1)
    wall, cpu = time.time() - t0, cpu_self() - c0
    out = {}
    for i, m in enumerate(obj.G[:, 0]):
        if abs(2 * np.pi * m / PERIOD) < K0:
            out[int(m)] = (float(np.real(r[i])), float(np.real(t[i])))
    return out, wall, cpu, len(obj.G)


# -------------------------------------------------------------- inksim ----

def inksim_binary():
    target = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    subprocess.run(["cargo", "build", "--release", "--quiet", "--example", "lamellar"],
                   cwd=ROOT, check=True)
    return target / "release" / "examples" / "lamellar"


def inksim(binary, cell, method, tol, threads):
    """One solve in its own process. Returns (record dict, cpu s)."""
    env = dict(os.environ, RAYON_NUM_THREADS=str(threads))
    c0 = cpu_children()
    p = subprocess.run([str(binary), "--tol", str(tol), "--methods", method, str(cell)],
                       cwd=ROOT, env=env, capture_output=True, text=True)
    cpu = cpu_children() - c0
    if p.returncode != 0:
        raise RuntimeError(f"lamellar {cell} nm {method}: {p.stderr.strip()}")
    lines = [json.loads(l[len("RESULT "):]) for l in p.stdout.splitlines() if l.startswith("RESULT ")]
    assert len(lines) == 1, p.stdout
    rec = lines[0]
    rec["orders"] = {m: (r, t) for m, r, t in zip(rec["m"], rec["R"], rec["T"])}
    return rec, cpu


# ------------------------------------------------------------ macromax ----

GAP = 520.0     # vacuum between each absorbing layer and the slab (nm)
SOURCE_DEPTH = 120.0  # source plane below the top absorbing layer (nm)
LINE_OFFSET = 200.0   # sampling lines above / below the slab (nm)


def macromax_setting(dx, bound, kmax, tol, max_iter=50000):
    """One macromax setting: grid step dx (= dz), absorbing-layer thickness
    `bound` at each z end with linear extinction rising to `kmax`, stop when
    macromax's residue < tol. Returns a dict with orders and costs."""
    import macromax
    from macromax.bound import LinearBound
    macromax.log.setLevel(logging.WARNING)
    for length in (bound, GAP, THICKNESS, SOURCE_DEPTH, LINE_OFFSET, PERIOD, STRIPE_W):
        if abs(length / dx - round(length / dx)) > 1e-9:
            raise ValueError(f"macromax grid step {dx} nm does not divide {length} nm")
    nx = int(round(PERIOD / dx))
    nz = int(round((2 * bound + 2 * GAP + THICKNESS) / dx))
    z = (np.arange(nz) + 0.5) * dx
    x = (np.arange(nx) + 0.5) * dx
    z_top, z_bot = bound + GAP, bound + GAP + THICKNESS
    slab = (z >= z_top) & (z < z_bot)
    eps = np.ones((nz, nx), dtype=complex)
    eps[slab, :] = N_BINDER**2
    eps[np.ix_(slab, (x >= STRIPE_X0) & (x < STRIPE_X0 + STRIPE_W))] = N_STRIPE**2
    src = np.zeros((nz, nx), dtype=complex)
    src[int(round((bound + SOURCE_DEPTH) / dx)), :] = 1.0
    i_r = int(round((z_top - LINE_OFFSET) / dx))
    i_t = int(round((z_bot + LINE_OFFSET) / dx))
    grid = macromax.Grid([nz, nx], dx)
    layers = LinearBound(grid, thickness=[[bound, bound], [0.0, 0.0]], max_extinction_coefficient=kmax)

    def run(e):
        t0, c0 = time.time(), cpu_self()
        s = macromax.solve(grid, vectorial=False, vacuum_wavelength=LAMBDA, source_distribution=src,
                           epsilon=e, bound=layers,
                           callback=lambda s: s.iteration < max_iter and s.residue > tol)
        field = np.asarray(s.E).reshape(nz, nx)
        return field, s.iteration, s.residue, time.time() - t0, cpu_self() - c0

    u_inc, it_inc, _, wall_inc, cpu_inc = run(np.ones((nz, nx), dtype=complex))
    u, it, res, wall, cpu = run(eps)

    def ft(line):
        return np.fft.fft(line) / nx

    inc_r, inc_t = ft(u_inc[i_r])[0], ft(u_inc[i_t])[0]
    fr, ftt = ft(u[i_r] - u_inc[i_r]), ft(u[i_t])
    orders = {}
    for m in range(-int(PERIOD / LAMBDA), int(PERIOD / LAMBDA) + 1):
        kz = np.sqrt(complex(K0**2 - (2 * np.pi * m / PERIOD) ** 2))
        w = kz.real / K0
        orders[m] = (float(abs(fr[m % nx] / inc_r) ** 2 * w), float(abs(ftt[m % nx] / inc_t) ** 2 * w))
    return {"nx": nx, "nz": nz, "orders": orders, "iterations": it, "residue": res,
            "wall": wall, "cpu": cpu, "cal_iterations": it_inc, "cal_wall": wall_inc, "cal_cpu": cpu_inc}


# --------------------------------------------------------------- table ----

def errors(orders, ref):
    d = {m: (abs(orders[m][0] - ref[m][0]), abs(orders[m][1] - ref[m][1])) for m in ORDERS}
    return max(max(v) for v in d.values()), d


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="coarse settings only")
    ap.add_argument("--rcwa-orders", default=None)
    ap.add_argument("--inksim-cells", default=None)
    ap.add_argument("--inksim-methods", default="auto,gmres")
    ap.add_argument("--tol", type=float, default=1e-8, help="inksim relative residual")
    ap.add_argument("--mm", default=None, help="macromax settings dx:bound:kmax, comma separated")
    ap.add_argument("--mm-tol", type=float, default=1e-6)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--json", default=None, help="also write all results here")
    a = ap.parse_args()
    if a.quick:
        rcwa_orders = [51, 101, 201]
        cells = [40, 20, 10]
        mm = [(40, 2000, 0.25), (20, 2000, 0.25)]
    else:
        rcwa_orders = [51, 101, 201, 401]
        cells = [40, 20, 10, 5]
        mm = [(40, 2000, 0.25), (20, 4000, 0.25), (10, 4000, 0.25), (10, 8000, 0.125),
              (5, 4000, 0.25), (5, 8000, 0.125)]
    if a.rcwa_orders:
        rcwa_orders = [int(s) for s in a.rcwa_orders.split(",")]
    if a.inksim_cells:
        cells = [float(s) for s in a.inksim_cells.split(",")]
    if a.mm:
        mm = [tuple(float(v) for v in s.split(":")) for s in a.mm.split(",")]

    rows = []  # (method, setting, max err, d, cost text, wall, cpu)
    print(f"grcwa {version('grcwa')}, macromax {version('macromax')}, numpy {np.__version__}", file=sys.stderr)

    # 1. RCWA: the reference is the finest truncation.
    runs = []
    for n in rcwa_orders:
        orders, wall, cpu, kept = rcwa(n)
        runs.append((n, kept, orders, wall, cpu))
        print(f"grcwa {kept} orders: R0 {orders[0][0]:.8f} T0 {orders[0][1]:.8f} ({wall:.1f} s)", file=sys.stderr)
    ref = runs[-1][2]
    if len(runs) > 1:
        ref_change = errors(runs[-2][2], ref)[0]
    else:
        ref_change = float("nan")
    fixture = ROOT / "tests" / "fixtures" / "lamellar_rcwa.json"
    fixture_diff = float("nan")
    if fixture.exists():
        case = [c for c in json.load(open(fixture))["cases"] if c["name"] == "strong_period4um"][0]
        fx = {o["m"]: (o["R"], o["T"]) for o in case["orders"]}
        fixture_diff = errors(ref, fx)[0]
    print(f"reference: grcwa {runs[-1][1]} orders; max change vs {runs[-2][1] if len(runs) > 1 else '-'} "
          f"orders {ref_change:.1e}; vs the fixture's 799-order result {fixture_diff:.1e}", file=sys.stderr)
    for n, kept, orders, wall, cpu in runs[:-1]:
        e, d = errors(orders, ref)
        rows.append(("grcwa", f"{kept} Fourier orders", e, d, "", wall, cpu))
    rows.append(("grcwa", f"{runs[-1][1]} Fourier orders (reference)", 0.0,
                 {m: (0.0, 0.0) for m in ORDERS}, f"change vs previous {ref_change:.0e}",
                 runs[-1][3], runs[-1][4]))

    # 2. inksim.
    binary = inksim_binary()
    ours = {}
    for cell in cells:
        for method in a.inksim_methods.split(","):
            rec, cpu = inksim(binary, cell, method, a.tol, a.threads)
            e, d = errors(rec["orders"], ref)
            ours[(cell, method)] = (rec, cpu)
            rows.append(("inksim", f"{method} ({rec['method']}), {cell:g} nm ({rec['nx']}×{rec['nz']}), tol {a.tol:.0e}",
                         e, d, f"{rec['iterations']} it, {rec['applications']} G applications",
                         rec["seconds"], cpu))
            print(f"inksim {cell} nm {method}: max err {e:.2e} ({rec['seconds']:.2f} s)", file=sys.stderr)
    # Richardson extrapolation of the two finest grids (both discretisations
    # are second order, tests/rcwa.rs): cost = both solves.
    if len(cells) >= 2:
        m0 = a.inksim_methods.split(",")[0]
        (f, cf), (c, cc) = ours[(cells[-1], m0)], ours[(cells[-2], m0)]
        ex = {m: ((4 * f["orders"][m][0] - c["orders"][m][0]) / 3, (4 * f["orders"][m][1] - c["orders"][m][1]) / 3)
              for m in ORDERS}
        e, d = errors(ex, ref)
        rows.append(("inksim", f"{m0}, Richardson of {cells[-2]:g} + {cells[-1]:g} nm", e, d,
                     "both solves", f["seconds"] + c["seconds"], cf + cc))

    # 3. macromax.
    for dx, bound, kmax in mm:
        r = macromax_setting(dx, bound, kmax, a.mm_tol)
        e, d = errors(r["orders"], ref)
        rows.append(("macromax", f"{dx:g} nm ({r['nx']}×{r['nz']}), layers {bound / 1000:g} µm, κmax {kmax:g}, "
                                 f"residue {a.mm_tol:.0e}", e, d,
                     f"{r['iterations']} it (+{r['cal_iterations']} it, {r['cal_wall']:.1f} s calibration)",
                     r["wall"], r["cpu"]))
        print(f"macromax {dx} nm, {bound} nm layers, kmax {kmax}: max err {e:.2e}, {r['iterations']} it, "
              f"{r['wall']:.1f} s", file=sys.stderr)

    print(f"\nReference: grcwa {runs[-1][1]} Fourier orders. Error = max over m = -3..3 of |ΔR_m|, |ΔT_m|.\n")
    print("| method | setting | max error | ΔR0 | ΔT0 | ΔT±1 | ΔT±3 | work | wall s | CPU s |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for meth, setting, e, d, work, wall, cpu in rows:
        print(f"| {meth} | {setting} | {e:.1e} | {d[0][0]:.1e} | {d[0][1]:.1e} | "
              f"{max(d[1][1], d[-1][1]):.1e} | {max(d[3][1], d[-3][1]):.1e} | {work} | {wall:.2f} | {cpu:.2f} |")
    if a.json:
        with open(a.json, "w") as fh:
            json.dump([{"method": r[0], "setting": r[1], "max_error": r[2],
                        "errors": {str(m): v for m, v in r[3].items()}, "work": r[4],
                        "wall_s": r[5], "cpu_s": r[6]} for r in rows], fh, indent=1)


if __name__ == "__main__":
    main()
