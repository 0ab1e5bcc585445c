//! Mie theory: the electromagnetic (vector) single scatterer, one
//! homogeneous sphere of relative index `m = n + iκ` (absorbing allowed) in a
//! non-absorbing host, lit by a plane wave — the grain of the baselines that
//! stand beside a Maxwell solve (METHOD §6), as [`super::sphere`] is the
//! scalar equation's.
//!
//! Notation and formulas are those of C. F. Bohren and D. R. Huffman,
//! *Absorption and Scattering of Light by Small Particles* (Wiley, 1983),
//! ch. 4, with time dependence `e^{−iωt}`; the numerics follow W. J.
//! Wiscombe, "Improved Mie scattering algorithms", *Appl. Opt.* 19,
//! 1505–1509 (1980).
//!
//! Size parameter `x = k a` (`k` the host's wavenumber, `a` the radius).
//! With the Riccati–Bessel functions `ψ_n(x) = x j_n(x)`,
//! `ξ_n(x) = x h_n^{(1)}(x)` and the logarithmic derivative
//! `D_n(mx) = ψ_n'(mx)/ψ_n(mx)`, the scattering coefficients are
//! - `a_n = [(D_n/m + n/x) ψ_n − ψ_{n−1}] / [(D_n/m + n/x) ξ_n − ξ_{n−1}]`,
//! - `b_n = [(m D_n + n/x) ψ_n − ψ_{n−1}] / [(m D_n + n/x) ξ_n − ξ_{n−1}]`
//!   (BH eq. 4.88), and
//! - `Q_ext = (2/x²) Σ (2n+1) Re(a_n + b_n)`,
//!   `Q_sca = (2/x²) Σ (2n+1)(|a_n|² + |b_n|²)`, `Q_abs = Q_ext − Q_sca`;
//! - `g Q_sca = (4/x²) [Σ n(n+2)/(n+1) Re(a_n a*_{n+1} + b_n b*_{n+1})
//!   + Σ (2n+1)/(n(n+1)) Re(a_n b*_n)]` (BH eq. 4.62);
//! - `S_1(θ) = Σ (2n+1)/(n(n+1)) (a_n π_n + b_n τ_n)`,
//!   `S_2(θ) = Σ (2n+1)/(n(n+1)) (a_n τ_n + b_n π_n)`, with
//!   `π_n = P_n¹/sin θ` and `τ_n = dP_n¹/dθ` by their upward recurrences.
//!
//! The amplitude scattering matrix is diagonal for a sphere: the scattered
//! far field's components parallel and perpendicular to the scattering plane
//! are `e^{ikr}/(−ikr)` times `S_2 E_∥,inc` and `S_1 E_⊥,inc` (BH eq. 3.12).
//! For natural light `dσ_sca/dΩ = (|S_1|² + |S_2|²)/(2k²)`, whose Legendre
//! moments [`phase_moments`] gives in the form of
//! [`super::sphere::phase_moments`] (`m_0 = σ_sca`, `m_1/m_0 = g`).
//!
//! **Numerics** (Wiscombe): the series stops after
//! `N = x + 4x^{1/3} + 1` terms for `x ≤ 8` and `x + 4.05 x^{1/3} + 2` above
//! ([`terms_needed`]); `D_n(mx)` by downward recurrence
//! `D_{n−1} = n/(mx) − 1/(D_n + n/(mx))`, stable for any `m` (large
//! absorption included), from `D = 0` at `max(N, |mx|) + 16 + 8|mx|^{1/3}`:
//! Wiscombe's start `max(N, |mx|) + 16` leaves the starting error in `D_n`
//! near the turning point `n ≈ |mx|` (3e-8 for `m = 1.5`, `x = 30`, where
//! `N ≈ |mx|`), and the added width of that region, a few `|mx|^{1/3}`,
//! brings it to rounding for `x ≤ 100`, `|m| ≤ 4.3` (checked against a start
//! at 4000);
//! `ψ_n` by Miller's downward recurrence and `y_n` (for `ξ_n = ψ_n + i x y_n`)
//! upward, each in its stable direction ([`super::special`]).

use super::special::{bessel_j, bessel_y, legendre_moments};
use super::sphere::CrossSections;
use num_complex::Complex64 as C64;
use std::f64::consts::PI;

/// The scattering coefficients of one sphere: `a[n − 1]`, `b[n − 1]` are
/// `a_n`, `b_n` for `n = 1..=N`.
#[derive(Debug, Clone, PartialEq)]
pub struct MieCoefficients {
    /// Size parameter `x = k a` they belong to.
    pub x: f64,
    /// Electric multipole coefficients `a_n`.
    pub a: Vec<C64>,
    /// Magnetic multipole coefficients `b_n`.
    pub b: Vec<C64>,
}

/// Efficiencies (cross sections over `π a²`) and asymmetry of one sphere.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MieEfficiencies {
    pub extinction: f64,
    pub scattering: f64,
    /// `Q_ext − Q_sca`.
    pub absorption: f64,
    /// Mean cosine of the scattering angle for natural light.
    pub asymmetry: f64,
}

/// Wiscombe's number of terms for size parameter `x`: `x + 4x^{1/3} + 1`
/// for `x ≤ 8`, `x + 4.05 x^{1/3} + 2` above, and at least 3 (so that the
/// small-sphere limit keeps its first corrections).
pub fn terms_needed(x: f64) -> usize {
    let x = x.max(0.0);
    let n = if x <= 8.0 {
        x + 4.0 * x.cbrt() + 1.0
    } else {
        x + 4.05 * x.cbrt() + 2.0
    };
    (n.floor() as usize).max(3)
}

/// `D_n(z) = ψ_n'(z)/ψ_n(z)` for `n = 0..=n_max` by downward recurrence
/// from `D = 0` at `start ≥ n_max`.
fn log_derivative(z: C64, n_max: usize, start: usize) -> Vec<C64> {
    let start = start.max(n_max);
    let mut d = vec![C64::new(0.0, 0.0); start + 1];
    for n in (1..=start).rev() {
        let r = n as f64 / z;
        d[n - 1] = r - 1.0 / (d[n] + r);
    }
    d.truncate(n_max + 1);
    d
}

/// The coefficients `a_n`, `b_n` (`n = 1..=`[`terms_needed`]`(x)`) of a
/// sphere of relative index `m` (`Im m ≥ 0` absorbs) and size parameter
/// `x > 0`.
pub fn coefficients(m: C64, x: f64) -> MieCoefficients {
    let n_stop = terms_needed(x);
    if x <= 0.0 {
        return MieCoefficients {
            x,
            a: vec![C64::new(0.0, 0.0); n_stop],
            b: vec![C64::new(0.0, 0.0); n_stop],
        };
    }
    let mx = m * x;
    let start =
        n_stop.max(mx.norm().ceil() as usize) + 16 + (8.0 * mx.norm().cbrt()).ceil() as usize;
    let d = log_derivative(mx, n_stop, start);
    let psi: Vec<f64> = bessel_j(C64::new(x, 0.0), n_stop)
        .iter()
        .map(|j| x * j.re)
        .collect();
    let y = bessel_y(x, n_stop);
    let xi: Vec<C64> = psi
        .iter()
        .zip(&y)
        .map(|(&p, &y)| C64::new(p, x * y))
        .collect();
    let (mut a, mut b) = (Vec::with_capacity(n_stop), Vec::with_capacity(n_stop));
    for n in 1..=n_stop {
        let r = n as f64 / x;
        let da = d[n] / m + r;
        let db = m * d[n] + r;
        a.push((da * psi[n] - psi[n - 1]) / (da * xi[n] - xi[n - 1]));
        b.push((db * psi[n] - psi[n - 1]) / (db * xi[n] - xi[n - 1]));
    }
    MieCoefficients { x, a, b }
}

impl MieCoefficients {
    /// `Q_ext`, `Q_sca`, `Q_abs` and `g` from the coefficients.
    pub fn efficiencies(&self) -> MieEfficiencies {
        let x2 = self.x * self.x;
        if x2 <= 0.0 {
            return MieEfficiencies {
                extinction: 0.0,
                scattering: 0.0,
                absorption: 0.0,
                asymmetry: 0.0,
            };
        }
        let (mut ext, mut sca, mut cos) = (0.0, 0.0, 0.0);
        let len = self.a.len();
        for i in 0..len {
            let n = (i + 1) as f64;
            let (a, b) = (self.a[i], self.b[i]);
            ext += (2.0 * n + 1.0) * (a + b).re;
            sca += (2.0 * n + 1.0) * (a.norm_sqr() + b.norm_sqr());
            cos += (2.0 * n + 1.0) / (n * (n + 1.0)) * (a * b.conj()).re;
            if i + 1 < len {
                let (a1, b1) = (self.a[i + 1], self.b[i + 1]);
                cos += n * (n + 2.0) / (n + 1.0) * (a * a1.conj() + b * b1.conj()).re;
            }
        }
        let (extinction, scattering) = (2.0 * ext / x2, 2.0 * sca / x2);
        MieEfficiencies {
            extinction,
            scattering,
            absorption: extinction - scattering,
            asymmetry: if sca > 0.0 { 2.0 * cos / sca } else { 0.0 },
        }
    }

    /// The amplitude functions `(S_1, S_2)` at `μ = cos θ`.
    pub fn amplitudes(&self, mu: f64) -> (C64, C64) {
        let (mut s1, mut s2) = (C64::new(0.0, 0.0), C64::new(0.0, 0.0));
        // π_0 = 0, π_1 = 1; π_{n+1} = ((2n+1) μ π_n − (n+1) π_{n−1}) / n.
        let (mut pi_prev, mut pi) = (0.0, 1.0);
        for (i, (a, b)) in self.a.iter().zip(&self.b).enumerate() {
            let n = (i + 1) as f64;
            let tau = n * mu * pi - (n + 1.0) * pi_prev;
            let f = (2.0 * n + 1.0) / (n * (n + 1.0));
            s1 += f * (a * pi + b * tau);
            s2 += f * (a * tau + b * pi);
            let next = ((2.0 * n + 1.0) * mu * pi - (n + 1.0) * pi_prev) / n;
            pi_prev = pi;
            pi = next;
        }
        (s1, s2)
    }

    /// Legendre moments of `(|S_1|² + |S_2|²)/2` (natural light's
    /// `k² dσ_sca/dΩ`), `2π ∫₋₁¹ … P_n(μ) dμ` for `n = 0..=2N`: the
    /// polynomial has degree `2N` in `μ`, so the quadrature is exact.
    pub fn intensity_moments(&self) -> Vec<f64> {
        legendre_moments(2 * self.a.len(), |mu| {
            let (s1, s2) = self.amplitudes(mu);
            0.5 * (s1.norm_sqr() + s2.norm_sqr())
        })
    }
}

/// The relative index `√ε_rel` (the root with `Im ≥ 0` for `Im ε_rel ≥ 0`).
fn index(eps_rel: C64) -> C64 {
    eps_rel.sqrt()
}

/// σ_ext, σ_sca, σ_abs (area units of `a²`) and g of a sphere of radius `a`
/// and relative permittivity `eps_rel` in a host of wavenumber `k`, in the
/// form of [`super::sphere::cross_sections`].
pub fn cross_sections(k: f64, eps_rel: C64, a: f64) -> CrossSections {
    if a <= 0.0 {
        return CrossSections {
            extinction: 0.0,
            scattering: 0.0,
            absorption: 0.0,
            asymmetry: 0.0,
        };
    }
    let q = coefficients(index(eps_rel), k * a).efficiencies();
    let area = PI * a * a;
    CrossSections {
        extinction: q.extinction * area,
        scattering: q.scattering * area,
        absorption: q.absorption * area,
        asymmetry: q.asymmetry,
    }
}

/// Legendre moments of the scattered intensity for natural light,
/// `m_n = 2π ∫₋₁¹ (dσ_sca/dΩ) P_n(cos θ) d cos θ` with
/// `dσ_sca/dΩ = (|S_1|² + |S_2|²)/(2k²)`, for `n = 0..=2N`: `m_0 = σ_sca`,
/// `m_1/m_0 = g`, as [`super::sphere::phase_moments`] gives them for the
/// scalar sphere (empty for `a ≤ 0`).
pub fn phase_moments(k: f64, eps_rel: C64, a: f64) -> Vec<f64> {
    if a <= 0.0 {
        return Vec::new();
    }
    let c = coefficients(index(eps_rel), k * a);
    let k2 = k * k;
    c.intensity_moments().into_iter().map(|m| m / k2).collect()
}

#[cfg(test)]
mod tests;
