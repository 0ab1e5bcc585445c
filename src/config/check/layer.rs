//! `[layer]` (thickness, fragment, binder, relief, equilibration) and
//! `[grid]` (from a cell size or explicit FFT-friendly counts).

use super::{Checker, REL_EPS};
use crate::config::raw::{RawGrid, RawLayer, RawSurface, RawVoxelPermittivity};
use crate::config::{
    ConfigError, GridSpec, Layer, Surface, VoxelPermittivity, MAX_EQUILIBRATE_SWEEPS,
    MAX_FILM_FRACTION, MAX_RELIEF_FRACTION, MAX_ROUGH_RMS_FRACTION,
};

const MAX_THICKNESS_NM: f64 = 20_000.0;
const MAX_FRAGMENT_NM: f64 = 100_000.0;
const MAX_CELL_NM: f64 = 1_000.0;
const MAX_GRID_DIM: usize = 4096;
/// Default z cell (nm) when the grid is given by `cell_nm`.
pub const DEFAULT_Z_CELL_NM: f64 = 10.0;
const DEFAULT_BINDER_INDEX: f64 = 1.558;

impl Checker<'_> {
    pub(super) fn layer(&self, raw: &RawLayer) -> Result<Layer, ConfigError> {
        let t = raw.thickness_nm;
        let thickness_nm = self.range(
            "layer.thickness_nm",
            t,
            t > 0.0 && t <= MAX_THICKNESS_NM,
            &format!("(0, {MAX_THICKNESS_NM}] nm"),
        )?;
        if raw.fragment_nm.len() != 2 {
            return Err(self.invalid(
                "layer.fragment_nm",
                format!(
                    "must be 2 values [x, y] in nm, got {}",
                    raw.fragment_nm.len()
                ),
            ));
        }
        let mut frag = [0.0; 2];
        for (i, &f) in raw.fragment_nm.iter().enumerate() {
            frag[i] = self.range(
                &format!("layer.fragment_nm[{i}]"),
                f,
                f > 0.0 && f <= MAX_FRAGMENT_NM,
                &format!("(0, {MAX_FRAGMENT_NM}] nm"),
            )?;
        }
        let b = raw.binder_index.unwrap_or(DEFAULT_BINDER_INDEX);
        let binder_index =
            self.range("layer.binder_index", b, (1.0..=3.0).contains(&b), "[1, 3]")?;
        let r = raw.relief_fraction.unwrap_or(0.0);
        let relief_fraction = self.range(
            "layer.relief_fraction",
            r,
            (0.0..=MAX_RELIEF_FRACTION).contains(&r),
            &format!("[0, {MAX_RELIEF_FRACTION}] (fraction of a grain's diameter)"),
        )?;
        let sweeps = raw.equilibrate_sweeps.unwrap_or(0);
        if !(0..=MAX_EQUILIBRATE_SWEEPS as i64).contains(&sweeps) {
            return Err(self.invalid(
                "layer.equilibrate_sweeps",
                format!(
                    "must be in [0, {MAX_EQUILIBRATE_SWEEPS}] (Monte Carlo sweeps, one attempted \
                     move per grain each; 0 = off), got {sweeps}"
                ),
            ));
        }
        let surface = self.surface(raw.surface.as_ref(), thickness_nm, frag)?;
        Ok(Layer {
            thickness_nm,
            fragment_x_nm: frag[0],
            fragment_y_nm: frag[1],
            binder_index,
            relief_fraction,
            equilibrate_sweeps: sweeps as u64,
            surface,
        })
    }

    /// `layer.surface`: the film within half the layer, the roughness within
    /// a quarter of it, its correlation length within the fragment.
    fn surface(
        &self,
        raw: Option<&RawSurface>,
        thickness_nm: f64,
        fragment_nm: [f64; 2],
    ) -> Result<Surface, ConfigError> {
        Ok(match raw {
            None | Some(RawSurface::Flat) => Surface::Flat,
            Some(&RawSurface::Conformal { film_nm }) => {
                let max = MAX_FILM_FRACTION * thickness_nm;
                Surface::Conformal {
                    film_nm: self.range(
                        "layer.surface.film_nm",
                        film_nm,
                        film_nm > 0.0 && film_nm <= max,
                        &format!("(0, {max}] nm (half the layer)"),
                    )?,
                }
            }
            Some(&RawSurface::Rough {
                rms_nm,
                correlation_nm,
            }) => {
                let max = MAX_ROUGH_RMS_FRACTION * thickness_nm;
                let rms_nm = self.range(
                    "layer.surface.rms_nm",
                    rms_nm,
                    rms_nm > 0.0 && rms_nm <= max,
                    &format!("(0, {max}] nm (a quarter of the layer)"),
                )?;
                let lmax = fragment_nm[0].min(fragment_nm[1]);
                let correlation_nm = self.range(
                    "layer.surface.correlation_nm",
                    correlation_nm,
                    correlation_nm > 0.0 && correlation_nm <= lmax,
                    &format!("(0, {lmax}] nm (the fragment's shorter side)"),
                )?;
                Surface::Rough {
                    rms_nm,
                    correlation_nm,
                }
            }
        })
    }

    pub(super) fn grid(&self, raw: &RawGrid, layer: &Layer) -> Result<GridSpec, ConfigError> {
        let explicit = [("nx", raw.nx), ("ny", raw.ny), ("nz", raw.nz)];
        let any_count = explicit.iter().any(|(_, v)| v.is_some());
        match raw.cell_nm {
            Some(_) if any_count => {
                Err(self.invalid("grid", "give either cell_nm or all of nx, ny, nz, not both"))
            }
            None if raw.z_cell_nm.is_some() => Err(self.invalid(
                "grid.z_cell_nm",
                "goes with cell_nm; with explicit counts set nz instead",
            )),
            None if !any_count => {
                Err(self.invalid("grid", "give either cell_nm or all of nx, ny, nz"))
            }
            Some(cell) => {
                let cell = self.range(
                    "grid.cell_nm",
                    cell,
                    cell > 0.0 && cell <= MAX_CELL_NM,
                    &format!("(0, {MAX_CELL_NM}] nm"),
                )?;
                let count = |axis: &str, len: f64, min: usize| {
                    let q = len / cell;
                    if q > MAX_GRID_DIM as f64 {
                        return Err(self.invalid(
                            "grid.cell_nm",
                            format!(
                                "cell {cell} nm needs {} cells along {axis}, more than \
                                 {MAX_GRID_DIM}; use a larger cell",
                                q.ceil()
                            ),
                        ));
                    }
                    Ok(((q * (1.0 - REL_EPS)).ceil() as usize).max(min))
                };
                let nx = next_fft_size(count("x", layer.fragment_x_nm, 1)?);
                let ny = next_fft_size(count("y", layer.fragment_y_nm, 1)?);
                let z_cell = match raw.z_cell_nm {
                    Some(z) => self.range(
                        "grid.z_cell_nm",
                        z,
                        z > 0.0 && z <= MAX_CELL_NM,
                        &format!("(0, {MAX_CELL_NM}] nm"),
                    )?,
                    None => cell.min(DEFAULT_Z_CELL_NM),
                };
                let nz = ((layer.thickness_nm / z_cell * (1.0 - REL_EPS)).ceil() as usize).max(2);
                if nz > MAX_GRID_DIM {
                    return Err(self.invalid(
                        "grid.z_cell_nm",
                        format!("needs {nz} cells along z, more than {MAX_GRID_DIM}"),
                    ));
                }
                Ok(GridSpec {
                    nx,
                    ny,
                    nz,
                    voxel_permittivity: voxel(raw),
                })
            }
            None => {
                let mut n = [0usize; 3];
                for (i, (axis, v)) in explicit.iter().enumerate() {
                    let key = format!("grid.{axis}");
                    let min = if i == 2 { 2 } else { 1 };
                    let v = v.ok_or_else(|| {
                        self.invalid(
                            key.as_str(),
                            "missing; give all of nx, ny, nz (or cell_nm alone)",
                        )
                    })?;
                    if v < min || v > MAX_GRID_DIM as i64 {
                        return Err(self
                            .invalid(key, format!("must be in [{min}, {MAX_GRID_DIM}], got {v}")));
                    }
                    let v = v as usize;
                    if i < 2 && !is_fft_size(v) {
                        return Err(self.invalid(
                            key,
                            format!(
                                "must be of the form 2^a 3^b 5^c (FFT-friendly), got {v}; \
                                 nearest larger is {}",
                                next_fft_size(v)
                            ),
                        ));
                    }
                    n[i] = v;
                }
                Ok(GridSpec {
                    nx: n[0],
                    ny: n[1],
                    nz: n[2],
                    voxel_permittivity: voxel(raw),
                })
            }
        }
    }
}

/// The checked `grid.voxel_permittivity` (its pairing with the equation is
/// checked with the solver).
fn voxel(raw: &RawGrid) -> VoxelPermittivity {
    match raw.voxel_permittivity {
        None | Some(RawVoxelPermittivity::Auto) => VoxelPermittivity::Auto,
        Some(RawVoxelPermittivity::Average) => VoxelPermittivity::Average,
        Some(RawVoxelPermittivity::Anisotropic) => VoxelPermittivity::Anisotropic,
    }
}

/// Whether `n ≥ 1` has no prime factor other than 2, 3, 5.
fn is_fft_size(mut n: usize) -> bool {
    if n == 0 {
        return false;
    }
    for p in [2, 3, 5] {
        while n.is_multiple_of(p) {
            n /= p;
        }
    }
    n == 1
}

/// Smallest 2^a·3^b·5^c ≥ `n` (`n ≥ 1`).
fn next_fft_size(n: usize) -> usize {
    let mut m = n.max(1);
    while !is_fft_size(m) {
        m += 1;
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fft_sizes() {
        let smooth: Vec<usize> = (1..=30).filter(|&n| is_fft_size(n)).collect();
        assert_eq!(
            smooth,
            [1, 2, 3, 4, 5, 6, 8, 9, 10, 12, 15, 16, 18, 20, 24, 25, 27, 30]
        );
        assert!(!is_fft_size(0));
        assert_eq!(next_fft_size(7), 8);
        assert_eq!(next_fft_size(81), 81);
        assert_eq!(next_fft_size(97), 100);
        assert_eq!(next_fft_size(4096), 4096);
        assert_eq!(next_fft_size(4001), 4050);
    }
}
