//! The two-flux layer: Kubelka–Munk reflectance on a Lambertian backing,
//! and Saunderson's correction for the layer's surface.

/// Kubelka–Munk reflectance of a layer of absorption coefficient `k`,
/// scattering coefficient `s` (1/length) and thickness `x` on a backing of
/// reflectance `rg`.
///
/// With `a = 1 + K/S`, `b = √(a² − 1)` and `t = tanh(b S X)/b`:
/// `R = [t (1 − R_g a) + R_g] / [t (a − R_g) + 1]`, the usual closed form
/// divided by `b coth(b S X)`, which stays finite in both limits:
/// - `K → 0` (`b → 0`, `t → S X`): `R = (R_g + SX(1 − R_g)) / (1 + SX(1 − R_g))`;
/// - `S → 0`: Beer's law through the layer and back, `R = R_g e^{−2KX}`
///   (taken exactly when S = 0 or K/S > 10¹²);
/// - `X → ∞`: `R∞ = a − b = 1 + K/S − √((K/S)² + 2K/S)`.
pub fn reflectance(k: f64, s: f64, x: f64, rg: f64) -> f64 {
    if s <= 0.0 || k > 1e12 * s {
        return rg * (-2.0 * k * x).exp();
    }
    let q = k / s;
    let a = 1.0 + q;
    let b = (q * q + 2.0 * q).sqrt();
    let bsx = b * s * x;
    let t = if bsx < 1e-8 { s * x } else { bsx.tanh() / b };
    (t * (1.0 - rg * a) + rg) / (t * (a - rg) + 1.0)
}

/// Reflectance of an infinitely thick layer, `R∞ = 1 + K/S − √((K/S)² + 2K/S)`
/// (1 for K = 0, 0 for S = 0).
pub fn reflectance_infinite(k: f64, s: f64) -> f64 {
    if s <= 0.0 {
        return 0.0;
    }
    let q = k / s;
    // 1 + q − √(q² + 2q) = 1 / (1 + q + √(q² + 2q)), without cancellation.
    1.0 / (1.0 + q + (q * q + 2.0 * q).sqrt())
}

/// Saunderson's correction: what an instrument measures of a layer whose
/// body reflectance (inside the surface) is `r`, with external reflectance
/// `r_e` of the surface (light arriving from outside) and internal diffuse
/// reflectance `r_i`:
/// `R_meas = r_e + (1 − r_e)(1 − r_i) R / (1 − r_i R)`. Pass `r_e` as the
/// specular term when it is included; [`saunderson_excluded`] leaves it out.
pub fn saunderson(r: f64, r_e: f64, r_i: f64) -> f64 {
    r_e + saunderson_excluded(r, r_e, r_i)
}

/// Saunderson's correction without the specular reflection itself
/// (geometries that do not see it: 45°/0°, d/8° SCE).
pub fn saunderson_excluded(r: f64, r_e: f64, r_i: f64) -> f64 {
    (1.0 - r_e) * (1.0 - r_i) * r / (1.0 - r_i * r)
}

/// Fresnel reflectance of unpolarised light (mean of s and p) going from
/// index `n1` into `n2` (real) at angle `theta` (rad) in medium 1; 1 beyond
/// the critical angle.
pub fn fresnel_unpolarised(n1: f64, n2: f64, theta: f64) -> f64 {
    let ci = theta.cos();
    let st = n1 / n2 * theta.sin();
    if st >= 1.0 {
        return 1.0;
    }
    let ct = (1.0 - st * st).sqrt();
    let rs = (n1 * ci - n2 * ct) / (n1 * ci + n2 * ct);
    let rp = (n2 * ci - n1 * ct) / (n2 * ci + n1 * ct);
    0.5 * (rs * rs + rp * rp)
}

/// External reflectance `r_e` of the binder's surface for light from air at
/// `polar_deg`.
pub fn external_reflectance(binder_index: f64, polar_deg: f64) -> f64 {
    fresnel_unpolarised(1.0, binder_index, polar_deg.to_radians())
}

/// Internal diffuse reflectance `r_i` of the binder's surface: Fresnel from
/// inside (binder → air) averaged over a Lambertian (diffuse) hemisphere,
/// `r_i = ∫₀¹ R(μ) 2μ dμ` (total internal reflection beyond the critical
/// angle counts 1). Computed by Gauss–Legendre on both sides of the critical
/// angle's μ, where R has a square-root edge.
pub fn internal_reflectance(binder_index: f64) -> f64 {
    let n = binder_index;
    let mu_c = if n > 1.0 {
        (1.0 - 1.0 / (n * n)).sqrt()
    } else {
        0.0
    };
    // μ = μ_c + (1 − μ_c) u² takes out the square-root edge at μ_c.
    let integrand = |u: f64| {
        let mu = mu_c + (1.0 - mu_c) * u * u;
        fresnel_unpolarised(n, 1.0, mu.clamp(0.0, 1.0).acos()) * 2.0 * mu * 2.0 * (1.0 - mu_c) * u
    };
    // Below μ_c: total internal reflection, ∫₀^μc 2μ dμ = μ_c².
    mu_c * mu_c + gauss(integrand, 0.0, 1.0, 64)
}

/// The unpolarised surface's reflectance for Lambertian light from air,
/// `r_ed = ∫₀¹ R(μ_a) 2μ_a dμ_a` (smooth in `μ_a`: composite Gauss).
pub fn diffuse_external_reflectance(binder_index: f64) -> f64 {
    gauss(
        |mu_a: f64| {
            external_reflectance(binder_index, mu_a.clamp(0.0, 1.0).acos().to_degrees())
                * 2.0
                * mu_a
        },
        0.0,
        1.0,
        64,
    )
}

/// Scalar (TE) Fresnel reflectance of the binder's surface for light from
/// air at `polar_deg`: the interface of the scalar wave equation the solver
/// solves (`u` and `∂u/∂z` continuous, `solver/airy`),
/// `((μ_a − n μ)/(μ_a + n μ))²`.
pub fn external_reflectance_scalar(binder_index: f64, polar_deg: f64) -> f64 {
    let mu_a = polar_deg.to_radians().cos();
    let n = binder_index;
    let mu = (1.0 - (1.0 - mu_a * mu_a) / (n * n)).max(0.0).sqrt();
    super::adding::fresnel_scalar(n, mu, mu_a)
}

/// The scalar surface's reflectance for Lambertian light from air,
/// `r_ed = ∫₀¹ R(μ_a) 2μ_a dμ_a` (smooth in `μ_a`: composite Gauss).
pub fn diffuse_external_reflectance_scalar(binder_index: f64) -> f64 {
    gauss(
        |mu_a: f64| {
            external_reflectance_scalar(binder_index, mu_a.clamp(0.0, 1.0).acos().to_degrees())
                * 2.0
                * mu_a
        },
        0.0,
        1.0,
        64,
    )
}

/// The scalar surface's reflectance for Lambertian light from inside the
/// binder, total internal reflection included: by étendue
/// `1 − r_i = (1 − r_ed)/n²`.
pub fn internal_reflectance_scalar(binder_index: f64) -> f64 {
    let n2 = binder_index * binder_index;
    1.0 - (1.0 - diffuse_external_reflectance_scalar(binder_index)) / n2
}

/// The backing a Kubelka–Munk layer sees in the wave scene: the binder's
/// lower surface over an air gap over Lambertian paper of `albedo`. Diffuse
/// light from inside is reflected by the surface (`r_i`) or leaves into the
/// gap (`1 − r_i`); there paper and surface exchange light (`albedo`,
/// `r_ed`) until it re-enters (`1 − r_ed`):
/// `R_g = r_i + (1 − r_i) ρ (1 − r_ed) / (1 − ρ r_ed)`.
pub fn scene_backing(albedo: f64, r_i: f64, r_ed: f64) -> f64 {
    r_i + (1.0 - r_i) * albedo * (1.0 - r_ed) / (1.0 - albedo * r_ed)
}

/// Composite Gauss–Legendre (3 points per panel) of `f` over `[a, b]`.
fn gauss(f: impl Fn(f64) -> f64, a: f64, b: f64, panels: usize) -> f64 {
    let x = (0.6f64).sqrt();
    let (nodes, weights) = ([-x, 0.0, x], [5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0]);
    let h = (b - a) / panels as f64;
    let mut sum = 0.0;
    for p in 0..panels {
        let mid = a + (p as f64 + 0.5) * h;
        for (t, w) in nodes.iter().zip(weights) {
            sum += w * f(mid + 0.5 * h * t);
        }
    }
    0.5 * h * sum
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_of_the_closed_form() {
        let (x, rg) = (2.0, 0.8);
        // K → 0: the lossless formula, continuous into K = 0.
        let s = 0.7;
        let lossless = (rg + s * x * (1.0 - rg)) / (1.0 + s * x * (1.0 - rg));
        assert!((reflectance(0.0, s, x, rg) - lossless).abs() < 1e-15);
        assert!((reflectance(1e-12, s, x, rg) - lossless).abs() < 1e-10);
        // S → 0: Beer's law, continuous into S = 0.
        let k = 0.3;
        let beer = rg * (-2.0 * k * x).exp();
        assert_eq!(reflectance(k, 0.0, x, rg), beer);
        assert!((reflectance(k, 1e-9, x, rg) - beer).abs() < 1e-8);
        // Very thick: R∞, whatever the backing.
        let r_inf = reflectance_infinite(k, s);
        let direct = 1.0 + k / s - ((k / s).powi(2) + 2.0 * k / s).sqrt();
        assert!((r_inf - direct).abs() < 1e-14);
        for rg in [0.0, 0.5, 1.0] {
            assert!((reflectance(k, s, 1e4, rg) - r_inf).abs() < 1e-12);
        }
        // No layer: the backing.
        assert!((reflectance(k, s, 0.0, rg) - rg).abs() < 1e-15);
        // Never NaN, always in [0, 1].
        for k in [0.0, 1e-300, 1e-6, 1.0, 1e6] {
            for s in [0.0, 1e-300, 1e-6, 1.0, 1e6] {
                let r = reflectance(k, s, x, rg);
                assert!((0.0..=1.0).contains(&r), "K {k}, S {s}: {r}");
            }
        }
    }

    #[test]
    fn saunderson_without_surface_is_the_identity() {
        for r in [0.0, 0.3, 0.9, 1.0] {
            assert_eq!(saunderson(r, 0.0, 0.0), r);
        }
    }

    #[test]
    fn surface_reflectances() {
        // Normal incidence: ((n − 1)/(n + 1))².
        assert!((external_reflectance(1.5, 0.0) - 0.04).abs() < 1e-15);
        // No index step, no reflection.
        assert!(internal_reflectance(1.0).abs() < 1e-15);
        // n = 1.5: r_i ≈ 0.596 (the value quoted with Saunderson's K2).
        let ri = internal_reflectance(1.5);
        assert!((ri - 0.596).abs() < 2e-3, "{ri}");
        // Energy: 1 − r_i = (1 − r_e,diffuse)/n² (the diffuse transmittances
        // out and in are related by n², Stokes/étendue).
        let n: f64 = 1.5;
        let re_diffuse = gauss(
            |mu| external_reflectance(n, mu.acos().to_degrees()) * 2.0 * mu,
            0.0,
            1.0,
            256,
        );
        let gap = (1.0 - ri) - (1.0 - re_diffuse) / (n * n);
        assert!(gap.abs() < 1e-9, "{ri} {re_diffuse} {gap}");
    }
}
