//! What an effect study finds: the change of the flop index and of the
//! colour along each axis between variants that differ on that axis only,
//! and the colour and flop index per label.
//!
//! The fast model is deterministic (no sampling): its figures carry no
//! statistical uncertainty, only numerical error. A change smaller than
//! [`FLOP_FLOOR`] in the flop index or [`DE00_FLOOR`] in ΔE00 is counted
//! as no change.

use super::row::EffectRow;
use crate::optics::colour::delta_e2000;
use crate::study::sweep::Study;

/// A flop-index change below this is numerical noise.
pub const FLOP_FLOOR: f64 = 0.01;
/// A ΔE00 below this is numerical noise.
pub const DE00_FLOOR: f64 = 0.05;
/// The geometry whose colour names a finish's hue: 45° illumination, 15°
/// from the specular (the near-specular "face" colour).
pub const FACE: (f64, f64) = (45.0, 15.0);

/// The colour of `row` in geometry (illumination, aspecular), as L*a*b*
/// and L*C*h.
pub fn colour_at(row: &EffectRow, (ill, asp): (f64, f64)) -> Option<([f64; 3], [f64; 3])> {
    row.rec
        .colours
        .iter()
        .find(|c| c.illumination_deg == ill && c.aspecular_deg == asp)
        .map(|c| (c.lab, c.lch))
}

/// One step along an axis (`from` → `to`) over every pair of variants
/// that differ on that axis only.
#[derive(Debug, Clone)]
pub struct Step {
    pub axis: String,
    pub from: String,
    pub to: String,
    /// Flop index of `to` minus `from`, per pair (where both have one).
    pub flop: Vec<f64>,
    /// ΔE00 at [`FACE`], per pair.
    pub de_face: Vec<f64>,
    /// The largest ΔE00 over the geometries, per pair.
    pub de_max: Vec<f64>,
}

/// The steps of every axis (its `compare` pairs).
pub fn steps(study: &Study, rows: &[EffectRow]) -> Vec<Step> {
    let mut out = vec![];
    for axis in &study.axes {
        let others: Vec<&str> = study
            .axes
            .iter()
            .map(|a| a.name.as_str())
            .filter(|a| *a != axis.name)
            .collect();
        let same_elsewhere =
            |a: &EffectRow, b: &EffectRow| others.iter().all(|o| a.v.label(o) == b.v.label(o));
        for (from, to) in &axis.compare {
            let mut step = Step {
                axis: axis.name.clone(),
                from: from.clone(),
                to: to.clone(),
                flop: vec![],
                de_face: vec![],
                de_max: vec![],
            };
            for a in rows
                .iter()
                .filter(|r| r.v.label(&axis.name) == Some(from.as_str()))
            {
                let Some(b) = rows
                    .iter()
                    .find(|b| b.v.label(&axis.name) == Some(to.as_str()) && same_elsewhere(a, b))
                else {
                    continue;
                };
                if let (Some(fa), Some(fb)) = (a.rec.flop_index, b.rec.flop_index) {
                    step.flop.push(fb - fa);
                }
                if let (Some(ca), Some(cb)) = (colour_at(a, FACE), colour_at(b, FACE)) {
                    step.de_face.push(delta_e2000(ca.0, cb.0));
                }
                let de = a
                    .rec
                    .colours
                    .iter()
                    .zip(&b.rec.colours)
                    .map(|(x, y)| delta_e2000(x.lab, y.lab))
                    .fold(0.0, f64::max);
                step.de_max.push(de);
            }
            if !step.de_max.is_empty() {
                out.push(step);
            }
        }
    }
    out
}

fn mean(xs: &[f64]) -> f64 {
    xs.iter().sum::<f64>() / xs.len().max(1) as f64
}

fn range(xs: &[f64]) -> (f64, f64) {
    xs.iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| {
            (lo.min(x), hi.max(x))
        })
}

impl Step {
    /// The step in words: how the flop index moves and how far the colour.
    pub fn sentence(&self) -> String {
        let n = self.de_max.len();
        let mut s = format!(
            "Along `{}`, {} → {} ({n} pair(s) differing only there): ",
            self.axis, self.from, self.to
        );
        if self.flop.is_empty() {
            s += "no flop index to compare; ";
        } else {
            let up = self.flop.iter().filter(|d| **d > FLOP_FLOOR).count();
            let down = self.flop.iter().filter(|d| **d < -FLOP_FLOOR).count();
            let same = self.flop.len() - up - down;
            let (lo, hi) = range(&self.flop);
            s += &format!(
                "the flop index rises in {up}, falls in {down}, is unchanged (within \
                 {FLOP_FLOOR}) in {same} (mean change {:+.2}, {lo:+.2} to {hi:+.2}); ",
                mean(&self.flop)
            );
        }
        let (_, de_hi) = range(&self.de_max);
        if de_hi < DE00_FLOOR {
            s += &format!("the colour is the same at every geometry (ΔE00 below {DE00_FLOOR}).");
        } else {
            let (lo, hi) = range(&self.de_face);
            s += &format!(
                "ΔE00 at {}as{} is {lo:.1}–{hi:.1} (mean {:.1}), the largest over the \
                 geometries {de_hi:.1}.",
                FACE.0,
                FACE.1,
                mean(&self.de_face)
            );
        }
        s
    }
}

/// The means of the variants with one label of an axis.
#[derive(Debug, Clone)]
pub struct LabelMeans {
    pub axis: String,
    pub label: String,
    pub variants: usize,
    pub flop: Option<f64>,
    /// L*, C*ab and the circular mean of h at [`FACE`].
    pub face_lch: Option<[f64; 3]>,
}

/// Per axis and label, in axis and label order.
pub fn label_means(study: &Study, rows: &[EffectRow]) -> Vec<LabelMeans> {
    let mut out = vec![];
    for axis in &study.axes {
        for value in &axis.values {
            let mine: Vec<&EffectRow> = rows
                .iter()
                .filter(|r| r.v.label(&axis.name) == Some(value.label.as_str()))
                .collect();
            if mine.is_empty() {
                continue;
            }
            let flops: Vec<f64> = mine.iter().filter_map(|r| r.rec.flop_index).collect();
            let lch: Vec<[f64; 3]> = mine
                .iter()
                .filter_map(|r| colour_at(r, FACE))
                .map(|c| c.1)
                .collect();
            let face_lch = (!lch.is_empty()).then(|| {
                let l = mean(&lch.iter().map(|c| c[0]).collect::<Vec<_>>());
                let c = mean(&lch.iter().map(|c| c[1]).collect::<Vec<_>>());
                let (s, co) = lch.iter().fold((0.0, 0.0), |(s, co), x| {
                    let h = x[2].to_radians();
                    (s + x[1] * h.sin(), co + x[1] * h.cos())
                });
                [l, c, s.atan2(co).to_degrees().rem_euclid(360.0)]
            });
            out.push(LabelMeans {
                axis: axis.name.clone(),
                label: value.label.clone(),
                variants: mine.len(),
                flop: (!flops.is_empty()).then(|| mean(&flops)),
                face_lch,
            });
        }
    }
    out
}

/// A colour name for a hue angle and chroma (CIELAB): below C*ab 6 a
/// neutral (silver, grey), else by the hue's sector.
pub fn hue_name(chroma: f64, hue_deg: f64) -> &'static str {
    if chroma < 6.0 {
        return "neutral (silver)";
    }
    match hue_deg.rem_euclid(360.0) {
        h if !(25.0..345.0).contains(&h) => "red",
        h if h < 60.0 => "orange",
        h if h < 105.0 => "yellow (gold)",
        h if h < 170.0 => "green",
        h if h < 225.0 => "cyan",
        h if h < 290.0 => "blue",
        h if h < 310.0 => "violet",
        _ => "magenta (red-violet)",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hues_are_named_by_sector() {
        assert_eq!(hue_name(2.0, 90.0), "neutral (silver)");
        assert_eq!(hue_name(30.0, 10.0), "red");
        assert_eq!(hue_name(30.0, 350.0), "red");
        assert_eq!(hue_name(30.0, 85.0), "yellow (gold)");
        assert_eq!(hue_name(30.0, 140.0), "green");
        assert_eq!(hue_name(30.0, 260.0), "blue");
        assert_eq!(hue_name(30.0, 329.0), "magenta (red-violet)");
    }
}
