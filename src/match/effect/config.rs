//! An effect paint's match file: `[match]` (the search settings, as a
//! scene's match), `[target]` of `kind = "multi-angle"` (CIELAB per
//! aspecular geometry), `base` (a paint file's table: `[base.paint]` inline
//! or `base = "paint.toml"`) and `[[unknown]]` (what the search varies:
//! `kind = "flakes"`, a layer's flake concentration and, for coated flakes,
//! the coating's thickness; `kind = "pigment"`, the volume fraction of one
//! of a layer's ordinary pigments). Raw serde structs deny unknown keys;
//! every error names the file, the key and what is allowed. The base is
//! checked by the paint checker itself (`inksim check` of a paint file).

use serde::Deserialize;
use std::path::{Path, PathBuf};
use toml::Value;

use crate::config::paint::{PaintScene, ReflectorSpec, MAX_FLAKE_FRACTION};
use crate::config::{parse_paint, Illuminant, StandardObserver, MAX_PVC};
use crate::optics::flakes::multiangle::{Geometry, ASPECULAR_15_DEG, ASPECULAR_45_DEG};
use crate::study::sweep::base_table;

use super::super::config::{
    check_band, check_conditions, check_settings, from_toml, invalid, output_names, three,
    RawSettings, Search,
};
use super::super::MatchError;

/// Largest coating thickness of an interference flake, nm.
pub const MAX_COATING_NM: f64 = 1000.0;

/// The multi-angle target: CIELAB per geometry under an illuminant and
/// observer, with its measurement noise.
#[derive(Debug, Clone)]
pub struct AngleTarget {
    pub colour: Vec<(Geometry, [f64; 3])>,
    pub illuminant: Illuminant,
    pub observer: StandardObserver,
    /// 1σ noise of L*, a*, b*.
    pub noise_lab: [f64; 3],
}

/// A layer's flakes as unknowns: always in every recipe.
#[derive(Debug, Clone, PartialEq)]
pub struct FlakeUnknown {
    /// The layer's name and its index in the paint (top first).
    pub layer: String,
    pub layer_index: usize,
    /// Bounds of the flakes' volume fraction of the layer.
    pub concentration_range: [f64; 2],
    /// Bounds of a coated flake's coating thickness, nm (None: fixed at
    /// the base's).
    pub coating_nm_range: Option<[f64; 2]>,
}

/// One of a layer's ordinary pigments as an optional colourant.
#[derive(Debug, Clone, PartialEq)]
pub struct PigmentUnknown {
    pub layer: String,
    pub layer_index: usize,
    /// The pigment's name and its index in the layer.
    pub pigment: String,
    pub pigment_index: usize,
    /// Bounds of its volume fraction when it is used.
    pub pvc_range: [f64; 2],
}

/// A checked effect match file.
#[derive(Debug, Clone)]
pub struct EffectSpec {
    pub path: PathBuf,
    /// The file's text as checked (embedded in the result file).
    pub text: String,
    pub name: String,
    pub output_dir: PathBuf,
    pub target: AngleTarget,
    /// The base paint, checked; the unknowns replace its values.
    pub paint: PaintScene,
    pub base_path: PathBuf,
    pub flakes: Vec<FlakeUnknown>,
    /// The optional colourants, in file order.
    pub pigments: Vec<PigmentUnknown>,
    pub search: Search,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawEffectFile {
    #[serde(rename = "match")]
    settings: RawSettings,
    target: RawAngleTarget,
    base: Option<Value>,
    #[serde(default)]
    unknown: Vec<RawUnknown>,
}

#[derive(Debug, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
enum RawAngleTarget {
    MultiAngle {
        illuminant: String,
        observer_deg: u32,
        noise_lab: Option<Vec<f64>>,
        colour: Vec<RawAngleColour>,
    },
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawAngleColour {
    illumination_deg: f64,
    aspecular_deg: f64,
    lab: Vec<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
enum RawUnknown {
    Flakes {
        layer: String,
        concentration_range: Vec<f64>,
        coating_nm_range: Option<Vec<f64>>,
    },
    Pigment {
        layer: String,
        pigment: String,
        pvc_range: Vec<f64>,
    },
}

impl EffectSpec {
    /// Read and check the effect match file `path`.
    pub fn load(path: &Path) -> Result<EffectSpec, MatchError> {
        EffectSpec::parse(path, &super::super::config::read_text(path)?)
    }

    /// Parse and check effect match-file `text` read from `path`.
    pub fn parse(path: &Path, text: &str) -> Result<EffectSpec, MatchError> {
        let raw: RawEffectFile = from_toml(
            path,
            text,
            "an effect match file has [match], [target] (kind = \"multi-angle\"), base and \
             [[unknown]]",
        )?;
        refuse_unsupported(path, &raw.settings)?;
        let target = check_target(path, raw.target)?;
        let (paint, base_path) = check_base(path, raw.base)?;
        let (flakes, pigments) = check_unknowns(path, &paint, raw.unknown)?;
        let search = check_settings(path, &raw.settings, false, pigments.len())?;
        check_band(
            path,
            "base.paint.wavelength_range_nm",
            &paint.wavelengths_nm,
        )?;
        let (name, output_dir) =
            output_names(path, "match", raw.settings.name, raw.settings.output_dir)?;
        Ok(EffectSpec {
            path: path.to_path_buf(),
            text: text.to_string(),
            name,
            output_dir,
            target,
            paint,
            base_path,
            flakes,
            pigments,
            search,
        })
    }
}

/// What an effect match does not do, refused in one line each.
fn refuse_unsupported(file: &Path, raw: &RawSettings) -> Result<(), MatchError> {
    if raw.verify.is_some() {
        return Err(invalid(
            file,
            "match.verify",
            "wave-optics verification is not supported for an effect paint: the wave pipeline \
             does not model flakes (the fast flake model is checked against its Monte Carlo, \
             docs/METHOD.md); remove [match.verify]",
        ));
    }
    if raw.thickness_range_nm.is_some() {
        return Err(invalid(
            file,
            "match.thickness_range_nm",
            "not supported for an effect paint: its layers' thicknesses are the base paint's; \
             the unknowns are [[unknown]] tables",
        ));
    }
    Ok(())
}

fn check_target(file: &Path, raw: RawAngleTarget) -> Result<AngleTarget, MatchError> {
    let RawAngleTarget::MultiAngle {
        illuminant,
        observer_deg,
        noise_lab,
        colour,
    } = raw;
    let (illuminant, observer, noise_lab) =
        check_conditions(file, &illuminant, observer_deg, &noise_lab)?;
    if colour.is_empty() {
        return Err(invalid(
            file,
            "target.colour",
            "give at least one { illumination_deg, aspecular_deg, lab }",
        ));
    }
    let mut out: Vec<(Geometry, [f64; 3])> = Vec::new();
    for (i, c) in colour.iter().enumerate() {
        let key = format!("target.colour[{i}]");
        let allowed: &[f64] = if c.illumination_deg == 45.0 {
            &ASPECULAR_45_DEG
        } else if c.illumination_deg == 15.0 {
            &ASPECULAR_15_DEG
        } else {
            return Err(invalid(
                file,
                &format!("{key}.illumination_deg"),
                format!(
                    "{} is not 45 or 15 (ASTM E2194 / E2539)",
                    c.illumination_deg
                ),
            ));
        };
        if !allowed.contains(&c.aspecular_deg) {
            return Err(invalid(
                file,
                &format!("{key}.aspecular_deg"),
                format!(
                    "{} is not one of {allowed:?} (at {}° illumination)",
                    c.aspecular_deg, c.illumination_deg
                ),
            ));
        }
        let g = Geometry {
            illumination_deg: c.illumination_deg,
            aspecular_deg: c.aspecular_deg,
        };
        if out.iter().any(|(h, _)| *h == g) {
            return Err(invalid(
                file,
                &key,
                format!("geometry {} is given twice", g.label()),
            ));
        }
        let lab = three(
            file,
            &format!("{key}.lab"),
            &c.lab,
            |k, x| {
                if k == 0 {
                    (0.0..=200.0).contains(&x)
                } else {
                    x.abs() <= 200.0
                }
            },
            "L* in [0, 200] (a metallic's near-specular L* exceeds 100), a*, b* in [-200, 200]",
        )?;
        out.push((g, lab));
    }
    Ok(AngleTarget {
        colour: out,
        illuminant,
        observer,
        noise_lab,
    })
}

/// The base paint's table (inline `[base.paint]` or its own file) checked
/// by the paint checker.
fn check_base(file: &Path, base: Option<Value>) -> Result<(PaintScene, PathBuf), MatchError> {
    let (table, base_path) = base_table(file, base).map_err(|m| MatchError::Config {
        file: file.to_path_buf(),
        message: m,
    })?;
    if !table.get("paint").is_some_and(Value::is_table) {
        return Err(invalid(
            file,
            "base",
            "a multi-angle target needs an effect paint as its base: [base.paint] or base = \
             \"paint.toml\" (a file with a [paint] table)",
        ));
    }
    let text = toml::to_string(&table).map_err(|e| MatchError::Config {
        file: file.to_path_buf(),
        message: format!("base: {e}"),
    })?;
    let paint = parse_paint(&base_path, &text).map_err(|e| MatchError::Config {
        file: file.to_path_buf(),
        message: format!("base paint: {e}"),
    })?;
    Ok((paint, base_path))
}

/// `[lo, hi]` of `key` with `lo_ok(lo) && lo <= hi && hi_ok(hi)`, else one
/// error saying `what`.
fn range(
    file: &Path,
    key: &str,
    v: &[f64],
    ok: impl Fn(f64, f64) -> bool,
    what: &str,
) -> Result<[f64; 2], MatchError> {
    match *v {
        [lo, hi] if lo.is_finite() && hi.is_finite() && lo <= hi && ok(lo, hi) => Ok([lo, hi]),
        _ => Err(invalid(file, key, format!("give [min, max] with {what}"))),
    }
}

fn layer_index(
    file: &Path,
    paint: &PaintScene,
    key: &str,
    name: &str,
) -> Result<usize, MatchError> {
    paint
        .layers
        .iter()
        .position(|l| l.name == name)
        .ok_or_else(|| {
            let names: Vec<&str> = paint.layers.iter().map(|l| l.name.as_str()).collect();
            invalid(
                file,
                key,
                format!(
                    "`{name}` is not a layer of the base paint ({})",
                    names.join(", ")
                ),
            )
        })
}

fn check_unknowns(
    file: &Path,
    paint: &PaintScene,
    raw: Vec<RawUnknown>,
) -> Result<(Vec<FlakeUnknown>, Vec<PigmentUnknown>), MatchError> {
    let mut flakes: Vec<FlakeUnknown> = Vec::new();
    let mut pigments: Vec<PigmentUnknown> = Vec::new();
    for (i, u) in raw.into_iter().enumerate() {
        let key = |k: &str| format!("unknown[{i}].{k}");
        match u {
            RawUnknown::Flakes {
                layer,
                concentration_range,
                coating_nm_range,
            } => {
                let li = layer_index(file, paint, &key("layer"), &layer)?;
                let l = &paint.layers[li];
                let Some(f) = &l.flakes else {
                    return Err(invalid(
                        file,
                        &key("layer"),
                        format!("layer `{layer}` of the base paint has no flakes"),
                    ));
                };
                if flakes.iter().any(|g| g.layer_index == li) {
                    return Err(invalid(
                        file,
                        &key("layer"),
                        format!("the flakes of layer `{layer}` are given twice"),
                    ));
                }
                let concentration_range = range(
                    file,
                    &key("concentration_range"),
                    &concentration_range,
                    |lo, hi| lo > 0.0 && hi <= MAX_FLAKE_FRACTION,
                    &format!("0 < min <= max <= {MAX_FLAKE_FRACTION} (volume fraction)"),
                )?;
                let coating_nm_range = match (coating_nm_range, &f.reflector) {
                    (None, _) => None,
                    (Some(v), ReflectorSpec::Coated { substrate, coating }) => {
                        let sd = coating.thickness_sd_nm;
                        let most = (l.thickness_um * 1000.0 - substrate.thickness_nm) / 2.0;
                        let most = most.min(MAX_COATING_NM);
                        Some(range(
                            file,
                            &key("coating_nm_range"),
                            &v,
                            |lo, hi| lo >= 2.0 * sd && lo > 0.0 && hi <= most,
                            &format!(
                                "2 × the coating's thickness_sd_nm ({}) <= min <= max <= {most} \
                                 nm (the flake must fit its layer)",
                                2.0 * sd
                            ),
                        )?)
                    }
                    (Some(_), r) => {
                        return Err(invalid(
                            file,
                            &key("coating_nm_range"),
                            format!(
                                "layer `{layer}`'s flakes are `{}`: only a coated (interference) \
                                 flake has a coating",
                                r.kind()
                            ),
                        ))
                    }
                };
                flakes.push(FlakeUnknown {
                    layer,
                    layer_index: li,
                    concentration_range,
                    coating_nm_range,
                });
            }
            RawUnknown::Pigment {
                layer,
                pigment,
                pvc_range,
            } => {
                let li = layer_index(file, paint, &key("layer"), &layer)?;
                let l = &paint.layers[li];
                let Some(pi) = l.pigments.iter().position(|p| p.name == pigment) else {
                    let names: Vec<&str> = l.pigments.iter().map(|p| p.name.as_str()).collect();
                    return Err(invalid(
                        file,
                        &key("pigment"),
                        format!(
                            "`{pigment}` is not a pigment of layer `{layer}` ({})",
                            if names.is_empty() {
                                "it has none".to_string()
                            } else {
                                names.join(", ")
                            }
                        ),
                    ));
                };
                if pigments
                    .iter()
                    .any(|p| p.layer_index == li && p.pigment_index == pi)
                {
                    return Err(invalid(
                        file,
                        &key("pigment"),
                        format!("`{pigment}` of layer `{layer}` is given twice"),
                    ));
                }
                let pvc_range = range(
                    file,
                    &key("pvc_range"),
                    &pvc_range,
                    |lo, hi| lo >= 0.0 && hi > 0.0 && hi <= MAX_PVC,
                    &format!("0 <= min <= max, 0 < max <= {MAX_PVC} (volume fraction)"),
                )?;
                pigments.push(PigmentUnknown {
                    layer,
                    layer_index: li,
                    pigment,
                    pigment_index: pi,
                    pvc_range,
                });
            }
        }
    }
    if flakes.is_empty() && pigments.is_empty() {
        return Err(invalid(
            file,
            "unknown",
            "give at least one [[unknown]]: kind = \"flakes\" (layer, concentration_range, \
             coating_nm_range) or kind = \"pigment\" (layer, pigment, pvc_range)",
        ));
    }
    check_fill(file, paint, &flakes, &pigments)?;
    Ok((flakes, pigments))
}

/// Every layer's pigments and flakes at their largest bounds fit the
/// paint checker's limit on the filled volume.
fn check_fill(
    file: &Path,
    paint: &PaintScene,
    flakes: &[FlakeUnknown],
    pigments: &[PigmentUnknown],
) -> Result<(), MatchError> {
    for (li, l) in paint.layers.iter().enumerate() {
        let mut total = 0.0;
        for (pi, p) in l.pigments.iter().enumerate() {
            total += pigments
                .iter()
                .find(|u| u.layer_index == li && u.pigment_index == pi)
                .map_or(p.volume_fraction, |u| u.pvc_range[1]);
        }
        total += match (&l.flakes, flakes.iter().find(|u| u.layer_index == li)) {
            (_, Some(u)) => u.concentration_range[1],
            (Some(f), None) => f.volume_fraction,
            (None, None) => 0.0,
        };
        if total > MAX_PVC {
            return Err(invalid(
                file,
                "unknown",
                format!(
                    "at their largest bounds the pigments and flakes of layer `{}` fill \
                     {total:.3} of it; at most {MAX_PVC} in all",
                    l.name
                ),
            ));
        }
    }
    Ok(())
}
