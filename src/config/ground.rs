//! What lies under the layer (`[substrate]`): the grounds a print or a
//! drawdown is measured on, and the reflectance spectrum a ground may be
//! given as (`wavelength_nm,reflectance`).
//!
//! Every ground is a flat Lambertian reflector behind an air gap under the
//! layer (METHOD §5): it enters the appearance after the wave solves, through
//! the geometric series of inter-reflections, so a scene's grounds never
//! change what is solved, and a hiding chart's black and white halves come
//! from the same solves.

use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Albedo of the paper, and of a white ground or a chart's white half,
/// when the scene gives none.
pub const DEFAULT_PAPER_ALBEDO: f64 = 0.9;

/// Albedo of a `white` ground and of a chart's white half when the scene
/// gives none: near the luminance factor of the white part of the hiding
/// charts used for ISO 6504-3 and ASTM D2805 drawdowns; give the chart's
/// own value (or its spectrum) where it is known.
pub const DEFAULT_WHITE_ALBEDO: f64 = 0.8;

/// What lies under the layer.
#[derive(Debug, Clone, PartialEq)]
pub enum Substrate {
    /// Nothing: the layer alone in vacuum (colour from the solved
    /// wavelengths only, no spectral proxy).
    None,
    /// Flat Lambertian paper of the given albedo behind an air gap
    /// (METHOD §5).
    Paper { albedo: f64 },
    /// A ground that reflects nothing: what is measured is the layer alone
    /// (its own reflectance), with the colour through the spectral proxy as
    /// on any ground.
    Black,
    /// A white Lambertian ground of the given albedo: optically the paper
    /// (behind an air gap, not in optical contact), named for what a
    /// drawdown is measured on.
    White { albedo: f64 },
    /// A Lambertian ground of a measured reflectance spectrum.
    Csv(Arc<ReflectanceSpectrum>),
    /// A hiding chart: the layer over a black half (reflecting nothing) and
    /// a white half (`white`), both from the same solves; the appearance is
    /// reported over both, with the contrast ratio and Kubelka's S and K.
    Chart { white: GroundReflectance },
}

impl Substrate {
    /// The Lambertian ground whose term the appearance adds to the layer's
    /// own reflection (for a chart its white half); None where nothing is
    /// added (no substrate, a black ground).
    pub fn ground(&self) -> Option<GroundReflectance> {
        match self {
            Substrate::None | Substrate::Black => None,
            Substrate::Paper { albedo } | Substrate::White { albedo } => {
                Some(GroundReflectance::Constant(*albedo))
            }
            Substrate::Csv(s) => Some(GroundReflectance::Spectrum(s.clone())),
            Substrate::Chart { white } => Some(white.clone()),
        }
    }

    /// A hiding chart (black and white halves).
    pub fn is_chart(&self) -> bool {
        matches!(self, Substrate::Chart { .. })
    }

    /// The `kind` as the scene names it.
    pub fn kind(&self) -> &'static str {
        match self {
            Substrate::None => "none",
            Substrate::Paper { .. } => "paper",
            Substrate::Black => "black",
            Substrate::White { .. } => "white",
            Substrate::Csv(_) => "csv",
            Substrate::Chart { .. } => "chart",
        }
    }

    /// The data file a ground was read from, if any (it enters the input
    /// hash).
    pub fn spectrum(&self) -> Option<&ReflectanceSpectrum> {
        match self {
            Substrate::Csv(s) => Some(s),
            Substrate::Chart {
                white: GroundReflectance::Spectrum(s),
            } => Some(s),
            _ => None,
        }
    }
}

impl Substrate {
    /// How a picture's title says what the layer lies on: `on paper of
    /// albedo 0.9`, `without substrate`, `on a black ground`, `over the
    /// white half of a hiding chart (albedo 0.8)`, …
    pub fn on_phrase(&self) -> String {
        match self {
            Substrate::None => "without substrate".into(),
            Substrate::Chart { white } => {
                format!("over the white half of a hiding chart ({white})")
            }
            other => format!("on {other}"),
        }
    }
}

impl fmt::Display for Substrate {
    /// `paper of albedo 0.9`, `a black ground`, `a hiding chart (black and
    /// white of albedo 0.8)`, …
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Substrate::None => write!(f, "nothing (the layer in air)"),
            Substrate::Paper { albedo } => write!(f, "paper of albedo {albedo}"),
            Substrate::Black => write!(f, "a black ground"),
            Substrate::White { albedo } => write!(f, "a white ground of albedo {albedo}"),
            Substrate::Csv(s) => write!(f, "a ground of reflectance {}", s.name()),
            Substrate::Chart { white } => {
                write!(f, "a hiding chart (black, and white of {white})")
            }
        }
    }
}

/// A Lambertian ground's reflectance (its albedo) at every wavelength.
#[derive(Debug, Clone, PartialEq)]
pub enum GroundReflectance {
    Constant(f64),
    Spectrum(Arc<ReflectanceSpectrum>),
}

impl GroundReflectance {
    /// The albedo at `wavelength_nm` (linear interpolation of a spectrum,
    /// held at its ends; a checked scene never asks outside its range).
    pub fn at(&self, wavelength_nm: f64) -> f64 {
        match self {
            GroundReflectance::Constant(a) => *a,
            GroundReflectance::Spectrum(s) => s.at(wavelength_nm),
        }
    }

    /// The single albedo of a constant ground.
    pub fn constant(&self) -> Option<f64> {
        match self {
            GroundReflectance::Constant(a) => Some(*a),
            GroundReflectance::Spectrum(_) => None,
        }
    }
}

impl fmt::Display for GroundReflectance {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            GroundReflectance::Constant(a) => write!(f, "albedo {a}"),
            GroundReflectance::Spectrum(s) => write!(f, "reflectance {}", s.name()),
        }
    }
}

/// A ground's reflectance spectrum read from a `wavelength_nm,reflectance`
/// table: wavelengths increasing, reflectances in [0, 1], at least two rows.
#[derive(Debug, Clone, PartialEq)]
pub struct ReflectanceSpectrum {
    /// The file as the scene resolved it.
    pub file: PathBuf,
    pub wavelengths_nm: Vec<f64>,
    pub reflectance: Vec<f64>,
    /// The file's bytes (they enter the input hash).
    pub bytes: Vec<u8>,
}

/// Why a reflectance table cannot be read.
#[derive(Debug, thiserror::Error)]
pub enum SpectrumError {
    #[error("cannot read {file}: {source}")]
    Read {
        file: PathBuf,
        source: std::io::Error,
    },
    #[error("{file}: {message}")]
    Bad { file: PathBuf, message: String },
}

impl ReflectanceSpectrum {
    /// Read `path`.
    pub fn from_csv(path: &Path) -> Result<Self, SpectrumError> {
        let bytes = std::fs::read(path).map_err(|source| SpectrumError::Read {
            file: path.to_path_buf(),
            source,
        })?;
        Self::parse(path, bytes)
    }

    /// Parse `bytes` as the text of a table read from `path`.
    pub fn parse(path: &Path, bytes: Vec<u8>) -> Result<Self, SpectrumError> {
        let bad = |message: String| SpectrumError::Bad {
            file: path.to_path_buf(),
            message,
        };
        let text = std::str::from_utf8(&bytes).map_err(|_| bad("is not UTF-8 text".into()))?;
        let mut rows = text
            .lines()
            .enumerate()
            .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
        let header = rows.next().map(|(_, l)| l.trim()).unwrap_or("");
        let names: Vec<&str> = header.split(',').map(str::trim).collect();
        if names != ["wavelength_nm", "reflectance"] {
            return Err(bad(format!(
                "the header must be `wavelength_nm,reflectance`, got `{header}`"
            )));
        }
        let (mut wavelengths_nm, mut reflectance) = (Vec::new(), Vec::new());
        for (i, line) in rows {
            let at = i + 1;
            let cells: Vec<&str> = line.split(',').map(str::trim).collect();
            if cells.len() != 2 {
                return Err(bad(format!(
                    "line {at}: expected 2 values (wavelength_nm, reflectance), got {}",
                    cells.len()
                )));
            }
            let num = |c: &str| -> Result<f64, SpectrumError> {
                c.parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| bad(format!("line {at}: `{c}` is not a finite number")))
            };
            let (wl, r) = (num(cells[0])?, num(cells[1])?);
            if wl <= 0.0 {
                return Err(bad(format!("line {at}: wavelength {wl} nm must be > 0")));
            }
            if wavelengths_nm.last().is_some_and(|&p| wl <= p) {
                return Err(bad(format!(
                    "line {at}: wavelengths must increase, {wl} nm follows {} nm",
                    wavelengths_nm.last().unwrap()
                )));
            }
            if !(0.0..=1.0).contains(&r) {
                return Err(bad(format!("line {at}: reflectance {r} is outside [0, 1]")));
            }
            wavelengths_nm.push(wl);
            reflectance.push(r);
        }
        if wavelengths_nm.len() < 2 {
            return Err(bad(format!(
                "needs at least two rows of data, got {}",
                wavelengths_nm.len()
            )));
        }
        Ok(ReflectanceSpectrum {
            file: path.to_path_buf(),
            wavelengths_nm,
            reflectance,
            bytes,
        })
    }

    /// First and last wavelength, nm.
    pub fn range_nm(&self) -> (f64, f64) {
        (
            self.wavelengths_nm[0],
            self.wavelengths_nm[self.wavelengths_nm.len() - 1],
        )
    }

    /// Whether `wavelength_nm` lies in the table's range.
    pub fn covers(&self, wavelength_nm: f64) -> bool {
        let (lo, hi) = self.range_nm();
        (lo..=hi).contains(&wavelength_nm)
    }

    /// Linear interpolation, held at the ends.
    pub fn at(&self, wavelength_nm: f64) -> f64 {
        let (w, r) = (&self.wavelengths_nm, &self.reflectance);
        if wavelength_nm <= w[0] {
            return r[0];
        }
        let k = w.partition_point(|&x| x < wavelength_nm);
        if k >= w.len() {
            return r[r.len() - 1];
        }
        if w[k] == wavelength_nm {
            return r[k];
        }
        let t = (wavelength_nm - w[k - 1]) / (w[k] - w[k - 1]);
        r[k - 1] * (1.0 - t) + r[k] * t
    }

    /// The file's name as messages and captions show it.
    pub fn name(&self) -> String {
        self.file.file_name().map_or_else(
            || self.file.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(text: &str) -> Result<ReflectanceSpectrum, SpectrumError> {
        ReflectanceSpectrum::parse(Path::new("g.csv"), text.as_bytes().to_vec())
    }

    #[test]
    fn a_table_interpolates_linearly_and_knows_its_range() {
        let t =
            table("# chart white\nwavelength_nm,reflectance\n400,0.5\n500,0.7\n700,0.9\n").unwrap();
        assert_eq!(t.range_nm(), (400.0, 700.0));
        assert_eq!(t.at(400.0), 0.5);
        assert_eq!(t.at(500.0), 0.7);
        assert!((t.at(450.0) - 0.6).abs() < 1e-15);
        assert!((t.at(600.0) - 0.8).abs() < 1e-15);
        assert!(t.covers(700.0) && !t.covers(399.9) && !t.covers(700.1));
    }

    #[test]
    fn bad_tables_say_what_and_where() {
        for (text, want) in [
            ("wavelength_nm,n\n400,1\n", "header"),
            ("wavelength_nm,reflectance\n400,0.5\n", "at least two rows"),
            (
                "wavelength_nm,reflectance\n400,0.5\n300,0.5\n",
                "line 3: wavelengths must increase",
            ),
            (
                "wavelength_nm,reflectance\n400,0.5\n500,1.2\n",
                "line 3: reflectance 1.2",
            ),
            ("wavelength_nm,reflectance\n400,x\n500,1\n", "line 2: `x`"),
            (
                "wavelength_nm,reflectance\n400,0.5,1\n500,1\n",
                "line 2: expected 2 values",
            ),
        ] {
            let e = table(text).unwrap_err().to_string();
            assert!(e.starts_with("g.csv: ") && e.contains(want), "{e}");
        }
    }
}
