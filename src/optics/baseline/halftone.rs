//! Halftones: layers printed on part of the area, in dots far wider than
//! the light's lateral spread inside the ink (tens of µm against a few),
//! so that each point of the print is one of the Neugebauer primaries (a
//! stack of the layers printed there, or the bare substrate) and the print
//! mixes them by area.
//!
//! - **Demichel**: dots of independent screens overlap at random, so the
//!   primary with the layers `S` covers `Π_{i∈S} aᵢ Π_{i∉S} (1 − aᵢ)` of
//!   the area, `aᵢ` layer `i`'s coverage ([`primaries`]).
//! - **Yule–Nielsen**: light entering the paper in one primary leaves it in
//!   another (the optical dot gain); the classical correction mixes the
//!   primaries' reflectance factors as `R = (Σ w_k R_k^{1/n})^n`, `n = 1`
//!   being Murray–Davies' plain area mixture ([`yule_nielsen`]). `n` is a
//!   property of the paper and the screen, fitted in practice (1.5–2 for
//!   coated papers); inksim takes it as given.

/// One Neugebauer primary: the layers printed there (indices, top first;
/// empty: the bare substrate) and its share of the area.
#[derive(Debug, Clone, PartialEq)]
pub struct Primary {
    pub layers: Vec<usize>,
    pub area: f64,
}

/// The primaries of layers printed at `coverage` (each in (0, 1]), with
/// Demichel's areas; those of zero area left out. Layers at full coverage
/// are in every primary, so a stack without halftones is one primary of
/// area 1.
pub fn primaries(coverage: &[f64]) -> Vec<Primary> {
    let n = coverage.len();
    let mut out = Vec::new();
    for mask in 0..(1usize << n) {
        let mut area = 1.0;
        let mut layers = Vec::new();
        for (i, &a) in coverage.iter().enumerate() {
            if mask & (1 << i) != 0 {
                area *= a;
                layers.push(i);
            } else {
                area *= 1.0 - a;
            }
        }
        if area > 0.0 {
            out.push(Primary { layers, area });
        }
    }
    out
}

/// The Yule–Nielsen mixture `(Σ w R^{1/n})^n` of `(area, value)` pairs;
/// exactly `Σ w R` for `n = 1`. A value below zero (a BRDF read from a
/// truncated Fourier series can dip a little below it) keeps its sign
/// through the power rather than giving NaN.
pub fn yule_nielsen(n: f64, parts: &[(f64, f64)]) -> f64 {
    if n == 1.0 {
        return parts.iter().map(|(w, v)| w * v).sum();
    }
    let root = |v: f64| v.signum() * v.abs().powf(1.0 / n);
    let s: f64 = parts.iter().map(|&(w, v)| w * root(v)).sum();
    s.signum() * s.abs().powf(n)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn demichel_areas_cover_the_print_once() {
        let p = primaries(&[0.3, 0.6]);
        assert_eq!(p.len(), 4);
        let area = |layers: &[usize]| p.iter().find(|x| x.layers == layers).unwrap().area;
        assert!((area(&[]) - 0.7 * 0.4).abs() < 1e-15);
        assert!((area(&[0]) - 0.3 * 0.4).abs() < 1e-15);
        assert!((area(&[1]) - 0.7 * 0.6).abs() < 1e-15);
        assert!((area(&[0, 1]) - 0.3 * 0.6).abs() < 1e-15);
        let total: f64 = p.iter().map(|x| x.area).sum();
        assert!((total - 1.0).abs() < 1e-15);
        // Full coverage: one primary, everything printed.
        assert_eq!(
            primaries(&[1.0, 1.0]),
            [Primary {
                layers: vec![0, 1],
                area: 1.0
            }]
        );
        assert_eq!(primaries(&[1.0, 0.5]).len(), 2);
    }

    #[test]
    fn yule_nielsen_mixes_roots_and_is_murray_davies_at_one() {
        let parts = [(0.25, 0.8), (0.75, 0.09)];
        assert!((yule_nielsen(1.0, &parts) - (0.2 + 0.0675)).abs() < 1e-15);
        let e = (0.25 * 0.8f64.sqrt() + 0.75 * 0.3).powi(2);
        assert!((yule_nielsen(2.0, &parts) - e).abs() < 1e-15);
        // One primary: itself, for any n.
        assert!((yule_nielsen(1.7, &[(1.0, 0.42)]) - 0.42).abs() < 1e-15);
        assert!(yule_nielsen(2.0, &[(0.5, -1e-4), (0.5, 0.0)]).is_finite());
    }
}
