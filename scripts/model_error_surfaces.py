#!/usr/bin/env python3
"""The scalar equation's error at flat surfaces: dissolved inks (homogeneous
layers, closed form) solved with solver.equation = "helmholtz" and "maxwell"
on paper of albedo 0.9, and the CIEDE2000 difference of their colours per
measurement geometry (D50, 2°). Writes a Markdown table to stdout.

Usage: python3 scripts/model_error_surfaces.py [--inksim target/release/inksim]
Needs only the standard library; runs in a few seconds (every solve is the
closed-form slab)."""
import argparse
import csv
import math
import os
import subprocess
import tempfile

SCENE = """seed = 1
realisations = 1
[layer]
thickness_nm = 1000.0
fragment_nm = [500.0, 500.0]
binder_index = 1.558
[[pigment]]
name = "ink"
material = {{ builtin = "{pigment}" }}
pvc = {pvc}
shape = {{ kind = "molecular" }}
[grid]
cell_nm = 25.0
[illumination]
wavelength_range_nm = {{ start = 400.0, stop = 700.0, step = 10.0 }}
polar_deg = [0.0]
[solver]
equation = "{equation}"
[substrate]
kind = "paper"
albedo = 0.9
[output]
dir = "{out}"
name = "r"
[appearance]
outputs = ["tile"]
"""


def de00(l1, a1, b1, l2, a2, b2):
    """CIEDE2000 (Sharma, Wu, Dalal 2005), checked on their test pair below."""
    c1, c2 = math.hypot(a1, b1), math.hypot(a2, b2)
    cb = (c1 + c2) / 2
    g = 0.5 * (1 - math.sqrt(cb**7 / (cb**7 + 25**7)))
    a1p, a2p = (1 + g) * a1, (1 + g) * a2
    c1p, c2p = math.hypot(a1p, b1), math.hypot(a2p, b2)
    h1 = math.degrees(math.atan2(b1, a1p)) % 360
    h2 = math.degrees(math.atan2(b2, a2p)) % 360
    dl, dc, dh = l2 - l1, c2p - c1p, h2 - h1
    if c1p * c2p == 0:
        dh = 0
    elif dh > 180:
        dh -= 360
    elif dh < -180:
        dh += 360
    dhh = 2 * math.sqrt(c1p * c2p) * math.sin(math.radians(dh / 2))
    lb, cbp = (l1 + l2) / 2, (c1p + c2p) / 2
    if c1p * c2p == 0:
        hb = h1 + h2
    elif abs(h1 - h2) <= 180:
        hb = (h1 + h2) / 2
    elif h1 + h2 < 360:
        hb = (h1 + h2 + 360) / 2
    else:
        hb = (h1 + h2 - 360) / 2
    t = (1 - 0.17 * math.cos(math.radians(hb - 30)) + 0.24 * math.cos(math.radians(2 * hb))
         + 0.32 * math.cos(math.radians(3 * hb + 6)) - 0.20 * math.cos(math.radians(4 * hb - 63)))
    sl = 1 + 0.015 * (lb - 50) ** 2 / math.sqrt(20 + (lb - 50) ** 2)
    sc, sh = 1 + 0.045 * cbp, 1 + 0.015 * cbp * t
    rt = -2 * math.sqrt(cbp**7 / (cbp**7 + 25**7)) * math.sin(
        math.radians(60 * math.exp(-(((hb - 275) / 25) ** 2))))
    return math.sqrt((dl / sl) ** 2 + (dc / sc) ** 2 + (dhh / sh) ** 2 + rt * (dc / sc) * (dhh / sh))


GEOMETRIES = ("45/0", "d/8 SCI", "d/8 SCE")


def colours(inksim, work, pigment, pvc, equation):
    out = os.path.join(work, f"{pigment}-{pvc}-{equation}")
    scene = os.path.join(work, "scene.toml")
    with open(scene, "w") as f:
        f.write(SCENE.format(pigment=pigment, pvc=pvc, equation=equation, out=out))
    subprocess.run([inksim, "run", scene], check=True, capture_output=True)
    subprocess.run([inksim, "export", os.path.join(out, "r.h5")], check=True, capture_output=True)
    with open(os.path.join(out, "r-colours.csv")) as f:
        return {r["geometry"]: tuple(float(r[k]) for k in ("L_star", "a_star", "b_star"))
                for r in csv.DictReader(f) if r["geometry"] in GEOMETRIES}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--inksim", default="target/release/inksim")
    args = ap.parse_args()
    assert abs(de00(50, 2.6772, -79.7751, 50, 0, -82.7485) - 2.0425) < 1e-4
    print("| ink | PVC | " + " | ".join(GEOMETRIES) + " | L* 45/0, Helmholtz → Maxwell |")
    print("|---|---|" + "---|" * len(GEOMETRIES) + "---|")
    with tempfile.TemporaryDirectory() as work:
        for pigment in ("red", "blue", "yellow"):
            for pvc in (0.15, 0.3, 0.5):
                h = colours(args.inksim, work, pigment, pvc, "helmholtz")
                m = colours(args.inksim, work, pigment, pvc, "maxwell")
                d = [de00(*h[g], *m[g]) for g in GEOMETRIES]
                print(f"| {pigment} | {round(pvc * 100)} % | " + " | ".join(f"{x:.2f}" for x in d)
                      + f" | {h['45/0'][0]:.2f} → {m['45/0'][0]:.2f} |")


if __name__ == "__main__":
    main()
