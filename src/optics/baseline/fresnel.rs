//! The flat binder surface's reflectance law of the baselines, after the
//! wave equation they stand beside (METHOD §6): s-like (TE) Fresnel for the
//! scalar Helmholtz equation, whose flat interfaces keep `u` and `∂u/∂z`
//! continuous; natural light's (the mean of the s and p powers) for
//! Maxwell's equations.

use super::{adding, km};
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
            Fresnel::Scalar => adding::fresnel_scalar(n, mu, mu_air),
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
            Fresnel::Scalar => km::external_reflectance_scalar(n, polar_deg),
            Fresnel::Unpolarised => km::external_reflectance(n, polar_deg),
        }
    }

    /// `r_ed`: reflectance for Lambertian light from air.
    pub fn diffuse_external(self, n: f64) -> f64 {
        match self {
            Fresnel::Scalar => km::diffuse_external_reflectance_scalar(n),
            Fresnel::Unpolarised => km::diffuse_external_reflectance(n),
        }
    }

    /// `r_i`: reflectance for Lambertian light from inside the binder,
    /// total internal reflection included.
    pub fn internal(self, n: f64) -> f64 {
        match self {
            Fresnel::Scalar => km::internal_reflectance_scalar(n),
            Fresnel::Unpolarised => km::internal_reflectance(n),
        }
    }
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
}
