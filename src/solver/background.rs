//! How the shifted form's background is chosen: the convergent-Born-series
//! shift (real centre and radius of the permittivity values, a margin) and
//! the mean background (the layer's mean permittivity with a loss floor,
//! per cell where a face holds air) — METHOD §4, "The convergent-Born-series
//! shift" and "The mean background". [`System`](super::System) builds its
//! shifted form from these.

use super::tensor;
use super::{Lattice, Wave};
use crate::config::Background;
use crate::raster::Anisotropy;
use ndarray::Array3;
use num_complex::Complex64 as C64;

/// ε_s = SHIFT_MARGIN · max|ε − ε_r| (1 makes CBS stall on the extreme voxels).
pub const SHIFT_MARGIN: f64 = 1.05;

/// The mean background's loss floor in the scalar equation:
/// `Im ε_bg ≥ MEAN_LOSS_FLOOR · max|ε − ⟨ε⟩|²`.
/// A lossless mean slab has sharp guided resonances that Krylov methods
/// resolve slowly; a loss growing with the square of the contrast (as the
/// scattering loss of the coherent wave does) damps them where scattering is
/// strong and leaves weak layers alone. 0.1 was the best of 0–0.25 on the
/// layers of docs/PERFORMANCE.md ("The mean background").
pub const MEAN_LOSS_FLOOR: f64 = 0.1;

/// In Maxwell's equations the floor grows at most linearly with the
/// contrast: `Im ε_bg ≥ min(MEAN_LOSS_FLOOR · r², MEAN_LOSS_CAP_MAXWELL · r)`,
/// `r = max|ε − ⟨ε⟩|`. A grain's polarisability saturates there as its
/// index grows (the local-field factor (ε − ε_m)/(ε + 2ε_m) tends to 1),
/// so high-index grains damp the coherent wave far less than the square of
/// the contrast says, and the scalar rule over-damps the background: on
/// rutile layers the applications are 1.2–2.3× fewer at the cap than
/// at `0.1 r²`, while layers of contrast below 1.5 (stand-ins, air
/// under a relief) keep the scalar floor, which suits them
/// (docs/PERFORMANCE.md, "High contrast: rutile in binder").
pub const MEAN_LOSS_CAP_MAXWELL: f64 = 0.15;

/// The loss floor of the cells between the layered zones is scaled by
/// `min(1, ⟨|ε − ε̄|²⟩ / (MEAN_LOSS_DILUTE · r²))`: the mean square contrast
/// over those cells against its largest. The floor stands for the
/// scattering loss of the coherent wave, which grows with the number of
/// grains; `r` alone does not see how many there are. For grains of volume
/// fraction f in binder the ratio is `f / (1 − f)`, so from about 7 % PVC
/// (isotropic grains; rutile's tensor grains from about 15 %) the floor is
/// whole, and a dilute layer takes the share its grains call for: 3 rutile
/// grains in a 1 µm layer (0.5 % PVC) took 1204 applications in Maxwell's
/// equations with the whole floor and 96 with their share
/// (docs/PERFORMANCE.md, "High contrast: rutile in binder"). The floor of
/// one [`ShiftParams::floor_per_zone`]`= false` for every cell is not
/// scaled.
pub const MEAN_LOSS_DILUTE: f64 = 0.08;

/// The dilute share of the floor ([`MEAN_LOSS_DILUTE`]) is taken whole
/// where the grains' size parameter inside them, `k0 n a` (n their largest
/// index, a their radius as the grid shows it), is at most the first
/// value, not at all from the second, and in proportion between. A large
/// high-index grain has sharp resonances of its own, and those need the
/// whole floor however few the grains are: rutile grains of 250 nm at 5 %
/// PVC took 1466 applications at 450 nm (`k0 n a` 5.3) with the whole floor
/// and 2502 with 0.3 of it, while at 550 nm (4.1) the share saved 30 %
/// (docs/PERFORMANCE.md, "High contrast: rutile in binder").
pub const DILUTE_GRAIN_SIZE: [f64; 2] = [4.0, 5.0];

/// How the shifted form's background is chosen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShiftParams {
    pub background: Background,
    /// CBS: `ε_s = margin · max|ε − ε_r|`, in [1, 100].
    pub margin: f64,
    /// Mean: the loss floor factor, in [0, 100].
    pub mean_loss_floor: f64,
    /// Mean: the floor is at most this times `max|ε − ⟨ε⟩|`, in [0, ∞]
    /// (∞: no cap, the scalar equation's default).
    pub mean_loss_cap: f64,
    /// Mean: the bulk's floor is scaled by `min(1, ⟨|ε − ε̄|²⟩ / (this ·
    /// r²))` ([`MEAN_LOSS_DILUTE`]) where its grains are not large
    /// ([`DILUTE_GRAIN_SIZE`]), in [0, 1]; 0: never scaled.
    pub mean_loss_dilute: f64,
    /// Mean: the cells holding air at either face take their own lateral
    /// mean ([`zone_cells`]: at most a quarter of the cells per face; the
    /// default); `false`: one mean for every cell.
    pub layered_air: bool,
    /// Mean: each layered cell takes the loss floor of the contrast left in
    /// it, and the cells between the zones that of theirs (the default);
    /// `false`: every cell the floor of the largest contrast in the grid.
    pub floor_per_zone: bool,
}

impl ShiftParams {
    /// The defaults for `background` in the scalar equation.
    pub const fn of(background: Background) -> ShiftParams {
        ShiftParams {
            background,
            margin: SHIFT_MARGIN,
            mean_loss_floor: MEAN_LOSS_FLOOR,
            mean_loss_cap: f64::INFINITY,
            mean_loss_dilute: MEAN_LOSS_DILUTE,
            layered_air: true,
            floor_per_zone: true,
        }
    }

    /// The defaults for `background` in the equation `wave` is solved in
    /// (Maxwell's caps the loss floor: [`MEAN_LOSS_CAP_MAXWELL`]).
    pub const fn for_wave(background: Background, wave: &Wave) -> ShiftParams {
        let mean_loss_cap = match wave {
            Wave::Scalar => f64::INFINITY,
            Wave::Vector { .. } => MEAN_LOSS_CAP_MAXWELL,
        };
        ShiftParams {
            mean_loss_cap,
            ..ShiftParams::of(background)
        }
    }
}

/// Real centre and radius of the permittivity values: (ε_r, max|ε − ε_r|),
/// the tensor voxels' spectra included ([`spread`]).
pub fn shift_of(eps: &Array3<C64>, tensor: Option<&Anisotropy>, eps_binder: f64) -> (f64, f64) {
    let (mut lo, mut hi) = (eps_binder, eps_binder);
    for e in eps.iter() {
        lo = lo.min(e.re);
        hi = hi.max(e.re);
    }
    if let Some(a) = tensor {
        for (e, sum, bound) in tensor::voxels(a, eps) {
            lo = lo.min(e.re + sum.re.min(0.0) - (bound - sum.norm()));
            hi = hi.max(e.re + sum.re.max(0.0) + (bound - sum.norm()));
        }
    }
    let er = 0.5 * (lo + hi);
    let rad = eps
        .iter()
        .map(|e| (e - er).norm())
        .fold((eps_binder - er).abs(), f64::max);
    (er, rad.max(spread(eps, tensor, C64::new(er, 0.0))))
}

/// The largest `‖ε_v − centre‖` over the tensor voxels: exact
/// (`max(|ε_v − c|, |ε_v + δ − c|)`) for one axis per voxel, the triangle
/// bound `|ε_v − c| + Σ|δ|` otherwise; 0 without a tensor part.
pub(super) fn spread(eps: &Array3<C64>, tensor: Option<&Anisotropy>, centre: C64) -> f64 {
    let Some(a) = tensor else { return 0.0 };
    spread_per_cell(a, eps, &vec![centre; a.nz()])
        .into_iter()
        .fold(0.0, f64::max)
}

/// [`spread`] of each cell's tensor voxels, each cell against its own
/// centre.
fn spread_per_cell(a: &Anisotropy, eps: &Array3<C64>, centres: &[C64]) -> Vec<f64> {
    (0..a.nz())
        .map(|iz| {
            let centre = centres[iz];
            tensor::slice_voxels(a, eps, iz)
                .map(|(e, sum, bound)| {
                    if bound - sum.norm() <= 1e-12 * bound {
                        (e - centre).norm().max((e + sum - centre).norm())
                    } else {
                        (e - centre).norm() + bound
                    }
                })
                .fold(0.0, f64::max)
        })
        .collect()
}

/// The share of the loss floor the cells `cells` take:
/// `min(1, ⟨|ε − ε̄_j|²⟩ / (dilute · r²))` over their voxels, a tensor
/// voxel counting the mean over three axes of its one-axis contrast
/// `(ε_v − ε̄) I + Σδ â âᵀ`; 1 where the scaling is off or `r` is 0.
fn dilute_share(
    eps: &Array3<C64>,
    tensor: Option<&Anisotropy>,
    means: &[C64],
    cells: std::ops::Range<usize>,
    rad: f64,
    lat: &Lattice,
    params: ShiftParams,
) -> f64 {
    if params.mean_loss_dilute <= 0.0 || rad <= 0.0 || cells.is_empty() {
        return 1.0;
    }
    let voxels = (cells.len() * eps.dim().1 * eps.dim().2) as f64;
    let sum: f64 = cells
        .clone()
        .map(|j| {
            let m = means[j];
            let plain: f64 = eps
                .index_axis(ndarray::Axis(0), j)
                .iter()
                .map(|e| (e - m).norm_sqr())
                .sum();
            let extra: f64 = tensor.map_or(0.0, |a| {
                tensor::slice_voxels(a, eps, j)
                    .map(|(e, s, _)| (2.0 * ((e - m).conj() * s).re + s.norm_sqr()) / 3.0)
                    .sum()
            });
            plain + extra
        })
        .sum();
    let share = (sum / voxels / (params.mean_loss_dilute * rad * rad)).min(1.0);
    if share >= 1.0 {
        return 1.0;
    }
    // Large high-index grains keep the whole floor: their own resonances
    // need it (see `DILUTE_GRAIN_SIZE`).
    let x = grain_size_parameter(eps, means, cells, rad, lat);
    let t = ((x - DILUTE_GRAIN_SIZE[0]) / (DILUTE_GRAIN_SIZE[1] - DILUTE_GRAIN_SIZE[0]))
        .clamp(0.0, 1.0);
    share + (1.0 - share) * t
}

/// The grains' size parameter inside them, `k0 n a`, as the grid shows it:
/// `n = √(Re ε̄ + r)` the largest index, `a = 4.5 V / S` from the volume V
/// and the faces S of the voxels whose contrast exceeds `r / 2`, over the
/// cells `cells` (the faces of a voxel staircase exceed a sphere's by
/// about 1.5, so a sphere of radius a gives about `4.5 V / S = a`).
fn grain_size_parameter(
    eps: &Array3<C64>,
    means: &[C64],
    cells: std::ops::Range<usize>,
    rad: f64,
    lat: &Lattice,
) -> f64 {
    let (_, ny, nx) = eps.dim();
    let d = [
        lat.size_nm[0] / nx as f64,
        lat.size_nm[1] / ny as f64,
        lat.size_nm[2] / lat.nz as f64,
    ];
    let grain = |j: usize, y: usize, x: usize| (eps[[j, y, x]] - means[j]).norm() > 0.5 * rad;
    let (mut volume, mut faces) = (0.0, 0.0);
    for j in cells.clone() {
        for y in 0..ny {
            for x in 0..nx {
                let g = grain(j, y, x);
                if g {
                    volume += d[0] * d[1] * d[2];
                }
                if g != grain(j, y, (x + 1) % nx) {
                    faces += d[1] * d[2];
                }
                if g != grain(j, (y + 1) % ny, x) {
                    faces += d[0] * d[2];
                }
                if j + 1 < cells.end && g != grain(j + 1, y, x) {
                    faces += d[0] * d[1];
                }
            }
        }
    }
    if faces == 0.0 {
        return 0.0;
    }
    let centre = means[cells.start].re;
    lat.k0 * (centre + rad).sqrt() * 4.5 * volume / faces
}

/// At most `nz / ZONE_CAP_DIVISOR` cells of a face take their own mean
/// ([`zone_cells`]): their sweep coefficients are stored cell by cell, so
/// the zones of both faces hold at most half the cells' coefficients
/// (counted in the memory model, `pipeline::memory`).
pub const ZONE_CAP_DIVISOR: usize = 4;

/// Bytes the sweep tables hold per harmonic for each layered zone cell: the
/// scalar (TE) table's, and in Maxwell's equations the TM table's beside it.
pub fn zone_cell_bytes(vector: bool) -> usize {
    super::shift::ZONE_CELL_BYTES
        + if vector {
            super::maxwell::TM_ZONE_CELL_BYTES
        } else {
            0
        }
}

/// The layered zones `(top, bottom)` the mean background takes: each face's
/// [`air_cells`], capped at a quarter of the cells. Where air reaches
/// deeper (a porous layer such as a conformal film draped into the gaps
/// between its grains, voids in an explicit structure), the outer quarter
/// at each face, where the air's share changes fastest, is layered and the
/// cells between share one mean.
pub fn zone_cells(eps: &Array3<C64>) -> (usize, usize) {
    let cap = eps.dim().0 / ZONE_CAP_DIVISOR;
    let (top, bottom) = air_cells(eps);
    (top.min(cap), bottom.min(cap))
}

/// Mean of the permittivity over every voxel, the mean background.
pub fn mean_eps(eps: &Array3<C64>) -> C64 {
    eps.iter().sum::<C64>() / eps.len() as f64
}

/// The layered zones of the mean background, `(top, bottom)` cells: from
/// the top face down to the deepest cell of the upper half that holds air
/// (a voxel of ε = 1: a relief above the binder, the air over a conformal
/// film or a rough surface), and likewise from the bottom face up (a layer
/// lit from below is solved upside down); 0 where a face is flat.
pub fn air_cells(eps: &Array3<C64>) -> (usize, usize) {
    let air = C64::new(1.0, 0.0);
    let nz = eps.dim().0;
    let has_air: Vec<bool> = eps
        .outer_iter()
        .map(|s| s.iter().any(|&e| e == air))
        .collect();
    let half = nz / 2;
    let top = (0..half).rev().find(|&j| has_air[j]).map_or(0, |j| j + 1);
    let bottom = (half..nz).find(|&j| has_air[j]).map_or(0, |j| nz - j);
    (top, bottom)
}

/// The mean background's permittivity per z cell: the mean of the cells
/// between the layered zones ([`zone_cells`]), and in each cell of a zone its
/// own lateral mean (the tensor voxels add a third of their trace). Each
/// takes the loss floor of the contrast left where it applies: a zone cell
/// its own, `r_j = max|ε − ε̄_j|` over the cell, the cells between the
/// largest of theirs ([`ShiftParams::floor_per_zone`]; a layer with flat
/// faces has one mean and one floor, as before). One floor for every cell,
/// from the largest contrast anywhere, let the air of a relief (r ≈ 1.2–1.4)
/// damp the bulk below it, whose own contrast is a fraction of that, and
/// the Krylov methods then spent their iterations undoing that loss.
pub(super) fn mean_profile(
    eps: &Array3<C64>,
    tensor: Option<&Anisotropy>,
    lat: &Lattice,
    params: ShiftParams,
) -> Vec<C64> {
    let (nz, ny, nx) = eps.dim();
    let (top, bottom) = if params.layered_air {
        zone_cells(eps)
    } else {
        (0, 0)
    };
    let plane = (ny * nx) as f64;
    // A third of the tensor traces of cell j, summed.
    let traces = |j: usize| {
        tensor.map_or(C64::new(0.0, 0.0), |a| {
            a.slice(j).iter().map(|t| t.delta).sum::<C64>() / 3.0
        })
    };
    // The sum of ε and of the tensor term over cell j.
    let cell_sum = |j: usize| eps.index_axis(ndarray::Axis(0), j).sum() + traces(j);
    let inner = top..nz - bottom;
    let bulk = if inner.len() == nz {
        // Flat faces: the mean over every voxel, summed as always.
        mean_eps(eps)
            + tensor.map_or(C64::new(0.0, 0.0), |a| {
                a.terms.iter().map(|t| t.delta).sum::<C64>() / (3.0 * eps.len() as f64)
            })
    } else {
        inner.clone().map(cell_sum).sum::<C64>() / (plane * inner.len() as f64)
    };
    let means: Vec<C64> = (0..nz)
        .map(|j| {
            if inner.contains(&j) {
                bulk
            } else {
                cell_sum(j) / plane
            }
        })
        .collect();
    // The contrast left in each cell, `r_j = max|ε − ε̄_j|` over its voxels
    // (the tensor voxels' spread included).
    let mut rad: Vec<f64> = eps
        .outer_iter()
        .zip(&means)
        .map(|(s, m)| {
            s.iter()
                .map(|e| (e - m).norm_sqr())
                .fold(0.0, f64::max)
                .sqrt()
        })
        .collect();
    if let Some(a) = tensor {
        for (r, spread) in rad.iter_mut().zip(spread_per_cell(a, eps, &means)) {
            *r = r.max(spread);
        }
    }
    let floor_of = |rad: f64| {
        // (`rad` is 0 on a homogeneous layer, where ∞ · 0 is NaN.)
        let cap = if rad > 0.0 {
            params.mean_loss_cap * rad
        } else {
            0.0
        };
        (params.mean_loss_floor * rad * rad).min(cap)
    };
    let largest = |cells: std::ops::Range<usize>| cells.map(|j| rad[j]).fold(0.0, f64::max);
    let global = floor_of(largest(0..nz));
    let inner_rad = largest(inner.clone());
    let inner_floor = floor_of(inner_rad)
        * dilute_share(eps, tensor, &means, inner.clone(), inner_rad, lat, params);
    means
        .iter()
        .enumerate()
        .map(|(j, m)| {
            let floor = if !params.floor_per_zone {
                global
            } else if inner.contains(&j) {
                inner_floor
            } else {
                floor_of(rad[j])
            };
            C64::new(m.re, m.im.max(floor).max(1e-9))
        })
        .collect()
}
