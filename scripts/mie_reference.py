#!/usr/bin/env python3
"""Reference Mie scattering of single spheres from an independent code, for
the vector Mie grain of the baselines (src/optics/baseline/mie.rs,
tests/mie_reference.rs).

Reference code: miepython (PyPI), version recorded in the fixture (written
with 3.3.0), by Scott Prahl, MIT licence; https://github.com/scottprahl/miepython.
It follows Wiscombe's MIEV0 algorithms (W. J. Wiscombe, Appl. Opt. 19,
1505 (1980)) in its own implementation.

Usage (in a venv with `pip install miepython numpy`):
    python scripts/mie_reference.py [--out tests/fixtures/mie_vector.json]
(A few seconds.)

Conventions. inksim writes the relative index of an absorbing sphere as
m = n + i kappa (time dependence exp(-i w t), Bohren & Huffman); miepython
takes m = n - i kappa and returns the scattering coefficients a_n, b_n of
Bohren & Huffman, but the complex conjugates of their amplitude functions
S1, S2 (Wiscombe's exp(+i w t) convention; norm="wiscombe" leaves them
unnormalised). The script passes conj(m), stores conj(S1), conj(S2), and
checks the convention itself: S(0) = sum (2n+1)/2 (a_n + b_n) from
miepython's own a_n, b_n, the optical theorem Q_ext = (4/x^2) Re S(0),
S1(0) = S2(0), and Q_abs > 0 for each absorbing case.

For each case (size parameter x, relative index m) the fixture holds:
- q_ext, q_sca, q_back, g from miepython.efficiencies_mx;
- a_n, b_n for n = 1..3 (miepython.coefficients);
- S1, S2 at the listed scattering angles (miepython.S1_S2, norm="wiscombe");
- chi_n = m_n / m_0, n = 0..10, the normalised Legendre moments of the
  unpolarised intensity (|S1|^2 + |S2|^2)/2, m_n = 2 pi int P_n(mu) I(mu) dmu,
  computed here by Gauss-Legendre quadrature with 2 N + 40 nodes (N
  miepython's number of terms; the integrand is a polynomial of degree
  2 N + 10, so the rule is exact); m_0 itself must equal pi x^2 Q_sca
  (k^2 sigma_sca) to 1e-10 and chi_1 must equal g to 1e-9.
"""

import argparse
import json
import platform
from importlib.metadata import version

import miepython
import numpy as np

# (name, x, Re m, Im m): dielectric, absorbing, rutile-like high index in a
# binder (2.73 / 1.558 = 1.75), metal-like, and large spheres.
CASES = [
    ("small-dielectric", 0.1, 1.5, 0.0),
    ("weak-sphere", 1.0, 1.005, 0.0),
    ("water", 1.0, 1.33, 0.0),
    ("absorbing", 3.0, 1.5, 0.01),
    ("rutile-in-binder", 10.0, 1.75, 0.0),
    ("rutile-absorbing", 5.0, 1.75, 0.05),
    ("hematite-like", 20.0, 1.9, 0.3),
    ("large-weakly-absorbing", 30.0, 1.5, 0.001),
    ("high-index-absorbing", 30.0, 3.0, 1.0),
    ("metal-like-small", 0.5, 0.2, 3.0),
    ("metal-like", 2.0, 0.3, 3.0),
]

ANGLES_DEG = [0.0, 30.0, 60.0, 90.0, 120.0, 150.0, 180.0]
MOMENTS = 10


def moments(m_mie, x, n_terms):
    """Normalised Legendre moments chi_0..chi_MOMENTS of (|S1|^2 + |S2|^2)/2
    and its m_0 = 2 pi int I dmu."""
    nodes, weights = np.polynomial.legendre.leggauss(2 * n_terms + 40)
    s1, s2 = miepython.S1_S2(m_mie, x, nodes, norm="wiscombe")
    intensity = 0.5 * (np.abs(s1) ** 2 + np.abs(s2) ** 2)
    m = []
    for n in range(MOMENTS + 1):
        p_n = np.polynomial.legendre.Legendre.basis(n)(nodes)
        m.append(2.0 * np.pi * float(np.sum(weights * intensity * p_n)))
    return [v / m[0] for v in m], m[0]


def case(name, x, m_re, m_im):
    m = complex(m_re, m_im)
    m_mie = m.conjugate()
    q_ext, q_sca, q_back, g = (float(v) for v in miepython.efficiencies_mx(m_mie, x))
    a, b = miepython.coefficients(m_mie, x)
    mu = np.cos(np.radians(ANGLES_DEG))
    s1, s2 = (np.conj(s) for s in miepython.S1_S2(m_mie, x, mu, norm="wiscombe"))
    # Convention checks (see the header).
    n = np.arange(1, len(a) + 1)
    forward = np.sum((2 * n + 1) / 2 * (a + b))
    assert abs(s1[0] - forward) < 1e-12 * abs(forward), (name, s1[0], forward)
    theorem = 4.0 / x**2 * s1[0].real
    assert abs(theorem - q_ext) < 1e-10 * q_ext, (name, theorem, q_ext)
    assert abs(s1[0] - s2[0]) < 1e-12 * abs(s1[0]), (name, s1[0], s2[0])
    if m_im > 0:
        assert q_ext - q_sca > 0, (name, q_ext, q_sca)
    chi, m0 = moments(m_mie, x, len(a))
    # m_0 = 2 pi int (|S1|^2+|S2|^2)/2 dmu = k^2 sigma_sca = pi x^2 Q_sca.
    sigma_check = abs(m0 - np.pi * x**2 * q_sca) / (np.pi * x**2 * q_sca)
    assert sigma_check < 1e-10, (name, sigma_check)
    assert abs(chi[1] - g) < 1e-9, (name, chi[1], g)
    pair = lambda z: [float(z.real), float(z.imag)]
    return {
        "name": name,
        "x": x,
        "m": [m_re, m_im],
        "n_terms_reference": len(a),
        "q_ext": q_ext,
        "q_sca": q_sca,
        "q_back": q_back,
        "g": g,
        "a": [pair(v) for v in a[:3]],
        "b": [pair(v) for v in b[:3]],
        "angles_deg": ANGLES_DEG,
        "s1": [pair(v) for v in s1],
        "s2": [pair(v) for v in s2],
        "chi": chi,
        "m0_relative_check": float(sigma_check),
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", default="tests/fixtures/mie_vector.json")
    args = parser.parse_args()
    out = {
        "generator": "scripts/mie_reference.py",
        "package": "miepython",
        "package_version": version("miepython"),
        "package_licence": "MIT",
        "numpy_version": np.__version__,
        "python_version": platform.python_version(),
        "conventions": "m = n + i kappa relative to the host (exp(-i w t)); miepython was called with "
                       "conj(m). a_n, b_n, S1, S2 of Bohren & Huffman (1983) ch. 4, unnormalised "
                       "(norm='wiscombe'; miepython's S1, S2 conjugated to Bohren & Huffman's); S(0) = sum (2n+1)/2 (a_n+b_n), "
                       "Q_ext = (4/x^2) Re S(0). a and b list n = 1, 2, 3.",
        "moments": "chi_n = m_n/m_0, n = 0..10, m_n = 2 pi int_-1^1 P_n(mu) (|S1|^2+|S2|^2)/2 dmu by "
                   "Gauss-Legendre with 2 N + 40 nodes (exact); m_0 = pi x^2 Q_sca checked to 1e-10",
        "cases": [case(*c) for c in CASES],
    }
    with open(args.out, "w") as f:
        json.dump(out, f, indent=1)
        f.write("\n")
    print(f"wrote {args.out} ({len(CASES)} cases)")


if __name__ == "__main__":
    main()
