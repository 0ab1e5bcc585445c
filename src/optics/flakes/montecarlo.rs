//! The full model of an effect paint (METHOD §10): Monte Carlo ray tracing
//! with explicit flakes, to check the fast model ([`super::paint`]).
//!
//! The paint is the fast model's: layers from the top down in one lacquer
//! (their boundaries do not reflect), under a flat surface to air (Fresnel,
//! natural light, total internal reflection from inside), on a ground
//! (Lambertian, a flat metal, or black). What differs is the flakes: here
//! they are **discs** of a given diameter, scattered at random through each
//! layer, each with its own normal drawn from the orientation
//! distribution, reflecting `R_f(|ω·m|)` about its normal and letting `T_f`
//! go on undeviated from both faces, as the fast model's flakes do (a
//! small disc's diffraction as a Gaussian tilt of the reflecting normal,
//! `σ_d` over the local cosine, drawn per reflection); a ray
//! cannot meet one flake twice in a row, and its way down and back up
//! passes the same discs, which the fast model's independent sublayers do
//! not know. The discs are a stationary random field without a box: the
//! plane is cut into square cells one diameter wide, and each cell's discs
//! (a Poisson number, their centres in the cell) are drawn from a seed of
//! the batch, the layer and the cell whenever a ray comes near, so the same
//! cell always holds the same discs and no pattern repeats. A ray's path is
//! walked cell by cell (a disc reaches at most half a cell beyond its own,
//! so the 3 × 3 cells about each cell on the path hold every disc it can
//! meet there). The ordinary
//! pigments are a medium between the discs: exponential free paths of their
//! scattering coefficient, their absorption as a weight `exp(−μa s)`, and
//! directions drawn from their phase function (the Legendre series of
//! their moments, tabulated, negative ringing set to 0).
//!
//! **Flakes per box.** The fast model's `a` is the flakes' projected area
//! (on the layer plane) per unit volume; a disc of area `A` and tilt `θ`
//! projects `A cos θ`, and normals are drawn by number from `D(m)` (a
//! Gaussian in angle times `sin θ`), so a cell of volume `V` holds on
//! average `a V / (A ⟨cos θ⟩)` discs.
//! Centres are uniform in the cell and in depth where the tilted disc stays
//! inside its layer (a depleted zone of `R sin θ` at each boundary, small
//! beside the layer's thickness).
//!
//! **Estimates.** Rays enter from air at one polar angle (azimuth 0). A ray
//! leaving to air after at least one deviation (a flake's reflection, a
//! pigment's scattering or the Lambertian ground) is scattered light; what
//! leaves undeviated is the mirror part, which the fast model holds apart
//! and which is not counted here either. The BRDF towards a view `v` is
//! estimated in a cone of half-angle `cone_deg` about it:
//! `π f ≈ π Σ w / (N Ω cos θ)` (`Ω` the cone's solid angle, `cos θ` each
//! ray's own), with the scattered hemispherical reflectance beside it.
//! The rays run in `batches`, each with its own disc field and seed, the
//! rays entering at random points of a wide area; means and standard
//! errors are over the batches (so the s.e. includes the fields'
//! variation), summed in batch order whatever the thread count.

use super::normals::Orientation;
use super::paint::{Ground, PaintLayer};
use super::thin_film;
use crate::optics::baseline::doubling;
use crate::optics::baseline::fresnel::fresnel_unpolarised;
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use rayon::prelude::*;
use std::f64::consts::PI;

/// Resolution of the full model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct McParams {
    /// Rays in all.
    pub rays: usize,
    /// Independent batches (disc sets).
    pub batches: usize,
    pub seed: u64,
    /// Half-angle of the view cones (°).
    pub cone_deg: f64,
}

impl Default for McParams {
    fn default() -> Self {
        McParams {
            rays: 1_000_000,
            batches: 40,
            seed: 1,
            cone_deg: 2.5,
        }
    }
}

/// A mean over batches and its standard error.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate {
    pub mean: f64,
    pub se: f64,
}

/// What the full model measures for one incidence.
#[derive(Debug, Clone, PartialEq)]
pub struct McResult {
    /// `π f` of the scattered light towards each view.
    pub views: Vec<Estimate>,
    /// The scattered light's hemispherical reflectance.
    pub scattered: Estimate,
    /// The mirror part (left undeviated), hemispherical.
    pub mirror: Estimate,
    /// Light absorbed (pigments, flakes, ground) or lost to roulette (0 on
    /// average).
    pub absorbed: Estimate,
}

/// Why the full model cannot run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum McError {
    #[error("{0}")]
    Input(String),
}

/// One disc.
#[derive(Debug, Clone, Copy)]
struct Disc {
    centre: [f64; 3],
    normal: [f64; 3],
}

/// A disc's name: layer, cell and place in the cell.
type DiscId = (usize, i64, i64, usize);

/// A batch's scratch, so that the walk along a ray does not allocate: one
/// cell's discs, and the cells already tested on the current path.
#[derive(Default)]
struct Scratch {
    discs: Vec<Disc>,
    tested: Vec<(i64, i64)>,
}

/// The paint as the tracer sees it.
struct Paint<'a> {
    lacquer: f64,
    layers: &'a [PaintLayer],
    /// Depth of each layer's top and of the ground (nm), from 0.
    depth: Vec<f64>,
    phase: Vec<Option<PhaseTable>>,
    ground: Ground,
    wavelength_nm: f64,
    /// Per layer: disc radius, cell width and mean discs per cell.
    radius: Vec<f64>,
    cell: Vec<f64>,
    per_cell: Vec<f64>,
}

/// Inverse CDF of a phase function in `cos Θ`.
struct PhaseTable {
    cdf: Vec<f64>,
    x: Vec<f64>,
}

const PHASE_NODES: usize = 2001;

impl PhaseTable {
    /// From normalised Legendre moments `χ_l` (isotropic when there are
    /// none): the density `p(x)/2` in `x = cos Θ` of
    /// [`doubling::phase_series`].
    fn new(moments: &[f64]) -> PhaseTable {
        let chi = if moments.is_empty() {
            &[1.0][..]
        } else {
            moments
        };
        let x: Vec<f64> = (0..PHASE_NODES)
            .map(|i| -1.0 + 2.0 * i as f64 / (PHASE_NODES - 1) as f64)
            .collect();
        let p: Vec<f64> = x
            .iter()
            .map(|&x| (0.5 * doubling::phase_series(chi, x)).max(0.0))
            .collect();
        let mut cdf = vec![0.0; PHASE_NODES];
        for i in 1..PHASE_NODES {
            cdf[i] = cdf[i - 1] + 0.5 * (p[i] + p[i - 1]) * (x[i] - x[i - 1]);
        }
        let total = cdf[PHASE_NODES - 1].max(f64::MIN_POSITIVE);
        for c in &mut cdf {
            *c /= total;
        }
        PhaseTable { cdf, x }
    }

    fn sample(&self, u: f64) -> f64 {
        let i = self
            .cdf
            .partition_point(|&c| c < u)
            .clamp(1, PHASE_NODES - 1);
        let (c0, c1) = (self.cdf[i - 1], self.cdf[i]);
        let f = if c1 > c0 { (u - c0) / (c1 - c0) } else { 0.5 };
        self.x[i - 1] + f * (self.x[i] - self.x[i - 1])
    }
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `d` turned by polar `cos_t` and azimuth `phi` about itself.
fn turn(d: [f64; 3], cos_t: f64, phi: f64) -> [f64; 3] {
    let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
    let (sp, cp) = phi.sin_cos();
    if d[2].abs() > 0.99999 {
        let s = d[2].signum();
        return [sin_t * cp, sin_t * sp, s * cos_t];
    }
    let q = (1.0 - d[2] * d[2]).sqrt();
    [
        sin_t * (d[0] * d[2] * cp - d[1] * sp) / q + d[0] * cos_t,
        sin_t * (d[1] * d[2] * cp + d[0] * sp) / q + d[1] * cos_t,
        -sin_t * cp * q + d[2] * cos_t,
    ]
}

/// A tilt drawn by number from the Gaussian-in-angle distribution: a
/// Rayleigh draw accepted with probability `sin θ / θ`, within 6σ and 90°.
fn draw_tilt(o: &Orientation, rng: &mut impl Rng) -> f64 {
    if o.sigma_rad <= 0.0 {
        return 0.0;
    }
    let limit = (6.0 * o.sigma_rad).min(PI / 2.0);
    loop {
        let u: f64 = rng.gen::<f64>().max(f64::MIN_POSITIVE);
        let t = o.sigma_rad * (-2.0 * u.ln()).sqrt();
        if t <= limit && rng.gen::<f64>() * t <= t.sin() {
            return t;
        }
    }
}

/// `⟨cos θ⟩` of the tilts drawn by number (`1 / ∫ D dω`).
fn mean_cos(o: &Orientation) -> f64 {
    if o.sigma_rad <= 0.0 {
        return 1.0;
    }
    let nodes = o.nodes(96, 1);
    1.0 / nodes.iter().map(|n| n.weight).sum::<f64>()
}

/// A Poisson count of mean `mean` (inversion; the means here are small).
pub(crate) fn poisson(mean: f64, rng: &mut impl Rng) -> usize {
    let (mut k, mut p) = (0usize, (-mean).exp());
    let mut cum = p;
    let u = rng.gen::<f64>();
    while u > cum && k < 10_000 {
        k += 1;
        p *= mean / k as f64;
        cum += p;
    }
    k
}

impl Paint<'_> {
    fn layer_at(&self, z: f64) -> usize {
        (self.depth.partition_point(|&d| d <= z).max(1) - 1).min(self.layers.len() - 1)
    }

    /// The discs of layer `k` with centres in cell `(ix, iy)` of field `seed`.
    fn cell_discs(&self, seed: u64, k: usize, ix: i64, iy: i64, out: &mut Vec<Disc>) {
        out.clear();
        let Some(f) = &self.layers[k].flakes else {
            return;
        };
        let mut h = seed ^ 0x51_7cc1_b727_220a;
        for v in [k as u64, ix as u64, iy as u64] {
            h = (h ^ v).wrapping_mul(0x9e37_79b9_7f4a_7c15).rotate_left(29);
        }
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(h);
        let (c, r) = (self.cell[k], self.radius[k]);
        let (top, bottom) = (self.depth[k], self.depth[k + 1]);
        for _ in 0..poisson(self.per_cell[k], &mut rng) {
            let t = draw_tilt(&f.orientation, &mut rng);
            let p = 2.0 * PI * rng.gen::<f64>();
            let normal = [t.sin() * p.cos(), t.sin() * p.sin(), t.cos()];
            let reach = r * t.sin();
            let z = if bottom - top > 2.0 * reach {
                top + reach + (bottom - top - 2.0 * reach) * rng.gen::<f64>()
            } else {
                0.5 * (top + bottom)
            };
            let x = (ix as f64 + rng.gen::<f64>()) * c;
            let y = (iy as f64 + rng.gen::<f64>()) * c;
            out.push(Disc {
                centre: [x, y, z],
                normal,
            });
        }
    }

    /// The nearest disc of layer `k` that the ray from `p` along `d` meets
    /// before `s_max`, other than `skip`: its distance and name.
    #[allow(clippy::too_many_arguments)]
    fn nearest_disc(
        &self,
        seed: u64,
        k: usize,
        p: [f64; 3],
        d: [f64; 3],
        s_max: f64,
        skip: Option<DiscId>,
        scratch: &mut Scratch,
    ) -> Option<(f64, DiscId, [f64; 3])> {
        self.layers[k].flakes.as_ref()?;
        let (c, r2) = (self.cell[k], self.radius[k] * self.radius[k]);
        let mut cell = [(p[0] / c).floor() as i64, (p[1] / c).floor() as i64];
        // Distance along the ray to the next cell wall in x and y, and per cell.
        let step = [d[0].signum() as i64, d[1].signum() as i64];
        let next_wall = |a: usize, i: i64| -> f64 {
            if d[a] > 0.0 {
                ((i + 1) as f64 * c - p[a]) / d[a]
            } else if d[a] < 0.0 {
                (i as f64 * c - p[a]) / d[a]
            } else {
                f64::INFINITY
            }
        };
        let mut t_next = [next_wall(0, cell[0]), next_wall(1, cell[1])];
        let t_step = [c / d[0].abs(), c / d[1].abs()];
        let mut best: Option<(f64, DiscId, [f64; 3])> = None;
        let Scratch { discs, tested } = scratch;
        tested.clear();
        loop {
            for ox in -1..=1 {
                for oy in -1..=1 {
                    let (ix, iy) = (cell[0] + ox, cell[1] + oy);
                    if tested.contains(&(ix, iy)) {
                        continue;
                    }
                    tested.push((ix, iy));
                    self.cell_discs(seed, k, ix, iy, discs);
                    for (j, disc) in discs.iter().enumerate() {
                        let id = (k, ix, iy, j);
                        if skip == Some(id) {
                            continue;
                        }
                        let m = disc.normal;
                        let dn = dot(d, m);
                        if dn.abs() < 1e-12 {
                            continue;
                        }
                        let q = [
                            disc.centre[0] - p[0],
                            disc.centre[1] - p[1],
                            disc.centre[2] - p[2],
                        ];
                        let u = dot(q, m) / dn;
                        if u <= 0.0 || u >= s_max || best.is_some_and(|b| u >= b.0) {
                            continue;
                        }
                        let x = [u * d[0] - q[0], u * d[1] - q[1], u * d[2] - q[2]];
                        if dot(x, x) <= r2 {
                            best = Some((u, id, m));
                        }
                    }
                }
            }
            let exit = t_next[0].min(t_next[1]);
            if best.is_some_and(|b| b.0 <= exit) || exit >= s_max {
                return best;
            }
            // Keep only the cells the next ones' neighbourhoods can share.
            if tested.len() > 64 {
                tested.drain(..tested.len() - 9);
            }
            let a = if t_next[0] <= t_next[1] { 0 } else { 1 };
            cell[a] += step[a];
            t_next[a] += t_step[a];
        }
    }
}

/// What one batch adds up.
#[derive(Debug, Clone, Default)]
struct Tally {
    views: Vec<f64>,
    scattered: f64,
    mirror: f64,
    absorbed: f64,
}

/// Roulette below this weight.
const ROULETTE: f64 = 1e-3;
/// Most events of one ray.
const MAX_EVENTS: usize = 100_000;
/// Rays enter at random points of a square this many cells wide.
const ENTRY_CELLS: f64 = 1e5;

/// Trace the paint for light from air at `incidence_deg` (azimuth 0) into
/// `views` (polar °, azimuth ° from the mirror direction's side, as
/// [`super::paint::PaintReflection::factor`]): `diameters_nm` is each
/// layer's flake diameter (ignored for a layer without flakes).
#[allow(clippy::too_many_arguments)]
pub fn trace(
    lacquer: f64,
    layers: &[PaintLayer],
    diameters_nm: &[f64],
    ground: Ground,
    wavelength_nm: f64,
    incidence_deg: f64,
    views: &[(f64, f64)],
    params: &McParams,
) -> Result<McResult, McError> {
    if layers.is_empty() || diameters_nm.len() != layers.len() {
        return Err(McError::Input(
            "one flake diameter per layer is needed".into(),
        ));
    }
    if params.batches < 2 || params.rays < params.batches {
        return Err(McError::Input(
            "at least 2 batches and one ray per batch".into(),
        ));
    }
    if diameters_nm.iter().any(|d| !(d.is_finite() && *d > 0.0)) {
        return Err(McError::Input("flake diameters must be > 0".into()));
    }
    let mut depth = vec![0.0];
    for l in layers {
        depth.push(depth.last().unwrap() + l.thickness_nm);
    }
    let per_cell = layers
        .iter()
        .zip(diameters_nm)
        .map(|(l, &dia)| {
            l.flakes.as_ref().map_or(0.0, |f| {
                let area = PI * dia * dia / 4.0;
                f.area_per_nm * dia * dia * l.thickness_nm / (area * mean_cos(&f.orientation))
            })
        })
        .collect();
    let paint = Paint {
        lacquer,
        layers,
        depth,
        phase: layers
            .iter()
            .map(|l| (l.pigments.mu_s > 0.0).then(|| PhaseTable::new(&l.pigments.moments)))
            .collect(),
        ground,
        wavelength_nm,
        radius: diameters_nm.iter().map(|d| 0.5 * d).collect(),
        cell: diameters_nm.to_vec(),
        per_cell,
    };
    let cone = params.cone_deg.to_radians();
    let solid = 2.0 * PI * (1.0 - cone.cos());
    let dirs: Vec<[f64; 3]> = views
        .iter()
        .map(|&(t, p)| {
            let (t, p) = (t.to_radians(), p.to_radians());
            [t.sin() * p.cos(), t.sin() * p.sin(), -t.cos()]
        })
        .collect();
    let per_batch = params.rays / params.batches;
    let tallies: Vec<Tally> = (0..params.batches)
        .into_par_iter()
        .map(|b| {
            let field = params.seed ^ (b as u64 + 1).wrapping_mul(0x9e37_79b9_7f4a_7c15);
            let mut rng = Xoshiro256PlusPlus::seed_from_u64(field.rotate_left(17));
            let mut t = Tally {
                views: vec![0.0; dirs.len()],
                ..Tally::default()
            };
            let mut scratch = Scratch::default();
            for _ in 0..per_batch {
                paint.ray(
                    field,
                    incidence_deg,
                    &dirs,
                    cone.cos(),
                    &mut rng,
                    &mut scratch,
                    &mut t,
                );
            }
            t
        })
        .collect();
    let n = per_batch as f64;
    let stat = |f: &dyn Fn(&Tally) -> f64| {
        let x: Vec<f64> = tallies.iter().map(|t| f(t) / n).collect();
        let m = x.iter().sum::<f64>() / x.len() as f64;
        let var = x.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (x.len() - 1) as f64;
        Estimate {
            mean: m,
            se: (var / x.len() as f64).sqrt(),
        }
    };
    Ok(McResult {
        views: (0..dirs.len())
            .map(|i| {
                let e = stat(&|t: &Tally| t.views[i]);
                Estimate {
                    mean: PI * e.mean / solid,
                    se: PI * e.se / solid,
                }
            })
            .collect(),
        scattered: stat(&|t: &Tally| t.scattered),
        mirror: stat(&|t: &Tally| t.mirror),
        absorbed: stat(&|t: &Tally| t.absorbed),
    })
}

impl Paint<'_> {
    /// One ray from air through field `seed`, tallied into `t`.
    #[allow(clippy::too_many_arguments)]
    fn ray(
        &self,
        seed: u64,
        incidence_deg: f64,
        views: &[[f64; 3]],
        cos_cone: f64,
        rng: &mut impl Rng,
        scratch: &mut Scratch,
        t: &mut Tally,
    ) {
        let n = self.lacquer;
        let theta = incidence_deg.to_radians();
        // The surface's own reflection is the mirror part; the rest enters.
        let r_in = fresnel_unpolarised(1.0, n, theta);
        t.mirror += r_in;
        let mut w = 1.0 - r_in;
        let sin_t = theta.sin() / n;
        let mut d = [sin_t, 0.0, (1.0 - sin_t * sin_t).sqrt()];
        let span = ENTRY_CELLS * self.cell.iter().copied().fold(0.0, f64::max);
        let mut p = [span * rng.gen::<f64>(), span * rng.gen::<f64>(), 0.0];
        let mut scattered = false;
        let mut last: Option<DiscId> = None;
        let ground_z = *self.depth.last().unwrap();
        for _ in 0..MAX_EVENTS {
            let k = self.layer_at(p[2] + 1e-9 * d[2].signum());
            let layer = &self.layers[k];
            let mu_s = layer.pigments.mu_s;
            let s_pig = if mu_s > 0.0 {
                -rng.gen::<f64>().max(f64::MIN_POSITIVE).ln() / mu_s
            } else {
                f64::INFINITY
            };
            // The layer's boundary along d.
            let s_z = if d[2] > 0.0 {
                (self.depth[k + 1] - p[2]) / d[2]
            } else if d[2] < 0.0 {
                (self.depth[k] - p[2]) / d[2]
            } else {
                f64::INFINITY
            };
            let s_free = s_pig.min(s_z);
            let hit = self.nearest_disc(seed, k, p, d, s_free, last, scratch);
            let s = hit.map_or(s_free, |h| h.0);
            w *= (-layer.pigments.mu_a * s).exp();
            for a in 0..3 {
                p[a] += s * d[a];
            }
            if let Some((_, id, m)) = hit {
                // A flake: reflect about its normal, or go on through it.
                let cos_l = dot(d, m).abs();
                let f = layer.flakes.as_ref().expect("discs come from flakes");
                let pw = f.table.at(cos_l);
                let kept = pw.r + pw.t;
                t.absorbed += w * (1.0 - kept);
                w *= kept;
                if kept <= 0.0 {
                    return;
                }
                if rng.gen::<f64>() * kept < pw.r {
                    // The disc's diffraction: the mirror's normal spread by
                    // σ_d over the local cosine, drawn per reflection.
                    let m = if f.diffraction_rad > 0.0 {
                        let o =
                            Orientation { sigma_rad: 0.0 }.at_incidence(f.diffraction_rad, cos_l);
                        let tilt = draw_tilt(&o, rng);
                        turn(m, tilt.cos(), 2.0 * PI * rng.gen::<f64>())
                    } else {
                        m
                    };
                    let dm = dot(d, m);
                    d = [
                        d[0] - 2.0 * dm * m[0],
                        d[1] - 2.0 * dm * m[1],
                        d[2] - 2.0 * dm * m[2],
                    ];
                    scattered = true;
                }
                last = Some(id);
            } else if s == s_pig {
                let table = self.phase[k]
                    .as_ref()
                    .expect("a scattering layer has a phase");
                let c = table.sample(rng.gen::<f64>());
                d = turn(d, c, 2.0 * PI * rng.gen::<f64>());
                scattered = true;
                last = None;
            } else if d[2] < 0.0 && k == 0 {
                // The surface from inside: reflect, or leave to air.
                p[2] = 0.0;
                let r = fresnel_unpolarised(n, 1.0, (-d[2]).clamp(-1.0, 1.0).acos());
                if rng.gen::<f64>() < r {
                    d[2] = -d[2];
                } else {
                    let lat = ((n * d[0]).powi(2) + (n * d[1]).powi(2)).min(1.0);
                    let e = [n * d[0], n * d[1], -(1.0 - lat).sqrt()];
                    if scattered {
                        t.scattered += w;
                        for (v, dir) in views.iter().enumerate() {
                            if dot(e, *dir) >= cos_cone {
                                t.views[v] += w / -e[2];
                            }
                        }
                    } else {
                        t.mirror += w;
                    }
                    return;
                }
                last = None;
            } else if d[2] > 0.0 && k + 1 == self.layers.len() {
                // The ground.
                p[2] = ground_z;
                match self.ground {
                    Ground::Black => {
                        t.absorbed += w;
                        return;
                    }
                    Ground::Lambertian { albedo } => {
                        t.absorbed += w * (1.0 - albedo);
                        w *= albedo;
                        let mu = rng.gen::<f64>().sqrt();
                        let phi = 2.0 * PI * rng.gen::<f64>();
                        let st = (1.0 - mu * mu).sqrt();
                        d = [st * phi.cos(), st * phi.sin(), -mu];
                        scattered = true;
                    }
                    Ground::Mirror { index } => {
                        let r = thin_film::unpolarised(
                            self.lacquer,
                            &[],
                            index,
                            self.wavelength_nm,
                            d[2],
                        )
                        .r;
                        t.absorbed += w * (1.0 - r);
                        w *= r;
                        d[2] = -d[2];
                    }
                }
                last = None;
            } else {
                // Into the next layer: no interface.
                p[2] = if d[2] > 0.0 {
                    self.depth[k + 1]
                } else {
                    self.depth[k]
                };
                last = None;
            }
            if w < ROULETTE {
                if rng.gen::<f64>() < 0.1 {
                    w *= 10.0;
                } else {
                    return;
                }
            }
        }
        t.absorbed += w;
    }
}
