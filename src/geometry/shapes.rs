//! Particle shapes as rigid clusters of spheres centred on one axis
//! (METHOD §2) and the orientation modes of their axes.
//!
//! A [`ShapeTemplate`] lists `(offset along the axis, radius)` for a particle
//! of effective diameter 1 (the diameter of the sphere whose volume equals the
//! volume of the union of the spheres). Because every centre lies on the axis,
//! the cross-section of the union at axial position `s` is a disc of radius²
//! `ρ²(s) = max_i (r_i² − (s − s_i)²)₊`, a maximum of parabolas; between the
//! breakpoints (sphere ends and pairwise parabola crossings) it is a single
//! quadratic, so Simpson's rule on each piece integrates `π ρ²` exactly.
//!
//! Shapes (length `L` = tip to tip, `D` = largest diameter, aspect `L / D`):
//! - sphere: one sphere;
//! - cylinder: `n` equal spheres of radius `D/2`, centres evenly spaced from
//!   `−(L/2 − D/2)` to `L/2 − D/2` (default aspect 3, i.e. `L` = 6 radii);
//! - rice grain: an ellipsoid-like grain with semi-axes `a = L/2`, `b = D/2`.
//!   Centres `s_i = a·t_i`, `t_i` evenly spaced in `[−u, u]`,
//!   `u = (a² − b²)/(a² + b²)`, radii `r_i = b·√(1 − t_i²)` (the ellipse
//!   profile at the centre). This `u` makes the end spheres reach exactly the
//!   tips `±a`; the end radius is `2ab²/(a² + b²)` (0.6 b at aspect 3).

use std::f64::consts::PI;

/// The shape of the particles of one species.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Shape {
    Sphere,
    /// `aspect` = length / diameter (≥ 1; 3 by default); `spheres` ≥ 2 and
    /// greater than `aspect` − 1 so that neighbouring spheres overlap.
    Cylinder {
        aspect: f64,
        spheres: usize,
    },
    /// `aspect` = length / largest diameter (> 1); `spheres` ≥ 2.
    Rice {
        aspect: f64,
        spheres: usize,
    },
}

impl Shape {
    /// Default cylinder: aspect 3 (length = 6 radii), 5 spheres.
    pub const DEFAULT_CYLINDER: Shape = Shape::Cylinder {
        aspect: 3.0,
        spheres: 5,
    };
}

/// How the axes of a species are drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Orientation {
    /// Uniform on the unit sphere.
    Random,
    /// Uniform direction in the x–y plane (the plane of the layer).
    InPlane,
    /// Along +z (normal to the layer).
    Perpendicular,
}

/// One shape at effective diameter 1: spheres as `(axial offset, radius)`,
/// ordered by offset.
#[derive(Debug, Clone, PartialEq)]
pub struct ShapeTemplate {
    pub spheres: Vec<(f64, f64)>,
}

impl ShapeTemplate {
    /// Builds the template of `shape` (checks the parameters).
    pub fn new(shape: Shape) -> Result<Self, String> {
        let raw = raw_spheres(shape)?;
        let v = union_volume(&raw);
        // Scale so that the union volume is that of a unit-diameter sphere.
        let k = (PI / 6.0 / v).cbrt();
        Ok(ShapeTemplate {
            spheres: raw.iter().map(|&(s, r)| (s * k, r * k)).collect(),
        })
    }

    /// Union volume of the template (π/6 up to rounding).
    pub fn volume(&self) -> f64 {
        union_volume(&self.spheres)
    }

    /// Half length tip to tip (largest `|s_i| + r_i`).
    pub fn half_length(&self) -> f64 {
        self.spheres
            .iter()
            .map(|&(s, r)| s.abs() + r)
            .fold(0.0, f64::max)
    }

    /// Largest sphere radius.
    pub fn max_radius(&self) -> f64 {
        self.spheres.iter().map(|&(_, r)| r).fold(0.0, f64::max)
    }

    /// Smallest sphere radius.
    pub fn min_radius(&self) -> f64 {
        self.spheres
            .iter()
            .map(|&(_, r)| r)
            .fold(f64::INFINITY, f64::min)
    }
}

fn raw_spheres(shape: Shape) -> Result<Vec<(f64, f64)>, String> {
    match shape {
        Shape::Sphere => Ok(vec![(0.0, 1.0)]),
        Shape::Cylinder { aspect, spheres } => {
            if !(aspect.is_finite() && (1.0..=100.0).contains(&aspect)) {
                return Err(format!(
                    "cylinder aspect {aspect} must be in [1, 100] (length / diameter)"
                ));
            }
            if !(2..=1000).contains(&spheres) || (spheres as f64) <= aspect - 1.0 {
                return Err(format!(
                    "cylinder of aspect {aspect}: {spheres} spheres; allowed {} ..= 1000 \
                     (neighbouring spheres must overlap)",
                    ((aspect - 1.0).floor() as usize + 1).max(2)
                ));
            }
            let half = aspect - 1.0; // radius 1, centres in [−(L/2 − 1), L/2 − 1]
            let n = spheres;
            Ok((0..n)
                .map(|i| (-half + 2.0 * half * i as f64 / (n - 1) as f64, 1.0))
                .collect())
        }
        Shape::Rice { aspect, spheres } => {
            if !(aspect.is_finite() && aspect > 1.0 && aspect <= 100.0) {
                return Err(format!(
                    "rice aspect {aspect} must be in (1, 100] (length / largest diameter)"
                ));
            }
            if !(2..=1000).contains(&spheres) {
                return Err(format!("rice grain: {spheres} spheres; allowed 2 ..= 1000"));
            }
            let (a, b) = (aspect, 1.0);
            let u = (a * a - b * b) / (a * a + b * b);
            let n = spheres;
            Ok((0..n)
                .map(|i| {
                    let t = -u + 2.0 * u * i as f64 / (n - 1) as f64;
                    (a * t, b * (1.0 - t * t).max(0.0).sqrt())
                })
                .collect())
        }
    }
}

/// Exact volume of the union of spheres centred on one axis, given as
/// `(axial offset, radius)` (see the module docs).
pub fn union_volume(spheres: &[(f64, f64)]) -> f64 {
    let cuts = breakpoints(spheres);
    let rho2 = |s: f64| {
        spheres
            .iter()
            .map(|&(c, r)| r * r - (s - c) * (s - c))
            .fold(0.0, f64::max)
    };
    cuts.windows(2)
        .map(|w| {
            let (a, b) = (w[0], w[1]);
            PI * (b - a) / 6.0 * (rho2(a) + 4.0 * rho2(0.5 * (a + b)) + rho2(b))
        })
        .sum()
}

/// Axial breakpoints of the union of spheres on one axis, `(axial offset,
/// radius)`, ascending and distinct: the sphere ends and the pairwise
/// crossings of the parabolas `r_i² − (s − s_i)²` (see the module docs).
pub(crate) fn breakpoints(spheres: &[(f64, f64)]) -> Vec<f64> {
    let mut cuts: Vec<f64> = Vec::with_capacity(2 * spheres.len() + spheres.len().pow(2));
    for (i, &(si, ri)) in spheres.iter().enumerate() {
        cuts.push(si - ri);
        cuts.push(si + ri);
        for &(sj, rj) in &spheres[i + 1..] {
            if (si - sj).abs() > 0.0 {
                // r_i² − (s − s_i)² = r_j² − (s − s_j)²  is linear in s.
                cuts.push((rj * rj - ri * ri + si * si - sj * sj) / (2.0 * (si - sj)));
            }
        }
    }
    cuts.retain(|c| c.is_finite());
    cuts.sort_by(f64::total_cmp);
    cuts.dedup();
    cuts
}

/// Draws a unit axis for `mode` from two uniform numbers in `[0, 1)`.
pub fn axis_from_uniforms(mode: Orientation, u1: f64, u2: f64) -> [f64; 3] {
    let phi = 2.0 * PI * u2;
    match mode {
        Orientation::Random => {
            let z = 1.0 - 2.0 * u1;
            let s = (1.0 - z * z).max(0.0).sqrt();
            [s * phi.cos(), s * phi.sin(), z]
        }
        Orientation::InPlane => [phi.cos(), phi.sin(), 0.0],
        Orientation::Perpendicular => [0.0, 0.0, 1.0],
    }
}

/// Order parameter `S = <P2(cos θ)> = <(3 cos²θ − 1)/2>`, θ the angle
/// between an axis and the layer normal z: 1 for axes along z, −1/2 for axes
/// in the plane, 0 for isotropic axes. `None` for no axes.
pub fn order_parameter<'a>(axes: impl IntoIterator<Item = &'a [f64; 3]>) -> Option<f64> {
    let (mut sum, mut n) = (0.0, 0usize);
    for a in axes {
        let c2 = a[2] * a[2] / (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
        sum += 1.5 * c2 - 0.5;
        n += 1;
    }
    (n > 0).then(|| sum / n as f64)
}

/// Distribution of the effective diameter of the grains of one species
/// around the species' nominal diameter `d`. Draws are truncated at
/// [`SizeDistribution::TRUNCATION`] standard deviations (redrawn when
/// outside), so every diameter lies in the documented
/// [`SizeDistribution::range`] and the layer checks can use its upper end.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum SizeDistribution {
    /// Every grain has the nominal diameter `d`.
    #[default]
    Fixed,
    /// `d (1 + σ z)`, `z` standard normal: `d` is the mean, `sigma` the
    /// relative standard deviation, in `[0, 0.3]` (so the range
    /// `d (1 ± 3σ)` stays positive).
    Normal { sigma: f64 },
    /// `d exp(σ z)`: `d` is the median, `sigma` the standard deviation of
    /// `ln d`, in `[0, 0.5]` (range `d e^{±3σ}`).
    LogNormal { sigma: f64 },
}

impl SizeDistribution {
    /// Draws lie within this many standard deviations of the centre.
    pub const TRUNCATION: f64 = 3.0;
    /// Largest `sigma` of [`SizeDistribution::Normal`].
    pub const MAX_NORMAL_SIGMA: f64 = 0.3;
    /// Largest `sigma` of [`SizeDistribution::LogNormal`].
    pub const MAX_LOG_NORMAL_SIGMA: f64 = 0.5;

    /// Checks `sigma` against its documented range.
    pub fn check(&self) -> Result<(), String> {
        let (s, max, name) = match *self {
            SizeDistribution::Fixed => return Ok(()),
            SizeDistribution::Normal { sigma } => (sigma, Self::MAX_NORMAL_SIGMA, "normal"),
            SizeDistribution::LogNormal { sigma } => {
                (sigma, Self::MAX_LOG_NORMAL_SIGMA, "log-normal")
            }
        };
        if s.is_finite() && (0.0..=max).contains(&s) {
            Ok(())
        } else {
            Err(format!("{name} size sigma {s} must be in [0, {max}]"))
        }
    }

    /// Smallest and largest diameter a draw can give for nominal `d`.
    pub fn range(&self, d: f64) -> (f64, f64) {
        let t = Self::TRUNCATION;
        match *self {
            SizeDistribution::Fixed => (d, d),
            SizeDistribution::Normal { sigma } => (d * (1.0 - t * sigma), d * (1.0 + t * sigma)),
            SizeDistribution::LogNormal { sigma } => {
                (d * (-t * sigma).exp(), d * (t * sigma).exp())
            }
        }
    }

    /// Mean of `D³` over the (truncated) distribution divided by `d³`, by
    /// Gauss–Hermite-free quadrature on the truncated normal (2 000 midpoint
    /// nodes in `z`; relative error < 1e-6). Used to estimate particle counts.
    pub fn mean_cube_ratio(&self) -> f64 {
        let f: &dyn Fn(f64) -> f64 = match *self {
            SizeDistribution::Fixed => return 1.0,
            SizeDistribution::Normal { sigma } => &move |z: f64| (1.0 + sigma * z).powi(3),
            SizeDistribution::LogNormal { sigma } => &move |z: f64| (3.0 * sigma * z).exp(),
        };
        let (n, t) = (2000, Self::TRUNCATION);
        let (mut num, mut den) = (0.0, 0.0);
        for k in 0..n {
            let z = -t + 2.0 * t * (k as f64 + 0.5) / n as f64;
            let w = (-0.5 * z * z).exp();
            num += w * f(z);
            den += w;
        }
        num / den
    }

    /// One diameter for nominal `d`, from `rng` (a standard normal by
    /// Box–Muller, redrawn until within the truncation).
    pub fn sample<R: rand::Rng>(&self, d: f64, rng: &mut R) -> f64 {
        let sigma = match *self {
            SizeDistribution::Fixed => return d,
            SizeDistribution::Normal { sigma } | SizeDistribution::LogNormal { sigma } => sigma,
        };
        let z = loop {
            let z = super::normal::standard_normal(rng);
            if z.abs() <= Self::TRUNCATION {
                break z;
            }
        };
        match *self {
            SizeDistribution::Normal { .. } => d * (1.0 + sigma * z),
            _ => d * (sigma * z).exp(),
        }
    }
}
