//! A paint layer's scattering in the azimuthal Fourier terms of the
//! adding–doubling directions: the flux kernels ([`FluxKernel`]) of every
//! term `m = 0, 1, …` per unit thickness, from its flakes and its ordinary
//! pigments.
//!
//! **Fourier terms.** An azimuthally isotropic layer scatters light from
//! azimuth `φ'` to `φ` by a kernel of `cos(φ − φ')`, so the azimuthal
//! Fourier terms of the radiance do not mix: term `m` of a flux arriving in
//! bin `j` goes to term `m` in bin `i` with weight `Q^m_ij = ∫ q_ij(Δφ)
//! cos(mΔφ) dΔφ`, `q_ij(Δφ)` the flux scattered per unit thickness and per
//! radian of azimuth. Each term is a slab problem of its own with the same
//! directions, the same unscattered light and the same flat interfaces
//! (which keep the azimuth); a Lambertian ground has only `m = 0`. With the
//! convention `f(φ) = (1/2π)[f₀ + 2 Σ_{m≥1} f_m cos mφ]`, a convolution in
//! azimuth is a product of terms, so adding and doubling apply term by term.
//!
//! **Flakes.** A ray along `ω` meets, per unit path, projected flake area
//! `a ∫ D(m) |ω·m| dω_m` ([`super::normals`], `a` the flakes' projected area
//! per unit volume); a flake with normal `m` reflects `R_f(|ω·m|)` of it
//! into `ω − 2(ω·m)m`, lets `T_f` go on undeviated and absorbs the rest.
//! Changing variables from the normal to the reflected direction
//! (`dω_o = 4 |ω·h| dω_h`, `h` the half vector), the flux scattered per unit
//! path into `dω_o` is `(a/4) D(h) R_f(|ω·h|) dω_o`, smooth in `ω_o` for a
//! spread σ > 0. For the incident direction of node `j` (azimuth 0) it is
//! integrated over each node's cell in `μ_o` (consecutive intervals as wide
//! as the nodes' quadrature weights, so power is kept however narrow the
//! lobe and each node receives its radiance times its own weight;
//! Gauss–Legendre on each cell, finer than σ) and against `cos mφ_o`
//! (midpoint rule in azimuth, finer than σ). Aligned flakes (σ = 0) reflect
//! each direction into its mirror image exactly: one node each.
//! The discrete kernel is then made reciprocal exactly,
//! `Q_ij c_j = Q_ji c_i` (`c` the nodes' flux weights), by averaging it with
//! its transpose, and the flakes' extinction is set to what the kernel
//! scatters (its term-0 column sums) plus what they absorb, so that a layer
//! without absorption returns all the light (white furnace) on the nodes.
//! Along the normal (the node `μ = 1`) a radiance has no azimuth, so the
//! terms `m ≥ 1` of that node's rows and columns are zero.
//!
//! **Pigments** (absorption `μa`, scattering `μs`, phase moments `χ_l` of
//! the baseline's grain models, δ-M truncated): term 0 is the baseline's
//! azimuth-averaged phase matrix with its energy correction; term `m ≥ 1` is
//! `μs w_i p_m(μ_i, μ_j)/(2 μ_j)` with `p_m = (1/2π) ∫ p(cos Θ) cos(mΔφ)
//! dΔφ`, by the addition theorem of the Legendre polynomials `p_m(μ, μ') =
//! Σ_{l≥m} (2l + 1) χ_l (l − m)!/(l + m)! P_l^m(μ) P_l^m(μ')` (exact for
//! the truncated series; `tests/effect_paint.rs` checks it against the
//! azimuthal integral by quadrature).

use super::normals::{DensityTable, Orientation};
use super::reflector::LocalTable;
use crate::optics::baseline::doubling::{phase_matrices, FluxKernel, Medium};
use crate::optics::baseline::matrix::Matrix;
use crate::optics::baseline::ordinates::{gauss_legendre, Ordinates};
use std::f64::consts::PI;

/// Flakes in a layer at one wavelength.
#[derive(Debug, Clone)]
pub struct FlakeMedium {
    /// Projected flake area per unit volume, 1/nm.
    pub area_per_nm: f64,
    pub orientation: Orientation,
    /// The disc's diffraction as a spread of the normals for light along
    /// the normal (`normals::diffraction_rad`; 0: none). Light at incidence
    /// cosine `μ` sees `orientation` broadened by `σ_d/μ`
    /// ([`Orientation::at_incidence`]); what the flakes intercept and absorb
    /// follows `orientation` alone.
    pub diffraction_rad: f64,
    /// The flake's `R`, `T` against the local angle.
    pub table: LocalTable,
}

/// Resolution of the quadrature over normals.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NormalQuadrature {
    /// Tilts and azimuths of the normals' quadrature (the aligned flakes'
    /// absorption).
    pub tilts: usize,
    pub azimuths: usize,
    /// The spread lobes' sampling against the default's (1: eight azimuths
    /// and two polar points per σ, at least 128 azimuths on `[0, π]`;
    /// 0.5 half of each).
    pub lobe_sampling: f64,
}

impl Default for NormalQuadrature {
    fn default() -> Self {
        NormalQuadrature {
            tilts: 24,
            azimuths: 96,
            lobe_sampling: 1.0,
        }
    }
}

/// The kernels of terms `0..modes` of a layer: flakes and pigments.
pub fn layer_kernels(
    ords: &Ordinates,
    pigments: &Medium,
    flakes: Option<&FlakeMedium>,
    modes: usize,
    quadrature: NormalQuadrature,
) -> Vec<FluxKernel> {
    let mut out = pigment_kernels(ords, pigments, modes);
    if let Some(f) = flakes {
        let flake = flake_kernels(ords, f, modes, quadrature);
        for (k, f) in out.iter_mut().zip(flake) {
            k.same = k.same.add(&f.same);
            k.opposite = k.opposite.add(&f.opposite);
            for (r, e) in k.rate.iter_mut().zip(&f.rate) {
                *r += e;
            }
        }
    }
    out
}

/// The ordinary pigments' kernels per nm of thickness.
pub fn pigment_kernels(ords: &Ordinates, medium: &Medium, modes: usize) -> Vec<FluxKernel> {
    let n = ords.len();
    let (mu_s, chi) = medium.delta_m(2 * n);
    let mu_e = medium.mu_a + mu_s;
    let rate: Vec<f64> = ords.mu.iter().map(|mu| mu_e / mu).collect();
    let empty = |rate: Vec<f64>| FluxKernel {
        rate,
        same: Matrix::zeros(n),
        opposite: Matrix::zeros(n),
    };
    if mu_s <= 0.0 {
        return (0..modes).map(|_| empty(rate.clone())).collect();
    }
    let mut out = Vec::with_capacity(modes);
    // Term 0: the baseline's phase matrices, energy-corrected.
    let (same0, opp0) = phase_matrices(ords, &chi);
    let flux = |p: &Matrix| {
        Matrix::from_fn(n, |i, j| {
            0.5 * mu_s * ords.weight[i] * p[(i, j)] / ords.mu[j]
        })
    };
    out.push(FluxKernel {
        rate: rate.clone(),
        same: flux(&same0),
        opposite: flux(&opp0),
    });
    if modes <= 1 {
        return out;
    }
    // Terms m ≥ 1 by the addition theorem: p_m(μ_i, μ_j) = Σ_{l≥m} (2l + 1)
    // χ_l q_l^m(μ_i) q_l^m(μ_j), q_l^m = √((l − m)!/(l + m)!) P_l^m, and
    // q_l^m(−μ) = (−1)^{l+m} q_l^m(μ) for the opposite hemisphere.
    let degree = chi.len();
    let top = modes.min(degree);
    let q = normalised_legendre(&ords.mu, degree, top);
    let mut terms_same = vec![Matrix::zeros(n); modes];
    let mut terms_opp = vec![Matrix::zeros(n); modes];
    for (m, (same_m, opp_m)) in terms_same
        .iter_mut()
        .zip(terms_opp.iter_mut())
        .enumerate()
        .take(top)
        .skip(1)
    {
        for i in 0..n {
            let qi = &q[(i * top + m) * degree..(i * top + m + 1) * degree];
            for j in i..n {
                let qj = &q[(j * top + m) * degree..(j * top + m + 1) * degree];
                // The sums over even and odd l − m.
                let (mut even, mut odd) = (0.0, 0.0);
                for l in m..degree {
                    let v = (2 * l + 1) as f64 * chi[l] * qi[l] * qj[l];
                    if (l - m) % 2 == 0 {
                        even += v;
                    } else {
                        odd += v;
                    }
                }
                for (a, b) in [(i, j), (j, i)] {
                    same_m[(a, b)] = even + odd;
                    opp_m[(a, b)] = even - odd;
                }
            }
        }
    }
    for m in 1..modes {
        out.push(FluxKernel {
            rate: rate.clone(),
            same: flux(&terms_same[m]),
            opposite: flux(&terms_opp[m]),
        });
    }
    out
}

/// `q_l^m(μ) = √((l − m)!/(l + m)!) P_l^m(μ)` (no Condon–Shortley sign) of
/// every node, order `m < orders` and degree `l < degree`, at
/// `[(node · orders + m) · degree + l]` (0 for `l < m`), by the stable
/// recurrences `q_m^m = √((2m − 1)/(2m)) √(1 − μ²) q_{m−1}^{m−1}`,
/// `q_{m+1}^m = √(2m + 1) μ q_m^m` and `√(l² − m²) q_l^m = (2l − 1) μ
/// q_{l−1}^m − √((l − 1)² − m²) q_{l−2}^m`.
fn normalised_legendre(mu: &[f64], degree: usize, orders: usize) -> Vec<f64> {
    let mut q = vec![0.0; mu.len() * orders * degree];
    for (i, &x) in mu.iter().enumerate() {
        let s = (1.0 - x * x).max(0.0).sqrt();
        let mut diagonal = 1.0;
        for m in 0..orders {
            if m > 0 {
                diagonal *= ((2 * m - 1) as f64 / (2 * m) as f64).sqrt() * s;
            }
            let row = &mut q[(i * orders + m) * degree..(i * orders + m + 1) * degree];
            if m >= degree {
                continue;
            }
            row[m] = diagonal;
            if m + 1 < degree {
                row[m + 1] = ((2 * m + 1) as f64).sqrt() * x * diagonal;
            }
            for l in m + 2..degree {
                let (lf, mf) = (l as f64, m as f64);
                row[l] = ((2 * l - 1) as f64 * x * row[l - 1]
                    - ((lf - 1.0) * (lf - 1.0) - mf * mf).sqrt() * row[l - 2])
                    / (lf * lf - mf * mf).sqrt();
            }
        }
    }
    q
}

/// The flakes' kernels per nm of thickness (reciprocal, energy-consistent).
pub fn flake_kernels(
    ords: &Ordinates,
    flakes: &FlakeMedium,
    modes: usize,
    quadrature: NormalQuadrature,
) -> Vec<FluxKernel> {
    let n = ords.len();
    let normals = flakes
        .orientation
        .nodes(quadrature.tilts, quadrature.azimuths);
    let a = flakes.area_per_nm;
    let mut same = vec![Matrix::zeros(n); modes];
    let mut opp = vec![Matrix::zeros(n); modes];
    let mut absorbed = vec![0.0; n];
    let mut cos_m = vec![0.0; modes];
    let aligned = flakes.orientation.sigma_rad <= 0.0 && flakes.diffraction_rad <= 0.0;
    if !aligned {
        let sampling = quadrature.lobe_sampling.clamp(0.1, 4.0);
        integrate_lobes(ords, flakes, modes, sampling, &mut same, &mut opp);
    }
    for j in 0..n {
        let mu_j = ords.mu[j];
        let w = [(1.0 - mu_j * mu_j).max(0.0).sqrt(), 0.0, mu_j];
        for node in &normals {
            let m = node.m;
            let dot = w[0] * m[0] + w[1] * m[1] + w[2] * m[2];
            let local = dot.abs();
            let p = flakes.table.at(local);
            let hit = a * node.weight * local / mu_j;
            absorbed[j] += hit * (1.0 - p.r - p.t).max(0.0);
            let flux = hit * p.r;
            if flux <= 0.0 || !aligned {
                continue;
            }
            let o = [
                w[0] - 2.0 * dot * m[0],
                w[1] - 2.0 * dot * m[1],
                w[2] - 2.0 * dot * m[2],
            ];
            let mu_o = o[2].abs();
            let phi = o[1].atan2(o[0]);
            // cos(mφ) by the recurrence.
            let c1 = phi.cos();
            for (k, c) in cos_m.iter_mut().enumerate() {
                *c = match k {
                    0 => 1.0,
                    1 => c1,
                    _ => 0.0,
                };
            }
            for k in 2..modes {
                cos_m[k] = 2.0 * c1 * cos_m[k - 1] - cos_m[k - 2];
            }
            let target = if o[2] > 0.0 { &mut same } else { &mut opp };
            for (i, share) in bracket(&ords.mu, mu_o) {
                for k in 0..modes {
                    target[k][(i, j)] += flux * share * cos_m[k];
                }
            }
        }
    }
    // Reciprocity: Q_ij c_j = Q_ji c_i.
    let c = &ords.flux_weight;
    let symmetric =
        |q: &Matrix| Matrix::from_fn(n, |i, j| 0.5 * (q[(i, j)] + q[(j, i)] * c[i] / c[j]));
    // Along the normal the radiance has no azimuth: terms m ≥ 1 vanish there.
    let axial: Vec<usize> = (0..n).filter(|&i| ords.mu[i] >= 1.0 - 1e-12).collect();
    let clean = |k: usize, q: Matrix| {
        let mut q = symmetric(&q);
        if k > 0 {
            for &a in &axial {
                for b in 0..n {
                    q[(a, b)] = 0.0;
                    q[(b, a)] = 0.0;
                }
            }
        }
        q
    };
    let same: Vec<Matrix> = same
        .into_iter()
        .enumerate()
        .map(|(k, q)| clean(k, q))
        .collect();
    let opp: Vec<Matrix> = opp
        .into_iter()
        .enumerate()
        .map(|(k, q)| clean(k, q))
        .collect();
    let scattered: Vec<f64> = same[0]
        .column_sums()
        .iter()
        .zip(opp[0].column_sums())
        .map(|(a, b)| a + b)
        .collect();
    let rate: Vec<f64> = scattered
        .iter()
        .zip(&absorbed)
        .map(|(s, a)| s + a)
        .collect();
    same.into_iter()
        .zip(opp)
        .map(|(same, opposite)| FluxKernel {
            rate: rate.clone(),
            same,
            opposite,
        })
        .collect()
}

crate::solver::simd::widest! {
    /// The spread flakes' kernels by integrating the reflected radiance over
    /// the view directions: per unit path the flux scattered into `dω_o` is
    /// `(a/4) D(h) R_f(|ω·h|) dω_o` (`h` the half vector, `dω_o = 4 |ω·h| dω_h`),
    /// integrated over each node's cell in `μ_o` (Gauss–Legendre on every
    /// cell, finer than σ) and against `cos mφ` in azimuth (midpoint rule on
    /// `[0, π]`, finer than σ).
    fn integrate_lobes(
        ords: &Ordinates,
        flakes: &FlakeMedium,
        modes: usize,
        sampling: f64,
        same: &mut [Matrix],
        opp: &mut [Matrix],
    ) -> () = integrate_lobes_body;
}

/// Relative step of the per-direction spreads of diffracting flakes
/// ([`integrate_lobes`]): a lobe up to 0.5 % wider or narrower than asked,
/// well inside what the Gaussian lobe itself leaves out of Airy's pattern
/// (docs/VALIDATION.md, "A small flake in wave optics").
const SPREAD_STEP: f64 = 1e-2;

/// Azimuths per chunk of [`integrate_lobes`]'s vector lanes.
const CHUNK: usize = 8;

#[inline(always)]
fn integrate_lobes_body(
    ords: &Ordinates,
    flakes: &FlakeMedium,
    modes: usize,
    sampling: f64,
    same: &mut [Matrix],
    opp: &mut [Matrix],
) {
    let n = ords.len();
    // The narrowest lobe (along the normal) sets the azimuths.
    let sigma = flakes
        .orientation
        .at_incidence(flakes.diffraction_rad, 1.0)
        .sigma_rad;
    let a = flakes.area_per_nm;
    let least = (128.0 * sampling).ceil() as usize;
    let azimuths = ((8.0 * sampling * PI / sigma).ceil() as usize).clamp(least, 2048);
    let dphi = PI / azimuths as f64;
    // The azimuths' cosines and sines, padded to whole chunks.
    let padded = azimuths.div_ceil(CHUNK) * CHUNK;
    let (cos_phi, sin_phi): (Vec<f64>, Vec<f64>) = (0..padded)
        .map(|q| {
            let phi = (q as f64 + 0.5) * dphi;
            (phi.cos(), phi.sin())
        })
        .unzip();
    let cos_table: Vec<f64> = (0..azimuths)
        .flat_map(|q| {
            let phi = (q as f64 + 0.5) * dphi;
            (0..modes).map(move |m| (m as f64 * phi).cos())
        })
        .collect();
    // Each node's cell of μ_o: consecutive intervals as wide as the nodes'
    // quadrature weights (from 0 to 1), all of a cell's flux to its node.
    // The flux a node receives is then its radiance times its own weight,
    // as the doubling reads it, so that the kernel is reciprocal before it
    // is symmetrised (hat functions between nodes would give each node the
    // spacing of its neighbours instead, which differs from its weight
    // where the nodes crowd at the critical angle; symmetrising such a
    // kernel adds flux).
    let total: f64 = ords.weight.iter().sum();
    let mut cells: Vec<(f64, f64)> = Vec::with_capacity(n);
    let mut lo = 0.0;
    for w in &ords.weight {
        let hi = (lo + w / total).min(1.0);
        cells.push((lo, hi));
        lo = hi;
    }
    // The Gauss–Legendre rules of 3 to 24 points, once.
    let rules: Vec<(Vec<f64>, Vec<f64>)> = (0..=24).map(|p| gauss_legendre(p.max(1))).collect();
    // The density against the half vector's cosine, tabulated (no `acos`,
    // no `exp` in the loop). At a fixed `μ_o` the half vector leans further
    // as the azimuth from the mirror side grows (`|ω − o|² = 2 − 2 ω·o`
    // grows while its `z` part stays), so the azimuths it reaches within
    // the density's extent are a leading run: the loop stops at the first
    // beyond.
    // Without diffraction one table serves every incident direction; with
    // it each direction has its own spread, rounded to a relative step of
    // SPREAD_STEP so that directions whose spreads agree that closely (most
    // of them where σ_d ≪ σ) share one table.
    let shared = (flakes.diffraction_rad <= 0.0).then(|| flakes.orientation.density_table());
    let mut own: Option<(i64, DensityTable, f64)> = None;
    let mut profile = vec![0.0; azimuths];
    // Per cell and hemisphere, the azimuthal profile summed over the cell's
    // points (the projection on `cos mφ` is linear, so it is done once per
    // cell), and how far it reaches.
    let mut cell_profile = [vec![0.0; azimuths], vec![0.0; azimuths]];
    let mut coefficients = vec![0.0; modes];
    for j in 0..n {
        let mu_j = ords.mu[j];
        let wj = [(1.0 - mu_j * mu_j).max(0.0).sqrt(), 0.0, mu_j];
        let scale = 0.25 * a / mu_j;
        let (table, sigma_j) = match &shared {
            Some(t) => (t, sigma),
            None => {
                let wanted = flakes
                    .orientation
                    .at_incidence(flakes.diffraction_rad, mu_j)
                    .sigma_rad;
                let key = (wanted.ln() / SPREAD_STEP.ln_1p()).round() as i64;
                if own.as_ref().is_none_or(|o| o.0 != key) {
                    let o = Orientation {
                        sigma_rad: (key as f64 * SPREAD_STEP.ln_1p()).exp(),
                    };
                    own = Some((key, o.density_table(), o.sigma_rad));
                }
                let (_, table, sigma_j) = own.as_ref().expect("made above");
                (table, *sigma_j)
            }
        };
        for (k, &(lo, hi)) in cells.iter().enumerate() {
            let span = (lo.clamp(0.0, 1.0).acos() - hi.clamp(0.0, 1.0).acos()).abs();
            let points = ((2.0 * sampling * span / sigma_j).ceil() as usize).clamp(3, 24);
            let (x, w) = &rules[points];
            let mut reach = [0usize; 2];
            for (x, w) in x.iter().zip(w) {
                let mu_o = lo + 0.5 * (hi - lo) * (x + 1.0);
                let weight = 0.5 * (hi - lo) * w;
                let sin_o = (1.0 - mu_o * mu_o).max(0.0).sqrt();
                for (side, sign) in [1.0, -1.0].into_iter().enumerate() {
                    let vz = wj[2] - sign * mu_o;
                    let mut end = 0;
                    // A chunk of azimuths at a time: the half vector's
                    // cosine and the local angle's (the square root and
                    // the divisions) across the chunk's lanes, then the
                    // tables per azimuth up to the first beyond the
                    // density's extent.
                    'chunks: for (chunk, (cs, ss)) in cos_phi
                        .chunks_exact(CHUNK)
                        .zip(sin_phi.chunks_exact(CHUNK))
                        .enumerate()
                    {
                        let mut cos_h = [0.0; CHUNK];
                        let mut local = [0.0; CHUNK];
                        let mut length = [0.0; CHUNK];
                        for t in 0..CHUNK {
                            let (vx, vy) = (wj[0] - sin_o * cs[t], -sin_o * ss[t]);
                            let len = (vx * vx + vy * vy + vz * vz).sqrt();
                            length[t] = len;
                            cos_h[t] = vz.abs() / len;
                            local[t] = (wj[0] * vx + wj[2] * vz).abs() / len;
                        }
                        for t in 0..CHUNK {
                            let q = chunk * CHUNK + t;
                            if q == azimuths {
                                break 'chunks;
                            }
                            if length[t] < 1e-12 {
                                profile[q] = 0.0;
                                end = q + 1;
                                continue;
                            }
                            if cos_h[t] < table.lo {
                                break 'chunks;
                            }
                            let d = table.at_cos(cos_h[t]).max(0.0);
                            profile[q] = scale * d * flakes.table.at(local[t]).r;
                            end = q + 1;
                        }
                    }
                    let target = &mut cell_profile[side];
                    // Clear what this cell has not written yet.
                    if end > reach[side] {
                        target[reach[side]..end].iter_mut().for_each(|v| *v = 0.0);
                        reach[side] = end;
                    }
                    for (t, p) in target.iter_mut().zip(&profile[..end]) {
                        *t += weight * p;
                    }
                }
            }
            for (side, matrices) in [(0, &mut *same), (1, &mut *opp)] {
                let end = reach[side];
                if end == 0 {
                    continue;
                }
                coefficients.iter_mut().for_each(|c| *c = 0.0);
                for (q, g) in cell_profile[side][..end].iter().enumerate() {
                    if *g == 0.0 {
                        continue;
                    }
                    let gw = 2.0 * g * dphi;
                    let row = &cos_table[q * modes..(q + 1) * modes];
                    for (c, cm) in coefficients.iter_mut().zip(row) {
                        *c += gw * cm;
                    }
                }
                for (m, c) in coefficients.iter().enumerate() {
                    matrices[m][(k, j)] += c;
                }
            }
        }
    }
}

/// The two nodes bracketing `mu` (ascending `nodes`) with linear shares.
fn bracket(nodes: &[f64], mu: f64) -> [(usize, f64); 2] {
    let last = nodes.len() - 1;
    if mu <= nodes[0] {
        return [(0, 1.0), (0, 0.0)];
    }
    if mu >= nodes[last] {
        return [(last, 1.0), (last, 0.0)];
    }
    let k = nodes.partition_point(|&x| x <= mu) - 1;
    let f = (mu - nodes[k]) / (nodes[k + 1] - nodes[k]);
    [(k, 1.0 - f), (k + 1, f)]
}
