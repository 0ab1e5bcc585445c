//! Expected error of a scene's fidelity settings, from the measurements of
//! docs/ACCURACY.md (examples/accuracy.rs, weak layer: red, 15 % PVC,
//! 100 nm spheres, 1 µm). Each knob's ΔE00 (max over the tile) against its
//! converged value is interpolated (log–log between measured points, held
//! beyond them); knobs finer than their reference cost nothing. These are
//! measurements on one layer, not bounds: denser or larger-grained layers
//! may differ (the typical and hard cases are not yet measured).

use crate::config::Scene;

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
const STEP_NM: [(f64, f64); 4] = [(100.0, 1.34), (50.0, 0.90), (30.0, 0.48), (10.0, 0.0)];
const TOLERANCE: [(f64, f64); 5] = [
    (1e-2, 0.04),
    (1e-3, 0.005),
    (1e-4, 0.0),
    (1e-6, 0.0),
    (1e-9, 0.0),
];
/// One realisation against eight.
const ONE_REALISATION_DE: f64 = 0.85;
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

/// One line per knob: the setting and its measured ΔE00, then the sum.
pub fn expected_error(scene: &Scene) -> Vec<String> {
    let l = &scene.layer;
    let cell = (l.fragment_x_nm / scene.grid.nx as f64).max(l.fragment_y_nm / scene.grid.ny as f64);
    let zc = l.thickness_nm / scene.grid.nz as f64;
    let wl = &scene.wavelengths_nm;
    let step = if wl.len() > 1 {
        (wl[wl.len() - 1] - wl[0]) / (wl.len() - 1) as f64
    } else {
        f64::INFINITY
    };
    let real = scene.realisations as f64;
    let de_real = if real >= 8.0 {
        0.0
    } else {
        ONE_REALISATION_DE * ((1.0 / real - 1.0 / 8.0) / (1.0 - 1.0 / 8.0)).sqrt()
    };
    let mut rows: Vec<(String, f64)> = Vec::new();
    if !scene.is_molecular() {
        rows.push((
            format!("lateral cell {cell:.1} nm"),
            lookup(&CELL_NM, cell, true),
        ));
        rows.push((format!("z cell {zc:.1} nm"), lookup(&Z_CELL_NM, zc, true)));
        match scene.realisation_target {
            // Realisations are added until the colour's ΔE00 standard error
            // is at most the target (or the most allowed are run).
            Some(t) => rows.push((
                format!("realisations up to {} (target s.e.)", scene.realisations),
                t.de00,
            )),
            None => rows.push((format!("realisations {}", scene.realisations), de_real)),
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
    let total: f64 = rows.iter().map(|r| r.1).sum();
    let mut out: Vec<String> = rows
        .iter()
        .map(|(k, v)| format!("{k}: ΔE00 ≈ {v:.2}"))
        .collect();
    out.push(format!(
        "expected ΔE00 (max over the tile, sum over knobs) ≈ {total:.2} — measured on a weak layer, docs/ACCURACY.md"
    ));
    out
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
