//! Expected error of a scene's fidelity settings.
//!
//! Three kinds of term, summed:
//! - **Discretisation** (cells, spectral step, tolerance, quadrature): each
//!   knob's ΔE00 (max over the tile) against its converged value, measured
//!   on the weak layer of docs/ACCURACY.md (examples/accuracy.rs: red, 15 %
//!   PVC, 100 nm spheres, 1 µm), interpolated log–log between measured
//!   points and held beyond them; knobs finer than their reference cost
//!   nothing. Measurements on one layer, not bounds.
//! - **Statistics of the fragment** ([`statistical_de00`]): the standard
//!   error of the 45°/0° colour's mean over the realisations. A fragment
//!   holds a finite number of grains, so its colour scatters about the
//!   ensemble's; the scatter falls as 1/√(grains × realisations) (the
//!   quick study's 300 granular variants give a slope of 0.51 in log–log).
//!   Per variant: s.e. ≈ C √(Σ_s 1/N_s / R), N_s the independent grains
//!   (clusters, when agglomerated) of species s in one fragment, R the
//!   realisations. C depends on the spectral step ([`fragment_c`]): a
//!   fragment's scatter changes from one wavelength to the next, so the
//!   finer the step the more of it the colour averages away. Calibrated on
//!   the quick study at 100 nm and measured at 20 nm (docs/ACCURACY.md,
//!   "Statistics of the fragment").
//! - **The scalar approximation** ([`super::model_error`]): a Helmholtz
//!   scene's distance to Maxwell's equations, measured on the stand-ins.

use crate::config::{GrainShape, Scene};

/// Measured (knob value, ΔE00 max) pairs, coarse to fine; the last is the
/// reference (ΔE = 0).
const CELL_NM: [(f64, f64); 5] = [
    (50.0, 0.25),
    (33.4, 0.11),
    (25.0, 0.05),
    (20.0, 0.01),
    (16.7, 0.0),
];
const Z_CELL_NM: [(f64, f64); 4] = [(25.0, 0.19), (20.0, 0.11), (10.0, 0.02), (5.0, 0.0)];
const STEP_NM: [(f64, f64); 6] = [
    (100.0, 1.34),
    (50.0, 0.90),
    (30.0, 0.48),
    (20.0, 0.11),
    (15.0, 0.16),
    (10.0, 0.0),
];
const TOLERANCE: [(f64, f64); 5] = [
    (1e-2, 0.04),
    (1e-3, 0.005),
    (1e-4, 0.0),
    (1e-6, 0.0),
    (1e-9, 0.0),
];
/// The fragment's statistical constant C at a 100 nm spectral step for
/// one pigment and for a mixture (at that step a mixture's hue also follows
/// the fragment's composition): the median over the quick study's granular
/// variants of s.e. / √(Σ 1/N_s / R) with R = 2, divided by 0.674 (the
/// median of a two-sample estimate's |z|) — docs/ACCURACY.md.
pub const FRAGMENT_C_SINGLE: f64 = 7.0;
pub const FRAGMENT_C_MIXTURE: f64 = 35.0;
/// The same at a 20 nm step, for one pigment and mixtures alike: the
/// largest measured there (red at the standard profile, 4.7; a yellow
/// and two yellow+blue variants with 8–12 realisations each, 2.6–3.1;
/// docs/ACCURACY.md).
pub const FRAGMENT_C_FINE: f64 = 4.7;
/// The spectral steps the constants were measured at, nm.
const COARSE_STEP_NM: f64 = 100.0;
const FINE_STEP_NM: f64 = 20.0;

/// The fragment's constant C for a `mixture` (or one pigment) at spectral
/// step `step_nm`: the measured constants at 100 and 20 nm, interpolated
/// log–log between them and held beyond them (a finer step is not counted
/// as better than 20 nm, nor one wavelength as worse than 100 nm).
pub fn fragment_c(mixture: bool, step_nm: f64) -> f64 {
    let coarse = if mixture {
        FRAGMENT_C_MIXTURE
    } else {
        FRAGMENT_C_SINGLE
    };
    let fine = FRAGMENT_C_FINE.min(coarse);
    if step_nm.is_nan() || step_nm >= COARSE_STEP_NM {
        return coarse;
    }
    if step_nm <= FINE_STEP_NM {
        return fine;
    }
    let t = (step_nm / FINE_STEP_NM).ln() / (COARSE_STEP_NM / FINE_STEP_NM).ln();
    fine * (coarse / fine).powf(t)
}

/// The spectral step of `scene`, nm (infinite for one wavelength).
fn spectral_step(scene: &Scene) -> f64 {
    let wl = &scene.wavelengths_nm;
    if wl.len() > 1 {
        (wl[wl.len() - 1] - wl[0]) / (wl.len() - 1) as f64
    } else {
        f64::INFINITY
    }
}
const QUADRATURE: [(f64, f64); 4] = [(2.0, 1.81), (4.0, 0.84), (6.0, 0.04), (12.0, 0.0)];

/// Interpolate ΔE at `x` in a table ordered coarse → fine (`decreasing`:
/// coarse = larger value).
fn lookup(table: &[(f64, f64)], x: f64, decreasing: bool) -> f64 {
    let coarse = table[0];
    let fine = table[table.len() - 1];
    let beyond_coarse = if decreasing {
        x >= coarse.0
    } else {
        x <= coarse.0
    };
    let beyond_fine = if decreasing { x <= fine.0 } else { x >= fine.0 };
    if beyond_coarse {
        return coarse.1;
    }
    if beyond_fine {
        return 0.0;
    }
    for w in table.windows(2) {
        let (a, b) = (w[0], w[1]);
        let inside = if decreasing {
            x <= a.0 && x >= b.0
        } else {
            x >= a.0 && x <= b.0
        };
        if inside {
            let t = (x.ln() - a.0.ln()) / (b.0.ln() - a.0.ln());
            return a.1 + t * (b.1 - a.1);
        }
    }
    0.0
}

/// Independent grains of each granular species in one fragment: the
/// species' volume over one grain's (the equal-volume sphere of
/// `diameter_nm`), over the cluster size when agglomerated.
pub fn grains_per_fragment(scene: &Scene) -> Vec<f64> {
    let l = &scene.layer;
    let volume = l.fragment_x_nm * l.fragment_y_nm * l.thickness_nm;
    scene
        .species
        .iter()
        .filter(|s| s.shape != GrainShape::Molecular && s.diameter_nm > 0.0)
        .map(|s| {
            let grain = std::f64::consts::PI / 6.0 * s.diameter_nm.powi(3);
            s.volume_fraction * volume / grain / s.cluster_size.max(1) as f64
        })
        .collect()
}

/// The expected standard error of the 45°/0° colour's ΔE00 with
/// `realisations` fragments (0 without grains: a homogeneous or explicit
/// layer is the same in every realisation).
pub fn statistical_de00(scene: &Scene, realisations: usize) -> f64 {
    let n = grains_per_fragment(scene);
    if n.is_empty() || scene.structure.is_some() {
        return 0.0;
    }
    let c = fragment_c(n.len() > 1, spectral_step(scene));
    let inv: f64 = n.iter().map(|n| 1.0 / n.max(1e-9)).sum();
    c * (inv / realisations.max(1) as f64).sqrt()
}

/// Realisations needed for the statistical term to reach `de00`.
pub fn realisations_for(scene: &Scene, de00: f64) -> usize {
    let one = statistical_de00(scene, 1);
    if one <= de00 {
        1
    } else {
        (one / de00).powi(2).ceil() as usize
    }
}

/// Realisations a run is expected to make: the count, or with a target
/// the fewest that reach it by [`statistical_de00`], within the target's
/// minimum and the scene's maximum.
pub fn expected_realisations(scene: &Scene) -> usize {
    match scene.realisation_target {
        Some(t) => realisations_for(scene, t.de00).clamp(t.min, scene.realisations.max(t.min)),
        None => scene.realisations,
    }
}

/// The expected ΔE00 of a scene: the sum of [`expected_rows`].
pub fn expected_de00(scene: &Scene) -> f64 {
    expected_rows(scene).iter().map(|r| r.1).sum()
}

/// One line per knob: the setting and its measured ΔE00, then the sum.
pub fn expected_error(scene: &Scene) -> Vec<String> {
    if scene.structure.is_some() {
        return vec![
            "not estimated for an explicit structure: the error tables (docs/ACCURACY.md) are \
             measured on grain layers; halve the cells and the spectral step once to see what \
             they cost for this one"
                .to_string(),
        ];
    }
    let rows = expected_rows(scene);
    let total: f64 = rows.iter().map(|r| r.1).sum();
    let mut out: Vec<String> = rows
        .iter()
        .map(|(k, v)| format!("{k}: ΔE00 ≈ {v:.2}"))
        .collect();
    out.push(format!(
        "expected ΔE00 ≈ {total:.2} (sum of the terms; discretisation measured on a weak \
         layer, statistics measured at 100 and 20 nm steps, the scalar approximation on the \
         stand-in pigments — docs/ACCURACY.md)"
    ));
    out
}

/// The terms of the expected error: (what, ΔE00).
pub fn expected_rows(scene: &Scene) -> Vec<(String, f64)> {
    let l = &scene.layer;
    let cell = (l.fragment_x_nm / scene.grid.nx as f64).max(l.fragment_y_nm / scene.grid.ny as f64);
    let zc = l.thickness_nm / scene.grid.nz as f64;
    let step = spectral_step(scene);
    let mut rows: Vec<(String, f64)> = Vec::new();
    if !scene.is_molecular() {
        rows.push((
            format!("lateral cell {cell:.1} nm"),
            lookup(&CELL_NM, cell, true),
        ));
        rows.push((format!("z cell {zc:.1} nm"), lookup(&Z_CELL_NM, zc, true)));
        let grains = grains_per_fragment(scene);
        if !grains.is_empty() && scene.structure.is_none() {
            let fewest = grains.iter().cloned().fold(f64::INFINITY, f64::min);
            let what = format!(
                "fragment {:.0} × {:.0} nm ({} grains{}), ",
                l.fragment_x_nm,
                l.fragment_y_nm,
                format_count(fewest),
                if grains.len() > 1 {
                    " of the rarest pigment"
                } else {
                    ""
                }
            );
            match scene.realisation_target {
                // Realisations are added until the colour's ΔE00 standard
                // error is at most the target (or the most allowed are run).
                Some(t) => {
                    let r = expected_realisations(scene);
                    rows.push((
                        format!(
                            "{what}realisations {}–{} to an s.e. of {}: about {r} expected",
                            t.min, scene.realisations, t.de00
                        ),
                        statistical_de00(scene, r),
                    ))
                }
                None => rows.push((
                    format!(
                        "{what}{} realisation(s): s.e. of the colour",
                        scene.realisations
                    ),
                    statistical_de00(scene, scene.realisations),
                )),
            }
        }
        rows.push((
            format!("tolerance {:.0e}", scene.solver.tolerance),
            lookup(&TOLERANCE, scene.solver.tolerance, true),
        ));
    }
    rows.push((
        if step.is_finite() {
            format!("spectral step {step:.0} nm")
        } else {
            "one wavelength".to_string()
        },
        if step.is_finite() {
            lookup(&STEP_NM, step, true)
        } else {
            STEP_NM[0].1
        },
    ));
    rows.push((
        format!("quadrature nodes {}", scene.appearance.quadrature_points),
        lookup(
            &QUADRATURE,
            scene.appearance.quadrature_points as f64,
            false,
        ),
    ));
    if let Some(m) = super::model_error::scalar_de00(scene) {
        use super::model_error::{grain_ratio, GRAIN_RATIO_LIMIT};
        let label = match grain_ratio(scene) {
            Some(g) if g.ratio.ln().abs() > GRAIN_RATIO_LIMIT.ln() => format!(
                "scalar approximation, not bounded for this layer: one {} grain scatters {:.1}× \
                 (transport) in the Helmholtz equation what it scatters in Maxwell's at {} nm, \
                 beyond the stand-ins' ≤ {GRAIN_RATIO_LIMIT}× where this term was measured; \
                 the value is theirs, a lower bound here (solver.equation = \"maxwell\" \
                 removes it)",
                g.species, g.ratio, g.wavelength_nm
            ),
            _ => "scalar approximation (the Helmholtz equation against Maxwell's; \
                  solver.equation = \"maxwell\" removes it)"
                .to_string(),
        };
        rows.push((label, m));
    }
    rows
}

/// `140`, `12.3`, `1.3`.
fn format_count(n: f64) -> String {
    if n >= 100.0 {
        format!("{n:.0}")
    } else {
        format!("{n:.1}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lookup_interpolates_and_holds() {
        assert_eq!(lookup(&CELL_NM, 60.0, true), 0.25);
        assert!((lookup(&CELL_NM, 25.0, true) - 0.05).abs() < 1e-12);
        assert_eq!(lookup(&CELL_NM, 10.0, true), 0.0);
        let mid = lookup(&CELL_NM, 30.0, true);
        assert!(mid > 0.05 && mid < 0.11);
        assert!((lookup(&QUADRATURE, 6.0, false) - 0.04).abs() < 1e-12);
        assert_eq!(lookup(&QUADRATURE, 1.0, false), 1.81);
        assert_eq!(lookup(&QUADRATURE, 32.0, false), 0.0);
    }
}
