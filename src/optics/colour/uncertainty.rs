//! Standard errors of derived colour quantities by first-order (linear)
//! propagation from the standard errors of L*, a*, b*, taken as independent:
//! chroma and hue angle in closed form, CIEDE2000 differences between two
//! independently estimated colours by central differences. Linear
//! propagation is meaningful while a quantity is large against its own
//! standard error (a hue at chroma near zero, or a ΔE00 near zero, is not).

use super::{delta_e2000, lab_to_lch};

/// Standard errors of L*, C*ab and h_ab (degrees) for CIELAB `lab` with
/// standard errors `se` of L*, a*, b*:
/// `σ_C = √((a σ_a)² + (b σ_b)²) / C`, `σ_h = √((b σ_a)² + (a σ_b)²) / C²`
/// (radians, returned in degrees). Chroma 0 gives infinite C and h errors
/// unless a* and b* are exact.
pub fn lch_se(lab: [f64; 3], se: [f64; 3]) -> [f64; 3] {
    let [_, a, b] = lab;
    let c = lab_to_lch(lab)[1];
    let c_se = ((a * se[1]).powi(2) + (b * se[2]).powi(2)).sqrt() / c;
    let h_se = ((b * se[1]).powi(2) + (a * se[2]).powi(2)).sqrt() / (c * c);
    let exact = se[1] == 0.0 && se[2] == 0.0;
    [
        se[0],
        if exact { 0.0 } else { c_se },
        if exact { 0.0 } else { h_se.to_degrees() },
    ]
}

/// Standard error of `ΔE00(lab1, lab2)` for independent colours with
/// standard errors `se1`, `se2` of L*, a*, b*: `√Σ (∂ΔE00/∂xₖ σₖ)²` over
/// the six coordinates, the derivatives by central differences.
pub fn delta_e2000_se(lab1: [f64; 3], se1: [f64; 3], lab2: [f64; 3], se2: [f64; 3]) -> f64 {
    const STEP: f64 = 1e-4;
    let mut var = 0.0;
    for (which, se) in [(0, se1), (1, se2)] {
        for k in 0..3 {
            if se[k] == 0.0 {
                continue;
            }
            let shifted = |d: f64| {
                let (mut p, mut q) = (lab1, lab2);
                if which == 0 {
                    p[k] += d;
                } else {
                    q[k] += d;
                }
                delta_e2000(p, q)
            };
            let g = (shifted(STEP) - shifted(-STEP)) / (2.0 * STEP);
            var += (g * se[k]).powi(2);
        }
    }
    var.sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chroma_and_hue_errors_follow_the_closed_form() {
        let [l, c, h] = lch_se([50.0, 3.0, 4.0], [1.0, 0.1, 0.2]);
        assert_eq!(l, 1.0);
        assert!((c - (0.09f64 + 0.64).sqrt() / 5.0).abs() < 1e-12);
        assert!((h - ((0.16f64 + 0.36).sqrt() / 25.0).to_degrees()).abs() < 1e-12);
        // Along a* only: σ_C = σ_a, σ_h = σ_b / C.
        let [_, c, h] = lch_se([50.0, 10.0, 0.0], [0.0, 0.3, 0.5]);
        assert!((c - 0.3).abs() < 1e-12 && (h - 0.05f64.to_degrees()).abs() < 1e-12);
        assert_eq!(lch_se([50.0, 0.0, 0.0], [1.0, 0.0, 0.0]), [1.0, 0.0, 0.0]);
    }

    #[test]
    fn lightness_difference_error_is_exact_for_neutral_colours() {
        // Neutral colours with mean L* 50: ΔE00 = |ΔL*| (S_L = 1 and its
        // derivative vanishes there), so σ = √(σ₁² + σ₂²).
        let se = delta_e2000_se(
            [45.0, 0.0, 0.0],
            [0.3, 0.0, 0.0],
            [55.0, 0.0, 0.0],
            [0.4, 0.0, 0.0],
        );
        assert!((se - 0.5).abs() < 1e-6, "{se}");
        assert_eq!(
            delta_e2000_se([45.0, 1.0, 2.0], [0.0; 3], [55.0, 3.0, 1.0], [0.0; 3]),
            0.0
        );
    }
}
