//! The effects table of a study: for every axis and every step `a → b` it
//! compares (the axis's `compare` pairs in the sweep file, else each label
//! to the next), the change of the measured colour between variants that
//! differ in that axis only.
//!
//! A step's pairs are the variants labelled `a` and `b` on the axis whose
//! labels on every other axis agree. Over its `n` pairs the table gives the
//! mean change of L*, C*ab and h° (hue differences taken in (−180°, 180°])
//! and the mean CIEDE2000 difference, each with the standard error of that
//! mean from the variants' own standard errors (independent variants:
//! `√Σ(σ_a² + σ_b²) / n`; ΔE00's by linear propagation, see
//! [`delta_e2000_se`]), present only when every variant has one; and the
//! smallest and largest ΔE00 of a pair, which show how much the step's
//! effect depends on the other axes.
//!
//! Over a hiding chart a step also has a **relative tinting strength**
//! (DIN 55986's colorimetric form of ISO 787-16's comparison of tints):
//! `100 % × (K/S)_b(λ*) / (K/S)_a(λ*)`, Kubelka's K/S of the `b` variant
//! over that of the `a` variant at `λ*`, the wavelength where `a`'s K/S is
//! largest (its colour pigment's absorption maximum as solved), in the
//! geometry of the tables (d/8 SCI). Between a pigment and a reference
//! pigment in the same white at the same ratio it is the pigment's tinting
//! strength against the reference; along a let-down ratio it shows how the
//! absorption dilutes. Its standard error propagates the two K/S's
//! relative errors (independent variants), and the step's value is the
//! mean over its pairs like the colour changes.

use super::Row;
use crate::optics::colour::{delta_e2000, delta_e2000_se, lab_to_lch, lch_se};
use crate::output::h5::HidingRecord;
use crate::study::sweep::Study;

/// A mean over pairs and its standard error (None without every s.e.).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeanSe {
    pub mean: f64,
    pub se: Option<f64>,
}

/// One step along one axis.
#[derive(Debug, Clone, PartialEq)]
pub struct Effect {
    pub axis: String,
    pub from: String,
    pub to: String,
    pub pairs: usize,
    /// Mean change of L*, C*ab and h° (degrees), `to` minus `from`.
    pub delta_lch: [MeanSe; 3],
    pub delta_e00: MeanSe,
    /// Smallest and largest ΔE00 of a pair.
    pub delta_e00_range: (f64, f64),
    /// Relative tinting strength, per cent (module docs), where every pair
    /// has both variants over a hiding chart.
    pub tinting_strength: Option<MeanSe>,
}

impl Effect {
    /// Words for the direction of the change of L* and C*ab, where it is
    /// larger than twice its standard error (or, without one, than 0.5).
    pub fn direction(&self) -> String {
        let clear = |m: &MeanSe| m.mean.abs() > m.se.map_or(0.5, |s| 2.0 * s);
        let mut words = vec![];
        let [l, c, _] = &self.delta_lch;
        if clear(l) {
            words.push(if l.mean > 0.0 { "lighter" } else { "darker" });
        }
        if clear(c) {
            words.push(if c.mean > 0.0 {
                "more chromatic"
            } else {
                "less chromatic"
            });
        }
        if words.is_empty() {
            "no clear change of L* or C*ab".into()
        } else {
            words.join(", ")
        }
    }
}

/// Hue difference `b − a` in (−180°, 180°].
pub fn hue_difference(a: f64, b: f64) -> f64 {
    let d = (b - a).rem_euclid(360.0);
    if d > 180.0 {
        d - 360.0
    } else {
        d
    }
}

/// Mean and standard error of the mean of per-pair `(value, se)`.
fn mean_se(values: &[(f64, Option<f64>)]) -> MeanSe {
    let n = values.len() as f64;
    let mean = values.iter().map(|v| v.0).sum::<f64>() / n;
    let se = values
        .iter()
        .map(|v| v.1.map(|s| s * s))
        .sum::<Option<f64>>()
        .map(|var| var.sqrt() / n);
    MeanSe { mean, se }
}

/// The relative tinting strength of `b` against `a`, per cent, with its
/// standard error (module docs); None where `a`'s K/S is not a positive
/// finite number at its maximum or `b` lacks that wavelength.
pub fn tinting_strength(a: &HidingRecord, b: &HidingRecord) -> Option<(f64, Option<f64>)> {
    let at = |h: &HidingRecord| {
        let i = h
            .wavelengths_nm
            .iter()
            .position(|&l| (l - a.k_over_s_max_wavelength_nm).abs() < 1e-6)?;
        let (ks, se) = &h.spectral[3];
        Some((*ks.get(i)?, se.as_ref().and_then(|s| s.get(i).copied())))
    };
    let (ka, sa) = at(a)?;
    let (kb, sb) = at(b)?;
    if !(ka > 0.0 && ka.is_finite() && kb.is_finite()) {
        return None;
    }
    let ratio = 100.0 * kb / ka;
    // Linear propagation of b/a: σ² = (σ_b/a)² + (b σ_a/a²)².
    let se = sa
        .zip(sb)
        .map(|(sa, sb)| 100.0 / ka * sb.hypot(kb * sa / ka));
    Some((ratio, se))
}

/// The effects of every step of every axis that has pairs (module docs).
pub(super) fn effects(study: &Study, rows: &[Row]) -> Vec<Effect> {
    let mut out = vec![];
    for axis in &study.axes {
        let others = |r: &Row| -> Vec<Option<String>> {
            study
                .axes
                .iter()
                .filter(|a| a.name != axis.name)
                .map(|a| r.v.label(&a.name).map(str::to_string))
                .collect()
        };
        for (from, to) in &axis.compare {
            let mut d: [Vec<(f64, Option<f64>)>; 4] = Default::default();
            let mut ts: Vec<Option<(f64, Option<f64>)>> = vec![];
            let mut range = (f64::INFINITY, f64::NEG_INFINITY);
            for r1 in rows.iter().filter(|r| r.v.label(&axis.name) == Some(from)) {
                let Some(r2) = rows
                    .iter()
                    .find(|r| r.v.label(&axis.name) == Some(to) && others(r) == others(r1))
                else {
                    continue;
                };
                let (Some(m1), Some(m2)) = (&r1.measured, &r2.measured) else {
                    continue;
                };
                let (a, b) = (m1.record.lab, m2.record.lab);
                let (la, lb) = (lab_to_lch(a), lab_to_lch(b));
                let ses = m1.record.lab_se.zip(m2.record.lab_se);
                let se_ab = ses.map(|(sa, sb)| (lch_se(a, sa), lch_se(b, sb)));
                for k in 0..3 {
                    let delta = if k == 2 {
                        hue_difference(la[2], lb[2])
                    } else {
                        lb[k] - la[k]
                    };
                    let se = se_ab.map(|(sa, sb)| sa[k].hypot(sb[k]));
                    d[k].push((delta, se));
                }
                ts.push(
                    r1.hiding
                        .as_ref()
                        .zip(r2.hiding.as_ref())
                        .and_then(|(h1, h2)| tinting_strength(h1, h2)),
                );
                let e = delta_e2000(a, b);
                range = (range.0.min(e), range.1.max(e));
                d[3].push((e, ses.map(|(sa, sb)| delta_e2000_se(a, sa, b, sb))));
            }
            if d[3].is_empty() {
                continue;
            }
            out.push(Effect {
                axis: axis.name.clone(),
                from: from.clone(),
                to: to.clone(),
                pairs: d[3].len(),
                delta_lch: [mean_se(&d[0]), mean_se(&d[1]), mean_se(&d[2])],
                delta_e00: mean_se(&d[3]),
                delta_e00_range: range,
                tinting_strength: ts
                    .into_iter()
                    .collect::<Option<Vec<_>>>()
                    .map(|v| mean_se(&v)),
            });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hue_differences_take_the_short_way_round() {
        assert_eq!(hue_difference(350.0, 10.0), 20.0);
        assert_eq!(hue_difference(10.0, 350.0), -20.0);
        assert_eq!(hue_difference(0.0, 180.0), 180.0);
    }

    #[test]
    fn mean_and_its_standard_error() {
        let m = mean_se(&[(1.0, Some(0.3)), (3.0, Some(0.4))]);
        assert_eq!(m.mean, 2.0);
        assert!((m.se.unwrap() - 0.25).abs() < 1e-15);
        assert_eq!(mean_se(&[(1.0, Some(0.3)), (3.0, None)]).se, None);
    }

    #[test]
    fn direction_needs_twice_the_standard_error() {
        let e = |l: f64, c: f64, se: Option<f64>| Effect {
            axis: "a".into(),
            from: "x".into(),
            to: "y".into(),
            pairs: 1,
            delta_lch: [
                MeanSe { mean: l, se },
                MeanSe { mean: c, se },
                MeanSe { mean: 0.0, se },
            ],
            delta_e00: MeanSe { mean: 1.0, se },
            delta_e00_range: (1.0, 1.0),
            tinting_strength: None,
        };
        assert_eq!(
            e(3.0, -3.0, Some(1.0)).direction(),
            "lighter, less chromatic"
        );
        assert_eq!(
            e(1.5, 0.2, Some(1.0)).direction(),
            "no clear change of L* or C*ab"
        );
        assert_eq!(e(-0.6, 0.0, None).direction(), "darker");
    }

    fn record(wavelengths: &[f64], ks: &[f64], se: &[f64]) -> HidingRecord {
        let imax = (0..ks.len())
            .max_by(|&p, &q| ks[p].total_cmp(&ks[q]))
            .unwrap();
        HidingRecord {
            geometry: "d/8 SCI".into(),
            contrast_ratio: 0.9,
            contrast_ratio_se: None,
            y_black: 50.0,
            y_white: 55.0,
            y_ground: 80.0,
            at_y: [(0.0, None); 4],
            k_over_s_max: ks[imax],
            k_over_s_max_se: Some(se[imax]),
            k_over_s_max_wavelength_nm: wavelengths[imax],
            wavelengths_nm: wavelengths.to_vec(),
            spectral: [
                (vec![], None),
                (vec![], None),
                (vec![], None),
                (ks.to_vec(), Some(se.to_vec())),
            ],
        }
    }

    #[test]
    fn tinting_strength_is_the_ratio_at_the_reference_maximum() {
        let wl = [450.0, 550.0, 650.0];
        let a = record(&wl, &[0.2, 1.0, 0.1], &[0.01, 0.05, 0.01]);
        // b peaks elsewhere: its value at a's maximum (550 nm) counts.
        let b = record(&wl, &[3.0, 0.8, 0.1], &[0.1, 0.04, 0.01]);
        let (t, se) = tinting_strength(&a, &b).unwrap();
        assert!((t - 80.0).abs() < 1e-12, "{t}");
        let want = 80.0 * (0.05f64.hypot(0.05));
        assert!((se.unwrap() - want).abs() < 1e-12, "{se:?} {want}");
        // Against itself: 100 %.
        assert!((tinting_strength(&a, &a).unwrap().0 - 100.0).abs() < 1e-12);
        // Without a's wavelength, or with no absorption, there is none.
        let c = record(&[440.0, 520.0], &[1.0, 1.0], &[0.0, 0.0]);
        assert!(tinting_strength(&a, &c).is_none());
        let white = record(&wl, &[0.0, 0.0, 0.0], &[0.0, 0.0, 0.0]);
        assert!(tinting_strength(&white, &a).is_none());
    }
}
