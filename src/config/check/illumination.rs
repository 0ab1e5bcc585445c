//! `[illumination]`: the wavelengths (a list or a range) and the polar
//! angles of incidence with their azimuth.

use super::{Checker, REL_EPS};
use crate::config::raw::{RawIllumination, RawRange};
use crate::config::{ConfigError, Incidence};

const MAX_WAVELENGTHS: usize = 10_000;

impl Checker<'_> {
    /// The wavelength list and the key it came from.
    pub(super) fn wavelengths(
        &self,
        raw: &RawIllumination,
    ) -> Result<(Vec<f64>, &'static str), ConfigError> {
        self.wavelength_list(
            "illumination",
            raw.wavelengths_nm.as_ref(),
            raw.wavelength_range_nm.as_ref(),
        )
    }

    /// The wavelength list of table `table` (`illumination`, `paint`) from
    /// its `wavelengths_nm` or `wavelength_range_nm`, and the key it came
    /// from.
    pub(super) fn wavelength_list(
        &self,
        table: &'static str,
        list: Option<&Vec<f64>>,
        range: Option<&RawRange>,
    ) -> Result<(Vec<f64>, &'static str), ConfigError> {
        let keys: (&'static str, &'static str) = match table {
            "paint" => ("paint.wavelengths_nm", "paint.wavelength_range_nm"),
            _ => (
                "illumination.wavelengths_nm",
                "illumination.wavelength_range_nm",
            ),
        };
        match (list, range) {
            (Some(_), Some(_)) => Err(self.invalid(
                table,
                "give either wavelengths_nm or wavelength_range_nm, not both",
            )),
            (None, None) => {
                Err(self.invalid(table, "give either wavelengths_nm or wavelength_range_nm"))
            }
            (Some(list), None) => {
                let key = keys.0;
                if list.is_empty() {
                    return Err(self.invalid(key, "must not be empty"));
                }
                if list.len() > MAX_WAVELENGTHS {
                    return Err(self.invalid(
                        key,
                        format!("at most {MAX_WAVELENGTHS} values, got {}", list.len()),
                    ));
                }
                self.increasing(key, list, |w| w > 0.0 && w.is_finite(), "(0, inf) nm")?;
                Ok((list.clone(), key))
            }
            (None, Some(r)) => {
                let key = keys.1;
                self.range(
                    &format!("{key}.start"),
                    r.start,
                    r.start > 0.0 && r.start.is_finite(),
                    "(0, inf) nm",
                )?;
                self.range(
                    &format!("{key}.stop"),
                    r.stop,
                    r.stop >= r.start && r.stop.is_finite(),
                    &format!("[start, inf) = [{}, inf) nm", r.start),
                )?;
                self.range(
                    &format!("{key}.step"),
                    r.step,
                    r.step > 0.0 && r.step.is_finite(),
                    "(0, inf) nm",
                )?;
                let q = (r.stop - r.start) / r.step;
                if q + 1.0 > MAX_WAVELENGTHS as f64 {
                    return Err(self.invalid(
                        key,
                        format!(
                            "gives {} wavelengths, more than {MAX_WAVELENGTHS}; use a larger step",
                            q.floor() + 1.0
                        ),
                    ));
                }
                let steps = (q * (1.0 + REL_EPS)).floor() as usize;
                let mut list: Vec<f64> = (0..=steps).map(|i| r.start + i as f64 * r.step).collect();
                let last = list.len() - 1;
                if (list[last] - r.stop).abs() <= REL_EPS * r.step {
                    list[last] = r.stop;
                }
                Ok((list, key))
            }
        }
    }

    pub(super) fn incidence(&self, raw: &RawIllumination) -> Result<Vec<Incidence>, ConfigError> {
        let key = "illumination.polar_deg";
        if raw.polar_deg.is_empty() {
            return Err(self.invalid(key, "must not be empty"));
        }
        let a = raw.azimuth_deg.unwrap_or(0.0);
        let azimuth_deg = self.range(
            "illumination.azimuth_deg",
            a,
            (-360.0..=360.0).contains(&a),
            "[-360, 360] deg",
        )?;
        self.polar_angles(key, &raw.polar_deg)?;
        Ok(raw
            .polar_deg
            .iter()
            .map(|&p| Incidence {
                polar_deg: p,
                azimuth_deg,
            })
            .collect())
    }
}
