#!/usr/bin/env python3
"""Exact reference for a DENSE random layer of spheres in a binder slab from
the T-matrix code treams (PyPI), for the side-by-side timing against
inksim's Maxwell solve in docs/PEERS.md.

Geometry: vacuum | slab 0 <= z <= H of binder (n = 1.558) | vacuum, one
square L x L cell (periodic in x and y) holding N equal absorbing spheres
(n = 1.4 + 0.7i relative to vacuum) at random positions from a fixed seed:
random sequential addition, no two spheres closer than GAP_NM surface to
surface (nearest periodic image), every sphere at least MARGIN_NM from both
faces; a sphere may cross the cell's side walls (both codes wrap it
periodically). Light, orders, R_mn, T_mn and A as in
scripts/treams_reference.py, whose `solve` (TMatrix.sphere ->
TMatrix.cluster -> latticeinteraction.solve with Ewald lattice sums ->
SMatrices.from_array in the diffraction orders |G| <= bmax, stacked with
the two interfaces), `timed` (process CPU seconds, BLAS pinned to one
thread) and `max_diff` (largest per-order |dR|, |dT| and |dA|) are reused
here unchanged; `--compare` is that script's compare.

Convergence: lmax is raised (at bmax = BMAX_HI = 6 (2 pi / L)) until the largest per-order
change between successive lmax is below 1e-4; then bmax is raised at that
lmax the same way; the last setting of both scans is the reference. The
cheapest setting within 1e-3 (and 1e-4) of it is searched over a small
grid of cheaper (lmax, bmax) and the lmax scan itself.

Usage (in a venv with `pip install treams==0.4.7 numpy`):
    python scripts/treams_dense.py [--out tests/fixtures/treams_dense.json] [--incidence 45:p ...]
    target/release/examples/spheres_slab $(python scripts/treams_dense.py --inksim-args 45:p) 20 10 \
        | python scripts/treams_dense.py --compare dense16:45:p
    # cost against the number of spheres per cell: the same layer tiled 2 x 2 (64 spheres per cell)
    python scripts/treams_dense.py --supercell 2 --time 2:3 --incidence 45:p
    target/release/examples/spheres_slab $(python scripts/treams_dense.py --supercell 2 --inksim-args 45:p) 10 \
        | python scripts/treams_dense.py --supercell 2 --compare dense16:45:p
"""
import os

for _v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_v] = "1"

import argparse
import json
import platform
import sys
import time
from importlib.metadata import version

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import numpy as np  # noqa: E402
import treams_reference as tr  # noqa: E402

NAME = "dense16"
PERIOD_NM = 500.0  # 20, 10 and 5 nm cells divide L and H
THICKNESS_NM = 300.0
N_SPHERES = 16
RADIUS_NM = 60.0
INDEX = tr.ABSORBING  # 1.4 + 0.7i
GAP_NM = 2.0
MARGIN_NM = 10.0
SEED = 20240611

LMAX_SCAN = [2, 3, 4, 5, 6, 7, 8, 9, 10]
BMAX_SCAN = [6.0, 8.0, 10.0, 12.0]  # in units of 2 pi / L, from BMAX_HI up
BMAX_HI = 6.0
STEP_TOL = 1e-4
CHEAP_GRID = [(l, b) for l in (2, 3, 4) for b in (2.0, 3.0, 4.0)]


def spheres():
    """The random layer: N non-overlapping spheres, fixed seed."""
    rng = np.random.default_rng(SEED)
    r = RADIUS_NM
    zlo, zhi = r + MARGIN_NM, THICKNESS_NM - r - MARGIN_NM
    centres = []
    tries = 0
    while len(centres) < N_SPHERES:
        tries += 1
        assert tries < 100_000, "layer too dense for random sequential addition"
        c = np.array([rng.uniform(0, PERIOD_NM), rng.uniform(0, PERIOD_NM), rng.uniform(zlo, zhi)])
        c = np.round(c, 3)
        ok = True
        for s in centres:
            d = c - s
            d[:2] -= PERIOD_NM * np.round(d[:2] / PERIOD_NM)
            if np.linalg.norm(d) < 2 * r + GAP_NM:
                ok = False
                break
        if ok:
            centres.append(c)
    return [{"center_nm": [float(x) for x in c], "radius_nm": r, "n": list(INDEX)} for c in centres]


def layer_stats(sph):
    vol = sum(4 / 3 * np.pi * s["radius_nm"] ** 3 for s in sph)
    gaps = []
    for i, a in enumerate(sph):
        best = np.inf
        for j, b in enumerate(sph):
            if i == j:
                continue
            d = np.array(a["center_nm"]) - np.array(b["center_nm"])
            d[:2] -= PERIOD_NM * np.round(d[:2] / PERIOD_NM)
            best = min(best, np.linalg.norm(d) - a["radius_nm"] - b["radius_nm"])
        gaps.append(best)
    return {
        "volume_fraction": vol / (PERIOD_NM**2 * THICKNESS_NM),
        "min_gap_nm": float(min(gaps)),
        "median_nearest_gap_nm": float(np.median(gaps)),
    }


def short(res, ref, lmax, bmax):
    return {"lmax": lmax, "bmax": bmax, "basis_size": res["basis_size"],
            "max_diff_vs_reference": tr.max_diff(res, ref) if ref is not None else None,
            "cpu_seconds": res["cpu_seconds"], "R": res["R"], "T": res["T"], "A": res["A"]}


def reference(case, theta, pol):
    """Converged result, its scans and the cheapest settings to 1e-3 / 1e-4."""
    say = lambda s: print(f"  {theta:g} {pol}: {s}", flush=True)  # noqa: E731
    runs = {}  # (lmax, bmax) -> result

    def run(lmax, bmax):
        if (lmax, bmax) not in runs:
            runs[(lmax, bmax)] = tr.timed(case, theta, pol, lmax, bmax)
            r = runs[(lmax, bmax)]
            say(f"lmax {lmax} bmax {bmax:g}: R {r['R']:.7f} T {r['T']:.7f} A {r['A']:.7f} "
                f"({r['cpu_seconds']:.1f} CPU s)")
        return runs[(lmax, bmax)]

    def converge(values, solve, label):
        """Solve at each value in turn until a step changes < STEP_TOL; the
        last value solved and the steps."""
        steps, prev = [], None
        for v in values:
            cur = solve(v)
            if prev is not None:
                steps.append({"from": prev[0], "to": v, "max_change": tr.max_diff(cur, prev[1])})
                say(f"  {label} {prev[0]:g} -> {v:g}: {steps[-1]['max_change']:.1e}")
                if steps[-1]["max_change"] < STEP_TOL:
                    break
            prev = (v, cur)
        return v, steps

    # lmax at a generous bmax, then bmax at that lmax.
    lmax_ref, lsteps = converge(LMAX_SCAN, lambda lmax: run(lmax, BMAX_HI), "lmax")
    bmax_ref, bsteps = converge(BMAX_SCAN, lambda bmax: run(lmax_ref, bmax), "bmax")
    ref = runs[(lmax_ref, bmax_ref)]
    for lmax, bmax in CHEAP_GRID:
        run(lmax, bmax)
    scan = sorted((short(r, ref, l, b) for (l, b), r in runs.items()), key=lambda s: (s["lmax"], s["bmax"]))
    cheapest = {}
    for tol in (1e-3, 1e-4):
        ok = [s for s in scan if s["max_diff_vs_reference"] < tol and (s["lmax"], s["bmax"]) != (lmax_ref, bmax_ref)]
        cheapest[f"{tol:.0e}"] = min(ok, key=lambda s: s["cpu_seconds"]) if ok else None
    return {
        "polar_deg": theta,
        "pol": pol,
        "lmax": lmax_ref,
        "bmax_in_2pi_over_L": bmax_ref,
        "basis_size": ref["basis_size"],
        "R": ref["R"],
        "T": ref["T"],
        "A": ref["A"],
        "orders": ref["orders"],
        "cpu_seconds": ref["cpu_seconds"],
        "lmax_steps": lsteps,
        "bmax_steps": bsteps,
        "scan": scan,
        "cheapest": cheapest,
    }


def write_fixture(out, incidences):
    t0 = time.process_time()
    sph = spheres()
    stats = layer_stats(sph)
    print(f"{NAME}: {len(sph)} spheres r {RADIUS_NM:g} nm in {PERIOD_NM:g}^2 x {THICKNESS_NM:g} nm, "
          f"volume fraction {stats['volume_fraction']:.3f}, min gap {stats['min_gap_nm']:.1f} nm", flush=True)
    case = {"name": NAME, "period_nm": PERIOD_NM, "thickness_nm": THICKNESS_NM, "spheres": sph}
    runs = []
    for theta, pol in incidences:
        res = reference(case, theta, pol)
        print(f"{NAME} {theta:g} {pol}: reference lmax {res['lmax']} bmax {res['bmax_in_2pi_over_L']:g} "
              f"({res['cpu_seconds']:.1f} CPU s), R {res['R']:.6f} T {res['T']:.6f} A {res['A']:.6f}; "
              f"to 1e-3: {res['cheapest']['1e-03']}", flush=True)
        runs.append(res)
    c = dict(case)
    c.update({"wavelength_nm": tr.WAVELENGTH, "n_binder": tr.N_BINDER, "azimuth_deg": 0.0,
              "seed": SEED, "min_gap_rule_nm": GAP_NM, "face_margin_nm": MARGIN_NM, **stats,
              "incidence": runs})
    fixture = {
        "generator": "scripts/treams_dense.py",
        "package": "treams",
        "package_version": version("treams"),
        "numpy_version": np.__version__,
        "scipy_version": version("scipy"),
        "python_version": platform.python_version(),
        "geometry": "vacuum | slab 0<=z<=H of binder with the spheres of one L x L cell (periodic in x, y; "
                    "spheres may cross the side walls) | vacuum; light from z<0, entering at z=0, incidence in "
                    "the x-z plane (azimuth 0); s = TE (E along y)",
        "method": "as tests/fixtures/treams_spheres.json (scripts/treams_reference.py solve): TMatrix.sphere, "
                  "TMatrix.cluster of all N spheres, latticeinteraction.solve (Ewald lattice sums), "
                  "SMatrices.from_array in the diffraction orders |G| <= bmax, stacked with the interfaces",
        "convergence_note": "lmax raised at bmax 6 (2 pi / L) until the largest per-order |dR|, |dT|, |dA| between "
                            "successive lmax is < 1e-4 (lmax_steps), then bmax raised at that lmax the same way "
                            "(bmax_steps); the last setting is the reference. scan: every setting solved, with "
                            "its difference from the reference and CPU seconds (one thread, one incidence, "
                            "everything from the sphere T-matrices to the order powers). cheapest: the cheapest "
                            "of the scan within 1e-3 / 1e-4 of the reference",
        "cases": [c],
        "total_cpu_seconds": time.process_time() - t0,
    }
    with open(out, "w") as f:
        json.dump(fixture, f, indent=1)
        f.write("\n")
    print(f"wrote {out} ({fixture['total_cpu_seconds']:.0f} CPU s)")


def supercell(case, k):
    """The stored layer tiled k x k: the same structure with k^2 N spheres per cell."""
    if k == 1:
        return case
    period = case["period_nm"]
    sph = [dict(s, center_nm=[s["center_nm"][0] + i * period, s["center_nm"][1] + j * period, s["center_nm"][2]])
           for i in range(k) for j in range(k) for s in case["spheres"]]
    return dict(case, period_nm=k * period, spheres=sph)


def inksim_args(path, what, k=1):
    """The examples/spheres_slab arguments of the stored layer (tiled k x k)."""
    polar, pol = what.split(":")
    with open(path) as f:
        case = supercell(json.load(f)["cases"][0], k)
    args = ["--period", f"{case['period_nm']:g}", "--thickness", f"{case['thickness_nm']:g}",
            "--polar", polar, "--pol", pol]
    for s in case["spheres"]:
        x, y, z = s["center_nm"]
        args += ["--sphere", f"{x:g},{y:g},{z:g},{s['radius_nm']:g},{s['n'][0]:g},{s['n'][1]:g}"]
    print(" ".join(args))


def tiled_error(orders, a_tot, inc, k):
    """Largest per-order |dR|, |dT| and |dA| of a K x K tiling's orders against the layer's reference:
    order (K m, K n) is the layer's (m, n), every other order is zero."""
    ref = {(o["m"], o["n"]): (o["R"], o["T"]) for o in inc["orders"]}
    seen = set()
    err = abs(a_tot - inc["A"])
    for m, n, r, t in orders:
        key = (m // k, n // k) if m % k == 0 and n % k == 0 else None
        want = ref.get(key, (0.0, 0.0))
        seen.add(key)
        err = max(err, abs(r - want[0]), abs(t - want[1]))
    assert set(ref) <= seen, "orders of the layer missing from the tiling"
    return err


def load_incidence(path, polar, pol):
    with open(path) as f:
        case = json.load(f)["cases"][0]
    inc = next(i for i in case["incidence"] if i["polar_deg"] == float(polar) and i["pol"] == pol)
    return case, inc


def supercell_compare(path, what, k):
    """inksim's RESULT lines for the K x K tiling (stdin) against the layer's reference."""
    _, polar, pol = what.split(":")
    _, inc = load_incidence(path, polar, pol)
    for line in sys.stdin:
        if line.startswith("RESULT "):
            r = json.loads(line[len("RESULT "):])
            err = tiled_error(r["orders"], r["A"], inc, k)
            print(f"inksim {k}x{k} tiling, {r['cell_nm']:g} nm ({r['nx']}x{r['nx']}x{r['nz']}): max error {err:.2e}, "
                  f"{r['iterations']} iterations, {r['cpu_seconds']:.2f} CPU s")


def supercell_time(path, setting, incidence, k):
    """One timed treams solve of the K x K tiling against the layer's reference."""
    lmax, bmax = int(setting.split(":")[0]), float(setting.split(":")[1])
    polar, pol = incidence.split(":")
    case, inc = load_incidence(path, polar, pol)
    res = tr.timed(supercell(case, k), float(polar), pol, lmax, k * bmax)
    err = tiled_error([(o["m"], o["n"], o["R"], o["T"]) for o in res["orders"]], res["A"], inc, k)
    print(f"treams {k}x{k} tiling ({k * k * len(case['spheres'])} spheres per cell), lmax {lmax}, "
          f"bmax {bmax:g} (2 pi / L of the layer): max error {err:.2e}, {res['cpu_seconds']:.1f} CPU s")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default="tests/fixtures/treams_dense.json")
    ap.add_argument("--incidence", nargs="+", default=["45:p"], metavar="POLAR:POL")
    ap.add_argument("--inksim-args", metavar="POLAR:POL",
                    help="print the examples/spheres_slab arguments of the stored layer")
    ap.add_argument("--compare", metavar="CASE:POLAR:POL",
                    help="read examples/spheres_slab RESULT lines from stdin and print their error "
                         "against the fixture (--out), e.g. dense16:45:p")
    ap.add_argument("--supercell", type=int, default=1, metavar="K",
                    help="with --inksim-args, --compare or --time: the layer tiled K x K (K^2 N spheres per "
                         "cell, the same structure; order (m, n) of the layer is order (K m, K n) of the tiling)")
    ap.add_argument("--time", metavar="LMAX:BMAX",
                    help="time one treams solve of the (tiled) layer at the first --incidence, bmax in 2 pi / L "
                         "of the layer, and print its error against the fixture's reference")
    args = ap.parse_args()
    if args.inksim_args:
        inksim_args(args.out, args.inksim_args, args.supercell)
    elif args.compare and args.supercell > 1:
        supercell_compare(args.out, args.compare, args.supercell)
    elif args.compare:
        tr.compare(args.out, args.compare)
    elif args.time:
        supercell_time(args.out, args.time, args.incidence[0], args.supercell)
    else:
        inc = [(float(w.split(":")[0]), w.split(":")[1]) for w in args.incidence]
        write_fixture(args.out, inc)


if __name__ == "__main__":
    main()
