//! Solver — the diffraction problem (METHOD §4).
//!
//! The layer's permittivity is split into the plain binder slab and the grains:
//! `ε = ε_b + Δε`. The scattered field solves `u = u_bg + G_bg [k0² Δε u]`
//! with the exact slab Green's operator ([`operator`], [`green`]): outgoing
//! plane waves above and below are built in, so no absorbing layers and no
//! padding are needed. The iterative methods solve the same equation in a
//! shifted form, on the convergent-Born-series shift or on the layer's mean
//! permittivity ([`Controls::background`], [`system`]).
//!
//! Takes a [`Problem`] (lattice, permittivity grid, binder), a [`Method`] and
//! [`Controls`]; gives a [`Solution`] (field, order amplitudes, absorption and
//! the [`SolveRecord`] of how it was found) through the one entry point
//! [`solve`], or a [`SolveError`].
//!
//! **The numerics**, one module each, importing only modules earlier in
//! this list: [`fft`] (batched 2-D FFTs), [`green`] (the slab Green's
//! function of one harmonic), [`lattice`] (the harmonics of a problem),
//! [`simd`] (lanes and the row copy of the sweeps), [`shift`] (the exact
//! shifted inverse, the CBS preconditioner), [`operator`] (`G_b` and `G_s` on
//! the 3-D grid), [`storage`] (f64 or f32 fields), [`system`] (the discrete
//! equation and its scratch) and [`airy`] (the homogeneous slab in closed
//! form).
//!
//! **The methods** ([`methods`]). The discrete equation is fixed; the
//! iterative methods differ only in how they reach its solution, so they
//! agree to solver tolerance and every solve can be checked by its energy
//! balance.
//!
//! * `born` ([`methods::born`]): `u ← u_bg + G V u`; stops and reports
//!   divergence.
//! * `time-marching` ([`methods::marching`]): pseudo-time marching
//!   `u ← u + dτ P r` with the convergent-Born-series preconditioner of
//!   Osnabrugge et al. (2016); converges for any contrast.
//! * `gmres` ([`methods::gmres`]): restarted GMRES(20) on the same
//!   preconditioned equation.
//! * `bicgstab` ([`methods::bicgstab`]): BiCGStab on it; fixed memory, two
//!   applications per iteration.
//! * `auto` ([`methods::auto`]): Born where its estimate allows, else
//!   BiCGStab, with time-marching as the last resort.
//! * `airy` ([`methods::closed_form`]): a layer without grains in closed
//!   form; chosen by the pipeline, not by scenes.
//!
//! **Adding a method**: write `methods/<name>.rs` with a type implementing
//! [`Solver`] (its [`Method`], bytes per voxel, applications per iteration,
//! validity; `run` for an iterative method on the shared [`System`], or
//! `solve` for one that is not), declare it in `methods/mod.rs`, map its
//! [`Method`] to it in [`Method::solver`] there, and list it above. Its name
//! is the one thing outside this folder: a variant and a name in
//! `config::Method` (the configuration stage comes first and reads scenes, so
//! the names are its). Scenes, result files and the study's cost model then
//! find it through the registry.

pub mod airy;
pub mod background;
pub mod fft;
pub mod green;
pub mod heartbeat;
pub mod jones;
pub mod lattice;
pub mod maxwell;
pub mod methods;
pub mod operator;
pub mod settle;
pub mod shift;
pub mod simd;
pub mod storage;
pub mod system;
pub mod tensor;

use crate::config::{Background, Linear, Method, Precision};
use ndarray::{Array2, Array3};
use num_complex::Complex64 as C64;

pub use background::{
    air_cells, zone_cell_bytes, zone_cells, ShiftParams, DILUTE_GRAIN_SIZE, MEAN_LOSS_CAP_MAXWELL,
    MEAN_LOSS_DILUTE, MEAN_LOSS_FLOOR, SHIFT_MARGIN, ZONE_CAP_DIVISOR,
};
pub use jones::Jones;
pub use lattice::Lattice;
pub use methods::{Outcome, Solver, Validity};
pub use storage::{dot, Field, Storage};
pub use system::{Scratch, System};

/// What every solve records, stored beside its result.
#[derive(Debug, Clone)]
pub struct SolveRecord {
    pub method: Method,
    /// The background the answering method ran on (`auto` may have moved
    /// from the mean to the CBS-preconditioned binder background).
    pub background: Background,
    pub iterations: usize,
    /// Number of applications of a background Green's operator.
    pub operator_applications: usize,
    /// Final relative residual ‖u_bg + G V u − u‖ / ‖u_bg‖.
    pub residual: f64,
    pub seconds: f64,
    /// Free text: why this method, fallbacks taken.
    pub note: String,
}

impl SolveRecord {
    /// Count the iterations, applications and seconds of `other` in this
    /// record's (the cost of attempts it replaced).
    pub fn add(&mut self, other: &SolveRecord) {
        self.iterations += other.iterations;
        self.operator_applications += other.operator_applications;
        self.seconds += other.seconds;
    }
}

/// Why a solve did not produce a trustworthy answer.
#[derive(Debug, Clone, thiserror::Error)]
pub enum SolveError {
    #[error("{method} diverged: residual grew to {residual:.3e} after {iterations} iterations")]
    Diverged {
        method: Method,
        iterations: usize,
        residual: f64,
    },
    #[error("{method} did not reach tolerance {tolerance:.1e}: residual {residual:.3e} after {iterations} iterations")]
    NotConverged {
        method: Method,
        iterations: usize,
        residual: f64,
        tolerance: f64,
    },
    #[error("{method} stalled: residual {residual:.3e} not halved in {window} iterations (after {iterations})")]
    Stalled {
        method: Method,
        iterations: usize,
        residual: f64,
        window: usize,
    },
    /// `auto` ran out of methods: what it tried, in order, with each
    /// failure, then the last method's failure.
    #[error("auto: {tried}; {last}")]
    Exhausted {
        tried: String,
        /// Operator applications of every attempt.
        applications: usize,
        last: Box<SolveError>,
    },
    #[error("invalid problem: {0}")]
    Invalid(String),
}

impl SolveError {
    /// Operator applications a failed solve spent (its iterations × its
    /// method's applications per iteration; every attempt of an exhausted
    /// `auto`); none for an invalid problem.
    pub fn applications(&self) -> usize {
        match *self {
            SolveError::Diverged {
                method, iterations, ..
            }
            | SolveError::NotConverged {
                method, iterations, ..
            }
            | SolveError::Stalled {
                method, iterations, ..
            } => {
                (iterations as f64 * method.solver().applications_per_iteration()).round() as usize
            }
            SolveError::Exhausted { applications, .. } => applications,
            SolveError::Invalid(_) => 0,
        }
    }
}

/// One diffraction problem: a permittivity grid, a wavelength, an incidence.
pub struct Problem<'a> {
    pub lattice: Lattice,
    /// Total permittivity per voxel, (nz, ny, nx).
    pub eps: &'a Array3<C64>,
    /// Binder permittivity (real: the binder is transparent).
    pub eps_binder: f64,
    /// The wave equation and, for Maxwell's, the incident polarisation.
    pub wave: Wave,
    /// The tensor part of the permittivity (Maxwell only): uniaxial terms
    /// `δ â âᵀ` added to `eps` per voxel, such as the anisotropic
    /// permittivity of cut voxels ([`crate::raster::anisotropy`]). None:
    /// isotropic.
    pub tensor: Option<&'a crate::raster::Anisotropy>,
}

/// Which wave equation a problem is solved in (METHOD §4, §9).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Wave {
    /// The scalar Helmholtz equation; the field is (nz, ny, nx).
    Scalar,
    /// Maxwell's equations, lit by a plane wave of polarisation state
    /// `polarisation` (s and p relative to the plane of incidence at
    /// `azimuth_deg`, which also fixes them at normal incidence); the field
    /// is (3 nz, ny, nx), E_x, E_y, E_z stacked.
    Vector {
        polarisation: Jones,
        azimuth_deg: f64,
    },
}

impl Problem<'_> {
    /// Lattice for a wavelength and incidence (polar, azimuth in degrees).
    pub fn lattice(
        grid: [usize; 3],
        size_nm: [f64; 3],
        wavelength_nm: f64,
        polar_deg: f64,
        azimuth_deg: f64,
    ) -> Lattice {
        let k0 = 2.0 * std::f64::consts::PI / wavelength_nm;
        let (s, p) = (polar_deg.to_radians().sin(), azimuth_deg.to_radians());
        Lattice {
            nx: grid[0],
            ny: grid[1],
            nz: grid[2],
            size_nm,
            k0,
            q: [k0 * s * p.cos(), k0 * s * p.sin()],
        }
    }
}

/// Iteration controls.
#[derive(Debug, Clone, Copy)]
pub struct Controls {
    pub tolerance: f64,
    pub max_iterations: usize,
    /// Field storage of the iterative methods ([`storage`]).
    pub precision: Precision,
    /// Background of the Krylov methods' Green's operator ([`system`]).
    pub background: Background,
}

/// A solved problem: the field and what the far field needs.
pub struct Solution {
    pub lattice: Lattice,
    /// Cell-averaged periodic field v, (nz, ny, nx); for Maxwell
    /// (3 nz, ny, nx), E_x, E_y, E_z stacked.
    pub field: Array3<C64>,
    /// Reflection amplitudes r_mn (total, u_mn(0) − δ), spectral layout
    /// (nx, ny); for Maxwell the s amplitude of each order.
    pub r: Array2<C64>,
    /// Transmission amplitudes t_mn, spectral layout (nx, ny); for Maxwell
    /// the s amplitude.
    pub t: Array2<C64>,
    /// Absorbed fraction of the incident power.
    pub absorption: f64,
    pub record: SolveRecord,
    /// Maxwell's p amplitudes; `None` for the scalar wave.
    pub vector: Option<VectorAmplitudes>,
}

/// The p amplitudes of every order of a Maxwell solution (E_p along
/// p̂ = (β ê_κ ± κ ẑ)/k0 of the outgoing wave), beside the s ones in
/// [`Solution::r`], [`Solution::t`], and the incident polarisation state.
#[derive(Debug, Clone)]
pub struct VectorAmplitudes {
    pub incident: Jones,
    pub r_p: Array2<C64>,
    pub t_p: Array2<C64>,
}

impl Solution {
    /// The specular amplitudes and the absorption: all there is of a
    /// homogeneous slab's answer.
    pub fn slab_response(&self) -> airy::SlabResponse {
        airy::SlabResponse {
            r: self.specular_r(),
            t: self.specular_t(),
            absorption: self.absorption,
        }
    }

    /// The specular order's co-polarised (r, t) amplitudes: the scalar
    /// wave's; for Maxwell those of the incident linear polarisation, and
    /// for a mixed state the s ones per unit incident s amplitude (see
    /// [`Solution::specular_p`] for p).
    fn specular(&self) -> (C64, C64) {
        match &self.vector {
            Some(v) => match v.incident.as_linear() {
                Some(Linear::P) => (v.r_p[[0, 0]], v.t_p[[0, 0]]),
                Some(Linear::S) => (self.r[[0, 0]], self.t[[0, 0]]),
                None => (self.r[[0, 0]] / v.incident.s, self.t[[0, 0]] / v.incident.s),
            },
            None => (self.r[[0, 0]], self.t[[0, 0]]),
        }
    }

    /// The specular order's reflection amplitude in the incident
    /// polarisation (co-polarised for Maxwell).
    pub fn specular_r(&self) -> C64 {
        self.specular().0
    }

    /// The specular order's co-polarised transmission amplitude.
    pub fn specular_t(&self) -> C64 {
        self.specular().1
    }

    /// For a mixed incident state, p's co-polarised specular (r, t) per
    /// unit incident p amplitude: `r_pp + r_ps s/p`, whose mean over the
    /// relative phase is `r_pp` (likewise s's in [`Solution::specular_r`]);
    /// `None` for the scalar wave and a linear polarisation.
    pub fn specular_p(&self) -> Option<[C64; 2]> {
        let v = self.vector.as_ref()?;
        match v.incident.as_linear() {
            Some(_) => None,
            None => Some([v.r_p[[0, 0]] / v.incident.p, v.t_p[[0, 0]] / v.incident.p]),
        }
    }

    /// The power of order (ix, iy) in reflection and transmission, before
    /// the `Re β / β00` factor: `|r|²` (scalar), `|r_s|² + |r_p|²` (Maxwell).
    pub fn order_power(&self, ix: usize, iy: usize) -> (f64, f64) {
        let (mut r, mut t) = (self.r[[ix, iy]].norm_sqr(), self.t[[ix, iy]].norm_sqr());
        if let Some(v) = &self.vector {
            r += v.r_p[[ix, iy]].norm_sqr();
            t += v.t_p[[ix, iy]].norm_sqr();
        }
        (r, t)
    }
}

/// Solve one problem with `method` (the one entry point for every method).
pub fn solve(p: &Problem, method: Method, ctl: &Controls) -> Result<Solution, SolveError> {
    method.solver().solve(p, ctl)
}

/// As [`solve`], starting from `start` (the field of an earlier solve of
/// the same problem).
pub fn solve_from(
    p: &Problem,
    method: Method,
    ctl: &Controls,
    start: &Array3<C64>,
) -> Result<Solution, SolveError> {
    method.solver().solve_from(p, ctl, Some(start))
}
