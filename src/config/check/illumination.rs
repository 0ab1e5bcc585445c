//! `[illumination]`: the wavelengths (a list or a range) and the polar
//! angles of incidence with their azimuth.

use super::{Checker, MAX_POLAR_DEG, REL_EPS};
use crate::config::raw::RawIllumination;
use crate::config::{ConfigError, Incidence};

const MAX_WAVELENGTHS: usize = 10_000;

impl Checker<'_> {
    /// The wavelength list and the key it came from.
    pub(super) fn wavelengths(
        &self,
        raw: &RawIllumination,
    ) -> Result<(Vec<f64>, &'static str), ConfigError> {
        match (&raw.wavelengths_nm, &raw.wavelength_range_nm) {
            (Some(_), Some(_)) => Err(self.invalid(
                "illumination",
                "give either wavelengths_nm or wavelength_range_nm, not both",
            )),
            (None, None) => Err(self.invalid(
                "illumination",
                "give either wavelengths_nm or wavelength_range_nm",
            )),
            (Some(list), None) => {
                let key = "illumination.wavelengths_nm";
                if list.is_empty() {
                    return Err(self.invalid(key, "must not be empty"));
                }
                if list.len() > MAX_WAVELENGTHS {
                    return Err(self.invalid(
                        key,
                        format!("at most {MAX_WAVELENGTHS} values, got {}", list.len()),
                    ));
                }
                for (i, &w) in list.iter().enumerate() {
                    let k = format!("{key}[{i}]");
                    self.range(&k, w, w > 0.0 && w.is_finite(), "(0, inf) nm")?;
                    if i > 0 && w <= list[i - 1] {
                        return Err(self.invalid(
                            k,
                            format!(
                                "values must be strictly increasing, got {w} after {}",
                                list[i - 1]
                            ),
                        ));
                    }
                }
                Ok((list.clone(), key))
            }
            (None, Some(r)) => {
                let key = "illumination.wavelength_range_nm";
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
        let mut out = Vec::with_capacity(raw.polar_deg.len());
        for (i, &p) in raw.polar_deg.iter().enumerate() {
            let k = format!("{key}[{i}]");
            self.range(
                &k,
                p,
                (0.0..=MAX_POLAR_DEG).contains(&p),
                &format!("[0, {MAX_POLAR_DEG}] deg"),
            )?;
            if i > 0 && p <= raw.polar_deg[i - 1] {
                return Err(self.invalid(
                    k,
                    format!(
                        "values must be strictly increasing, got {p} after {}",
                        raw.polar_deg[i - 1]
                    ),
                ));
            }
            out.push(Incidence {
                polar_deg: p,
                azimuth_deg,
            });
        }
        Ok(out)
    }
}
