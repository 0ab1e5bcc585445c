//! The flat binder surface's reflectance law of the baselines, after the
//! wave equation they stand beside (METHOD §6): s-like (TE) Fresnel for the
//! scalar Helmholtz equation, whose flat interfaces keep `u` and `∂u/∂z`
//! continuous; natural light's (the mean of the s and p powers) for
//! Maxwell's equations — and the surface reflectances the baselines take
//! from it: `r_e` from air at an angle, `r_ed` for Lambertian light from
//! air, `r_i` for Lambertian light from inside.

use crate::config::Equation;

/// Which Fresnel reflectance a flat binder–air surface has.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fresnel {
    /// s-like (TE): `r = (n μ − μ_a)/(n μ + μ_a)`, the scalar wave's.
    Scalar,
    /// Natural light: `(r_s² + r_p²)/2`, `r_p = (μ − n μ_a)/(μ + n μ_a)`.
    Unpolarised,
}

impl Fresnel {
    /// The surfaces of the baselines beside a solve of `equation`.
    pub fn of(equation: Equation) -> Fresnel {
        match equation {
            Equation::Helmholtz => Fresnel::Scalar,
            Equation::Maxwell => Fresnel::Unpolarised,
        }
    }

    /// The name in a result file.
    pub fn name(self) -> &'static str {
        match self {
            Fresnel::Scalar => "scalar-fresnel",
            Fresnel::Unpolarised => "unpolarised-fresnel",
        }
    }

    /// One line on what it is.
    pub fn description(self) -> &'static str {
        match self {
            Fresnel::Scalar => {
                "flat binder surfaces with the s-like (TE) Fresnel reflectance, u and du/dz \
                 continuous: the interface of the scalar Helmholtz equation"
            }
            Fresnel::Unpolarised => {
                "flat binder surfaces with the Fresnel reflectance of natural light, the mean of \
                 the s and p powers"
            }
        }
    }

    /// Reflectance between the binder direction `mu` and its refracted air
    /// direction `mu_air` (the same from either side), binder index `n`.
    pub fn between(self, n: f64, mu: f64, mu_air: f64) -> f64 {
        match self {
            Fresnel::Scalar => fresnel_scalar(n, mu, mu_air),
            Fresnel::Unpolarised => {
                let rs = (n * mu - mu_air) / (n * mu + mu_air);
                let rp = (mu - n * mu_air) / (mu + n * mu_air);
                0.5 * (rs * rs + rp * rp)
            }
        }
    }

    /// `r_e`: reflectance for light from air at `polar_deg`.
    pub fn external(self, n: f64, polar_deg: f64) -> f64 {
        match self {
            Fresnel::Scalar => external_reflectance_scalar(n, polar_deg),
            Fresnel::Unpolarised => external_reflectance(n, polar_deg),
        }
    }

    /// `r_ed`: reflectance for Lambertian light from air.
    pub fn diffuse_external(self, n: f64) -> f64 {
        match self {
            Fresnel::Scalar => diffuse_external_reflectance_scalar(n),
            Fresnel::Unpolarised => diffuse_external_reflectance(n),
        }
    }

    /// `r_i`: reflectance for Lambertian light from inside the binder,
    /// total internal reflection included.
    pub fn internal(self, n: f64) -> f64 {
        match self {
            Fresnel::Scalar => internal_reflectance_scalar(n),
            Fresnel::Unpolarised => internal_reflectance(n),
        }
    }
}

/// Scalar (TE) Fresnel reflectance between the binder direction `mu` and
/// its air direction `mu_air`, for a binder of index `n`:
/// `((n μ − μ_a)/(n μ + μ_a))²`, the same from either side.
pub fn fresnel_scalar(n: f64, mu: f64, mu_air: f64) -> f64 {
    let r = (n * mu - mu_air) / (n * mu + mu_air);
    r * r
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
    fresnel_scalar(n, mu, mu_a)
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
    fn the_laws_agree_with_the_surface_reflectances() {
        let n: f64 = 1.558;
        for deg in [0.0f64, 8.0, 45.0, 80.0] {
            let mu_a = deg.to_radians().cos();
            let mu = (1.0 - (1.0 - mu_a * mu_a) / (n * n)).sqrt();
            for f in [Fresnel::Scalar, Fresnel::Unpolarised] {
                let (a, b) = (f.between(n, mu, mu_a), f.external(n, deg));
                assert!((a - b).abs() < 1e-14, "{f:?} {deg}: {a} {b}");
            }
        }
        // At normal incidence s and p are one; at Brewster's angle p vanishes.
        let r0 = ((n - 1.0) / (n + 1.0)).powi(2);
        assert!((Fresnel::Unpolarised.external(n, 0.0) - r0).abs() < 1e-15);
        let brewster = n.atan().to_degrees();
        let half_s = 0.5 * Fresnel::Scalar.external(n, brewster);
        assert!((Fresnel::Unpolarised.external(n, brewster) - half_s).abs() < 1e-14);
        // Étendue: 1 − r_i = (1 − r_ed)/n² for both laws.
        for f in [Fresnel::Scalar, Fresnel::Unpolarised] {
            let gap = (1.0 - f.internal(n)) - (1.0 - f.diffuse_external(n)) / (n * n);
            assert!(gap.abs() < 1e-9, "{f:?}: {gap}");
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
