//! The slab Green's function of one Bloch harmonic (METHOD §4).
//!
//! For a harmonic with lateral wave vector κ the background is a slab
//! `0 ≤ z ≤ H` of permittivity `ε_bg` in vacuum. Its Green's function solves
//! `g'' + γ(z)² g = −δ(z − z')` with outgoing conditions; inside the slab
//!
//! `g = K [e^{iγ|z−z'|} + ρ e^{iγ(z+z')} + ρ e^{iγ(2H−z−z')} + ρ²E e^{−iγ|z−z'|}]`,
//! `K = (i/2γ)/(1 − ρ²E)`, `ρ = (γ−β)/(γ+β)`, `E = e^{2iγH}`.
//!
//! **Discretisation (our choice, see module docs of `operator`).** The field is
//! represented by its average over each of the `N` z-cells and the source is
//! cell-constant; the operator is the Galerkin matrix
//! `G_jk = (1/dz) ∫_j ∫_k g(z, z') dz dz'`, integrated exactly. Every entry is
//! a product of powers `q^m` (`q = e^{iγ dz}`, `|q| ≤ 1`) and the cell factors
//! `φ1(x) = (e^x−1)/x`, `φ2(x) = (e^x−1−x)/x²` at `x = iγ dz`, so only decaying
//! exponentials ever appear. Galerkin makes the discrete energy balance exact:
//! `ΣR + ΣT + A = 1` holds to solver tolerance at any resolution, which is
//! what lets every solve check itself.
//!
//! **Grazing harmonics.** `K` is singular as `γ → 0` while the bracket
//! vanishes; `g` is an even, analytic function of `γ²` there. For
//! `|γ| H < SMALL_GAMMA_H` we therefore average the operator over a small
//! circle in the `γ²` plane (mean-value property), which gives the finite
//! limit to round-off. Such harmonics use a dense `N × N` matrix.

use num_complex::Complex64 as C64;

/// Below this |γ|·H a harmonic is treated by the contour average.
pub const SMALL_GAMMA_H: f64 = 1e-2;
/// Radius of the averaging circle, as |γ|·H on the circle.
const CONTOUR_GAMMA_H: f64 = 0.05;
/// Points on the averaging circle (error ~ (r/R)^M, R the distance to the
/// nearest resonance in γ²; negligible).
const CONTOUR_POINTS: usize = 8;

/// Square root on the physical branch: Im ≥ 0 (and Re ≥ 0 when purely real).
pub fn sqrt_branch(z: C64) -> C64 {
    let s = z.sqrt();
    if s.im < 0.0 || (s.im == 0.0 && s.re < 0.0) {
        -s
    } else {
        s
    }
}

/// φ1(x) = (e^x − 1)/x, stable near 0.
pub fn phi1(x: C64) -> C64 {
    if x.norm() < 1e-3 {
        C64::new(1.0, 0.0) + x * (0.5 + x * (1.0 / 6.0 + x / 24.0))
    } else {
        (x.exp() - 1.0) / x
    }
}

/// φ2(x) = (e^x − 1 − x)/x², stable near 0.
pub fn phi2(x: C64) -> C64 {
    if x.norm() < 1e-2 {
        C64::new(0.5, 0.0) + x * (1.0 / 6.0 + x * (1.0 / 24.0 + x * (1.0 / 120.0 + x / 720.0)))
    } else {
        (x.exp() - 1.0 - x) / (x * x)
    }
}

/// Scalar data of one harmonic in one background, everything the O(N)
/// sweeps need. Entries of the Galerkin matrix (without the overall `K dz`):
/// off-diagonal `f2 q^{|j−k|−1} + rf (q^{j+k} + q^{2N−2−j−k}) + r2n q^{N−1−|j−k|}`,
/// diagonal `diag + rf (q^{2j} + q^{2N−2−2j})`.
#[derive(Debug, Clone, Copy)]
pub struct Coef {
    /// q = e^{iγ dz}.
    pub q: C64,
    /// K·dz (times any normalisation the caller folds in).
    pub kdz: C64,
    /// φ1(x)².
    pub f2: C64,
    /// ρ φ1².
    pub rf: C64,
    /// ρ² q^N φ1².
    pub r2n: C64,
    /// Self-cell terms: 2φ2(x) + 2ρ²E φ2(−x).
    pub diag: C64,
    /// φ1(x) and ρ, q^N for u_bg and the boundary functionals.
    pub phi1: C64,
    pub rho: C64,
    pub qn: C64,
    /// γ inside, β outside.
    pub gamma: C64,
    pub beta: C64,
}

/// The physical setting of a 1-D slab problem.
#[derive(Debug, Clone, Copy)]
pub struct Slab {
    /// Free-space wavenumber k0 (rad/nm).
    pub k0: f64,
    /// Thickness H (nm).
    pub thickness: f64,
    /// Number of z cells.
    pub nz: usize,
}

impl Slab {
    pub fn dz(&self) -> f64 {
        self.thickness / self.nz as f64
    }
}

/// Coefficients for given γ² and β (γ on the Im ≥ 0 branch).
pub fn coef_from(slab: &Slab, gamma2: C64, beta: C64) -> Coef {
    let n = slab.nz;
    let h = slab.thickness;
    let dz = slab.dz();
    let i = C64::i();
    let gamma = sqrt_branch(gamma2);
    let x = i * gamma * dz;
    let q = x.exp();
    let qn = (i * gamma * h).exp();
    let e = qn * qn;
    let rho = (gamma - beta) / (gamma + beta);
    let k = (i / (2.0 * gamma)) / (1.0 - rho * rho * e);
    let p1 = phi1(x);
    // E φ2(−x) = (e^{iγ(2H−dz)} − E + E x)/x², or E·series near 0.
    let e_phi2m = if x.norm() < 1e-2 {
        e * phi2(-x)
    } else {
        ((i * gamma * (2.0 * h - dz)).exp() - e + e * x) / (x * x)
    };
    let _ = n;
    Coef {
        q,
        kdz: k * dz,
        f2: p1 * p1,
        rf: rho * p1 * p1,
        r2n: rho * rho * qn * p1 * p1,
        diag: 2.0 * phi2(x) + 2.0 * rho * rho * e_phi2m,
        phi1: p1,
        rho,
        qn,
        gamma,
        beta,
    }
}

/// Integer power by repeated squaring (q^m, m ≥ 0).
fn powi(q: C64, m: usize) -> C64 {
    q.powu(m as u32)
}

impl Coef {
    /// Galerkin matrix entry G_jk (including K dz).
    pub fn entry(&self, nz: usize, j: usize, k: usize) -> C64 {
        let q = self.q;
        let sep = self.rf * (powi(q, j + k) + powi(q, 2 * nz - 2 - j - k));
        let body = if j == k {
            self.diag
        } else {
            let d = j.abs_diff(k);
            self.f2 * powi(q, d - 1) + self.r2n * powi(q, nz - 1 - d)
        };
        self.kdz * (body + sep)
    }

    /// Weights w_k with r = Σ_k w_k s_k (field at z = 0 from a cell source).
    pub fn top_weight(&self, nz: usize, k: usize) -> C64 {
        let q = self.q;
        self.kdz
            * (1.0 + self.rho)
            * self.phi1
            * (powi(q, k) + self.rho * self.qn * powi(q, nz - 1 - k))
    }

    /// Weights w_k with t = Σ_k w_k s_k (field at z = H from a cell source).
    pub fn bottom_weight(&self, nz: usize, k: usize) -> C64 {
        let q = self.q;
        self.kdz
            * (1.0 + self.rho)
            * self.phi1
            * (powi(q, nz - 1 - k) + self.rho * self.qn * powi(q, k))
    }
}

/// Response of the background slab to a unit plane wave from above:
/// cell averages of u_bg, and the reflection and transmission amplitudes.
pub fn background_response(slab: &Slab, gamma2: C64, beta: C64, cells: &mut [C64]) -> (C64, C64) {
    let c = coef_from(slab, gamma2, beta);
    let n = slab.nz;
    let e = c.qn * c.qn;
    let a = 2.0 * beta / ((c.gamma + beta) * (1.0 - c.rho * c.rho * e));
    let b = c.rho * c.qn * a;
    for (j, cell) in cells.iter_mut().enumerate() {
        *cell = c.phi1 * (a * powi(c.q, j) + b * powi(c.q, n - 1 - j));
    }
    let r = a * (1.0 + c.rho * e) - 1.0;
    let t = a * c.qn * (1.0 + c.rho);
    (r, t)
}

/// True when a harmonic needs the contour average.
pub fn is_small_gamma(slab: &Slab, gamma2: C64) -> bool {
    gamma2.norm().sqrt() * slab.thickness < SMALL_GAMMA_H
}

/// Weight of each point of [`contour`] in the mean.
pub const CONTOUR_WEIGHT: f64 = 1.0 / CONTOUR_POINTS as f64;

/// The points in the γ² plane whose mean (each weighted
/// [`CONTOUR_WEIGHT`]) gives a near-grazing harmonic's operator: a circle
/// of radius `(CONTOUR_GAMMA_H / H)²` around `gamma2`. Shared by every
/// operator that is analytic in γ² (the scalar kernel, the vector columns).
pub fn contour(slab: &Slab, gamma2: C64) -> impl Iterator<Item = C64> {
    let r = (CONTOUR_GAMMA_H / slab.thickness).powi(2);
    (0..CONTOUR_POINTS).map(move |p| {
        let ang = 2.0 * std::f64::consts::PI * (p as f64 + 0.5) / CONTOUR_POINTS as f64;
        gamma2 + C64::from_polar(r, ang)
    })
}

/// Dense Galerkin matrix (row-major N×N, including K dz) and the top/bottom
/// weights for a harmonic near γ = 0, by the contour average.
pub fn dense_small_gamma(slab: &Slab, gamma2: C64, beta: C64) -> (Vec<C64>, Vec<C64>, Vec<C64>) {
    let n = slab.nz;
    let mut m = vec![C64::new(0.0, 0.0); n * n];
    let mut top = vec![C64::new(0.0, 0.0); n];
    let mut bot = vec![C64::new(0.0, 0.0); n];
    let w = CONTOUR_WEIGHT;
    for g2 in contour(slab, gamma2) {
        let c = coef_from(slab, g2, beta);
        for j in 0..n {
            for k in 0..n {
                m[j * n + k] += w * c.entry(n, j, k);
            }
            top[j] += w * c.top_weight(n, j);
            bot[j] += w * c.bottom_weight(n, j);
        }
    }
    (m, top, bot)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Brute-force Galerkin entry by midpoint quadrature of the closed form.
    fn brute(slab: &Slab, gamma2: C64, beta: C64, j: usize, k: usize, m: usize) -> C64 {
        let g = sqrt_branch(gamma2);
        let h = slab.thickness;
        let dz = slab.dz();
        let i = C64::i();
        let rho = (g - beta) / (g + beta);
        let e = (2.0 * i * g * h).exp();
        let kk = (i / (2.0 * g)) / (1.0 - rho * rho * e);
        let mut s = C64::new(0.0, 0.0);
        for a in 0..m {
            let z = (j as f64 + (a as f64 + 0.5) / m as f64) * dz;
            for b in 0..m {
                let zp = (k as f64 + (b as f64 + 0.5) / m as f64) * dz;
                let d = (z - zp).abs();
                s += kk
                    * ((i * g * d).exp()
                        + rho * (i * g * (z + zp)).exp()
                        + rho * (i * g * (2.0 * h - z - zp)).exp()
                        + rho * rho * e * (-i * g * d).exp());
            }
        }
        s * dz / (m * m) as f64
    }

    #[test]
    fn galerkin_entries_match_quadrature() {
        let slab = Slab {
            k0: 2.0 * std::f64::consts::PI / 500.0,
            thickness: 1000.0,
            nz: 6,
        };
        let k0 = slab.k0;
        for kap in [0.0, 0.5 * k0, 1.3 * k0, 3.0 * k0] {
            let g2 = C64::new(k0 * k0 * 2.427 - kap * kap, 0.0);
            let beta = sqrt_branch(C64::new(k0 * k0 - kap * kap, 0.0));
            let c = coef_from(&slab, g2, beta);
            for j in 0..6 {
                for k in 0..6 {
                    let a = c.entry(6, j, k);
                    let b = brute(&slab, g2, beta, j, k, 400);
                    assert!(
                        (a - b).norm() <= 1e-4 * b.norm().max(1e-3),
                        "{kap} {j} {k}: {a} vs {b}"
                    );
                }
            }
        }
    }

    /// Near γ = 0 compare with the independent cos/sinc form
    /// g = −φ₋(z<) φ₊(z>) / W, which has no 1/γ at all.
    #[test]
    fn contour_average_matches_trig_form_at_zero_gamma() {
        let slab = Slab {
            k0: 0.01,
            thickness: 1000.0,
            nz: 5,
        };
        let beta = C64::new(0.0, 0.004);
        let gamma2 = C64::new(0.0, 0.0);
        let (m, top, _bot) = dense_small_gamma(&slab, gamma2, beta);
        let h = slab.thickness;
        let i = C64::i();
        // γ = 0: φ₋(z) = 1 − iβz, φ₊(z) = 1 − iβ(H − z), W = β²H + 2iβ.
        let w = beta * beta * h + 2.0 * i * beta;
        let g = |z: f64, zp: f64| {
            let (lo, hi) = if z < zp { (z, zp) } else { (zp, z) };
            -(1.0 - i * beta * lo) * (1.0 - i * beta * (h - hi)) / w
        };
        let dz = slab.dz();
        let q = 300;
        for j in 0..5 {
            for k in 0..5 {
                let mut s = C64::new(0.0, 0.0);
                for a in 0..q {
                    for b in 0..q {
                        let z = (j as f64 + (a as f64 + 0.5) / q as f64) * dz;
                        let zp = (k as f64 + (b as f64 + 0.5) / q as f64) * dz;
                        s += g(z, zp);
                    }
                }
                let s = s * dz / (q * q) as f64;
                assert!(
                    (m[j * 5 + k] - s).norm() < 1e-5 * s.norm(),
                    "{j}{k}: {} vs {s}",
                    m[j * 5 + k]
                );
            }
            let mut s = C64::new(0.0, 0.0);
            for a in 0..q {
                s += g(0.0, (j as f64 + (a as f64 + 0.5) / q as f64) * dz);
            }
            let s = s * dz / q as f64;
            assert!((top[j] - s).norm() < 1e-6 * s.norm());
        }
    }

    /// u_bg against an independent transfer-matrix solution
    /// `(u, u')(H) = M (u, u')(0)`, `M = [[cos γH, sin γH/γ], [−γ sin γH, cos γH]]`,
    /// for real and absorbing slabs at normal and oblique incidence: r, t to
    /// 1e-10 and the cell averages against quadrature of the exact field.
    #[test]
    fn background_response_matches_transfer_matrix() {
        let i = C64::i();
        for eps in [
            C64::new(2.427, 0.0),
            C64::new(1.32, 2.24),
            C64::new(2.0, 0.3),
        ] {
            for polar in [0.0f64, 40.0, 75.0] {
                let slab = Slab {
                    k0: 2.0 * std::f64::consts::PI / 550.0,
                    thickness: 900.0,
                    nz: 9,
                };
                let k0 = slab.k0;
                let kap = k0 * polar.to_radians().sin();
                let g2 = k0 * k0 * eps - kap * kap;
                let beta = C64::new((k0 * k0 - kap * kap).sqrt(), 0.0);
                let mut cells = vec![C64::new(0.0, 0.0); 9];
                let (r, t) = background_response(&slab, g2, beta, &mut cells);
                // Transfer matrix, written with γ² only (no branch choice).
                let g = g2.sqrt();
                let h = slab.thickness;
                let (c, sg) = ((g * h).cos(), (g * h).sin() / g);
                let gs = -g * (g * h).sin();
                // t = c(1+r) + sg iβ(1−r);  iβ t = gs(1+r) + c iβ(1−r)
                let (a1, b1) = (c - i * beta * sg, c + i * beta * sg);
                let (a2, b2) = (gs - i * beta * c, gs + i * beta * c);
                // t = a1 r + b1,  iβ t = a2 r + b2
                let r_tm = (b2 - i * beta * b1) / (i * beta * a1 - a2);
                let t_tm = a1 * r_tm + b1;
                assert!(
                    (r - r_tm).norm() < 1e-10 && (t - t_tm).norm() < 1e-10,
                    "{eps} {polar}: {r} vs {r_tm}"
                );
                let u0 = 1.0 + r_tm;
                let du0 = i * beta * (1.0 - r_tm);
                let q = 400;
                let dz = slab.dz();
                for (j, cell) in cells.iter().enumerate() {
                    let mut acc = C64::new(0.0, 0.0);
                    for a in 0..q {
                        let z = (j as f64 + (a as f64 + 0.5) / q as f64) * dz;
                        acc += (g * z).cos() * u0 + (g * z).sin() / g * du0;
                    }
                    let avg = acc / q as f64;
                    assert!(
                        (cell - avg).norm() < 1e-5 * avg.norm().max(1e-3),
                        "cell {j}: {cell} vs {avg}"
                    );
                }
            }
        }
    }

    /// The Galerkin entries for an absorbing background, against quadrature.
    #[test]
    fn galerkin_entries_match_quadrature_absorbing_background() {
        let slab = Slab {
            k0: 2.0 * std::f64::consts::PI / 450.0,
            thickness: 700.0,
            nz: 5,
        };
        let k0 = slab.k0;
        for kap in [0.0, 0.7 * k0, 2.0 * k0] {
            let g2 = k0 * k0 * C64::new(1.32, 2.24) - kap * kap;
            let beta = sqrt_branch(C64::new(k0 * k0 - kap * kap, 0.0));
            let c = coef_from(&slab, g2, beta);
            for j in 0..5 {
                for k in 0..5 {
                    let a = c.entry(5, j, k);
                    let b = brute(&slab, g2, beta, j, k, 400);
                    assert!(
                        (a - b).norm() <= 1e-4 * b.norm().max(1e-3),
                        "{kap} {j} {k}: {a} vs {b}"
                    );
                }
            }
        }
    }
}
