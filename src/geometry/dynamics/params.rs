//! Parameters of the dynamics packer and their validation.

use crate::geometry::shapes::{Orientation, Shape, ShapeTemplate};
use crate::geometry::{
    check_relief, check_sweeps, draw_all_diameters, options_of, GeometryError, SpeciesOptions,
};

/// One species for [`pack_dynamics`](super::pack_dynamics).
#[derive(Debug, Clone)]
pub struct DynSpecies {
    pub shape: Shape,
    /// Diameter of the equal-volume sphere, nm (> 0); the nominal one with a
    /// size distribution ([`DynParams::options`]).
    pub effective_diameter_nm: f64,
    /// Target volume fraction of the fragment, in `[0, 1)`.
    pub volume_fraction: f64,
    pub orientation: Orientation,
    /// Alignment torque strength (≥ 0, 0 = none; see the module docs); only
    /// with [`Orientation::InPlane`] or [`Orientation::Perpendicular`].
    pub field: f64,
}

/// Fragment and species for [`pack_dynamics`](super::pack_dynamics).
#[derive(Debug, Clone)]
pub struct DynParams {
    /// `[Lx, Ly, H]`, nm.
    pub size_nm: [f64; 3],
    pub species: Vec<DynSpecies>,
    /// Largest overlap accepted, as a fraction of the smallest sphere radius
    /// of all particles, in `(0, 0.5]` (default 0.01).
    pub overlap_tolerance: f64,
    /// Volume fraction added per batch, in `(0, 1]` (default 0.1).
    pub batch_fraction: f64,
    /// Relaxation steps allowed per batch (≥ 1, default 100 000).
    pub max_steps_per_batch: u64,
    /// First-order steps of a batch after which, if it has not converged,
    /// its relaxation continues with FIRE (default 200; 0: FIRE from the
    /// start, `u64::MAX`: never).
    pub fire_after_steps: u64,
    /// Size distribution and clustering per species; empty: defaults.
    pub options: Vec<SpeciesOptions>,
    /// Grains may protrude through the top surface `z = 0` by up to this
    /// fraction of their effective diameter, `[0, MAX_RELIEF_FRACTION]`
    /// (default 0: flat top).
    pub relief_fraction: f64,
    /// Hard-particle Monte Carlo sweeps run on the packed fragment
    /// ([`crate::geometry::mc::equilibrate`], moves may not deepen an overlap beyond
    /// the tolerance), `[0, mc::MAX_SWEEPS]` (default 0: none).
    pub equilibrate_sweeps: u64,
}

impl DynParams {
    /// Parameters with the defaults above.
    pub fn new(size_nm: [f64; 3], species: Vec<DynSpecies>) -> Self {
        DynParams {
            size_nm,
            species,
            overlap_tolerance: 0.01,
            batch_fraction: 0.1,
            max_steps_per_batch: 100_000,
            fire_after_steps: 200,
            options: Vec::new(),
            relief_fraction: 0.0,
            equilibrate_sweeps: 0,
        }
    }
}

/// One species after validation, lengths for effective diameter 1.
#[derive(Debug, Clone)]
pub(super) struct Spec {
    /// `(axial offset, radius)`.
    pub(super) spheres: Vec<(f64, f64)>,
    pub(super) half_length: f64,
    pub(super) r_min: f64,
    pub(super) r_max: f64,
    pub(super) s_max: f64,
    pub(super) inertia: f64,
    /// Signed alignment strength (+ towards z, − towards the plane).
    pub(super) field: f64,
    /// Grains per seeded cluster.
    pub(super) group: usize,
}

/// Checks the parameters; returns the species and their diameters.
pub(super) fn validate(
    p: &DynParams,
    seed: u64,
) -> Result<(Vec<Spec>, Vec<Vec<f64>>), GeometryError> {
    let [lx, ly, h] = p.size_nm;
    for (name, v) in [("Lx", lx), ("Ly", ly), ("H", h)] {
        if !(v.is_finite() && v > 0.0) {
            return Err(GeometryError::Invalid(format!(
                "fragment size {name} = {v} nm must be finite and > 0"
            )));
        }
    }
    let tol = p.overlap_tolerance;
    if !(tol.is_finite() && tol > 0.0 && tol <= 0.5) {
        return Err(GeometryError::Invalid(format!(
            "overlap_tolerance {tol} must be in (0, 0.5]"
        )));
    }
    let b = p.batch_fraction;
    if !(b.is_finite() && b > 0.0 && b <= 1.0) {
        return Err(GeometryError::Invalid(format!(
            "batch_fraction {b} must be in (0, 1]"
        )));
    }
    if p.max_steps_per_batch == 0 {
        return Err(GeometryError::Invalid(
            "max_steps_per_batch must be ≥ 1".into(),
        ));
    }
    let options = options_of(&p.options, p.species.len())?;
    check_relief(p.relief_fraction)?;
    check_sweeps(p.equilibrate_sweeps)?;
    let volume = lx * ly * h;
    let mut total = 0.0;
    let mut out = Vec::with_capacity(p.species.len());
    for (i, s) in p.species.iter().enumerate() {
        let tpl = ShapeTemplate::new(s.shape)
            .map_err(|e| GeometryError::Invalid(format!("species {i}: {e}")))?;
        let d = s.effective_diameter_nm;
        if !(d.is_finite() && d > 0.0) {
            return Err(GeometryError::Invalid(format!(
                "species {i}: effective diameter {d} nm must be finite and > 0"
            )));
        }
        let dmax = options[i].size.range(d).1;
        let half_length = tpl.half_length();
        let r_max = tpl.max_radius();
        // Thinnest extent along z the largest particle can take in its mode.
        let need_z = dmax
            * match s.orientation {
                Orientation::Perpendicular => 2.0 * half_length,
                _ => 2.0 * r_max,
            };
        if need_z > h {
            return Err(GeometryError::GrainTooLarge {
                species: i,
                diameter_nm: need_z,
                thickness_nm: h,
            });
        }
        let half = 0.5 * lx.min(ly);
        if 2.0 * half_length * dmax > half {
            return Err(GeometryError::Invalid(format!(
                "species {i}: particle length {} nm exceeds half the lateral period \
                 ({half} nm); allowed length ≤ min(Lx, Ly)/2",
                2.0 * half_length * dmax
            )));
        }
        let f = s.volume_fraction;
        if !(f.is_finite() && (0.0..1.0).contains(&f)) {
            return Err(GeometryError::Invalid(format!(
                "species {i}: volume fraction {f} must be in [0, 1)"
            )));
        }
        let fld = s.field;
        if !(fld.is_finite() && fld >= 0.0) {
            return Err(GeometryError::Invalid(format!(
                "species {i}: field {fld} must be finite and ≥ 0"
            )));
        }
        if fld > 0.0 && s.orientation == Orientation::Random {
            return Err(GeometryError::Invalid(format!(
                "species {i}: field {fld} needs orientation in-plane or perpendicular \
                 (random has no field direction); allowed 0 for random"
            )));
        }
        total += f;
        let spheres = tpl.spheres.clone();
        let w: f64 = spheres.iter().map(|&(_, r)| r * r * r).sum();
        let inertia = spheres
            .iter()
            .map(|&(o, r)| r * r * r * (o * o + 0.4 * r * r))
            .sum::<f64>()
            / w;
        let sign = match s.orientation {
            Orientation::Perpendicular => 1.0,
            Orientation::InPlane => -1.0,
            Orientation::Random => 0.0,
        };
        out.push(Spec {
            half_length,
            r_min: tpl.min_radius(),
            r_max,
            s_max: spheres.iter().map(|&(o, _)| o.abs()).fold(0.0, f64::max),
            inertia,
            field: sign * fld,
            group: options[i].cluster_size,
            spheres,
        });
    }
    // Random close packing of equal spheres is ≈ 0.64; ordered packings
    // reach 0.74. Beyond that no packer can go.
    if total >= 0.74 {
        return Err(GeometryError::Invalid(format!(
            "total volume fraction {total} beyond reach; allowed < 0.74"
        )));
    }
    let species: Vec<(f64, f64)> = p
        .species
        .iter()
        .map(|s| (s.effective_diameter_nm, s.volume_fraction))
        .collect();
    Ok((out, draw_all_diameters(&species, &options, volume, seed)?))
}
