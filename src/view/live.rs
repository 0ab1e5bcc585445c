//! Live recompute: scenes a fast model recomputes in milliseconds, with the
//! parameters the page offers as controls.
//!
//! [`LiveModel`] is the hook: a model names its parameters ([`Param`]) and
//! gives the page's data for any values of them. [`RadiativeTransfer`] is
//! the classical baseline of a scene (`appearance.baseline`, its first
//! model; Kubelka–Munk when it names none): the pigments' volume fractions,
//! the layer's thickness and the paper's albedo are its controls. The
//! baseline's body is diffuse: the page draws it as a Lambertian body of the
//! baseline's 45°/0° colour (gamut mapped) under the binder's flat surface,
//! whose specular reflectance is Fresnel's (`optics::baseline::fresnel`,
//! the law the model uses), and says so.

use serde::Serialize;

use super::result::{page_colours, rgb_to_xyz, PageResult};
use super::table::{display_rgb, PageBrdf};
use super::ViewError;
use crate::config::{Baseline, Measurement, Scene};
use crate::optics::baseline::{self, BaselineColour, BaselineInput};
use crate::optics::colour::Observer;
use crate::output::h5::{MeasuredRecord, MeasuredSpectrum};
use crate::pipeline::baseline::baseline_input;

/// One control of a live model.
#[derive(Debug, Clone, Serialize)]
pub struct Param {
    pub key: String,
    pub label: String,
    pub unit: String,
    pub min: f64,
    pub max: f64,
    pub step: f64,
    pub value: f64,
}

impl Param {
    /// A pigment's volume fraction, 0–0.55.
    pub fn volume_fraction(key: String, label: String, value: f64) -> Param {
        Param::ranged(key, label, "1", (0.0, 0.55, 0.005), value)
    }

    /// A layer's thickness, 100 nm – 20 µm.
    pub fn thickness(key: String, label: String, value: f64) -> Param {
        Param::ranged(key, label, "nm", (100.0, 20000.0, 50.0), value)
    }

    /// The paper's albedo, 0–1.
    pub fn paper_albedo(value: f64) -> Param {
        Param::ranged(
            "paper_albedo".into(),
            "paper albedo".into(),
            "1",
            (0.0, 1.0, 0.01),
            value,
        )
    }

    /// A control over `(min, max, step)`.
    pub fn ranged(
        key: String,
        label: String,
        unit: &str,
        (min, max, step): (f64, f64, f64),
        value: f64,
    ) -> Param {
        Param {
            key,
            label,
            unit: unit.into(),
            min,
            max,
            step,
            value,
        }
    }
}

/// A model the server recomputes when a control moves.
pub trait LiveModel: Send {
    /// What it is, in words, for the page.
    fn describe(&self) -> String;
    /// Its controls, with their starting values.
    fn params(&self) -> Vec<Param>;
    /// The page's data at `values` (one per parameter, in order, already
    /// within their ranges).
    fn compute(&self, values: &[f64]) -> Result<PageResult, ViewError>;
}

/// Why a scene cannot be recomputed live.
pub(super) fn not_live(scene: &Scene, why: &str) -> ViewError {
    ViewError::NotLive {
        path: scene.path().to_path_buf(),
        why: why.to_string(),
    }
}

/// A scene's radiative-transfer baseline (module docs).
pub struct RadiativeTransfer {
    name: String,
    model: Baseline,
    input: BaselineInput,
    names: Vec<String>,
    observer: Observer,
}

impl RadiativeTransfer {
    pub fn new(scene: &Scene) -> Result<RadiativeTransfer, ViewError> {
        if scene.stack.is_some() {
            return Err(not_live(
                scene,
                "a stack: its live model is the stack's (view::live_stack)",
            ));
        }
        let input = baseline_input(scene)
            .map_err(|e| not_live(scene, &e.to_string()))?
            .ok_or_else(|| not_live(scene, "the baselines need paper of one albedo"))?;
        Ok(RadiativeTransfer {
            name: scene.output.name.clone(),
            model: scene
                .appearance
                .baseline
                .first()
                .copied()
                .unwrap_or(Baseline::KubelkaMunk),
            names: scene.species.iter().map(|s| s.name.clone()).collect(),
            input,
            observer: Observer::standard(scene.appearance.illuminant, scene.appearance.observer),
        })
    }
}

impl LiveModel for RadiativeTransfer {
    fn describe(&self) -> String {
        format!(
            "radiative transfer ({}), recomputed live; drawn as a Lambertian body of its 45°/0° \
             colour under the binder's Fresnel surface",
            self.model.name()
        )
    }

    fn params(&self) -> Vec<Param> {
        let mut p: Vec<Param> = self
            .input
            .species
            .iter()
            .zip(&self.names)
            .enumerate()
            .map(|(k, (s, name))| {
                Param::volume_fraction(
                    format!("pvc{k}"),
                    format!("volume fraction of {name}"),
                    s.volume_fraction,
                )
            })
            .collect();
        p.push(Param::thickness(
            "thickness_nm".into(),
            "layer thickness".into(),
            self.input.thickness_nm,
        ));
        p.push(Param::paper_albedo(self.input.paper_albedo));
        p
    }

    fn compute(&self, values: &[f64]) -> Result<PageResult, ViewError> {
        let ns = self.input.species.len();
        let input = self.input.with_recipe(
            &values[..ns.min(values.len())],
            values.get(ns).copied().unwrap_or(self.input.thickness_nm),
            values
                .get(ns + 1)
                .copied()
                .unwrap_or(self.input.paper_albedo),
        );
        let geometries = Measurement::ALL;
        let colours =
            baseline::baseline_colours(self.model, &input, &geometries, &|_| None, &self.observer)
                .map_err(|e| ViewError::Live(e.to_string()))?;
        baseline_page(
            &self.name,
            self.describe(),
            self.model,
            &input,
            &colours,
            &self.observer,
        )
    }
}

/// The page's data of a baseline's colours: the colours and spectra in
/// every geometry, and the object drawn as a Lambertian body of the 45°/0°
/// colour (gamut mapped) under the binder's Fresnel surface (of `top`, the
/// layer the light meets first).
pub(super) fn baseline_page(
    name: &str,
    description: String,
    model: Baseline,
    top: &BaselineInput,
    colours: &[BaselineColour],
    observer: &Observer,
) -> Result<PageResult, ViewError> {
    let records: Vec<MeasuredRecord> = colours
        .iter()
        .map(|c| MeasuredRecord {
            geometry: c.geometry.name().to_string(),
            lab: c.lab,
            xyz: [f64::NAN; 3],
            lab_se: None,
            de00_se: None,
        })
        .collect();
    let spectra: Vec<MeasuredSpectrum> = colours
        .iter()
        .map(|c| MeasuredSpectrum {
            geometry: c.geometry.name().to_string(),
            wavelengths_nm: c.spectrum_wavelengths_nm.clone(),
            spectrum: c.reflectance_factor.clone(),
            solved_nm: vec![],
            solved: vec![],
        })
        .collect();
    let obs = observer;
    let colours = page_colours(&records, &spectra, obs);
    let lab = colours
        .iter()
        .find(|c| c.geometry == Measurement::FortyFiveZero.name())
        .map(|c| c.lab)
        .ok_or_else(|| ViewError::Live("no 45°/0° colour".into()))?;
    let fresnel = baseline::surfaces(model, top.equation);
    let n = top.binder_index;
    let brdf = PageBrdf::lambertian(
        display_rgb(obs, lab),
        &|t| fresnel.external(n, t.min(89.9)),
        "Lambertian body of the model's 45°/0° colour (gamut mapped) under the binder's \
         Fresnel surface"
            .into(),
    );
    Ok(PageResult {
        name: format!("{name} (live)"),
        model: description,
        conditions: match obs.conditions() {
            Some((ill, o)) => format!("{ill}, {}°", o.degrees()),
            None => "custom observer".into(),
        },
        colours,
        brdf,
        labels: vec![],
        rgb_to_xyz: rgb_to_xyz(obs),
        white_xyz: obs.white_xyz(),
        sparkle: None,
    })
}
