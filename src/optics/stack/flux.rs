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
//! `R` and `T`. Only the azimuthal mean of the scattering enters (the
//! Fourier term `m = 0` of the adding method), which is what the
//! measurement geometries and the white sky need (`optics::baseline::transfer`).
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
/// Azimuthal points of the annulus quadrature.
const AZIMUTH_POINTS: usize = 64;

/// One quadrature point of a bin: the table cell it lies in with its
/// bilinear fractions ([`TableSpec::locate`]), its weight (projected solid
/// angle) and the coverage there.
#[derive(Debug, Clone, Copy)]
struct Point {
    at: (usize, usize, f64, f64),
    weight: f64,
    coverage: f64,
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
        self.bins
            .iter()
            .map(|points| {
                points
                    .iter()
                    .filter(|p| p.coverage > 0.0)
                    .map(|p| p.weight * self.spec.bilinear(&t.density, p.at) / p.coverage)
                    .sum()
            })
            .collect()
    }

    /// Column of flux per bin of one solve's `part` (diffuse orders only),
    /// scaled to the orders' exact diffuse power.
    fn diffuse_column(&self, eff: &Efficiencies, part: Part) -> Vec<f64> {
        let exact: f64 = eff
            .orders
            .iter()
            .filter(|o| o.m != 0 || o.n != 0)
            .map(|o| match part {
                Part::DiffuseReflection => o.reflectance,
                Part::DiffuseTransmission => o.transmittance,
            })
            .sum();
        let mut col = self.bin_fluxes(&table::spread(eff, part, self.spec));
        let total: f64 = col.iter().sum();
        if total > 0.0 {
            for v in &mut col {
                *v *= exact / total;
            }
        }
        col
    }
}

/// A layer's flux matrices: all of its scattering, and its specular part
/// alone (the unscattered light, diagonal).
#[derive(Debug, Clone)]
pub struct LayerSlab {
    pub total: Slab,
    pub specular: Slab,
}

/// The layer of one realisation at one wavelength from its solves:
/// `solve(side, j)` is the solve lit from `side` at node `j`'s angle, or
/// why there is none.
pub fn layer_slab<'e, E>(
    q: &BinQuadrature,
    k: usize,
    solve: &dyn Fn(Side, usize) -> Result<&'e Efficiencies, E>,
) -> Result<LayerSlab, E> {
    let mut total = Slab::transparent(k);
    let mut spec = Slab::transparent(k);
    for (side, r, t, rs, ts) in [
        (
            Side::Above,
            &mut total.r_down,
            &mut total.t_down,
            &mut spec.r_down,
            &mut spec.t_down,
        ),
        (
            Side::Below,
            &mut total.r_up,
            &mut total.t_up,
            &mut spec.r_up,
            &mut spec.t_up,
        ),
    ] {
        *t = Matrix::zeros(k);
        *ts = Matrix::zeros(k);
        for j in 0..k {
            let eff = solve(side, j)?;
            // The specular (0, 0) order's power, |r00|² and |t00|² (the
            // same medium above and below).
            let (r00, t00) = (eff.r00.norm_sqr(), eff.t00.norm_sqr());
            let cr = q.diffuse_column(eff, Part::DiffuseReflection);
            let ct = q.diffuse_column(eff, Part::DiffuseTransmission);
            for i in 0..k {
                r[(i, j)] = cr[i];
                t[(i, j)] = ct[i];
            }
            r[(j, j)] += r00;
            t[(j, j)] += t00;
            rs[(j, j)] = r00;
            ts[(j, j)] = t00;
        }
    }
    Ok(LayerSlab {
        total,
        specular: spec,
    })
}
