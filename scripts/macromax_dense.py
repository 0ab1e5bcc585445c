#!/usr/bin/env python3
"""The dense sphere layer of scripts/treams_dense.py solved with the vector
convergent-Born code macromax (PyPI, `vectorial=True`), for the timing
against inksim's Maxwell solve in docs/PEERS.md. Prints one inksim-style
`RESULT {json}` line per setting, which `scripts/treams_dense.py --compare`
reads.

Geometry (tests/fixtures/treams_dense.json, case dense16): vacuum | binder
slab 0 <= z <= H (n = 1.558, H = 300 nm) holding 16 absorbing spheres
(r = 60 nm, n = 1.4 + 0.7i) | vacuum, one L x L cell (L = 500 nm) periodic in
x and y, lambda = 550 nm, light from z < 0 travelling to +z.

Incidence: normal only (0 deg; `s` = E along y, `p` = E along x; at 0 deg
the fixture stores `s`). macromax 0.2.2's grid is periodic with a plain FFT
(no Bloch phase / k-offset option), so a plane wave at 45 deg cannot be
represented in the 500 nm cell (sin 45 deg L / lambda = 0.643 is not an
integer); oblique incidence is therefore not run.

macromax set-up (the approach of scripts/peers.py, in 3-D):
- grid (x, y, z), step dx in all three, E[0..2] = Ex, Ey, Ez; x and y span
  one period exactly (FFT-periodic); along z
  [layer b][vacuum g][slab H][vacuum g][layer b], the z direction periodic
  too, so the two `LinearBound` layers (extinction rising linearly from 0 to
  kappa_max over b) meet through the wrap.
- epsilon per voxel: volume average of epsilon over 4^3 sub-samples of the
  voxel (binder / sphere; spheres wrap through the side walls), vacuum
  outside the slab. The slab faces lie on voxel faces.
- source: one grid plane of constant `source_distribution` along the
  polarisation at depth b + SOURCE_DEPTH; it radiates a plane wave to +z
  (towards the slab) and one to -z (into the top layer).
- planes: z_R = LINE_OFFSET above the slab, between source and slab;
  z_T = LINE_OFFSET below it.
- calibration: the same solve with epsilon = 1 everywhere (same grid, source
  and layers) gives the incident field E_inc; it does not depend on the
  structure and is timed separately (`calibration` in the RESULT line), not
  in cpu_seconds, as in docs/PEERS.md.
- with F_mn(E) = the (m, n) Fourier coefficient over the xy plane (numpy
  FFT / (nx ny)) and E_0 = F_00 of the incident polarisation component of
  E_inc on the same plane:
      R_mn = sum_c |F_mn(E_c(z_R) - E_inc,c(z_R))|^2 / |E_0(z_R)|^2 * Re kz_mn / k0
      T_mn = sum_c |F_mn(E_c(z_T))|^2 / |E_0(z_T)|^2 * Re kz_mn / k0
  over the propagating orders (at normal incidence and L < lambda, only
  (0, 0), whose field is transverse, so this is the exact power ratio,
  both polarisations of the order included), A = 1 - R - T.
- stop when macromax's residue < --tol (default 1e-6, as docs/PEERS.md).

Timing: one thread (OpenBLAS/OMP/MKL = 1, and os.cpu_count patched to 1
before macromax loads, because macromax's numpy backend sizes its FFTW and
BLAS threads by it); CPU seconds by time.process_time() around
macromax.solve (the epsilon raster and the order extraction are a few ms
and not included).

Usage (venv: pip install macromax numpy scipy pyfftw):
    python scripts/macromax_dense.py --settings 20:8000:0.25,10:8000:0.25 \
        | python scripts/treams_dense.py --compare dense16:0:s
    # settings: dx_nm:layer_nm:kappa_max[,...]; --gap, --tol, --pol
    python scripts/macromax_dense.py --no-spheres --settings 20:4000:0.25   # bare slab vs Airy
Layers: the bare slab (normal incidence, exact against Airy) needs
LinearBound layers of >= 4-8 um at kappa_max 0.25; 1 um layers reflect enough
to put R off by ~0.09.
"""
import os

for _v in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_v] = "1"
os.cpu_count = lambda: 1  # macromax's numpy backend sizes its FFTW/BLAS threads by this

import argparse  # noqa: E402
import json  # noqa: E402
import logging  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from importlib.metadata import version  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
FIXTURE = ROOT / "tests" / "fixtures" / "treams_dense.json"
SOURCE_DEPTH = 100.0  # source plane below the top absorbing layer (nm)
LINE_OFFSET = 160.0   # sampling planes above / below the slab (nm)
SUB = 4               # sub-samples per voxel edge for the epsilon average


def load_case(no_spheres=False):
    with open(FIXTURE) as f:
        fx = json.load(f)
    case = next(c for c in fx["cases"] if c["name"] == "dense16")
    if no_spheres:  # the bare binder slab, for the check against the Airy formula
        case = dict(case, spheres=[])
    return case


def airy(case):
    """R, T of the bare binder slab in vacuum at normal incidence."""
    n, h, k0 = case["n_binder"], case["thickness_nm"], 2 * np.pi / case["wavelength_nm"]
    r01 = (1 - n) / (1 + n)
    t01, t10 = 2 / (1 + n), 2 * n / (1 + n)
    ph = np.exp(1j * n * k0 * h)
    r = (r01 - r01 * ph**2) / (1 - r01**2 * ph**2)
    t = t01 * t10 * ph / (1 - r01**2 * ph**2)
    return abs(r) ** 2, abs(t) ** 2


def raster(case, dx):
    """(nx, nx, nzs) epsilon of the slab: volume average over SUB^3 sub-samples."""
    L, H = case["period_nm"], case["thickness_nm"]
    nx, nzs = int(round(L / dx)), int(round(H / dx))
    eps_b = case["n_binder"] ** 2
    eps = np.full((nx, nx, nzs), eps_b, dtype=complex)
    off = (np.arange(SUB) + 0.5) / SUB * dx  # sub-sample offsets within a voxel
    for s in case["spheres"]:
        cx, cy, cz = s["center_nm"]
        r = s["radius_nm"]
        eps_s = complex(*s["n"]) ** 2
        # voxel index ranges (unwrapped in x, y) touching the sphere
        ix = np.arange(int(np.floor((cx - r) / dx)), int(np.floor((cx + r) / dx)) + 1)
        iy = np.arange(int(np.floor((cy - r) / dx)), int(np.floor((cy + r) / dx)) + 1)
        iz = np.arange(max(0, int(np.floor((cz - r) / dx))), min(nzs - 1, int(np.floor((cz + r) / dx))) + 1)
        px = (ix[:, None] * dx + off[None, :]).ravel() - cx
        py = (iy[:, None] * dx + off[None, :]).ravel() - cy
        pz = (iz[:, None] * dx + off[None, :]).ravel() - cz
        inside = (px[:, None, None] ** 2 + py[None, :, None] ** 2 + pz[None, None, :] ** 2) <= r * r
        frac = inside.reshape(len(ix), SUB, len(iy), SUB, len(iz), SUB).mean(axis=(1, 3, 5))
        sel = np.ix_(ix % nx, iy % nx, iz)
        eps[sel] += frac * (eps_s - eps_b)
    return eps


def setting(case, dx, bound, kmax, gap, tol, pol, max_iter=100000):
    import macromax
    from macromax.bound import LinearBound
    macromax.log.setLevel(logging.WARNING)
    L, H, lam = case["period_nm"], case["thickness_nm"], case["wavelength_nm"]
    for length in (bound, gap, H, L, SOURCE_DEPTH, LINE_OFFSET):
        if abs(length / dx - round(length / dx)) > 1e-9:
            raise ValueError(f"grid step {dx} nm does not divide {length} nm")
    nx = int(round(L / dx))
    nb, ng, nzs = (int(round(v / dx)) for v in (bound, gap, H))
    nz = 2 * nb + 2 * ng + nzs
    k_top = nb + ng  # first slab voxel
    eps = np.ones((nx, nx, nz), dtype=complex)
    eps[:, :, k_top:k_top + nzs] = raster(case, dx)
    comp = 1 if pol == "s" else 0  # E along y (s at azimuth 0) or x
    src = np.zeros((3, nx, nx, nz), dtype=complex)
    src[comp, :, :, int(round((bound + SOURCE_DEPTH) / dx))] = 1.0
    i_r = k_top - int(round(LINE_OFFSET / dx))
    i_t = k_top + nzs - 1 + int(round(LINE_OFFSET / dx))
    grid = macromax.Grid([nx, nx, nz], dx)
    layers = LinearBound(grid, thickness=[[0.0, 0.0], [0.0, 0.0], [bound, bound]], max_extinction_coefficient=kmax)

    def run(e):
        t0, c0 = time.time(), time.process_time()
        s = macromax.solve(grid, vectorial=True, vacuum_wavelength=lam, source_distribution=src,
                           epsilon=e, bound=layers,
                           callback=lambda s: s.iteration < max_iter and s.residue > tol)
        field = np.asarray(s.E).reshape(3, nx, nx, nz)
        cpu, wall = time.process_time() - c0, time.time() - t0
        return field[:, :, :, [i_r, i_t]].copy(), s.iteration, float(s.residue), cpu, wall

    e_inc, it_inc, res_inc, cpu_inc, wall_inc = run(np.ones((nx, nx, nz), dtype=complex))
    e, it, res, cpu, wall = run(eps)

    def ft(plane):  # (3, nx, nx) -> per component Fourier coefficients
        return np.fft.fft2(plane, axes=(1, 2)) / (nx * nx)

    inc_r, inc_t = ft(e_inc[..., 0]), ft(e_inc[..., 1])
    fr, ftt = ft(e[..., 0] - e_inc[..., 0]), ft(e[..., 1])
    n0r, n0t = abs(inc_r[comp, 0, 0]) ** 2, abs(inc_t[comp, 0, 0]) ** 2
    k0 = 2 * np.pi / lam
    orders = []
    mmax = int(L / lam) + 1
    for m in range(-mmax, mmax + 1):
        for n in range(-mmax, mmax + 1):
            kx, ky = 2 * np.pi * m / L, 2 * np.pi * n / L
            if kx * kx + ky * ky >= k0 * k0:
                continue
            w = np.sqrt(k0 * k0 - kx * kx - ky * ky) / k0
            rr = float(np.sum(abs(fr[:, m % nx, n % nx]) ** 2) / n0r * w)
            tt = float(np.sum(abs(ftt[:, m % nx, n % nx]) ** 2) / n0t * w)
            orders.append([m, n, rr, tt])
    r_tot = sum(o[2] for o in orders)
    t_tot = sum(o[3] for o in orders)
    # flatness of the calibration field over the transmission plane (should be ~0)
    cal_flat = float(np.std(e_inc[comp, :, :, 1]) / abs(np.mean(e_inc[comp, :, :, 1])))
    return {
        "code": "macromax", "macromax_version": version("macromax"), "vectorial": True,
        "cell_nm": dx, "nx": nx, "nz": nz, "nz_slab": nzs, "layer_nm": bound, "kappa_max": kmax, "gap_nm": gap,
        "polar_deg": 0.0, "pol": pol, "method": "macromax-cbs", "tol": tol,
        "iterations": it, "residue": res, "cpu_seconds": cpu, "wall_seconds": wall,
        "calibration": {"iterations": it_inc, "residue": res_inc, "cpu_seconds": cpu_inc, "wall_seconds": wall_inc,
                        "flatness": cal_flat},
        "R": r_tot, "T": t_tot, "A": 1.0 - r_tot - t_tot, "orders": orders,
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--settings", default="20:8000:0.25", help="dx_nm:layer_nm:kappa_max[,...]")
    ap.add_argument("--gap", type=float, default=300.0, help="vacuum between slab and each layer (nm)")
    ap.add_argument("--tol", type=float, default=1e-6, help="macromax residue to stop at")
    ap.add_argument("--pol", default="s", choices=["s", "p"], help="normal incidence, s = E along y")
    ap.add_argument("--no-spheres", action="store_true",
                    help="the bare binder slab instead, with its error against the Airy formula")
    a = ap.parse_args()
    case = load_case(a.no_spheres)
    print(f"macromax {version('macromax')}, numpy {np.__version__}, scipy {version('scipy')}, "
          f"pyfftw {version('pyfftw') if _has('pyfftw') else 'absent'}", file=sys.stderr, flush=True)
    for s in a.settings.split(","):
        dx, bound, kmax = (float(v) for v in s.split(":"))
        rec = setting(case, dx, bound, kmax, a.gap, a.tol, a.pol)
        print(f"macromax {dx:g} nm ({rec['nx']}x{rec['nx']}x{rec['nz']}), layers {bound:g} nm kappa {kmax:g}: "
              f"R {rec['R']:.6f} T {rec['T']:.6f} A {rec['A']:.6f}, {rec['iterations']} it "
              f"(residue {rec['residue']:.1e}), {rec['cpu_seconds']:.1f} CPU s; calibration "
              f"{rec['calibration']['iterations']} it {rec['calibration']['cpu_seconds']:.1f} CPU s",
              file=sys.stderr, flush=True)
        if a.no_spheres:
            ra, ta = airy(case)
            print(f"  bare slab: Airy R {ra:.6f} T {ta:.6f}; error {max(abs(rec['R'] - ra), abs(rec['T'] - ta)):.2e}",
                  file=sys.stderr, flush=True)
            continue
        print("RESULT " + json.dumps(rec), flush=True)


def _has(mod):
    try:
        __import__(mod)
        return True
    except ImportError:
        return False


if __name__ == "__main__":
    main()
