#!/usr/bin/env python3
"""Check a BSDF exported by `inksim export <result.h5> --mitsuba` in Mitsuba 3.

Loads `<name>.bsdf` as a `measured` BSDF in Mitsuba 3's `scalar_spectral`
variant, evaluates it at every row of `<name>-bsdf-samples.csv` (directions
and wavelength, with inksim's own evaluation `brdf_cos` = BRDF x cos(theta_o),
which is what Mitsuba's `eval` returns) and prints the relative error per
direction, its maximum and median. Exits 1 when the largest relative error
exceeds --tolerance.

Needs `pip install mitsuba` (3.x). Usage:

    python scripts/mitsuba_check.py runs/demo/demo.bsdf \
        runs/demo/demo-bsdf-samples.csv [--tolerance 0.05] [--json out.json]
"""

import argparse
import csv
import json
import math
import statistics
import sys


def unit(theta_deg, phi_deg):
    t, p = math.radians(theta_deg), math.radians(phi_deg)
    return (math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t))


def compare(bsdf_path, samples_path, variant="scalar_spectral"):
    """Rows of (inputs, inksim, mitsuba, relative error)."""
    import mitsuba as mi

    mi.set_variant(variant)
    bsdf = mi.load_dict({"type": "measured", "filename": str(bsdf_path)})
    ctx = mi.BSDFContext()
    rows = []
    with open(samples_path, newline="", encoding="utf-8") as f:
        for r in csv.DictReader(f):
            v = {k: float(x) for k, x in r.items()}
            si = mi.SurfaceInteraction3f()
            si.wi = mi.Vector3f(*unit(v["theta_i_deg"], v["phi_i_deg"]))
            si.wavelengths = mi.Spectrum([v["wavelength_nm"]] * 4)
            wo = mi.Vector3f(*unit(v["theta_o_deg"], v["phi_o_deg"]))
            m = float(bsdf.eval(ctx, si, wo)[0])
            ref = v["brdf_cos"]
            rel = abs(m - ref) / ref if ref > 0 else abs(m)
            rows.append((v, ref, m, rel))
    return rows


def summary(rows):
    rel = [r[3] for r in rows]
    return {
        "n": len(rel),
        "max_relative_error": max(rel),
        "median_relative_error": statistics.median(rel),
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("bsdf")
    ap.add_argument("samples")
    ap.add_argument("--variant", default="scalar_spectral")
    ap.add_argument("--tolerance", type=float, default=0.05)
    ap.add_argument("--json", help="write the summary here")
    a = ap.parse_args()
    rows = compare(a.bsdf, a.samples, a.variant)
    s = summary(rows)
    worst = max(rows, key=lambda r: r[3])
    v = worst[0]
    print(
        f"{s['n']} evaluations ({a.variant}): relative error max {s['max_relative_error']:.3g}, "
        f"median {s['median_relative_error']:.3g}; worst at theta_i {v['theta_i_deg']:g}, "
        f"theta_o {v['theta_o_deg']:g}, phi_o - phi_i {v['phi_o_deg'] - v['phi_i_deg']:g} deg, "
        f"{v['wavelength_nm']:g} nm: inksim {worst[1]:.6g}, mitsuba {worst[2]:.6g}"
    )
    if a.json:
        with open(a.json, "w", encoding="utf-8") as f:
            json.dump(s, f, indent=1)
    return 0 if s["max_relative_error"] <= a.tolerance else 1


if __name__ == "__main__":
    sys.exit(main())
