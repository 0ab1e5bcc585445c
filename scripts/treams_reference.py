#!/usr/bin/env python3
"""Exact references for square lattices of spheres in a binder slab from an
independent T-matrix code (treams, PyPI), for tests/treams.rs and the
side-by-side timing in docs/PEERS.md.

Geometry (all cases): vacuum | slab 0 <= z <= H of binder (n = 1.558) with
one or two spheres per L x L cell, none touching the faces | vacuum. Light
arrives from z < 0 and enters the slab at z = 0, polar angle theta in the
x-z plane (azimuth 0), s (E along y, TE) or p (TM); lambda = 550 nm. Sphere
indices are relative to vacuum. Order (m, n) has tangential wave vector
k0 sin(theta) (1, 0) + 2 pi (m, n) / L; R_mn, T_mn are the powers carried
by that order (both outgoing polarisations) per incident power, A = 1 - R - T
(treams is exact in energy for lossless spheres; see the fixture's sanity).

How treams solves it (its documented array_spheres example, with the
spheres embedded in the binder): the sphere T-matrix in the binder
(TMatrix.sphere up to multipole order lmax), the lattice interaction by
Ewald lattice sums (TMatrix.latticeinteraction.solve; several spheres per
cell: TMatrix.cluster first), the array's S-matrix in a basis of the
diffraction orders with |G| <= bmax (SMatrices.from_array), stacked with
the two planar interfaces and the propagation through the binder to and from
the array's reference plane (SMatrices.interface / propagation / stack).
Per-order powers are the z-Poynting flux of each order's amplitudes
(treams' own poynting_avg_z, which SMatrices.tr sums).

Convergence (stored per case and incidence): the multipole order lmax and
the plane-wave cutoff bmax are raised until the largest per-order change is
below 1e-6 typically (always < 1e-4); the Ewald split parameter eta (treams
chooses it) is varied over 0.5 and 1.0 to show the lattice sums do not
matter. A homogeneous slab (no spheres) is checked against the Airy formula
in s and p, which also fixes treams' polarisation labels (parity 0 = TE = s).

Usage (in a venv with `pip install treams numpy`):
    python scripts/treams_reference.py [--out tests/fixtures/treams_spheres.json]
    target/release/examples/spheres_slab ... | python scripts/treams_reference.py \
        --compare CASE:POLAR:POL      # inksim's RESULT lines against the fixture
(The fixture takes a few minutes on one core; every solve is pinned to one
thread, the CPU seconds stored are time.process_time of this process.)
"""
import os

for _v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_v] = "1"

import argparse
import json
import platform
import subprocess
import sys
import time
import warnings
from importlib.metadata import version

import numpy as np
import treams
from treams._smatrix import poynting_avg_z

# treams 0.4.7 with numpy 2: pw.translate warns that its ufunc output is
# uninitialised where `where` is false; treams zeroes those entries itself.
warnings.filterwarnings("ignore", message="'where' used without 'out'")

WAVELENGTH = 550.0
N_BINDER = 1.558
ABSORBING = [1.4, 0.7]
RUTILE = [2.7, 0.0]

# Spheres: centre (x, y, z) in nm within the L x L x H cell (z from the lit
# face), radius nm, index [n', n''] relative to vacuum.
CASES = [
    {
        "name": "absorbing_r150",
        "period_nm": 800.0,
        "thickness_nm": 600.0,
        "spheres": [{"center_nm": [400.0, 400.0, 300.0], "radius_nm": 150.0, "n": ABSORBING}],
    },
    {
        # Sub-diffractive at normal incidence (2 pi / L > n_binder k0): a
        # lossless sphere lattice with diffraction orders guided in the slab
        # has guided-mode resonances (at L = 800 nm, 45 deg, R swings from 0.04
        # to 0.31 within 4 nm of wavelength), too sharp for a per-order test.
        "name": "rutile_r110",
        "period_nm": 340.0,
        "thickness_nm": 600.0,
        "spheres": [{"center_nm": [170.0, 170.0, 300.0], "radius_nm": 110.0, "n": RUTILE}],
    },
    {
        "name": "pair",
        "period_nm": 800.0,
        "thickness_nm": 600.0,
        "spheres": [
            {"center_nm": [250.0, 250.0, 250.0], "radius_nm": 120.0, "n": ABSORBING},
            {"center_nm": [550.0, 520.0, 380.0], "radius_nm": 100.0, "n": RUTILE},
        ],
    },
]
INCIDENCE = [(0.0, "s"), (0.0, "p"), (45.0, "s"), (45.0, "p")]

LMAX_SCAN = [2, 3, 4, 5, 6, 8, 10]
BMAX_SCAN = [3.0, 4.0, 6.0, 8.0]  # in units of 2 pi / L
ETA_CHECK = [0.5, 1.0]
LMAX_REF, BMAX_REF = 10, 8.0


def k0():
    return 2 * np.pi / WAVELENGTH


def solve(case, theta, pol, lmax, bmax, eta=0.0):
    """Per-order (m, n) -> (R, T) and totals for one incidence."""
    kk = k0()
    period = case["period_nm"]
    h = case["thickness_nm"]
    vac = treams.Material()
    binder = treams.Material(N_BINDER**2)
    kpar = kk * np.sin(np.radians(theta)) * np.array([1.0, 0.0])
    lattice = treams.Lattice.square(period)
    spheres = case["spheres"]
    tms = [
        treams.TMatrix.sphere(
            lmax,
            kk,
            s["radius_nm"],
            [treams.Material(complex(*s["n"]) ** 2), binder],
            poltype="parity",
        )
        for s in spheres
    ]
    # Reference plane of the array: the middle of the spheres' z extent.
    zs = [s["center_nm"][2] for s in spheres]
    z_lo = min(s["center_nm"][2] - s["radius_nm"] for s in spheres)
    z_hi = max(s["center_nm"][2] + s["radius_nm"] for s in spheres)
    assert 0 < z_lo and z_hi < h, "a sphere touches a face"
    z_ref = 0.5 * (z_lo + z_hi)
    if len(tms) == 1:
        tm = tms[0]
        assert abs(zs[0] - z_ref) < 1e-12
    else:
        pos = [[s["center_nm"][0], s["center_nm"][1], s["center_nm"][2] - z_ref] for s in spheres]
        tm = treams.TMatrix.cluster(tms, pos)
    arr = tm.latticeinteraction.solve(lattice, kpar, eta=eta)
    pwb = treams.PlaneWaveBasisByComp.diffr_orders(kpar, lattice, bmax * 2 * np.pi / period)
    sm = treams.SMatrices
    stack = sm.stack(
        [
            sm.interface(pwb, kk, [vac, binder], poltype="parity"),
            sm.propagation([0, 0, z_ref], pwb, kk, binder, poltype="parity"),
            sm.from_array(arr, pwb),
            sm.propagation([0, 0, h - z_ref], pwb, kk, binder, poltype="parity"),
            sm.interface(pwb, kk, [binder, vac], poltype="parity"),
        ]
    )
    # parity 0 = TE (s: E along y at azimuth 0), 1 = TM (p).
    inc = treams.plane_wave(
        kpar, 0 if pol == "s" else 1, k0=kk, basis=pwb, material=vac, modetype="up", poltype="parity"
    )
    trans, refl = stack.illuminate(inc)
    paz = poynting_avg_z(pwb, kk, vac, "parity")[0]
    inc_a = np.asarray(inc)
    s_inc = np.real(np.conj(inc_a) @ paz @ inc_a)
    t_tot, r_tot = stack.tr(inc)
    m = np.rint((pwb.kx - kpar[0]) * period / (2 * np.pi)).astype(int)
    n = np.rint((pwb.ky - kpar[1]) * period / (2 * np.pi)).astype(int)
    orders = []
    for mn in sorted(set(zip(m.tolist(), n.tolist()))):
        sel = (m == mn[0]) & (n == mn[1])
        kx = kpar[0] + 2 * np.pi * mn[0] / period
        ky = kpar[1] + 2 * np.pi * mn[1] / period
        if kx * kx + ky * ky >= kk * kk:
            continue  # evanescent in vacuum
        sub = np.ix_(sel, sel)
        pr = np.real(np.conj(np.asarray(refl)[sel]) @ paz[sub] @ np.asarray(refl)[sel]) / s_inc
        pt = np.real(np.conj(np.asarray(trans)[sel]) @ paz[sub] @ np.asarray(trans)[sel]) / s_inc
        orders.append({"m": mn[0], "n": mn[1], "R": float(pr), "T": float(pt)})
    r_sum = sum(o["R"] for o in orders)
    t_sum = sum(o["T"] for o in orders)
    assert abs(r_sum - r_tot) < 1e-9 and abs(t_sum - t_tot) < 1e-9, (r_sum, r_tot, t_sum, t_tot)
    return {"orders": orders, "R": r_sum, "T": t_sum, "A": 1.0 - r_sum - t_sum, "basis_size": len(pwb)}


def timed(*args, **kw):
    t0 = time.process_time()
    res = solve(*args, **kw)
    res["cpu_seconds"] = time.process_time() - t0
    return res


def max_diff(a, b):
    """Largest |dR_mn|, |dT_mn| and |dA| between two results (same orders)."""
    ka = {(o["m"], o["n"]): o for o in a["orders"]}
    kb = {(o["m"], o["n"]): o for o in b["orders"]}
    assert ka.keys() == kb.keys()
    d = max(max(abs(ka[k]["R"] - kb[k]["R"]), abs(ka[k]["T"] - kb[k]["T"])) for k in ka)
    return max(d, abs(a["A"] - b["A"]))


def airy(eps, h, theta, pol):
    """R, T of a homogeneous slab in vacuum (characteristic matrix)."""
    kk = k0()
    kx = kk * np.sin(np.radians(theta))
    kz0 = np.sqrt(kk * kk - kx * kx + 0j)
    kz1 = np.sqrt(eps * kk * kk - kx * kx + 0j)
    if kz1.imag < 0:
        kz1 = -kz1
    # admittance-like quantities: s: kz; p: kz / eps
    q0, q1 = (kz0, kz1) if pol == "s" else (kz0, kz1 / eps)
    d = kz1 * h
    m11, m12 = np.cos(d), 1j * np.sin(d) / q1
    m21, m22 = 1j * q1 * np.sin(d), np.cos(d)
    den = q0 * m11 + q0 * q0 * m12 + m21 + q0 * m22
    r = (q0 * m11 + q0 * q0 * m12 - m21 - q0 * m22) / den
    t = 2 * q0 / den
    return abs(r) ** 2, abs(t) ** 2


def airy_check():
    """treams with a vanishing sphere (index of the binder) against Airy."""
    worst = 0.0
    rows = []
    h = 600.0
    for theta in (0.0, 45.0, np.degrees(np.arctan(N_BINDER))):
        for pol in ("s", "p"):
            case = {
                "period_nm": 800.0,
                "thickness_nm": h,
                "spheres": [{"center_nm": [400.0, 400.0, 300.0], "radius_nm": 100.0, "n": [N_BINDER, 0.0]}],
            }
            res = solve(case, theta, pol, 3, 3.0)
            r, t = airy(N_BINDER**2, h, theta, pol)
            err = max(abs(res["R"] - r), abs(res["T"] - t))
            worst = max(worst, err)
            rows.append({"polar_deg": theta, "pol": pol, "R": res["R"], "T": res["T"], "R_airy": r, "T_airy": t})
    return {"max_error": worst, "cases": rows}


def reference(case, theta, pol):
    """Converged result with its convergence evidence."""
    ref = timed(case, theta, pol, LMAX_REF, BMAX_REF)
    lscan = []
    for lmax in LMAX_SCAN:
        r = ref if lmax == LMAX_REF else timed(case, theta, pol, lmax, BMAX_REF)
        lscan.append({"lmax": lmax, "bmax": BMAX_REF, "max_diff_vs_reference": max_diff(r, ref),
                      "cpu_seconds": r["cpu_seconds"], "R": r["R"], "T": r["T"]})
    bscan = []
    for bmax in BMAX_SCAN:
        r = ref if bmax == BMAX_REF else timed(case, theta, pol, LMAX_REF, bmax)
        bscan.append({"lmax": LMAX_REF, "bmax": bmax, "basis_size": r["basis_size"],
                      "max_diff_vs_reference": max_diff(r, ref), "cpu_seconds": r["cpu_seconds"]})
    eta = [{"eta": e, "max_diff_vs_reference": max_diff(solve(case, theta, pol, LMAX_REF, BMAX_REF, eta=e), ref)}
           for e in ETA_CHECK]
    prev_l = next(s for s in lscan if s["lmax"] == LMAX_SCAN[-2])["max_diff_vs_reference"]
    prev_b = next(s for s in bscan if s["bmax"] == BMAX_SCAN[-2])["max_diff_vs_reference"]
    # Cheapest setting of the scans within 1e-3 and 1e-4 of the reference.
    grid = []
    for lmax in LMAX_SCAN:
        for bmax in BMAX_SCAN:
            if lmax > 6 and bmax > 4:
                continue
            r = timed(case, theta, pol, lmax, bmax)
            grid.append((r["cpu_seconds"], lmax, bmax, max_diff(r, ref)))
    cheapest = {}
    for tol in (1e-3, 1e-4):
        best = min(g for g in grid if g[3] < tol)
        cheapest[f"{tol:.0e}"] = {"lmax": best[1], "bmax": best[2], "max_diff_vs_reference": best[3],
                                  "cpu_seconds": best[0]}
    return {
        "polar_deg": theta,
        "pol": pol,
        "lmax": LMAX_REF,
        "bmax_in_2pi_over_L": BMAX_REF,
        "basis_size": ref["basis_size"],
        "R": ref["R"],
        "T": ref["T"],
        "A": ref["A"],
        "orders": ref["orders"],
        "cpu_seconds": ref["cpu_seconds"],
        "max_change_from_lmax_minus": prev_l,
        "max_change_from_bmax_minus": prev_b,
        "max_change_with_eta": max(e["max_diff_vs_reference"] for e in eta),
        "lmax_scan": lscan,
        "bmax_scan": bscan,
        "eta_scan": eta,
        "cheapest": cheapest,
    }


def write_fixture(out):
    t0 = time.process_time()
    airy_res = airy_check()
    print(f"Airy check: max error {airy_res['max_error']:.2e}", flush=True)
    if airy_res["max_error"] > 1e-8:
        sys.exit("treams does not reproduce the homogeneous slab")
    cases = []
    for case in CASES:
        runs = []
        for theta, pol in INCIDENCE:
            res = reference(case, theta, pol)
            print(f"{case['name']} {theta:g} {pol}: R {res['R']:.6f} T {res['T']:.6f} A {res['A']:.6f} "
                  f"({len(res['orders'])} orders), lmax change {res['max_change_from_lmax_minus']:.1e}, "
                  f"bmax change {res['max_change_from_bmax_minus']:.1e}, eta {res['max_change_with_eta']:.1e}, "
                  f"{res['cpu_seconds']:.2f} CPU s; to 1e-3: {res['cheapest']['1e-03']}", flush=True)
            runs.append(res)
        c = dict(case)
        c.update({"wavelength_nm": WAVELENGTH, "n_binder": N_BINDER, "azimuth_deg": 0.0, "incidence": runs})
        cases.append(c)
    fixture = {
        "generator": "scripts/treams_reference.py",
        "package": "treams",
        "package_version": version("treams"),
        "numpy_version": np.__version__,
        "scipy_version": version("scipy"),
        "python_version": platform.python_version(),
        "geometry": "vacuum | slab 0<=z<=H of binder with the spheres of one L x L cell (square lattice) | vacuum; "
                    "light from z<0, entering at z=0, incidence in the x-z plane (azimuth 0); s = TE (E along y)",
        "method": "TMatrix.sphere (parity basis) in the binder, TMatrix.cluster for several spheres, "
                  "latticeinteraction.solve (Ewald lattice sums), SMatrices.from_array in the diffraction-order "
                  "basis |G| <= bmax, stacked with SMatrices.interface and SMatrices.propagation; per-order "
                  "powers from treams' poynting_avg_z (their sum is SMatrices.tr)",
        "orders_note": "order (m, n): tangential wave vector k0 sin(theta) (1, 0) + 2 pi (m, n) / L; R, T: both "
                       "outgoing polarisations; A = 1 - sum R - sum T",
        "convergence_note": "reference: lmax 10, bmax 8 (2 pi / L). max_change_from_lmax_minus: largest per-order "
                            "|dR|, |dT| (and |dA|) between lmax 8 and 10; max_change_from_bmax_minus: between bmax "
                            "6 and 8; max_change_with_eta: the Ewald split parameter set to 0.5 and 1.0 instead of "
                            "treams' choice. cheapest: the cheapest (lmax, bmax) of the scans within 1e-3 / 1e-4 of "
                            "the reference, with its CPU seconds (one thread, one incidence and polarisation, "
                            "everything from the sphere T-matrix to the order powers)",
        "airy_check": airy_res,
        "cases": cases,
        "total_cpu_seconds": time.process_time() - t0,
    }
    with open(out, "w") as f:
        json.dump(fixture, f, indent=1)
        f.write("\n")
    print(f"wrote {out} ({fixture['total_cpu_seconds']:.0f} CPU s)")


def compare(path, what):
    """Largest |dR_mn|, |dT_mn|, |dA| of inksim's RESULT lines (stdin)."""
    name, polar, pol = what.split(":")
    with open(path) as f:
        fx = json.load(f)
    case = next(c for c in fx["cases"] if c["name"] == name)
    inc = next(i for i in case["incidence"] if i["polar_deg"] == float(polar) and i["pol"] == pol)
    ref = {(o["m"], o["n"]): (o["R"], o["T"]) for o in inc["orders"]}
    print(f"{name} {polar} deg {pol}: treams {inc['cpu_seconds']:.2f} CPU s (lmax {inc['lmax']}); "
          f"to 1e-3: {inc['cheapest']['1e-03']}; to 1e-4: {inc['cheapest']['1e-04']}")
    for line in sys.stdin:
        if not line.startswith("RESULT "):
            continue
        r = json.loads(line[len("RESULT "):])
        ours = {(o[0], o[1]): (o[2], o[3]) for o in r["orders"]}
        assert ours.keys() == ref.keys(), (sorted(ours), sorted(ref))
        err = max(max(abs(ours[k][0] - ref[k][0]), abs(ours[k][1] - ref[k][1])) for k in ref)
        err = max(err, abs(r["A"] - inc["A"]))
        print(f"inksim {r['cell_nm']:g} nm ({r['nx']}x{r['nx']}x{r['nz']}): max error {err:.2e}, "
              f"{r['iterations']} iterations, {r['cpu_seconds']:.2f} CPU s, {r['wall_seconds']:.2f} wall s")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default="tests/fixtures/treams_spheres.json")
    ap.add_argument("--compare", metavar="CASE:POLAR:POL",
                    help="read examples/spheres_slab RESULT lines from stdin and print their error "
                         "against the fixture (--out) incidence, e.g. pair:45:s")
    args = ap.parse_args()
    if args.compare:
        compare(args.out, args.compare)
    else:
        write_fixture(args.out)


if __name__ == "__main__":
    main()
