//! `[appearance]` (products, viewing angles, BRDF cell, quadrature, colour
//! conditions, measurement geometries and the classical baseline) and
//! `[substrate]` (none, paper, a black, white or measured ground, or a
//! hiding chart).

use super::Checker;
use crate::config::raw::{RawAppearance, RawBaseline, RawProduct, RawSubstrate};
use crate::config::{
    Appearance, Baseline, ConfigError, GroundReflectance, Illuminant, Incidence, Measurement,
    Products, ReflectanceSpectrum, StandardObserver, Substrate, DEFAULT_PAPER_ALBEDO,
    DEFAULT_WHITE_ALBEDO,
};
use std::path::Path;
use std::sync::Arc;
const DEFAULT_QUADRATURE_POINTS: i64 = 6;

impl Checker<'_> {
    pub(super) fn appearance(
        &self,
        raw: Option<&RawAppearance>,
        incidence: &[Incidence],
        default_outputs: &[RawProduct],
    ) -> Result<Appearance, ConfigError> {
        let viewing_deg = match raw.and_then(|a| a.viewing_deg.as_ref()) {
            None => incidence.iter().map(|i| i.polar_deg).collect(),
            Some(list) => {
                let key = "appearance.viewing_deg";
                if list.is_empty() {
                    return Err(self.invalid(key, "must not be empty"));
                }
                self.polar_angles(key, list)?;
                list.clone()
            }
        };
        let mut products = Products::default();
        let list = raw
            .and_then(|a| a.outputs.clone())
            .unwrap_or_else(|| default_outputs.to_vec());
        for p in list {
            match p {
                RawProduct::Brdf => products.brdf = true,
                RawProduct::Btdf => products.btdf = true,
                RawProduct::Tile => products.tile = true,
                RawProduct::Merl => products.merl = true,
                RawProduct::Preview => products.preview = true,
            }
        }
        let brdf_cell = match raw.and_then(|a| a.brdf_cell) {
            None => None,
            Some(c) => Some(self.range(
                "appearance.brdf_cell",
                c,
                c > 0.0 && c <= 1.0,
                "(0, 1] (in units of sin θ)",
            )?),
        };
        let q = raw
            .and_then(|a| a.quadrature_points)
            .unwrap_or(DEFAULT_QUADRATURE_POINTS);
        if !(2..=32).contains(&q) {
            return Err(self.invalid(
                "appearance.quadrature_points",
                format!("must be in [2, 32], got {q}"),
            ));
        }
        let (illuminant, observer) = self.colour_conditions(
            "appearance",
            raw.and_then(|a| a.illuminant.as_deref()),
            raw.and_then(|a| a.observer_deg),
        )?;
        let measurements = match raw.and_then(|a| a.measurements.as_ref()) {
            None => Measurement::ALL.to_vec(),
            Some(names) => {
                let mut out = Vec::with_capacity(names.len());
                for name in names {
                    let m = Measurement::from_name(name).ok_or_else(|| {
                        self.invalid(
                            "appearance.measurements",
                            format!(
                                "unknown geometry \"{name}\"; allowed: \"45/0\", \"d/8 SCI\", \"d/8 SCE\""
                            ),
                        )
                    })?;
                    if out.contains(&m) {
                        return Err(self.invalid(
                            "appearance.measurements",
                            format!("\"{name}\" is listed twice"),
                        ));
                    }
                    out.push(m);
                }
                out
            }
        };
        let baseline = self.baseline(raw.and_then(|a| a.baseline.as_ref()))?;
        Ok(Appearance {
            viewing_deg,
            products,
            brdf_cell,
            quadrature_points: q as usize,
            illuminant,
            observer,
            measurements,
            baseline,
        })
    }

    /// `<table>.illuminant` (default D50) and `<table>.observer_deg`
    /// (default 2).
    pub(super) fn colour_conditions(
        &self,
        table: &str,
        illuminant: Option<&str>,
        observer_deg: Option<i64>,
    ) -> Result<(Illuminant, StandardObserver), ConfigError> {
        let illuminant = match illuminant {
            None => Illuminant::D50,
            Some(name) => Illuminant::from_name(name).ok_or_else(|| {
                self.invalid(
                    format!("{table}.illuminant"),
                    format!("unknown illuminant \"{name}\"; allowed: \"D50\", \"D65\", \"A\""),
                )
            })?,
        };
        let observer = match observer_deg {
            None => StandardObserver::TwoDegree,
            Some(d) => u32::try_from(d)
                .ok()
                .and_then(StandardObserver::from_degrees)
                .ok_or_else(|| {
                    self.invalid(
                        format!("{table}.observer_deg"),
                        format!("must be 2 (CIE 1931) or 10 (CIE 1964), got {d}"),
                    )
                })?,
        };
        Ok((illuminant, observer))
    }

    /// `appearance.baseline`: one name or a list, each a known model, none
    /// twice.
    fn baseline(&self, raw: Option<&RawBaseline>) -> Result<Vec<Baseline>, ConfigError> {
        let key = "appearance.baseline";
        let names: Vec<&str> = match raw {
            None => return Ok(Vec::new()),
            Some(RawBaseline::One(name)) => vec![name.as_str()],
            Some(RawBaseline::Many(list)) => list.iter().map(String::as_str).collect(),
        };
        if names.is_empty() {
            return Err(self.invalid(
                key,
                "must not be an empty list (leave the key out for none)",
            ));
        }
        let mut out = Vec::with_capacity(names.len());
        for name in names {
            let model = Baseline::from_name(name).ok_or_else(|| {
                let allowed: Vec<String> = Baseline::ALL
                    .iter()
                    .map(|b| format!("\"{}\"", b.name()))
                    .collect();
                self.invalid(
                    key,
                    format!(
                        "unknown baseline \"{name}\"; allowed: {}",
                        allowed.join(", ")
                    ),
                )
            })?;
            if out.contains(&model) {
                return Err(self.invalid(key, format!("\"{name}\" is listed twice")));
            }
            out.push(model);
        }
        Ok(out)
    }

    /// `[substrate]`; a ground's spectrum must cover every wavelength of
    /// the scene (`wavelengths_nm`), as a material's data must.
    pub(super) fn substrate(
        &self,
        raw: Option<&RawSubstrate>,
        wavelengths_nm: &[f64],
    ) -> Result<Substrate, ConfigError> {
        let albedo = |key: &str, a: Option<f64>, default: f64| {
            let a = a.unwrap_or(default);
            self.range(key, a, (0.0..=1.0).contains(&a), "[0, 1]")
        };
        Ok(match raw {
            Some(RawSubstrate::None {}) => Substrate::None,
            None => Substrate::Paper {
                albedo: DEFAULT_PAPER_ALBEDO,
            },
            Some(RawSubstrate::Paper { albedo: a }) => Substrate::Paper {
                albedo: albedo("substrate.albedo", *a, DEFAULT_PAPER_ALBEDO)?,
            },
            Some(RawSubstrate::Black {}) => Substrate::Black,
            Some(RawSubstrate::White { albedo: a }) => Substrate::White {
                albedo: albedo("substrate.albedo", *a, DEFAULT_WHITE_ALBEDO)?,
            },
            Some(RawSubstrate::Csv { file }) => {
                Substrate::Csv(self.ground_spectrum("substrate.file", file, wavelengths_nm)?)
            }
            Some(RawSubstrate::Chart {
                white_albedo,
                white_csv,
            }) => Substrate::Chart {
                white: match (white_albedo, white_csv) {
                    (Some(_), Some(_)) => {
                        return Err(self.invalid(
                            "substrate.white_csv",
                            "give the white half's albedo (white_albedo) or its spectrum \
                             (white_csv), not both",
                        ))
                    }
                    (_, Some(file)) => GroundReflectance::Spectrum(self.ground_spectrum(
                        "substrate.white_csv",
                        file,
                        wavelengths_nm,
                    )?),
                    (a, None) => GroundReflectance::Constant(albedo(
                        "substrate.white_albedo",
                        *a,
                        DEFAULT_WHITE_ALBEDO,
                    )?),
                },
            },
        })
    }

    /// A ground's reflectance table `rel` (relative to the scene file),
    /// covering every wavelength of the scene.
    pub(super) fn ground_spectrum(
        &self,
        key: &str,
        rel: &str,
        wavelengths_nm: &[f64],
    ) -> Result<Arc<ReflectanceSpectrum>, ConfigError> {
        if rel.trim().is_empty() {
            return Err(self.invalid(key, "must not be empty"));
        }
        let path = self.file.parent().unwrap_or(Path::new("")).join(rel);
        let s =
            ReflectanceSpectrum::from_csv(&path).map_err(|e| self.invalid(key, e.to_string()))?;
        if let Some(&wl) = wavelengths_nm.iter().find(|&&wl| !s.covers(wl)) {
            let (lo, hi) = s.range_nm();
            return Err(self.invalid(
                key,
                format!(
                    "wavelength {wl} nm is outside the data range [{lo}, {hi}] nm of the \
                     ground reflectance `{rel}` (tables are never extrapolated)"
                ),
            ));
        }
        Ok(Arc::new(s))
    }
}
