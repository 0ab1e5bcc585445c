//! The memory model of a run and the preflight that holds a run to it.
//!
//! Peak resident bytes of one scene (or study variant):
//! `BASELINE_BYTES + voxels × (B_method + 32 + 8 × species)`, with
//! `B_method` the solver's own peak per voxel from its registry
//! (`Solver::bytes_per_voxel`, measured by `examples/solver_memory`,
//! docs/PERFORMANCE.md "Memory") plus the 16 B of a looser answer a
//! tighter solve starts from ([`MAXWELL_PER_SCALAR`] times both for
//! Maxwell's three components), 32 B for the pipeline's ε grid and its
//! flipped copy for the solves from below, and 8 B per species for the
//! raster's volume fractions. With anisotropic cut voxels (Maxwell) the
//! voxels a grain surface cuts hold [`CUT_VOXEL_BYTES`] more, their share
//! estimated by [`cut_share`]; a uniaxial crystal's grains in Maxwell hold
//! [`CRYSTAL_VOXEL_BYTES`] in every voxel they touch. Where air can reach
//! into the grid, the mean background's layered zones add their sweep
//! tables ([`zone_bytes`]). The grid is the one the run solves on
//! (including the cells a relief adds on top).
//!
//! The limit is the smaller of `--max-memory` and the machine's available
//! memory (`MemAvailable` of /proc/meminfo, where present). [`preflight`]
//! compares the estimate with it before anything large is allocated and,
//! when the estimate is within it, reserves the estimate once with a
//! fallible allocation (`Vec::try_reserve_exact`), so that a request the
//! system refuses is an error of this scene rather than an abort of the
//! process.

use crate::config::{Equation, Method, Precision, Scene};
use crate::raster::anisotropy::{GrainShare, Normal, Term};
use crate::solver::{zone_cell_bytes, ZONE_CAP_DIVISOR};

use super::grains::grid_of;
use super::PipelineError;

/// Resident memory of the program before any field is allocated (binary,
/// geometry, tables): the 23 MB baseline of docs/PERFORMANCE.md, rounded up.
pub const BASELINE_BYTES: f64 = 25e6;

/// A Maxwell solve's own peak per voxel over the scalar one's, same method
/// and precision: three field components (fields, spectrum, sweep tables),
/// one ε grid. Measured 2.8–3.2× (`solver_memory … maxwell`, every method
/// and precision, docs/PERFORMANCE.md "Memory"); the largest is kept.
pub const MAXWELL_PER_SCALAR: f64 = 3.2;

/// The field of a looser answer a tighter solve starts from (one complex
/// f64 per unknown; three unknowns a voxel in Maxwell), held while it
/// runs.
pub const WARM_START_BYTES: f64 = 16.0;

/// Bytes a cut voxel holds with anisotropic voxels: its surface normal
/// (32 B) and the tensor term of each wavelength's grid and its flipped
/// copy (48 B each).
pub const CUT_VOXEL_BYTES: f64 =
    (std::mem::size_of::<Normal>() + 2 * std::mem::size_of::<Term>()) as f64;

/// Bytes a voxel a crystal grain touches holds in Maxwell: the grain's share
/// with its axis (40 B) and its tensor term in the grid and the flipped copy
/// (48 B each).
pub const CRYSTAL_VOXEL_BYTES: f64 =
    (std::mem::size_of::<GrainShare>() + 2 * std::mem::size_of::<Term>()) as f64;

/// The estimated share of voxels a grain surface cuts: `Σ 9 f_s c / d_s`
/// (at most 1) over the species, with `f_s` the volume fraction, `d_s` the
/// diameter and `c` the mean of the cell's three edges. A surface of area
/// `A` cuts about `A Σ_i ⟨|n_i|⟩ / (cell face ⊥ i)` voxels, `⟨|n_i|⟩ = 1/2`
/// on a sphere, and spheres have `A/V = 6/d`. The demo scene (20 % of
/// 200 nm grains, 25 × 25 × 10 nm cells): estimated 18 %, counted 13.4 %.
pub fn cut_share(scene: &Scene) -> f64 {
    species_cut_shares(scene).iter().sum::<f64>().min(1.0)
}

/// Each species' term of [`cut_share`] (0 for a molecular one).
fn species_cut_shares(scene: &Scene) -> Vec<f64> {
    let [nx, ny, nz] = solve_grid(scene);
    let cell = (scene.layer.fragment_x_nm / nx as f64
        + scene.layer.fragment_y_nm / ny as f64
        + scene.layer.thickness_nm / nz as f64)
        / 3.0;
    scene
        .species
        .iter()
        .map(|s| {
            if s.shape == crate::config::GrainShape::Molecular || s.diameter_nm <= 0.0 {
                0.0
            } else {
                9.0 * s.volume_fraction * cell / s.diameter_nm
            }
        })
        .collect()
}

/// The estimated share of voxels the grains of tensor crystals
/// ([`Scene::crystal_tensors`]: uniaxial crystals in Maxwell) touch: each
/// such species' volume fraction plus its cut share, at most 1.
pub fn crystal_share(scene: &Scene) -> f64 {
    scene
        .species
        .iter()
        .zip(species_cut_shares(scene))
        .zip(scene.crystal_tensors())
        .filter(|(_, tensor)| *tensor)
        .map(|((s, cut), _)| s.volume_fraction + cut)
        .sum::<f64>()
        .min(1.0)
}

/// Bytes per voxel of a solve: the method's own peak from the solver's
/// registry plus the warm start's field (times [`MAXWELL_PER_SCALAR`] for
/// Maxwell), plus the pipeline's ε grid and its flipped copy (16 B each).
pub fn bytes_per_voxel(m: Method, p: Precision, e: Equation) -> f64 {
    let factor = match e {
        Equation::Helmholtz => 1.0,
        Equation::Maxwell => MAXWELL_PER_SCALAR,
    };
    factor * (m.solver().bytes_per_voxel(p) + WARM_START_BYTES) + 32.0
}

/// The grid a scene solves on, `[nx, ny, nz]`.
pub fn solve_grid(scene: &Scene) -> [usize; 3] {
    let g = grid_of(scene);
    [g.nx, g.ny, g.nz]
}

/// Estimated peak resident bytes of a run of `scene`.
pub fn estimate_bytes(scene: &Scene) -> f64 {
    let voxels: f64 = solve_grid(scene).iter().map(|&n| n as f64).product();
    BASELINE_BYTES
        + voxels
            * (bytes_per_voxel(
                scene.solver.method,
                scene.solver.precision,
                scene.solver.equation,
            ) + 8.0 * scene.species.len() as f64
                + anisotropic_bytes(scene)
                + zone_bytes(scene))
}

/// The peak resident memory the layered zones add over their tables' own
/// bytes. Measured 1.6× (a conformal film over 30 % of 200 nm spheres in
/// Maxwell's equations, 60 × 60 × 50 cells, both zones at their cap, lit
/// from above only: peak 176 MB against 131 MB with one mean, tables of
/// 28 MB; `/usr/bin/time -v inksim run`), and up to about 1.8× with the
/// solves from below; each solve builds and drops its tables, and the
/// allocator keeps some of what they held. 2× is kept.
pub const ZONE_PEAK_PER_TABLE: f64 = 2.0;

/// Per voxel, the sweep tables of the mean background's layered zones
/// (`solver::zone_cells`): where air can reach into the grid (a relief, a
/// conformal film, a rough surface, an explicit structure), each face's
/// zone may take a quarter of the cells, whose coefficients are stored per
/// harmonic and cell (`solver::zone_cell_bytes`), times
/// [`ZONE_PEAK_PER_TABLE`]; 0 for a flat top.
pub fn zone_bytes(scene: &Scene) -> f64 {
    if super::flat_top(scene) && scene.structure.is_none() {
        return 0.0;
    }
    let vector = scene.solver.equation == Equation::Maxwell;
    ZONE_PEAK_PER_TABLE * (zone_cell_bytes(vector) * 2) as f64 / ZONE_CAP_DIVISOR as f64
}

/// The cut voxels' share of [`CUT_VOXEL_BYTES`] per voxel (0 without
/// anisotropic voxels) and the crystal grains' of [`CRYSTAL_VOXEL_BYTES`].
fn anisotropic_bytes(scene: &Scene) -> f64 {
    let surfaces = scene
        .grid
        .voxel_permittivity
        .anisotropic(scene.solver.equation);
    let cut = if surfaces { cut_share(scene) } else { 0.0 };
    CUT_VOXEL_BYTES * cut + CRYSTAL_VOXEL_BYTES * crystal_share(scene)
}

/// A run whose memory estimate exceeds the limit: what to say about it.
#[derive(Debug, thiserror::Error)]
#[error(
    "grid {grid}, method {method} ({precision} fields, {equation}): estimated peak memory \
     {estimate} exceeds {limit}; use fewer cells (a larger [grid] cell_nm or a smaller \
     fragment){lighter}, or {remedy}"
)]
pub struct OverMemory {
    pub grid: String,
    pub method: String,
    pub precision: String,
    /// The equation's name.
    pub equation: &'static str,
    /// The lighter settings the scene does not use yet (f32 fields,
    /// time-marching, the scalar equation), each after a comma.
    pub lighter: String,
    pub estimate: String,
    pub limit: String,
    pub remedy: &'static str,
}

/// Where a memory limit came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LimitSource {
    /// `--max-memory`.
    Flag,
    /// The machine's available memory (`MemAvailable`).
    Available,
}

/// The memory a run may use.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MemoryLimit {
    pub bytes: f64,
    pub source: LimitSource,
}

impl MemoryLimit {
    /// The smaller of `flag` (bytes) and the machine's available memory;
    /// `None` when neither is known.
    pub fn resolve(flag: Option<u64>) -> Option<MemoryLimit> {
        let flag = flag.map(|b| MemoryLimit {
            bytes: b as f64,
            source: LimitSource::Flag,
        });
        let machine = available_memory().map(|b| MemoryLimit {
            bytes: b as f64,
            source: LimitSource::Available,
        });
        match (flag, machine) {
            (Some(f), Some(m)) if m.bytes < f.bytes => Some(m),
            (Some(f), _) => Some(f),
            (None, m) => m,
        }
    }

    /// What to change when a run does not fit.
    pub fn remedy(&self) -> &'static str {
        match self.source {
            LimitSource::Flag => "raise --max-memory",
            LimitSource::Available => "run where more memory is free",
        }
    }

    /// `24.0 GB (--max-memory)` or `24.0 GB (available on this machine)`.
    pub fn describe(&self) -> String {
        let from = match self.source {
            LimitSource::Flag => "--max-memory",
            LimitSource::Available => "available on this machine",
        };
        format!("{} ({from})", human_bytes(self.bytes))
    }
}

/// Available memory in bytes (Linux `MemAvailable`), if known.
pub fn available_memory() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/meminfo").ok()?;
    meminfo_available(&s)
}

/// `MemAvailable` of /proc/meminfo text, in bytes.
fn meminfo_available(s: &str) -> Option<u64> {
    let line = s.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// Check the scene's estimate against `limit`; one error line naming the
/// grid, the estimate, the limit and what to change (`check`, `plan`).
pub fn fits(scene: &Scene, limit: Option<MemoryLimit>) -> Result<(), PipelineError> {
    admit(scene, limit, false)
}

/// [`fits`], then reserve the estimate once with a fallible allocation so a
/// request the system refuses is this scene's error, not an abort (`run`).
pub fn preflight(scene: &Scene, limit: Option<MemoryLimit>) -> Result<(), PipelineError> {
    admit(scene, limit, true)
}

fn admit(scene: &Scene, limit: Option<MemoryLimit>, reserve: bool) -> Result<(), PipelineError> {
    if scene.is_molecular() {
        return Ok(());
    }
    let bytes = estimate_bytes(scene);
    let [nx, ny, nz] = solve_grid(scene);
    let what = |limit: String, remedy| {
        PipelineError::Memory(Box::new(OverMemory {
            grid: format!("{nx} × {ny} × {nz}"),
            method: scene.solver.method.name().to_string(),
            precision: match scene.solver.precision {
                Precision::F64 => "f64",
                Precision::F32 => "f32",
            }
            .to_string(),
            equation: scene.solver.equation.name(),
            lighter: lighter(scene),
            estimate: human_bytes(bytes),
            limit,
            remedy,
        }))
    };
    if let Some(l) = limit {
        if bytes > l.bytes {
            return Err(what(l.describe(), l.remedy()));
        }
    }
    if reserve {
        let mut probe: Vec<u8> = Vec::new();
        probe.try_reserve_exact(bytes as usize).map_err(|_| {
            what(
                "what the system would allocate".into(),
                "run where more memory is free",
            )
        })?;
    }
    Ok(())
}

/// The settings that would lower a scene's memory and that it does not
/// use yet, each as `, key = value`.
fn lighter(scene: &Scene) -> String {
    let mut s = String::new();
    if scene.solver.precision == Precision::F64 {
        s.push_str(", solver precision = \"f32\"");
    }
    if scene.solver.method != Method::TimeMarching {
        s.push_str(", method = \"time-marching\"");
    }
    if scene.solver.equation == Equation::Maxwell {
        s.push_str(", equation = \"helmholtz\" (a third of the memory)");
    }
    s
}

/// `800 kB`, `12 MB`, `3.4 GB`, `1.2 TB`.
pub fn human_bytes(b: f64) -> String {
    if b < 1e6 {
        format!("{:.0} kB", b / 1e3)
    } else if b < 1e9 {
        format!("{:.0} MB", b / 1e6)
    } else if b < 1e12 {
        format!("{:.1} GB", b / 1e9)
    } else {
        format!("{:.1} TB", b / 1e12)
    }
}

/// Parse a memory size: bytes, or a number with K, M, G or T (powers of
/// 1000, an optional trailing `B`; `Ki`, `Mi`, `Gi`, `Ti` for powers of 1024).
pub fn parse_bytes(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let split = t
        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
        .unwrap_or(t.len());
    let (num, unit) = t.split_at(split);
    let unit = unit.trim().to_ascii_uppercase();
    let unit = unit.strip_suffix('B').unwrap_or(&unit);
    let scale = match unit {
        "" => 1.0,
        "K" => 1e3,
        "M" => 1e6,
        "G" => 1e9,
        "T" => 1e12,
        "KI" => 1024.0,
        "MI" => 1024f64.powi(2),
        "GI" => 1024f64.powi(3),
        "TI" => 1024f64.powi(4),
        _ => {
            return Err(format!(
                "`{s}`: unknown unit (allowed: K, M, G, T, Ki, Mi, Gi, Ti)"
            ))
        }
    };
    let v: f64 = num
        .parse()
        .map_err(|_| format!("`{s}`: not a size (e.g. 512M, 24G)"))?;
    let b = v * scale;
    if !(1.0..1e18).contains(&b) {
        return Err(format!("`{s}`: must be between 1 byte and 1000 PB"));
    }
    Ok(b as u64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_with_units() {
        assert_eq!(parse_bytes("512"), Ok(512));
        assert_eq!(parse_bytes("24G"), Ok(24_000_000_000));
        assert_eq!(parse_bytes("2.5 GB"), Ok(2_500_000_000));
        assert_eq!(parse_bytes("1Mi"), Ok(1 << 20));
        assert_eq!(parse_bytes("3kb"), Ok(3000));
        assert!(parse_bytes("12X").is_err());
        assert!(parse_bytes("G").is_err());
        assert!(parse_bytes("0").is_err());
    }

    #[test]
    fn meminfo_is_read_in_kibibytes() {
        let text = "MemTotal:       16318412 kB\nMemFree:  1 kB\nMemAvailable:    2000 kB\n";
        assert_eq!(meminfo_available(text), Some(2_048_000));
        assert_eq!(meminfo_available("MemTotal: 5 kB\n"), None);
    }

    #[test]
    fn the_model_adds_the_pipeline_grids_to_the_solver_rates() {
        let h = Equation::Helmholtz;
        assert_eq!(
            bytes_per_voxel(Method::TimeMarching, Precision::F64, h),
            134.0
        );
        assert_eq!(bytes_per_voxel(Method::BiCgStab, Precision::F64, h), 213.0);
        assert_eq!(bytes_per_voxel(Method::BiCgStab, Precision::F32, h), 157.0);
        assert_eq!(bytes_per_voxel(Method::Gmres, Precision::F64, h), 469.0);
        let m = bytes_per_voxel(Method::BiCgStab, Precision::F32, Equation::Maxwell);
        assert!((m - (3.2 * (109.0 + 16.0) + 32.0)).abs() < 1e-9, "{m}");
        assert_eq!(human_bytes(2.5e9), "2.5 GB");
        assert_eq!(human_bytes(2.05e5), "205 kB");
        assert_eq!(human_bytes(2.2e14), "220.0 TB");
    }
}
