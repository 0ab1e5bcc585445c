//! Optics — the paper substrate (METHOD §5): a flat Lambertian reflector
//! of albedo ρp under the layer, combined with the layer's scattering by the
//! geometric series of inter-reflections, which are incoherent.
//!
//! `f_total(ω_i, ω_o) = f_layer(ω_i, ω_o) + ρp T(ω_i) T(ω_o) / (π (1 − ρp R_dd↑))`
//!
//! with `T(ω)` the layer's total transmittance for incidence from ω above
//! (by reciprocity it also governs what the layer transmits upwards into ω
//! from diffuse light below) and `R_dd↑` its albedo for diffuse light from
//! below. Hemispherical integrals use Gauss–Legendre quadrature in cos θ on
//! [0, 1] (θ from 0 to 90°), so a layer's angular functions are needed only at
//! the quadrature nodes.

use std::f64::consts::PI;

/// Gauss–Legendre nodes and weights on `μ = cos θ ∈ [0, 1]`.
#[derive(Debug, Clone)]
pub struct Hemisphere {
    /// Nodes μ_k = cos θ_k, increasing.
    pub mu: Vec<f64>,
    /// Weights w_k with Σ w_k f(μ_k) ≈ ∫₀¹ f(μ) dμ.
    pub weight: Vec<f64>,
}

impl Hemisphere {
    /// `n`-point rule (exact for polynomials of degree 2n − 1 in μ).
    pub fn new(n: usize) -> Self {
        let n = n.max(1);
        let (mut mu, mut weight) = (Vec::with_capacity(n), Vec::with_capacity(n));
        for i in 0..n {
            // Newton on P_n from the Chebyshev guess.
            let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut dp = 1.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                    p0 = p1;
                    p1 = p2;
                }
                let pn = if n == 1 { x } else { p1 };
                let pm = if n == 1 { 1.0 } else { p0 };
                dp = n as f64 * (x * pn - pm) / (x * x - 1.0);
                let dx = pn / dp;
                x -= dx;
                if dx.abs() < 1e-15 {
                    break;
                }
            }
            let w = 2.0 / ((1.0 - x * x) * dp * dp);
            // Map [−1, 1] → [0, 1].
            mu.push(0.5 * (x + 1.0));
            weight.push(0.5 * w);
        }
        let mut idx: Vec<usize> = (0..n).collect();
        idx.sort_by(|&a, &b| mu[a].total_cmp(&mu[b]));
        Hemisphere {
            mu: idx.iter().map(|&i| mu[i]).collect(),
            weight: idx.iter().map(|&i| weight[i]).collect(),
        }
    }

    /// Polar angles of the nodes in degrees.
    pub fn polar_deg(&self) -> Vec<f64> {
        self.mu.iter().map(|m| m.acos().to_degrees()).collect()
    }

    /// Cosine-weighted hemispherical average `2 ∫₀¹ f(μ) μ dμ` of a quantity
    /// given at the nodes (the diffuse albedo for f = R(μ)).
    pub fn diffuse(&self, f: &[f64]) -> f64 {
        assert_eq!(f.len(), self.mu.len(), "one value per node");
        2.0 * self
            .mu
            .iter()
            .zip(&self.weight)
            .zip(f)
            .map(|((m, w), f)| w * m * f)
            .sum::<f64>()
    }
}

/// The paper and what the layer presents to it.
#[derive(Debug, Clone, Copy)]
pub struct Paper {
    /// Lambertian albedo ρp (0.9 in the reference study).
    pub albedo: f64,
    /// The layer's albedo for diffuse light from below, R_dd↑.
    pub r_dd_up: f64,
}

impl Paper {
    /// The paper term of the BRDF (1/sr): `ρp T_i T_o / (π (1 − ρp R_dd↑))`.
    pub fn brdf(&self, t_in: f64, t_out: f64) -> f64 {
        self.albedo * t_in * t_out / (PI * (1.0 - self.albedo * self.r_dd_up))
    }

    /// Hemispherical reflectance of the paper term for incidence with layer
    /// transmittance `t_in`, given the layer's diffuse transmittance `t_d`
    /// (`2∫T μ dμ`): `ρp T_i T_d / (1 − ρp R_dd↑)` — also the radiance factor
    /// of the paper term under a uniform white sky seen from that direction.
    pub fn hemispherical(&self, t_in: f64, t_d: f64) -> f64 {
        self.albedo * t_in * t_d / (1.0 - self.albedo * self.r_dd_up)
    }
}
