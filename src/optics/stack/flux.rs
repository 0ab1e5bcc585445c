//! One wave-solved layer as flux matrices over the adding method's
//! directions: the solves of a layer inside its binder, from above and from
//! below at every direction of the [`Ordinates`], turned into a [`Slab`].
//!
//! Column `j` of a matrix is the solve lit at node `j`'s angle: the
//! specular (0, 0) order goes back into bin `j` (reflection) or on in bin
//! `j` (transmission), exactly; the other orders are spread onto the smooth
//! angular table ([`table::spread`]: power-preserving, two order spacings
//! wide), whose scattering function is integrated over each bin's annulus
//! of directions, and the column's diffuse part is then scaled to the
//! orders' exact diffuse power, so each column carries exactly the solve's
//! `R` and `T`. The azimuthal mean of the scattering (the Fourier term
//! `m = 0` of the adding method) is what the measurement geometries and the
//! white sky need (`optics::baseline::transfer`); the BRDF in the plane of
//! incidence needs the terms `m ≥ 1` as well: element `(i, j)` of term `m`
//! is the flux into bin `i` weighted by `cos m(φ − φ_j)`, `φ_j` the azimuth
//! of the light's own direction (the specular order's), so that one
//! scattering after another is a product of matrices term by term (their
//! azimuthal kernels convolve). Only cosines enter: each layer is taken as
//! statistically isotropic and mirror-symmetric in its plane, so the
//! ensemble's sine terms vanish, and a realisation counts with its mirror
//! image. Light along the normal has no azimuth of its own; its terms
//! `m ≥ 1` vanish for an isotropic layer and are set to 0.
//!
//! Bin `i` is the directions whose flux a Lambertian radiance puts in node
//! `i`: in `μ²` (the flux of a Lambertian radiance between `μ_a` and `μ_b`
//! is `μ_b² − μ_a²`) the interval of width `c_i` (the flux weight), bins
//! side by side from the horizon to the normal.

use crate::optics::baseline::adding::Slab;
use crate::optics::baseline::matrix::Matrix;
use crate::optics::baseline::ordinates::{gauss_legendre, Ordinates};
use crate::optics::farfield::table::{self, node_coverage, AngularTable, Part, TableSpec};
use crate::optics::farfield::{Efficiencies, Side};

/// Radial Gauss nodes per bin of the annulus quadrature.
const RADIAL_POINTS: usize = 4;
/// Azimuthal points of the annulus quadrature: exact for the Fourier terms
/// up to [`AZIMUTHAL_TERMS`] of any scattering that is itself band-limited
/// to 64 − m.
const AZIMUTH_POINTS: usize = 64;

/// Azimuthal Fourier terms (`m = 0, 1, …`) a stack carries for its BRDF.
/// The diffuse orders are spread two order spacings wide on the table, so
/// the scattering is smooth in azimuth: 16 terms reproduce it in the plane
/// of incidence to 1 % of its peak, the floor the table's bilinear reading
/// sets (unit test below).
pub const AZIMUTHAL_TERMS: usize = 16;

/// One quadrature point of a bin: the table cell it lies in with its
/// bilinear fractions ([`TableSpec::locate`]), its weight (projected solid
/// angle) and the coverage there.
#[derive(Debug, Clone, Copy)]
struct Point {
    at: (usize, usize, f64, f64),
    weight: f64,
    coverage: f64,
    /// Azimuth of the point's direction (rad).
    phi: f64,
}

/// The annulus quadrature of every bin on one table layout.
#[derive(Debug, Clone)]
pub struct BinQuadrature {
    spec: TableSpec,
    bins: Vec<Vec<Point>>,
}

impl BinQuadrature {
    /// The bins of `ords` on tables of layout `spec`.
    pub fn new(ords: &Ordinates, spec: TableSpec) -> BinQuadrature {
        let n = spec.n();
        let coverage: Vec<f64> = (0..n * n)
            .map(|k| node_coverage(spec, k % n, k / n))
            .collect();
        let (x, w) = gauss_legendre(RADIAL_POINTS);
        let mut bins = Vec::with_capacity(ords.len());
        let mut edge = 0.0; // μ² at the bin's lower end
        for &c in &ords.flux_weight {
            let (mu2_lo, mu2_hi) = (edge, (edge + c).min(1.0));
            edge += c;
            // s = √(1 − μ²): the bin's annulus in projected directions.
            let (s_lo, s_hi) = (
                (1.0 - mu2_hi).max(0.0).sqrt(),
                (1.0 - mu2_lo).max(0.0).sqrt(),
            );
            let mut points = Vec::with_capacity(RADIAL_POINTS * AZIMUTH_POINTS);
            let dphi = 2.0 * std::f64::consts::PI / AZIMUTH_POINTS as f64;
            for (xr, wr) in x.iter().zip(&w) {
                let rho = s_lo + (s_hi - s_lo) * 0.5 * (xr + 1.0);
                let w_rho = 0.5 * (s_hi - s_lo) * wr * rho * dphi;
                for a in 0..AZIMUTH_POINTS {
                    let phi = (a as f64 + 0.5) * dphi;
                    // |s| ≤ 1 always lies inside the table.
                    let Some(at) = spec.locate(rho * phi.cos(), rho * phi.sin()) else {
                        continue;
                    };
                    points.push(Point {
                        at,
                        weight: w_rho,
                        coverage: spec.bilinear(&coverage, at),
                        phi,
                    });
                }
            }
            bins.push(points);
        }
        BinQuadrature { spec, bins }
    }

    /// The table layout the quadrature reads.
    pub fn spec(&self) -> TableSpec {
        self.spec
    }

    /// The flux of `t` in each bin: `∫ f d²s` over the bin's annulus, with
    /// `f = D / C` the table's scattering function.
    pub fn bin_fluxes(&self, t: &AngularTable) -> Vec<f64> {
        self.bin_moments(t, 0.0, 1).swap_remove(0)
    }

    /// The azimuthal Fourier moments of `t` in each bin about azimuth
    /// `phi0` (rad): element `[m][i]` is `∫ f cos m(φ − φ0) d²s` over bin
    /// `i`, for `m < terms`.
    pub fn bin_moments(&self, t: &AngularTable, phi0: f64, terms: usize) -> Vec<Vec<f64>> {
        let mut out = vec![vec![0.0; self.bins.len()]; terms];
        for (i, points) in self.bins.iter().enumerate() {
            for p in points.iter().filter(|p| p.coverage > 0.0) {
                let v = p.weight * self.spec.bilinear(&t.density, p.at) / p.coverage;
                // cos mΔ by the Chebyshev recurrence.
                let c1 = (p.phi - phi0).cos();
                let (mut prev, mut cur) = (c1, 1.0);
                for row in out.iter_mut() {
                    row[i] += v * cur;
                    (prev, cur) = (cur, 2.0 * c1 * cur - prev);
                }
            }
        }
        out
    }

    /// Columns of flux per bin of one solve's `part` (diffuse orders only),
    /// Fourier term by term about the light's azimuth, scaled so that term
    /// 0 carries the orders' exact diffuse power.
    fn diffuse_columns(&self, eff: &Efficiencies, part: Part, terms: usize) -> Vec<Vec<f64>> {
        let exact: f64 = eff
            .orders
            .iter()
            .filter(|o| o.m != 0 || o.n != 0)
            .map(|o| match part {
                Part::DiffuseReflection => o.reflectance,
                Part::DiffuseTransmission => o.transmittance,
            })
            .sum();
        // The light's own azimuth: the specular order's; none along the normal.
        let own = eff
            .orders
            .iter()
            .find(|o| o.m == 0 && o.n == 0)
            .filter(|o| o.theta_deg.to_radians().sin() > 1e-9)
            .map(|o| o.phi_deg.to_radians());
        let table = table::spread(eff, part, self.spec);
        let mut cols = self.bin_moments(&table, own.unwrap_or(0.0), terms);
        if own.is_none() {
            for c in cols.iter_mut().skip(1) {
                c.fill(0.0);
            }
        }
        let total: f64 = cols[0].iter().sum();
        if total > 0.0 {
            for v in cols.iter_mut().flatten() {
                *v *= exact / total;
            }
        }
        cols
    }
}

/// A layer's flux matrices: all of its scattering, and its specular part
/// alone (the unscattered light, diagonal); with the Fourier terms `m ≥ 1`
/// of all of it when they were asked for.
#[derive(Debug, Clone)]
pub struct LayerSlab {
    /// The azimuthal mean (term 0).
    pub total: Slab,
    pub specular: Slab,
    /// Terms `m = 1, 2, …` of `total` (empty: the mean only).
    pub azimuthal: Vec<Slab>,
}

/// The layer of one realisation at one wavelength from its solves, with
/// `terms` azimuthal Fourier terms (1: the mean only): `solve(side, j)` is
/// the solve lit from `side` at node `j`'s angle, or why there is none.
pub fn layer_slab<'e, E>(
    q: &BinQuadrature,
    k: usize,
    terms: usize,
    solve: &dyn Fn(Side, usize) -> Result<&'e Efficiencies, E>,
) -> Result<LayerSlab, E> {
    let terms = terms.max(1);
    let mut all: Vec<Slab> = (0..terms).map(|_| Slab::transparent(k)).collect();
    let mut spec = Slab::transparent(k);
    for s in all.iter_mut().chain(std::iter::once(&mut spec)) {
        s.t_down = Matrix::zeros(k);
        s.t_up = Matrix::zeros(k);
    }
    for side in [Side::Above, Side::Below] {
        for j in 0..k {
            let eff = solve(side, j)?;
            // The specular (0, 0) order's power (|r00|² and |t00|² of the
            // scalar wave; the same medium above and below): along the
            // light's own direction, the same in every Fourier term.
            let (r00, t00) = eff.specular_power();
            let cr = q.diffuse_columns(eff, Part::DiffuseReflection, terms);
            let ct = q.diffuse_columns(eff, Part::DiffuseTransmission, terms);
            for (m, s) in all.iter_mut().enumerate() {
                let (r, t) = match side {
                    Side::Above => (&mut s.r_down, &mut s.t_down),
                    Side::Below => (&mut s.r_up, &mut s.t_up),
                };
                for i in 0..k {
                    r[(i, j)] = cr[m][i];
                    t[(i, j)] = ct[m][i];
                }
                r[(j, j)] += r00;
                t[(j, j)] += t00;
            }
            let (rs, ts) = match side {
                Side::Above => (&mut spec.r_down, &mut spec.t_down),
                Side::Below => (&mut spec.r_up, &mut spec.t_up),
            };
            rs[(j, j)] = r00;
            ts[(j, j)] = t00;
        }
    }
    let total = all.remove(0);
    Ok(LayerSlab {
        total,
        specular: spec,
        azimuthal: all,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optics::baseline::ordinates::OrdinateParams;
    use crate::optics::farfield::Order;
    use num_complex::Complex64 as C64;

    /// A smooth, lopsided spread of orders on a lattice of spacing `d`
    /// around the light's own direction `s0` (azimuth 40°).
    fn lopsided(d: f64, theta0_deg: f64) -> Efficiencies {
        let (t0, p0) = (theta0_deg.to_radians(), 40f64.to_radians());
        let s0 = (t0.sin() * p0.cos(), t0.sin() * p0.sin());
        let mut orders = Vec::new();
        for m in -30i32..=30 {
            for n in -30i32..=30 {
                let (sx, sy) = (s0.0 + m as f64 * d, s0.1 + n as f64 * d);
                let rho = (sx * sx + sy * sy).sqrt();
                if rho >= 1.0 {
                    continue;
                }
                let dx = (sx - s0.0, sy - s0.1);
                let p = (-(dx.0 * dx.0 + dx.1 * dx.1) / 0.3).exp() * (1.0 + 0.6 * dx.0);
                // The specular order carries |r00|², |t00|² (below).
                let specular = m == 0 && n == 0;
                orders.push(Order {
                    m,
                    n,
                    theta_deg: rho.asin().to_degrees(),
                    phi_deg: sy.atan2(sx).to_degrees(),
                    reflectance: if specular { 0.01 } else { 1e-3 * p },
                    transmittance: if specular { 0.81 } else { 2e-3 * p },
                });
            }
        }
        Efficiencies {
            orders,
            r00: C64::new(0.1, 0.0),
            t00: C64::new(0.9, 0.0),
            specular_p: None,
            total_reflectance: 0.0,
            total_transmittance: 0.0,
            absorption: 0.0,
            energy_balance: 0.0,
        }
    }

    /// The Fourier terms summed at the light's own azimuth give the
    /// scattering in the plane of incidence: against the same table read
    /// directly along that azimuth over each bin's radial nodes.
    #[test]
    fn fourier_terms_rebuild_the_plane_of_incidence() {
        let ords = Ordinates::new(1.5, OrdinateParams::default(), &[0.0, 30.0, 60.0]).unwrap();
        let d = 0.06;
        let q = BinQuadrature::new(&ords, TableSpec::new(2.0 * d));
        let eff = lopsided(d, 30.0);
        let t = table::spread(&eff, Part::DiffuseReflection, q.spec);
        let phi0 = 40f64.to_radians();
        let (x, w) = gauss_legendre(RADIAL_POINTS);
        let n = q.spec.n();
        let coverage: Vec<f64> = (0..n * n)
            .map(|k| node_coverage(q.spec, k % n, k / n))
            .collect();
        // ∫ f(ρ, φ0) ρ dρ over each bin, straight from the table.
        let mut direct = Vec::new();
        let mut edge = 0.0;
        for &c in &ords.flux_weight {
            let (s_lo, s_hi) = (
                (1.0 - (edge + c).min(1.0)).max(0.0).sqrt(),
                (1.0 - edge).max(0.0).sqrt(),
            );
            edge += c;
            direct.push(
                x.iter()
                    .zip(&w)
                    .map(|(xr, wr)| {
                        let rho = s_lo + (s_hi - s_lo) * 0.5 * (xr + 1.0);
                        let at = q.spec.locate(rho * phi0.cos(), rho * phi0.sin()).unwrap();
                        0.5 * (s_hi - s_lo) * wr * rho * q.spec.bilinear(&t.density, at)
                            / q.spec.bilinear(&coverage, at)
                    })
                    .sum::<f64>(),
            );
        }
        let largest = direct.iter().fold(0.0f64, |a, &b| a.max(b.abs()));
        assert!(largest > 0.0);
        let worst = |terms: usize| {
            let m = q.bin_moments(&t, phi0, terms);
            (0..ords.len())
                .map(|i| {
                    let rebuilt = (m[0][i] + 2.0 * m[1..].iter().map(|m| m[i]).sum::<f64>())
                        / (2.0 * std::f64::consts::PI);
                    (rebuilt - direct[i]).abs()
                })
                .fold(0.0f64, f64::max)
        };
        let (used, few) = (worst(AZIMUTHAL_TERMS), worst(3));
        // The table's bilinear reading (kinks at its cell edges) sets a
        // floor near 1 % that more terms do not lower.
        assert!(used <= 1e-2 * largest, "{used:e} of {largest:e}");
        // Too few terms cannot: the test can fail.
        assert!(
            few > 5.0 * used,
            "3 terms {few:e}, {AZIMUTHAL_TERMS}: {used:e}"
        );
    }

    /// Light along the normal has no Fourier terms beyond the mean, and
    /// every term carries the specular order on its diagonal.
    #[test]
    fn normal_light_keeps_only_its_mean() {
        let ords = Ordinates::new(1.5, OrdinateParams::default(), &[0.0, 30.0]).unwrap();
        let q = BinQuadrature::new(&ords, TableSpec::new(0.12));
        let k = ords.len();
        let normal = ords.mu.len() - 1;
        let effs: Vec<Efficiencies> = ords
            .mu
            .iter()
            .map(|m| lopsided(0.06, m.clamp(-1.0, 1.0).acos().to_degrees()))
            .collect();
        let slab = layer_slab(&q, k, 4, &|_, j| Ok::<_, ()>(&effs[j])).unwrap();
        assert_eq!(slab.azimuthal.len(), 3);
        for s in &slab.azimuthal {
            for i in 0..k {
                let diag = if i == normal { 0.01 } else { 0.0 };
                assert!((s.r_down[(i, normal)] - diag).abs() < 1e-15);
            }
            assert!((s.t_up[(3, 3)] - slab.specular.t_up[(3, 3)]) > 0.0);
        }
        let total: f64 = (0..k).map(|i| slab.total.r_down[(i, normal)]).sum();
        let diffuse: f64 = effs[normal]
            .orders
            .iter()
            .filter(|o| o.m != 0 || o.n != 0)
            .map(|o| o.reflectance)
            .sum();
        assert!((total - 0.01 - diffuse).abs() < 1e-12 * diffuse.max(1.0));
    }
}
