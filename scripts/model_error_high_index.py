#!/usr/bin/env python3
"""One grain's scattering in the scalar equation against Maxwell's, for
high-index pigments: the scalar sphere (u and du/dr continuous at the
surface, partial waves in closed form here) against vector Mie from an
independent code (miepython, PyPI, MIT licence, Scott Prahl). Prints a
Markdown table of Q_sca and the transport efficiency Q_sca (1 - g) of each,
and their ratios, per grain diameter and wavelength.

Usage (in a venv with `pip install miepython scipy numpy`):
    python3 scripts/model_error_high_index.py [--n 2.75] [--binder 1.5]

Conventions: a lossless sphere of index n in a binder of index n_b,
relative index m = n / n_b, size parameter x = pi d n_b / lambda. The
scalar sphere's coefficients: u = j_l(kr) + a_l h_l(kr) outside,
c_l j_l(mkr) inside; Q_sca = (4/x^2) sum (2l+1) |a_l|^2 and
g = sum over l of the cross terms as for any partial-wave series."""
import argparse
import math

import miepython
import numpy as np
from scipy.special import spherical_jn, spherical_yn


def scalar_sphere(m, x, terms=40):
    """Q_sca and g of the scalar sphere."""
    a = []
    for l in range(terms):
        j, dj = spherical_jn(l, x), spherical_jn(l, x, True)
        h = j + 1j * spherical_yn(l, x)
        dh = dj + 1j * spherical_yn(l, x, True)
        js, djs = spherical_jn(l, m * x), spherical_jn(l, m * x, True)
        a.append((m * djs * j - js * dj) / (js * dh - m * djs * h))
    a = np.array(a)
    l = np.arange(terms)
    q = 4 / x**2 * np.sum((2 * l + 1) * abs(a) ** 2)
    # g = sum_l 2 (l+1) Re(a_l conj(a_{l+1})) * 4/x^2 / q (Legendre recursion)
    cross = np.sum((l[:-1] + 1) * 2 * np.real(a[:-1] * np.conj(a[1:])))
    g = 4 / x**2 * cross / q
    return q, g


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--n", type=float, default=2.75, help="grain index (rutile ~2.75 at 550 nm)")
    p.add_argument("--binder", type=float, default=1.5)
    args = p.parse_args()
    m = args.n / args.binder
    print(f"n = {args.n} in n_b = {args.binder} (m = {m:.3f}); miepython {miepython.__version__}\n")
    print("| d (nm) | λ (nm) | Q_sca Maxwell | Q_sca scalar | ratio | Q_sca(1−g) ratio |")
    print("|---|---|---|---|---|---|")
    for d in (100, 250, 450):
        for lam in (450, 550, 650):
            x = math.pi * d * args.binder / lam
            _, qv, _, gv = miepython.efficiencies_mx(m, x)
            qs, gs = scalar_sphere(m, x)
            print(
                f"| {d} | {lam} | {qv:.3f} | {qs:.3f} | {qs / qv:.2f} | "
                f"{qs * (1 - gs) / (qv * (1 - gv)):.2f} |"
            )


if __name__ == "__main__":
    main()
