//! What an effect study will cost: each variant solved by the fast model at
//! its middle wavelength, timed, and scaled to its wavelengths.
//!
//! Time: the process's CPU time of that one solve (over its threads, so a
//! loaded machine does not inflate it) times the number of wavelengths,
//! over the threads the run spreads them on, plus [`FIXED_S`] for the
//! colours, the sparkle figures, the pictures and the file. Memory: the
//! bytes of the reflection the run keeps per wavelength (measured on that
//! solve) times the wavelengths, plus [`BASE_BYTES`]. A guide (±2×).

use super::super::cpu::process_cpu_s;
use super::super::sweep::Variant;
use crate::config::paint::PaintScene;
use crate::pipeline;

/// Seconds per variant beyond the wavelengths' solves (colours, sparkle,
/// two pictures, the result file). Measured: configs/study-effect.toml's
/// 48 variants (16 wavelengths) took 147 s of CPU, 3.06 s each, against
/// 16 × 0.19 s = 3.0 s of solves as `plan` timed them, so the rest is under
/// 0.1 s of CPU; 0.4 s allows for writing three files on a busy disk.
pub const FIXED_S: f64 = 0.4;
/// Memory of a paint run beyond its kept reflections (the process, the
/// pictures, the in-plane BRDF): 32 MiB.
pub const BASE_BYTES: f64 = 32.0 * 1024.0 * 1024.0;

/// The estimate of one variant.
#[derive(Debug, Clone)]
pub struct PaintEstimate {
    pub wavelengths: usize,
    /// Fourier terms the fast model kept at the timed wavelength.
    pub terms: usize,
    /// CPU seconds of the timed wavelength.
    pub probe_cpu_s: f64,
    pub seconds: f64,
    pub bytes: f64,
}

/// Time `v` at its middle wavelength and estimate its run on `threads`
/// threads; an error (a material without data there) is the variant's.
pub fn estimate(v: &Variant<PaintScene>, threads: usize) -> Result<PaintEstimate, String> {
    let wl = &v.scene.wavelengths_nm;
    let mid = wl[wl.len() / 2];
    let t = process_cpu_s();
    let probe = pipeline::probe_paint(&v.scene, mid).map_err(|e| e.to_string())?;
    let cpu = process_cpu_s() - t;
    let n = wl.len();
    // The wavelengths run in parallel: as many rounds as the threads need.
    let rounds = n.div_ceil(threads.max(1)) as f64;
    Ok(PaintEstimate {
        wavelengths: n,
        terms: probe.terms,
        probe_cpu_s: cpu,
        seconds: rounds * cpu + FIXED_S,
        bytes: n as f64 * probe.kept_bytes + BASE_BYTES,
    })
}
