//! The fit file: `[fit]` (what is unknown, the geometry and noise of the
//! measurements, the output), `[pigment]` (the unknown pigment: its name,
//! grain diameter fixed or free within bounds, and its known `n` or the
//! bounds of a free one), an optional `[white]` (a known scene pigment
//! used in the tints), `base` (the scene whose binder, colour band and
//! fast model the drawdowns share) and `[[drawdown]]` (each measured
//! drawdown: its ground, thickness, volume fractions and reflectance
//! CSV). Read into raw serde structs (`deny_unknown_fields`, units in key
//! names) and checked into a [`FitSpec`]; every error is one line naming
//! the file, the key and what is allowed. The pigments, the base scene and
//! each drawdown's ground are checked by the scene checker itself.

use serde::Deserialize;
use std::path::{Path, PathBuf};
use toml::{Table, Value};

use crate::config::{
    Baseline, GroundReflectance, Measurement, ReflectanceSpectrum, Scene, Substrate, MAX_PVC,
};

use super::super::config::{
    base_without_pigments, checked_scene, fast_model, from_toml, invalid, output_names, read_text,
};
use super::super::MatchError;

/// Most drawdowns a fit file may list.
pub const MAX_DRAWDOWNS: usize = 64;
/// Thickest drawdown, nm (1 mm: the fast model has no solver's limit).
pub const MAX_DRAWDOWN_NM: f64 = 1.0e6;
/// Default measurement noise (1σ) of each reflectance factor: a good
/// spectrophotometer's repeatability.
pub const DEFAULT_NOISE: f64 = 0.002;
/// Largest absorption index the fit may give (the material tables' limit).
pub const MAX_K: f64 = 10.0;

/// Which optical constants of the pigment are unknown.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Unknowns {
    /// `k(λ)` only; `n` is known and constant.
    K { n: f64 },
    /// `n(λ)` and `k(λ)`, `n` within the bounds.
    NAndK { n_range: [f64; 2] },
}

impl Unknowns {
    /// The name in the fit file.
    pub fn name(self) -> &'static str {
        match self {
            Unknowns::K { .. } => "k",
            Unknowns::NAndK { .. } => "n-and-k",
        }
    }

    /// Unknowns per wavelength.
    pub fn per_wavelength(self) -> usize {
        match self {
            Unknowns::K { .. } => 1,
            Unknowns::NAndK { .. } => 2,
        }
    }
}

/// The unknown pigment.
#[derive(Debug, Clone, PartialEq)]
pub struct UnknownPigment {
    pub name: String,
    /// The grain diameter (equal-volume sphere), nm: the value when fixed,
    /// the first guess when free.
    pub diameter_nm: f64,
    /// Bounds of a free diameter, nm.
    pub diameter_range_nm: Option<[f64; 2]>,
    pub unknowns: Unknowns,
}

/// One reflectance spectrum of a drawdown over one ground.
#[derive(Debug, Clone)]
pub struct Reading {
    /// `over black`, `over white`, `over paper`, …
    pub over: String,
    /// The ground's albedo (0 for black).
    pub ground: GroundReflectance,
    pub spectrum: ReflectanceSpectrum,
    /// The file as written in the fit file.
    pub csv: String,
}

/// One drawdown: a layer of the unknown pigment (and the white) measured
/// over one ground, or over both halves of a hiding chart.
#[derive(Debug, Clone)]
pub struct Drawdown {
    pub name: String,
    pub thickness_nm: f64,
    /// Volume fraction of the unknown pigment.
    pub pvc: f64,
    /// Volume fraction of the white (0: a masstone).
    pub white_pvc: f64,
    pub readings: Vec<Reading>,
}

/// A checked fit file.
#[derive(Debug, Clone)]
pub struct FitSpec {
    pub path: PathBuf,
    pub name: String,
    pub output_dir: PathBuf,
    /// The base scene with the unknown pigment (species 0, a placeholder
    /// index) and the white (species 1, when given).
    pub scene: Scene,
    /// The fast model (the base scene's first baseline).
    pub model: Baseline,
    /// The geometry every spectrum was measured in.
    pub geometry: Measurement,
    /// 1σ noise of each measured reflectance factor.
    pub noise: f64,
    pub pigment: UnknownPigment,
    /// The white's name, when the tints have one.
    pub white: Option<String>,
    pub drawdowns: Vec<Drawdown>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawFitFile {
    fit: RawSettings,
    pigment: RawPigment,
    white: Option<Table>,
    base: Option<Value>,
    #[serde(default)]
    drawdown: Vec<RawDrawdown>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSettings {
    name: Option<String>,
    output_dir: Option<PathBuf>,
    unknowns: String,
    geometry: String,
    noise_reflectance: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawPigment {
    name: String,
    diameter_nm: f64,
    diameter_range_nm: Option<Vec<f64>>,
    n: Option<f64>,
    n_range: Option<Vec<f64>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawDrawdown {
    name: Option<String>,
    substrate: Table,
    thickness_nm: f64,
    pvc: f64,
    white_pvc: Option<f64>,
    csv: Option<String>,
    csv_black: Option<String>,
    csv_white: Option<String>,
}

/// Whether TOML `text` is a fit file (has a `[fit]` table).
pub fn is_fit_text(text: &str) -> bool {
    text.parse::<Table>()
        .map(|t| t.contains_key("fit"))
        .unwrap_or(false)
}

/// `[lo, hi]` of `key` with `ok(lo, hi)`, else `what` in the message.
fn pair(
    file: &Path,
    key: &str,
    v: &[f64],
    ok: impl Fn(f64, f64) -> bool,
    what: &str,
) -> Result<[f64; 2], MatchError> {
    match *v {
        [lo, hi] if lo.is_finite() && hi.is_finite() && ok(lo, hi) => Ok([lo, hi]),
        _ => Err(invalid(file, key, format!("give {what}"))),
    }
}

impl FitSpec {
    /// Read and check the fit file `path`.
    pub fn load(path: &Path) -> Result<FitSpec, MatchError> {
        FitSpec::parse(path, &read_text(path)?)
    }

    /// Parse and check fit-file `text` read from `path`.
    pub fn parse(path: &Path, text: &str) -> Result<FitSpec, MatchError> {
        let raw: RawFitFile = from_toml(
            path,
            text,
            "a fit file has [fit], [pigment], [white], base and [[drawdown]]",
        )?;
        let s = &raw.fit;
        let geometry = Measurement::from_name(&s.geometry).ok_or_else(|| {
            invalid(
                path,
                "fit.geometry",
                format!("`{}` is not one of 45/0, d/8 SCI, d/8 SCE", s.geometry),
            )
        })?;
        let noise = s.noise_reflectance.unwrap_or(DEFAULT_NOISE);
        if !(noise > 0.0 && noise <= 0.1) {
            return Err(invalid(
                path,
                "fit.noise_reflectance",
                format!("{noise} is outside (0, 0.1] (1σ of a reflectance factor)"),
            ));
        }
        let pigment = check_pigment(path, &s.unknowns, &raw.pigment)?;
        let (scene, white, table, scene_path) = check_scene(path, raw.base, &pigment, raw.white)?;
        let model = fast_model(path, &scene)?;
        let drawdowns = check_drawdowns(
            path,
            (&table, &scene_path),
            &raw.drawdown,
            &scene,
            white.is_some(),
        )?;
        let (name, output_dir) = output_names(
            path,
            "fit",
            raw.fit.name.clone(),
            raw.fit.output_dir.clone(),
        )?;
        Ok(FitSpec {
            path: path.to_path_buf(),
            name,
            output_dir,
            scene,
            model,
            geometry,
            noise,
            pigment,
            white,
            drawdowns,
        })
    }
}

fn check_pigment(
    file: &Path,
    unknowns: &str,
    raw: &RawPigment,
) -> Result<UnknownPigment, MatchError> {
    let d = raw.diameter_nm;
    let diameter_range_nm = match raw.diameter_range_nm.as_deref() {
        None => None,
        Some(v) => Some(pair(
            file,
            "pigment.diameter_range_nm",
            v,
            |lo, hi| lo > 0.0 && lo < hi && hi <= 20000.0 && (lo..=hi).contains(&d),
            "[min, max] in nm with 0 < min < max <= 20000 around pigment.diameter_nm (the \
             first guess)",
        )?),
    };
    let unknowns = match (unknowns, raw.n, raw.n_range.as_deref()) {
        ("k", Some(n), None) if (1.0..=MAX_K).contains(&n) => Unknowns::K { n },
        ("k", Some(n), None) => {
            return Err(invalid(
                file,
                "pigment.n",
                format!("{n} is outside [1, {MAX_K}] (the known real index)"),
            ))
        }
        ("k", None, _) => {
            return Err(invalid(
                file,
                "pigment.n",
                "give the known real index n (fit.unknowns = \"k\" fits k only)",
            ))
        }
        ("k", _, Some(_)) => {
            return Err(invalid(
                file,
                "pigment.n_range",
                "remove it: with fit.unknowns = \"k\" n is known (pigment.n)",
            ))
        }
        ("n-and-k", None, Some(v)) => Unknowns::NAndK {
            n_range: pair(
                file,
                "pigment.n_range",
                v,
                |lo, hi| lo >= 1.0 && lo < hi && hi <= MAX_K,
                &format!("[min, max] with 1 <= min < max <= {MAX_K}"),
            )?,
        },
        ("n-and-k", Some(_), _) => {
            return Err(invalid(
                file,
                "pigment.n",
                "remove it: with fit.unknowns = \"n-and-k\" n is fitted within pigment.n_range",
            ))
        }
        ("n-and-k", None, None) => {
            return Err(invalid(
                file,
                "pigment.n_range",
                "give [min, max] of n (fit.unknowns = \"n-and-k\")",
            ))
        }
        (other, _, _) => {
            return Err(invalid(
                file,
                "fit.unknowns",
                format!("`{other}` is not one of k, n-and-k"),
            ))
        }
    };
    Ok(UnknownPigment {
        name: raw.name.clone(),
        diameter_nm: d,
        diameter_range_nm,
        unknowns,
    })
}

/// The first guess of `n` (the known one, or the middle of its range).
fn start_n(u: Unknowns) -> f64 {
    match u {
        Unknowns::K { n } => n,
        Unknowns::NAndK { n_range } => 0.5 * (n_range[0] + n_range[1]),
    }
}

/// The base scene with the unknown pigment (a placeholder index) and the
/// white as its pigments, checked by the scene checker; the white's name,
/// the scene's table and the path it is read as.
#[allow(clippy::type_complexity)]
fn check_scene(
    file: &Path,
    base: Option<Value>,
    pigment: &UnknownPigment,
    white: Option<Table>,
) -> Result<(Scene, Option<String>, Table, PathBuf), MatchError> {
    let (mut table, scene_path) = base_without_pigments(
        file,
        base,
        "remove it: each [[drawdown]] gives its pvc and white_pvc",
    )?;
    if table.contains_key("substrate") {
        return Err(invalid(
            file,
            "base.substrate",
            "remove it: each [[drawdown]] gives its own substrate",
        ));
    }
    let mut unknown = Table::new();
    unknown.insert("name".into(), Value::String(pigment.name.clone()));
    let mut index = Table::new();
    let nk = vec![Value::Float(start_n(pigment.unknowns)), Value::Float(0.01)];
    index.insert("index".into(), Value::Array(nk));
    unknown.insert("material".into(), Value::Table(index));
    unknown.insert("diameter_nm".into(), Value::Float(pigment.diameter_nm));
    unknown.insert("pvc".into(), Value::Float(0.01));
    let mut pigments = vec![Value::Table(unknown)];
    let white_name = match white {
        None => None,
        Some(mut w) => {
            if w.contains_key("pvc") || w.contains_key("share") {
                return Err(invalid(
                    file,
                    "white.pvc",
                    "not allowed: each [[drawdown]] gives its white_pvc",
                ));
            }
            let name = match w.get("name") {
                Some(Value::String(s)) => s.clone(),
                _ => {
                    return Err(invalid(
                        file,
                        "white.name",
                        "give the white's name (a string)",
                    ))
                }
            };
            if name == pigment.name {
                return Err(invalid(
                    file,
                    "white.name",
                    format!("`{name}` is the unknown pigment's name; give the white another"),
                ));
            }
            w.insert("pvc".into(), Value::Float(0.01));
            pigments.push(Value::Table(w));
            Some(name)
        }
    };
    table.insert("pigment".into(), Value::Array(pigments));
    let mut ground = Table::new();
    ground.insert("kind".into(), Value::String("white".into()));
    table.insert("substrate".into(), Value::Table(ground));
    let scene = checked_scene(
        file,
        &table,
        &scene_path,
        "base scene with the pigment and the white",
        &|m| {
            m.replace("pigment[0].", "pigment.")
                .replace("pigment[1].", "white.")
        },
    )?;
    Ok((scene, white_name, table, scene_path))
}

/// The drawdowns: each one's ground checked as the substrate of the scene
/// `base` (its table and path) by the scene checker, its spectra read
/// (they must cover the scene's colour band).
fn check_drawdowns(
    file: &Path,
    base: (&Table, &Path),
    raw: &[RawDrawdown],
    scene: &Scene,
    has_white: bool,
) -> Result<Vec<Drawdown>, MatchError> {
    if raw.is_empty() || raw.len() > MAX_DRAWDOWNS {
        return Err(invalid(
            file,
            "drawdown",
            format!(
                "give 1 to {MAX_DRAWDOWNS} [[drawdown]] tables, got {}",
                raw.len()
            ),
        ));
    }
    let (table, scene_path) = base;
    let band = scene.wavelengths_nm.clone();
    let mut out: Vec<Drawdown> = Vec::with_capacity(raw.len());
    for (i, d) in raw.iter().enumerate() {
        let key = |k: &str| format!("drawdown[{i}].{k}");
        let name = d
            .name
            .clone()
            .unwrap_or_else(|| format!("drawdown {}", i + 1));
        if out.iter().any(|o| o.name == name) {
            return Err(invalid(
                file,
                &key("name"),
                format!("`{name}` is given twice"),
            ));
        }
        let t = d.thickness_nm;
        if !(t > 0.0 && t <= MAX_DRAWDOWN_NM) {
            return Err(invalid(
                file,
                &key("thickness_nm"),
                format!("{t} is outside (0, {MAX_DRAWDOWN_NM}] nm"),
            ));
        }
        if !(d.pvc > 0.0 && d.pvc <= MAX_PVC) {
            return Err(invalid(
                file,
                &key("pvc"),
                format!(
                    "{} is outside (0, {MAX_PVC}] (the unknown pigment's volume fraction)",
                    d.pvc
                ),
            ));
        }
        let white_pvc = d.white_pvc.unwrap_or(0.0);
        if !(0.0..=MAX_PVC).contains(&white_pvc) || d.pvc + white_pvc > MAX_PVC {
            return Err(invalid(
                file,
                &key("white_pvc"),
                format!(
                    "{white_pvc} is outside [0, {MAX_PVC}], or pvc + white_pvc exceeds {MAX_PVC}"
                ),
            ));
        }
        if white_pvc > 0.0 && !has_white {
            return Err(invalid(
                file,
                &key("white_pvc"),
                "a tint needs the [white] pigment; give it, or white_pvc = 0",
            ));
        }
        let mut t = table.clone();
        t.insert("substrate".into(), Value::Table(d.substrate.clone()));
        let rename = |m: String| m.replace("substrate.", &key("substrate."));
        let s = checked_scene(file, &t, scene_path, &format!("drawdown[{i}]"), &rename)?;
        let grounds: Vec<(&str, GroundReflectance, Option<&String>, String)> = match &s.substrate {
            Substrate::Black => vec![(
                "black",
                GroundReflectance::Constant(0.0),
                d.csv.as_ref(),
                key("csv"),
            )],
            Substrate::Chart { white } => vec![
                (
                    "black",
                    GroundReflectance::Constant(0.0),
                    d.csv_black.as_ref(),
                    key("csv_black"),
                ),
                (
                    "white",
                    white.clone(),
                    d.csv_white.as_ref(),
                    key("csv_white"),
                ),
            ],
            other => match other.ground() {
                Some(g) => vec![(other.kind(), g, d.csv.as_ref(), key("csv"))],
                None => {
                    return Err(invalid(
                        file,
                        &key("substrate.kind"),
                        "a drawdown lies on black, white, paper, csv or chart",
                    ))
                }
            },
        };
        let chart = s.substrate.is_chart();
        let stray = if chart {
            d.csv.is_some()
        } else {
            d.csv_black.is_some() || d.csv_white.is_some()
        };
        if stray {
            return Err(invalid(
                file,
                &key(if chart { "csv" } else { "csv_black" }),
                "a chart's two halves are csv_black and csv_white; another ground's spectrum is csv",
            ));
        }
        let mut readings = Vec::with_capacity(grounds.len());
        for (over, ground, csv, k) in grounds {
            let Some(csv) = csv else {
                return Err(invalid(
                    file,
                    &k,
                    "give the measured spectrum (CSV wavelength_nm,reflectance)",
                ));
            };
            let p = file.parent().unwrap_or(Path::new("")).join(csv);
            let spectrum =
                ReflectanceSpectrum::from_csv(&p).map_err(|e| invalid(file, &k, e.to_string()))?;
            let (lo, hi) = spectrum.range_nm();
            if lo > band[0] || hi < band[band.len() - 1] {
                return Err(invalid(
                    file,
                    &k,
                    format!(
                        "the spectrum covers {lo}–{hi} nm, the colour band {}–{} nm: it must \
                         cover the band",
                        band[0],
                        band[band.len() - 1]
                    ),
                ));
            }
            readings.push(Reading {
                over: format!("over {over}"),
                ground,
                spectrum,
                csv: csv.clone(),
            });
        }
        out.push(Drawdown {
            name,
            thickness_nm: d.thickness_nm,
            pvc: d.pvc,
            white_pvc,
            readings,
        });
    }
    Ok(out)
}
