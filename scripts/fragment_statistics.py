#!/usr/bin/env python3
"""The fragment's statistical error, measured on a finished study.

Reads every variant of a study folder (runs/study/<profile>/variants/*.h5),
takes the stored standard error of the 45°/0° colour's ΔE00
(appearance/measured/45_0/de00_se) and relates it to the independent
grains a fragment holds: N_s = φ_s · A · t / (π d³/6) / cluster size for
each granular species s (the same count as src/pipeline/accuracy.rs).

Prints the log–log slope of s.e. against Σ 1/N_s (1/2 if the scatter is
that of N independent grains), the constant C of s.e. ≈ C √(Σ 1/N_s / R)
per pigment (median, divided by 0.674: the median of |z| for a standard
normal z, which is how a two-realisation s.e. estimate scatters about the
true one), and how the measured s.e. compares with the model that uses
the constants in accuracy.rs.

    python3 scripts/fragment_statistics.py runs/study/quick [C_single C_mixture]

Needs h5py and numpy (`python3 -m pip install ./python`).
"""

import collections
import glob
import math
import sys
import tomllib

import h5py
import numpy as np

MEDIAN_ABS_Z = 0.674


def text(v):
    return v.decode() if isinstance(v, bytes) else str(v)


def grains(cfg):
    """1/N summed over granular species, or None for a layer without grains."""
    layer = cfg["layer"]
    fx, fy = layer["fragment_nm"]
    volume = fx * fy * layer["thickness_nm"]
    pigments = cfg["pigment"]
    shares = [p.get("share", 1.0) for p in pigments]
    inv = 0.0
    for p, share in zip(pigments, shares):
        if p.get("shape", {}).get("kind") == "molecular":
            continue
        phi = p.get("pvc", layer["pvc"] * share / sum(shares))
        size = p.get("agglomeration", {}).get("cluster_size", 1)
        n = phi * volume / (math.pi / 6 * p["diameter_nm"] ** 3) / size
        inv += 1.0 / n
    return inv if inv > 0 else None


def main():
    root = sys.argv[1]
    c_single, c_mixture = (float(x) for x in sys.argv[2:4]) if len(sys.argv) > 3 else (7.0, 35.0)
    rows = []
    for path in sorted(glob.glob(f"{root}/variants/*.h5")):
        with h5py.File(path, "r") as f:
            cfg = tomllib.loads(text(f["config"][()]))
            m = f["appearance/measured/45_0"]
            if "de00_se" not in m:
                continue
            se = float(np.asarray(m["de00_se"]).ravel()[0])
        inv = grains(cfg)
        if inv is None:
            continue
        name = path.rsplit("/", 1)[-1][:-3]
        mixture = len(cfg["pigment"]) > 1
        rows.append((name, se, inv, cfg.get("realisations", 1), mixture))
    if not rows:
        sys.exit(f"no granular variant with a standard error under {root}")
    print(f"{len(rows)} granular variants with a standard error under {root}")
    x = np.log([r[2] for r in rows])
    y = np.log([max(r[1], 1e-6) for r in rows])
    slope, _ = np.polyfit(x, y, 1)
    print(f"slope of log s.e. on log Σ 1/N: {slope:.2f} (1/2 for independent grains)")
    groups = collections.defaultdict(list)
    for name, se, inv, r, _ in rows:
        groups[name.split("_")[0]].append(se / math.sqrt(inv / r))
    print("pigment      variants  median C_hat  C = median / 0.674")
    for k, v in sorted(groups.items()):
        med = float(np.median(v))
        print(f"{k:<12} {len(v):>8}  {med:>12.1f}  {med / MEDIAN_ABS_Z:>18.1f}")
    ratio = []
    for name, se, inv, r, mixture in rows:
        c = c_mixture if mixture else c_single
        ratio.append(se / (c * math.sqrt(inv / r)))
    ratio = np.array(ratio)
    p50, p90, p99 = np.percentile(ratio, [50, 90, 99])
    print(
        f"measured / model (C = {c_single:g} single, {c_mixture:g} mixture): "
        f"median {p50:.2f}, 90th percentile {p90:.2f}, 99th {p99:.2f}; "
        f"{np.mean(ratio > 1) * 100:.0f} % of variants above the model"
    )
    print("largest measured s.e.:")
    for name, se, inv, r, _ in sorted(rows, key=lambda t: -t[1])[:6]:
        print(f"  {name:<34} s.e. {se:6.2f}  grains (effective) {1 / inv:8.1f}")


if __name__ == "__main__":
    main()
