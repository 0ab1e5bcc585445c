//! Axis scales of the plots: linear or logarithmic, their ranges chosen to
//! cover the data and end on ticks, and their tick labels.

use super::super::colour_bar::decade_label;

/// Decades a positive data range must span before it is shown on a log scale.
pub const LOG_WHEN_DECADES: f64 = 2.0;

/// A value axis from `lo` to `hi`; on a log scale both are positive.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scale {
    pub lo: f64,
    pub hi: f64,
    pub log: bool,
    /// Tick step of a linear scale (`None`: the 1-2-5 step of its span).
    pub step: Option<f64>,
}

impl Scale {
    /// Linear scale from `lo` to `hi` (`hi > lo`).
    pub fn linear(lo: f64, hi: f64) -> Scale {
        Scale {
            lo,
            hi,
            log: false,
            step: None,
        }
    }

    /// Categories `0 … n − 1`, each centred in its own slot.
    pub fn categories(n: usize) -> Scale {
        Scale::linear(-0.5, n.max(1) as f64 - 0.5)
    }

    /// The scale covering every finite value (with its error bar, if any):
    /// logarithmic when all are positive and they span at least
    /// [`LOG_WHEN_DECADES`] decades (ends at whole decades), else linear
    /// with ends on multiples of its tick step, including 0 when `zero`.
    /// `None` when no value is finite.
    pub fn covering(values: impl IntoIterator<Item = (f64, f64)>, zero: bool) -> Option<Scale> {
        Scale::covering_as(values, zero, true)
    }

    /// [`Scale::covering`], always linear.
    pub fn covering_linear(
        values: impl IntoIterator<Item = (f64, f64)>,
        zero: bool,
    ) -> Option<Scale> {
        Scale::covering_as(values, zero, false)
    }

    fn covering_as(
        values: impl IntoIterator<Item = (f64, f64)>,
        zero: bool,
        may_log: bool,
    ) -> Option<Scale> {
        let (mut lo, mut hi, mut min_pos) = (f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY);
        let mut all_positive = true;
        for (v, e) in values {
            if !v.is_finite() {
                continue;
            }
            let e = if e.is_finite() { e.abs() } else { 0.0 };
            lo = lo.min(v - e);
            hi = hi.max(v + e);
            all_positive &= v > 0.0;
            if v > 0.0 {
                min_pos = min_pos.min((v - e).max(v * 0.5));
            }
        }
        if !(lo.is_finite() && hi.is_finite()) {
            return None;
        }
        if may_log && all_positive && (hi / min_pos).log10() >= LOG_WHEN_DECADES {
            return Some(Scale {
                lo: 10f64.powf(min_pos.log10().floor()),
                hi: 10f64.powf(hi.log10().ceil()),
                log: true,
                step: None,
            });
        }
        if zero {
            lo = lo.min(0.0);
            hi = hi.max(0.0);
        }
        if hi - lo < 1e-12 * hi.abs().max(lo.abs()).max(1e-300) {
            let pad = (hi.abs() * 0.05).max(1e-3);
            lo -= pad;
            hi += pad;
        }
        let step = tick_step(hi - lo);
        Some(Scale {
            step: Some(step),
            ..Scale::linear((lo / step).floor() * step, (hi / step).ceil() * step)
        })
    }

    /// The same linear scale widened by `frac` of its span at both ends,
    /// so markers at the ends are drawn whole (a log scale is unchanged).
    pub fn padded(self, frac: f64) -> Scale {
        if self.log {
            return self;
        }
        let pad = frac * (self.hi - self.lo);
        Scale {
            lo: self.lo - pad,
            hi: self.hi + pad,
            log: false,
            step: Some(self.step.unwrap_or_else(|| tick_step(self.hi - self.lo))),
        }
    }

    /// Position of `v` along the axis, 0 at `lo` and 1 at `hi`; `None` for a
    /// value a log scale cannot show (≤ 0) or that is not finite.
    pub fn t(&self, v: f64) -> Option<f64> {
        if !v.is_finite() {
            return None;
        }
        if self.log {
            (v > 0.0).then(|| (v / self.lo).log10() / (self.hi / self.lo).log10())
        } else {
            Some((v - self.lo) / (self.hi - self.lo))
        }
    }

    /// Tick values and their labels: multiples of a 1-2-5 step (about five
    /// ticks), or whole decades on a log scale (every k-th when many).
    pub fn ticks(&self) -> Vec<(f64, String)> {
        if self.log {
            let (a, b) = (
                self.lo.log10().round() as i64,
                self.hi.log10().round() as i64,
            );
            let every = ((b - a) / 6 + 1).max(1);
            return (a..=b)
                .filter(|d| (d - a) % every == 0)
                .map(|d| (10f64.powi(d as i32), decade_label(d)))
                .collect();
        }
        let step = self.step.unwrap_or_else(|| tick_step(self.hi - self.lo));
        let decimals = (-step.log10().floor()).max(0.0) as usize;
        let first = (self.lo / step - 1e-9).ceil() as i64;
        let last = (self.hi / step + 1e-9).floor() as i64;
        (first..=last)
            .map(|k| {
                let v = k as f64 * step;
                (v, number_label(v, decimals))
            })
            .collect()
    }
}

/// The smallest of 1, 2, 5 × 10ⁿ at least `span / 5`.
pub fn tick_step(span: f64) -> f64 {
    let raw = (span / 5.0).abs().max(1e-300);
    let d = 10f64.powf(raw.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * d)
        .find(|&s| s >= raw * (1.0 - 1e-9))
        .unwrap_or(10.0 * d)
}

/// `v` with `decimals` decimals and a true minus sign; no "−0".
pub fn number_label(v: f64, decimals: usize) -> String {
    let s = format!("{v:.decimals$}");
    if s.trim_start_matches('-')
        .chars()
        .all(|c| c == '0' || c == '.')
    {
        return s.trim_start_matches('-').to_string();
    }
    s.replace('-', "−")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_scale_covers_its_data_and_ends_on_ticks() {
        let s = Scale::covering([(0.13, 0.0), (0.47, 0.02)], false).unwrap();
        assert!(!s.log);
        assert!(s.lo <= 0.13 && s.hi >= 0.49, "{s:?}");
        let t = s.ticks();
        assert!((t[0].0 - s.lo).abs() < 1e-12 && (t.last().unwrap().0 - s.hi).abs() < 1e-12);
        assert!((3..=11).contains(&t.len()), "{t:?}");
        // 48 … 141 rounds out to 40 … 160 on a step of 20, which the ticks
        // keep (the span alone would ask for 50).
        let l = Scale::covering([(48.0, 0.0), (141.0, 0.0)], false).unwrap();
        let t = l.ticks();
        assert_eq!((t[0].0, t.last().unwrap().0), (l.lo, l.hi));
        assert_eq!((l.lo, l.hi, t.len()), (40.0, 160.0, 7));
        let z = Scale::covering([(0.13, 0.0), (0.47, 0.0)], true).unwrap();
        assert_eq!(z.lo, 0.0);
        let p = z.padded(0.05);
        assert!(p.lo < z.lo && p.hi > z.hi && p.ticks() == z.ticks());
    }

    #[test]
    fn decades_of_positive_data_give_a_log_scale() {
        let s = Scale::covering([(2e-4, 0.0), (0.3, 0.0)], false).unwrap();
        assert!(s.log);
        assert_eq!((s.lo, s.hi), (1e-4, 1.0));
        assert_eq!(s.ticks().first().unwrap().1, "10⁻⁴");
        assert_eq!(s.t(1e-2), Some(0.5));
        assert_eq!(s.t(0.0), None);
        assert!(
            !Scale::covering_linear([(2e-4, 0.0), (0.3, 0.0)], false)
                .unwrap()
                .log
        );
        // Less than two decades stays linear.
        assert!(
            !Scale::covering([(0.02, 0.0), (0.3, 0.0)], false)
                .unwrap()
                .log
        );
    }

    #[test]
    fn steps_and_labels() {
        assert_eq!(tick_step(1.0), 0.2);
        assert_eq!(tick_step(30.0), 10.0);
        assert_eq!(tick_step(0.7), 0.2);
        assert_eq!(number_label(-0.0, 1), "0.0");
        assert_eq!(number_label(-2.5, 1), "−2.5");
        assert!(Scale::covering([(f64::NAN, 0.0)], false).is_none());
        let flat = Scale::covering([(5.0, 0.0), (5.0, 0.0)], false).unwrap();
        assert!(flat.lo < 5.0 && flat.hi > 5.0);
    }
}
