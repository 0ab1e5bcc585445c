//! The match file: `[match]` (search settings and output), `[target]` (the
//! colour to match), `base` (the scene whose layer, ground and colour band
//! the recipe is for) and `[[palette]]` (the pigments it may use, each a
//! scene pigment table plus its `pvc_range`). Read into raw serde structs
//! (`deny_unknown_fields`, tagged target, units in key names) and checked
//! into a [`MatchSpec`]; every error names the file, the key and what is
//! allowed. The palette is checked as the base scene's pigments, by the
//! scene checker itself (materials, sizes, shapes), so a palette pigment is
//! valid exactly when it would be valid in a scene.

use serde::Deserialize;
use std::path::{Path, PathBuf};
use toml::{Table, Value};

use crate::config::{
    parse_scene, Baseline, ConfigError, Illuminant, Measurement, ReflectanceSpectrum, Scene,
    StandardObserver, MAX_PVC,
};
use crate::study::sweep::base_table;

use super::MatchError;

/// Most pigments a palette may hold.
pub const MAX_PALETTE: usize = 24;
/// Most colourants in one recipe.
pub const MAX_COLOURANTS: usize = 4;
/// Most starting points per subset.
pub const MAX_STARTS: usize = 64;
/// The volume fraction each palette pigment is given while the base scene
/// is checked (the search sets the real ones).
const CHECK_PVC: f64 = 0.01;
/// Default measurement noise of each of L*, a*, b* (1σ), a good
/// spectrophotometer's repeatability.
pub const DEFAULT_NOISE_LAB: f64 = 0.05;
/// The colour grid must reach at least this far into the blue and red, nm.
const BAND_NM: (f64, f64) = (430.0, 680.0);

/// What the search minimises.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Objective {
    /// Root-mean-square difference of the reflectance factors on the grid
    /// (a spectrum target).
    SpectralRms,
    /// CIEDE2000 (root-mean-square over the target's geometries).
    De00,
}

impl Objective {
    pub fn name(self) -> &'static str {
        match self {
            Objective::SpectralRms => "spectral-rms",
            Objective::De00 => "de00",
        }
    }
}

/// The colour to match.
#[derive(Debug, Clone)]
pub enum TargetColour {
    /// CIELAB in one or more geometries.
    Lab(Vec<(Measurement, [f64; 3])>),
    /// A reflectance-factor spectrum measured in one geometry.
    Spectrum {
        geometry: Measurement,
        spectrum: ReflectanceSpectrum,
    },
}

/// The target and the conditions it is stated in.
#[derive(Debug, Clone)]
pub struct Target {
    pub colour: TargetColour,
    pub illuminant: Illuminant,
    pub observer: StandardObserver,
    /// Measurement noise (1σ) of L*, a*, b*.
    pub noise_lab: [f64; 3],
}

impl Target {
    /// The geometries the target is stated in.
    pub fn geometries(&self) -> Vec<Measurement> {
        match &self.colour {
            TargetColour::Lab(c) => c.iter().map(|(m, _)| *m).collect(),
            TargetColour::Spectrum { geometry, .. } => vec![*geometry],
        }
    }
}

/// One palette pigment: its name and the bounds on its volume fraction.
#[derive(Debug, Clone, PartialEq)]
pub struct PaletteEntry {
    pub name: String,
    /// Least and most volume fraction of the layer.
    pub pvc_range: [f64; 2],
}

/// The search settings.
#[derive(Debug, Clone)]
pub struct Search {
    pub tolerance_de00: f64,
    pub max_colourants: usize,
    pub starts: usize,
    pub objective: Objective,
    /// Most total volume fraction of a recipe.
    pub max_total_pvc: f64,
    /// Bounds on the thickness when the search may change it.
    pub thickness_range_nm: Option<[f64; 2]>,
    /// How many recipes are reported.
    pub recipes: usize,
}

/// The wave-optics verification of the best recipes (`[match.verify]`):
/// each is solved by the full pipeline at the base scene's own fidelity
/// (grid, fragment, realisations, equation, tolerance) and corrected by
/// the fast–exact difference until it is within the tolerance.
#[derive(Debug, Clone, PartialEq)]
pub struct VerifySpec {
    /// How many of the best recipes are verified.
    pub recipes: usize,
    /// Most correction steps after the first verification.
    pub max_steps: usize,
    /// Solved wavelengths: every this many nm over the colour band (both
    /// ends included).
    pub wavelength_step_nm: f64,
}

/// Most recipes verified.
pub const MAX_VERIFIED: usize = 5;
/// Most correction steps.
pub const MAX_STEPS: usize = 10;

/// A checked match file.
#[derive(Debug, Clone)]
pub struct MatchSpec {
    pub path: PathBuf,
    /// The file's text as checked (embedded in the result file).
    pub text: String,
    pub name: String,
    pub output_dir: PathBuf,
    pub target: Target,
    /// The base scene with the palette as its pigments, in palette order.
    pub scene: Scene,
    /// The fast model (the base scene's first baseline, default
    /// `kubelka-munk`).
    pub model: Baseline,
    pub palette: Vec<PaletteEntry>,
    pub search: Search,
    /// The wave-optics verification, when asked for.
    pub verify: Option<VerifySpec>,
    /// The base scene's table with the palette as its pigments (the
    /// verification's scenes are made from it), and the path it is read as.
    pub base: Table,
    pub base_path: PathBuf,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMatchFile {
    #[serde(rename = "match")]
    settings: RawSettings,
    target: RawTarget,
    base: Option<Value>,
    #[serde(default)]
    palette: Vec<Table>,
}

/// `[match]` as written (a scene's match and an effect paint's share it).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawSettings {
    pub(crate) name: Option<String>,
    pub(crate) output_dir: Option<PathBuf>,
    tolerance_de00: f64,
    max_colourants: Option<usize>,
    starts: Option<usize>,
    objective: Option<String>,
    max_total_pvc: Option<f64>,
    pub(crate) thickness_range_nm: Option<Vec<f64>>,
    recipes: Option<usize>,
    pub(crate) verify: Option<RawVerify>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawVerify {
    recipes: Option<usize>,
    max_steps: Option<usize>,
    wavelength_step_nm: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
enum RawTarget {
    Lab {
        illuminant: String,
        observer_deg: u32,
        noise_lab: Option<Vec<f64>>,
        colour: Vec<RawColour>,
    },
    Spectrum {
        illuminant: String,
        observer_deg: u32,
        noise_lab: Option<Vec<f64>>,
        csv: String,
        geometry: String,
    },
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawColour {
    geometry: String,
    lab: Vec<f64>,
}

/// Whether TOML match-file `text` matches an effect paint: its target is
/// `kind = "multi-angle"` ([`super::effect`]).
pub fn is_effect_text(text: &str) -> bool {
    text.parse::<Table>().is_ok_and(|t| {
        t.get("target")
            .and_then(|v| v.get("kind"))
            .and_then(Value::as_str)
            == Some("multi-angle")
    })
}

/// Whether TOML `text` is a match file (has a `[match]` table).
pub fn is_match_text(text: &str) -> bool {
    text.parse::<Table>()
        .map(|t| t.contains_key("match"))
        .unwrap_or(false)
}

/// A [`MatchError::Config`] of `file`, key `key`.
pub(crate) fn invalid(file: &Path, key: &str, message: impl Into<String>) -> MatchError {
    MatchError::Config {
        file: file.to_path_buf(),
        message: format!("key `{key}`: {}", message.into()),
    }
}

/// The fast model: the base scene's first baseline (default
/// `kubelka-munk`), a Kubelka–Munk one.
pub(crate) fn fast_model(path: &Path, scene: &Scene) -> Result<Baseline, MatchError> {
    let model = scene
        .appearance
        .baseline
        .first()
        .copied()
        .unwrap_or(Baseline::KubelkaMunk);
    if !matches!(model, Baseline::KubelkaMunk | Baseline::KubelkaMunkScene) {
        return Err(invalid(
            path,
            "base.appearance.baseline",
            format!(
                "the fast model is `kubelka-munk` or `kubelka-munk-scene`, got `{}`",
                model.name()
            ),
        ));
    }
    Ok(model)
}

/// The text of the file `path`, or one error naming it.
pub(crate) fn read_text(path: &Path) -> Result<String, MatchError> {
    std::fs::read_to_string(path).map_err(|e| MatchError::Config {
        file: path.to_path_buf(),
        message: format!("cannot read: {e}"),
    })
}

/// `text` (read from `path`) as the raw serde type `T`; an error is one
/// line with the parser's line number and `what` the file holds.
pub(crate) fn from_toml<T: serde::de::DeserializeOwned>(
    path: &Path,
    text: &str,
    what: &str,
) -> Result<T, MatchError> {
    toml::from_str(text).map_err(|e| {
        let line = e
            .span()
            .map(|s| text[..s.start.min(text.len())].matches('\n').count() + 1);
        MatchError::Config {
            file: path.to_path_buf(),
            message: format!(
                "{}{} ({what})",
                line.map_or(String::new(), |l| format!("line {l}: ")),
                e.message().trim()
            ),
        }
    })
}

impl MatchSpec {
    /// Read and check the match file `path`.
    pub fn load(path: &Path) -> Result<MatchSpec, MatchError> {
        MatchSpec::parse(path, &read_text(path)?)
    }

    /// Parse and check match-file `text` read from `path`.
    pub fn parse(path: &Path, text: &str) -> Result<MatchSpec, MatchError> {
        let raw: RawMatchFile = from_toml(
            path,
            text,
            "a match file has [match], [target], base and [[palette]]",
        )?;
        let target = check_target(path, raw.target)?;
        let (palette, scene, base, base_path) = check_palette(path, raw.base, raw.palette)?;
        let model = fast_model(path, &scene)?;
        let search = check_search(path, &raw.settings, &target, &scene, palette.len())?;
        let verify = raw
            .settings
            .verify
            .as_ref()
            .map(|v| check_verify(path, v, &search))
            .transpose()?;
        let (name, output_dir) =
            output_names(path, "match", raw.settings.name, raw.settings.output_dir)?;
        let spec = MatchSpec {
            path: path.to_path_buf(),
            text: text.to_string(),
            name,
            output_dir,
            target,
            scene,
            model,
            palette,
            search,
            verify,
            base,
            base_path,
        };
        Ok(spec)
    }
}

/// The checked `<table>.name` (default: the file's stem) and
/// `<table>.output_dir` (default `runs/<name>`) of the file `path`.
pub(crate) fn output_names(
    path: &Path,
    table: &str,
    name: Option<String>,
    output_dir: Option<PathBuf>,
) -> Result<(String, PathBuf), MatchError> {
    let name = match name {
        Some(n) if n.is_empty() || crate::study::sweep::sanitise(&n) != n => {
            return Err(invalid(
                path,
                &format!("{table}.name"),
                format!("`{n}` must be non-empty and use only A-Z a-z 0-9 _ . -"),
            ))
        }
        Some(n) => n,
        None => path.file_stem().map_or(table.into(), |s| {
            crate::study::sweep::sanitise(&s.to_string_lossy())
        }),
    };
    let output_dir = output_dir.unwrap_or_else(|| PathBuf::from("runs").join(&name));
    Ok((name, output_dir))
}

/// The 3 numbers of `key`, each checked by `ok` (`what` says the range).
pub(crate) fn three(
    file: &Path,
    key: &str,
    v: &[f64],
    ok: impl Fn(usize, f64) -> bool,
    what: &str,
) -> Result<[f64; 3], MatchError> {
    if v.len() != 3 {
        return Err(invalid(
            file,
            key,
            format!("must be 3 numbers, got {}", v.len()),
        ));
    }
    for (i, &x) in v.iter().enumerate() {
        if !x.is_finite() || !ok(i, x) {
            return Err(invalid(file, key, format!("{x} is outside {what}")));
        }
    }
    Ok([v[0], v[1], v[2]])
}

/// The target's illuminant, observer and noise (`target.illuminant`,
/// `target.observer_deg`, `target.noise_lab`, default
/// [`DEFAULT_NOISE_LAB`]).
pub(crate) fn check_conditions(
    file: &Path,
    illuminant: &str,
    observer_deg: u32,
    noise: &Option<Vec<f64>>,
) -> Result<(Illuminant, StandardObserver, [f64; 3]), MatchError> {
    let illuminant = Illuminant::from_name(illuminant).ok_or_else(|| {
        invalid(
            file,
            "target.illuminant",
            format!("`{illuminant}` is not one of D50, D65, A"),
        )
    })?;
    let observer = StandardObserver::from_degrees(observer_deg).ok_or_else(|| {
        invalid(
            file,
            "target.observer_deg",
            format!("{observer_deg} is not 2 or 10"),
        )
    })?;
    let noise_lab = match noise {
        Some(v) => three(
            file,
            "target.noise_lab",
            v,
            |_, x| x > 0.0 && x <= 5.0,
            "(0, 5] (1σ of L*, a*, b*)",
        )?,
        None => [DEFAULT_NOISE_LAB; 3],
    };
    Ok((illuminant, observer, noise_lab))
}

fn check_target(file: &Path, raw: RawTarget) -> Result<Target, MatchError> {
    let (illuminant, observer_deg, noise) = match &raw {
        RawTarget::Lab {
            illuminant,
            observer_deg,
            noise_lab,
            ..
        }
        | RawTarget::Spectrum {
            illuminant,
            observer_deg,
            noise_lab,
            ..
        } => (illuminant, *observer_deg, noise_lab),
    };
    let (illuminant, observer, noise_lab) =
        check_conditions(file, illuminant, observer_deg, noise)?;
    let geometry = |key: &str, name: &str| {
        Measurement::from_name(name).ok_or_else(|| {
            invalid(
                file,
                key,
                format!("`{name}` is not one of 45/0, d/8 SCI, d/8 SCE"),
            )
        })
    };
    let colour = match raw {
        RawTarget::Lab { colour, .. } => {
            if colour.is_empty() {
                return Err(invalid(
                    file,
                    "target.colour",
                    "give at least one { geometry, lab }",
                ));
            }
            let mut out: Vec<(Measurement, [f64; 3])> = Vec::new();
            for (i, c) in colour.iter().enumerate() {
                let m = geometry(&format!("target.colour[{i}].geometry"), &c.geometry)?;
                if out.iter().any(|(g, _)| *g == m) {
                    return Err(invalid(
                        file,
                        &format!("target.colour[{i}].geometry"),
                        format!("`{}` is given twice", m.name()),
                    ));
                }
                let lab = three(
                    file,
                    &format!("target.colour[{i}].lab"),
                    &c.lab,
                    |k, x| {
                        if k == 0 {
                            (0.0..=100.0).contains(&x)
                        } else {
                            x.abs() <= 200.0
                        }
                    },
                    "L* in [0, 100], a*, b* in [-200, 200]",
                )?;
                out.push((m, lab));
            }
            TargetColour::Lab(out)
        }
        RawTarget::Spectrum {
            csv, geometry: g, ..
        } => {
            let p = file.parent().unwrap_or(Path::new("")).join(&csv);
            let spectrum = ReflectanceSpectrum::from_csv(&p)
                .map_err(|e| invalid(file, "target.csv", e.to_string()))?;
            TargetColour::Spectrum {
                geometry: geometry("target.geometry", &g)?,
                spectrum,
            }
        }
    };
    Ok(Target {
        colour,
        illuminant,
        observer,
        noise_lab,
    })
}

/// The palette's entries, and the base scene with the palette as its
/// pigments (checked by the scene checker).
fn check_palette(
    file: &Path,
    base: Option<Value>,
    palette: Vec<Table>,
) -> Result<(Vec<PaletteEntry>, Scene, Table, PathBuf), MatchError> {
    let (mut table, scene_path) = base_without_pigments(
        file,
        base,
        "remove it: the palette's pvc_range bounds give the PVC",
    )?;
    if table.contains_key("paint") {
        return Err(invalid(
            file,
            "base",
            "an effect paint ([paint]) is matched to multi-angle colours: give target.kind = \
             \"multi-angle\" and [[unknown]] tables (docs/MATCH.md, \"Effect paints\")",
        ));
    }
    if palette.is_empty() || palette.len() > MAX_PALETTE {
        return Err(invalid(
            file,
            "palette",
            format!(
                "give 1 to {MAX_PALETTE} [[palette]] pigments, got {}",
                palette.len()
            ),
        ));
    }
    let mut entries = Vec::with_capacity(palette.len());
    let mut pigments = Vec::with_capacity(palette.len());
    for (i, mut p) in palette.into_iter().enumerate() {
        let key = |k: &str| format!("palette[{i}].{k}");
        for k in ["pvc", "share"] {
            if p.contains_key(k) {
                return Err(invalid(
                    file,
                    &key(k),
                    "not allowed: give pvc_range = [min, max]",
                ));
            }
        }
        let range = match p.remove("pvc_range") {
            Some(Value::Array(a)) => a
                .iter()
                .map(|v| v.as_float().or(v.as_integer().map(|i| i as f64)))
                .collect::<Option<Vec<f64>>>(),
            _ => None,
        };
        let range = match range.as_deref() {
            Some(&[lo, hi]) if (0.0..=hi).contains(&lo) && hi > 0.0 && hi <= MAX_PVC => [lo, hi],
            _ => {
                return Err(invalid(
                    file,
                    &key("pvc_range"),
                    format!(
                    "give [min, max] volume fractions with 0 <= min <= max, 0 < max <= {MAX_PVC}"
                ),
                ))
            }
        };
        let name = match p.get("name") {
            Some(Value::String(s)) => s.clone(),
            _ => {
                return Err(invalid(
                    file,
                    &key("name"),
                    "give the pigment's name (a string)",
                ))
            }
        };
        p.insert("pvc".into(), Value::Float(CHECK_PVC));
        pigments.push(Value::Table(p));
        entries.push(PaletteEntry {
            name,
            pvc_range: range,
        });
    }
    table.insert("pigment".into(), Value::Array(pigments));
    let scene = checked_scene(
        file,
        &table,
        &scene_path,
        "base scene with the palette as its pigments",
        &|m| m.replace("pigment[", "palette["),
    )?;
    Ok((entries, scene, table, scene_path))
}

/// The base scene's table of the file `file` (inline or its own file, and
/// that file's path), refused when it has pigments, a stack or a
/// `layer.pvc` (`pvc_why` says where the volume fractions come from).
pub(crate) fn base_without_pigments(
    file: &Path,
    base: Option<Value>,
    pvc_why: &str,
) -> Result<(Table, PathBuf), MatchError> {
    let (table, scene_path) = base_table(file, base).map_err(|m| MatchError::Config {
        file: file.to_path_buf(),
        message: m,
    })?;
    if table.contains_key("pigment") || table.contains_key("stack") {
        return Err(invalid(
            file,
            "base",
            "the base scene must have no [[pigment]] or [[stack]]: this file gives the pigments",
        ));
    }
    if let Some(Value::Table(layer)) = table.get("layer") {
        if layer.contains_key("pvc") {
            return Err(invalid(file, "base.layer.pvc", pvc_why));
        }
    }
    Ok((table, scene_path))
}

/// The scene `table` checked by the scene checker as if read from
/// `scene_path`; an error is one line of `file` saying `what` was checked,
/// its key renamed by `rename` into the user's file.
pub(crate) fn checked_scene(
    file: &Path,
    table: &Table,
    scene_path: &Path,
    what: &str,
    rename: &dyn Fn(String) -> String,
) -> Result<Scene, MatchError> {
    let text = toml::to_string(table).map_err(|e| MatchError::Config {
        file: file.to_path_buf(),
        message: format!("base: {e}"),
    })?;
    parse_scene(scene_path, &text).map_err(|e| MatchError::Config {
        file: file.to_path_buf(),
        message: format!("{what}: {}", rename(scene_message(&e))),
    })
}

/// What the scene checker says, without its file (the match file is named
/// already) and without the position in the combined scene text, which is
/// not the user's file.
fn scene_message(e: &ConfigError) -> String {
    match e {
        ConfigError::Parse { message, .. } => match message.split_once(", column ") {
            Some((line, rest)) if line.starts_with("line ") => {
                rest.split_once(": ").map_or(rest, |(_, m)| m).to_string()
            }
            _ => message.clone(),
        },
        ConfigError::Invalid { key, message, .. } => format!("key `{key}`: {message}"),
        other => other.to_string(),
    }
}

fn check_verify(file: &Path, raw: &RawVerify, search: &Search) -> Result<VerifySpec, MatchError> {
    let recipes = raw.recipes.unwrap_or(1);
    if !(1..=MAX_VERIFIED.min(search.recipes)).contains(&recipes) {
        return Err(invalid(
            file,
            "match.verify.recipes",
            format!(
                "{recipes} is outside [1, {}] (at most {MAX_VERIFIED}, and no more than \
                 match.recipes)",
                MAX_VERIFIED.min(search.recipes)
            ),
        ));
    }
    let max_steps = raw.max_steps.unwrap_or(3);
    if max_steps > MAX_STEPS {
        return Err(invalid(
            file,
            "match.verify.max_steps",
            format!("{max_steps} is outside [0, {MAX_STEPS}]"),
        ));
    }
    let step = raw.wavelength_step_nm.unwrap_or(20.0);
    if !(step.is_finite() && (5.0..=100.0).contains(&step)) {
        return Err(invalid(
            file,
            "match.verify.wavelength_step_nm",
            format!("{step} is outside [5, 100] nm"),
        ));
    }
    Ok(VerifySpec {
        recipes,
        max_steps,
        wavelength_step_nm: step,
    })
}

fn check_search(
    file: &Path,
    raw: &RawSettings,
    target: &Target,
    scene: &Scene,
    palette: usize,
) -> Result<Search, MatchError> {
    let spectral = matches!(target.colour, TargetColour::Spectrum { .. });
    let search = check_settings(file, raw, spectral, palette)?;
    check_band(
        file,
        "base.illumination.wavelengths_nm",
        &scene.wavelengths_nm,
    )?;
    Ok(search)
}

/// The search settings of `[match]` (`spectral`: the target is a
/// spectrum; `palette`: how many optional colourants there are).
pub(crate) fn check_settings(
    file: &Path,
    raw: &RawSettings,
    spectral: bool,
    palette: usize,
) -> Result<Search, MatchError> {
    let tol = raw.tolerance_de00;
    if !(tol.is_finite() && tol > 0.0 && tol <= 20.0) {
        return Err(invalid(
            file,
            "match.tolerance_de00",
            format!("{tol} is outside (0, 20]"),
        ));
    }
    let max_colourants = raw.max_colourants.unwrap_or(3);
    if !(1..=MAX_COLOURANTS).contains(&max_colourants) {
        return Err(invalid(
            file,
            "match.max_colourants",
            format!("{max_colourants} is outside [1, {MAX_COLOURANTS}]"),
        ));
    }
    // No subset is larger than the palette.
    let max_colourants = max_colourants.min(palette);
    let starts = raw.starts.unwrap_or(4);
    if !(1..=MAX_STARTS).contains(&starts) {
        return Err(invalid(
            file,
            "match.starts",
            format!("{starts} is outside [1, {MAX_STARTS}]"),
        ));
    }
    let objective = match raw.objective.as_deref() {
        None if spectral => Objective::SpectralRms,
        None | Some("de00") => Objective::De00,
        Some("spectral-rms") if spectral => Objective::SpectralRms,
        Some("spectral-rms") => {
            return Err(invalid(
                file,
                "match.objective",
                "`spectral-rms` needs a spectrum target (target.kind = \"spectrum\")",
            ))
        }
        Some(o) => {
            return Err(invalid(
                file,
                "match.objective",
                format!("`{o}` is not one of spectral-rms, de00"),
            ))
        }
    };
    let max_total_pvc = raw.max_total_pvc.unwrap_or(MAX_PVC);
    if !(max_total_pvc > 0.0 && max_total_pvc <= MAX_PVC) {
        return Err(invalid(
            file,
            "match.max_total_pvc",
            format!("{max_total_pvc} is outside (0, {MAX_PVC}]"),
        ));
    }
    let thickness_range_nm = match raw.thickness_range_nm.as_deref() {
        None => None,
        Some(&[lo, hi]) if lo > 0.0 && lo <= hi && hi <= 20000.0 => Some([lo, hi]),
        Some(_) => {
            return Err(invalid(
                file,
                "match.thickness_range_nm",
                "give [min, max] in nm with 0 < min <= max <= 20000",
            ))
        }
    };
    let recipes = raw.recipes.unwrap_or(5);
    if !(1..=100).contains(&recipes) {
        return Err(invalid(
            file,
            "match.recipes",
            format!("{recipes} is outside [1, 100]"),
        ));
    }
    Ok(Search {
        tolerance_de00: tol,
        max_colourants,
        starts,
        objective,
        max_total_pvc,
        thickness_range_nm,
        recipes,
    })
}

/// The colour grid `wavelengths_nm` (key `key`) reaches far enough into
/// the blue and the red.
pub(crate) fn check_band(file: &Path, key: &str, wavelengths_nm: &[f64]) -> Result<(), MatchError> {
    let band = (
        wavelengths_nm.first().copied().unwrap_or(f64::NAN),
        wavelengths_nm.last().copied().unwrap_or(f64::NAN),
    );
    if !(band.0 <= BAND_NM.0 && band.1 >= BAND_NM.1) {
        return Err(invalid(
            file,
            key,
            format!(
                "the colour grid is the band of these wavelengths, {}–{} nm; it must reach {} nm \
                 or below and {} nm or above",
                band.0, band.1, BAND_NM.0, BAND_NM.1
            ),
        ));
    }
    Ok(())
}
