#!/usr/bin/env python3
"""What an incoherent stack leaves out by not tracking polarisation between
its layers (docs/METHOD.md, "Stacks"): two flat, homogeneous, absorbing
layers of different binders on Lambertian paper, lit at 45° and seen along
the normal (45°/0°), and under diffuse light, in closed form.

Between the layers inksim adds natural light's fluxes: every flat surface
reflects the mean of its s and p reflectances. Exact for this geometry is
to add each polarisation's fluxes on its own (a flat surface keeps s and p
apart; the paper turns any light into natural light) and average at the
end. Both are computed here, independently of inksim, with every
multiple reflection between the surfaces and the paper:

- the collimated beam down through air | layer 1 | layer 2 to the paper,
  per polarisation, with the bounces between the surfaces;
- the paper's light (natural) going up: what the stack returns to the
  paper per direction and polarisation (its reflectance from below),
  integrated over the hemisphere (Gauss–Legendre in cos² θ);
- the light leaving along the normal (s and p alike there).

Prints, per case, the 45°/0° and diffuse reflectance factors both ways
and their relative difference, and the L* difference it makes.

Usage: python3 scripts/stack_polarisation.py   (standard library only)
"""
import math


def fresnel(n1, n2, cos1):
    """Power reflectances (s, p) from medium n1 into n2 at cosine cos1;
    total internal reflection gives (1, 1)."""
    sin2 = (n1 / n2) ** 2 * (1.0 - cos1 * cos1)
    if sin2 >= 1.0:
        return 1.0, 1.0
    cos2 = math.sqrt(1.0 - sin2)
    rs = (n1 * cos1 - n2 * cos2) / (n1 * cos1 + n2 * cos2)
    rp = (n2 * cos1 - n1 * cos2) / (n2 * cos1 + n1 * cos2)
    return rs * rs, rp * rp


def cos_in(n_from, n_to, cos_from):
    sin2 = (n_from / n_to) ** 2 * (1.0 - cos_from * cos_from)
    return None if sin2 >= 1.0 else math.sqrt(1.0 - sin2)


def gauss_legendre(n):
    """Nodes and weights on [0, 1] (Newton on Legendre's P_n)."""
    xs, ws = [], []
    for i in range(n):
        x = math.cos(math.pi * (i + 0.75) / (n + 0.5))
        for _ in range(100):
            p0, p1 = 1.0, x
            for k in range(2, n + 1):
                p0, p1 = p1, ((2 * k - 1) * x * p1 - (k - 1) * p0) / k
            dp = n * (x * p1 - p0) / (x * x - 1.0)
            dx = p1 / dp
            x -= dx
            if abs(dx) < 1e-15:
                break
        xs.append(0.5 * (x + 1.0))
        ws.append(1.0 / ((1.0 - x * x) * dp * dp))
    return xs, ws


def two_layers(n, a, d, mu, pol):
    """Down: flux of a collimated beam of polarisation `pol` (0 s, 1 p)
    reaching the paper, lit from air at cosine `mu`. n = (n1, n2), a the
    intensity absorption coefficients (1/µm), d the thicknesses (µm)."""
    (n1, n2), (a1, a2), (d1, d2) = n, a, d
    c1 = cos_in(1.0, n1, mu)
    c2 = cos_in(n1, n2, c1)
    if c2 is None:
        return 0.0
    r01 = fresnel(1.0, n1, mu)[pol]
    r12 = fresnel(n1, n2, c1)[pol]
    e1 = math.exp(-a1 * d1 / c1)
    e2 = math.exp(-a2 * d2 / c2)
    # bounces in layer 1 between surface 1|2 and surface 1|0 (same r as 0|1)
    return (1 - r01) * e1 * (1 - r12) / (1.0 - r12 * r01 * e1 * e1) * e2


def from_below(n, a, d, c2, pol):
    """Reflectance of the stack above the paper for light going up in layer 2
    at cosine c2, polarisation `pol` (bounces between the two surfaces)."""
    (n1, n2), (a1, a2), (d1, d2) = n, a, d
    e2 = math.exp(-a2 * d2 / c2)
    r21 = fresnel(n2, n1, c2)[pol]
    c1 = cos_in(n2, n1, c2)
    if c1 is None:
        return e2 * e2  # total reflection at 2|1
    e1 = math.exp(-a1 * d1 / c1)
    r10 = fresnel(n1, 1.0, c1)[pol]
    up = r21 + (1 - r21) ** 2 * e1 * e1 * r10 / (1.0 - r21 * r10 * e1 * e1)
    return e2 * e2 * up


def mean_fresnel_patch():
    """Let index 2 of fresnel() be natural light's mean reflectance."""
    base = fresnel

    def patched(n1, n2, cos1):
        rs, rp = base(n1, n2, cos1)
        return rs, rp, 0.5 * (rs + rp)

    return patched


def reflectance_factors(n, a, d, albedo, exact):
    """45°/0° and diffuse (d/0) reflectance factors of layers + paper."""
    pols = [0, 1] if exact else [2]
    xs, ws = gauss_legendre(48)
    # Stack reflectance from below for the paper's Lambertian light:
    # average over the projected hemisphere in layer 2 (u = cos² θ uniform).
    r_below = 0.0
    for u, w in zip(xs, ws):
        c2 = math.sqrt(u)
        r_below += w * sum(from_below(n, a, d, c2, p) for p in pols) / len(pols)
    # Along the normal up to air (s and p alike): the flux transmission is
    # the same both ways, and radiance over n² is kept across the surfaces.
    up0 = two_layers(n, a, d, 1.0, 0) / n[1] ** 2

    def via_paper(down):
        return albedo * down / (1.0 - albedo * r_below) * up0
    down45 = sum(two_layers(n, a, d, math.cos(math.radians(45.0)), p) for p in pols) / len(pols)
    # Diffuse light from air: average the beam over the projected hemisphere.
    down_d = 0.0
    for u, w in zip(xs, ws):
        mu = math.sqrt(u)
        down_d += w * sum(two_layers(n, a, d, mu, p) for p in pols) / len(pols)
    return via_paper(down45), via_paper(down_d)


def lstar(y):
    t = y
    return 116.0 * (t ** (1.0 / 3.0) if t > (6 / 29) ** 3 else t / (3 * (6 / 29) ** 2) + 4 / 29) - 16.0


def main():
    global fresnel
    fresnel = mean_fresnel_patch()
    cases = [
        ("clear coat 1.5 over ink 1.7", (1.50, 1.70)),
        ("ink 1.7 over ink 1.5", (1.70, 1.50)),
        ("clear coat 1.4 over ink 1.9", (1.40, 1.90)),
    ]
    print("| stack | absorbance of the ink (1/µm) | 45°/0° natural | per polarisation | relative | ΔL* | d/0 relative | ΔL* |")
    print("|---|---|---|---|---|---|---|---|")
    worst = 0.0
    for name, n in cases:
        for a_ink in [0.0, 0.2, 1.0, 3.0]:
            # A clear coat of 20 µm over 2 µm of ink; or two 2 µm inks.
            clear = "clear" in name
            a = (0.0, a_ink) if clear else (a_ink, a_ink)
            d = (20.0, 2.0) if clear else (2.0, 2.0)
            r_nat = reflectance_factors(n, a, d, 0.9, exact=False)
            r_pol = reflectance_factors(n, a, d, 0.9, exact=True)
            rel = [(p - q) / q for p, q in zip(r_pol, r_nat)]
            dl = [lstar(p) - lstar(q) for p, q in zip(r_pol, r_nat)]
            worst = max(worst, max(abs(x) for x in dl))
            print(
                f"| {name} | {a_ink:g} | {r_nat[0]:.5f} | {r_pol[0]:.5f} | {rel[0]:+.1e} | {dl[0]:+.3f} "
                f"| {rel[1]:+.1e} | {dl[1]:+.3f} |"
            )
    print(f"\nlargest |ΔL*|: {worst:.3f}")


if __name__ == "__main__":
    main()
