//! Live recompute of a stack of layers (`[[stack]]`): the adding–doubling
//! baseline of its layers (each layer's radiative-transfer slab, added
//! under the surface; layers printed on part of the area mixed by
//! Yule–Nielsen as the wave stack mixes them). Its controls are each
//! layer's pigments' volume fractions and thickness, each layer's coverage
//! and the paper's albedo. The page draws the result as the single layer's
//! live model does ([`super::live::baseline_page`]).

use super::live::{baseline_page, not_live, LiveModel, Param};
use super::result::PageResult;
use super::ViewError;
use crate::config::{Baseline, Measurement, Scene};
use crate::optics::baseline::{self, BaselineInput};
use crate::optics::colour::Observer;
use crate::pipeline::baseline::baseline_input;

/// A stack's adding–doubling baseline (module docs).
pub struct StackTransfer {
    name: String,
    model: Baseline,
    /// Per layer, top first: its baseline input and its pigments' names.
    layers: Vec<(BaselineInput, Vec<String>)>,
    coverage: Vec<f64>,
    yule_nielsen_n: f64,
    observer: Observer,
}

impl StackTransfer {
    pub fn new(scene: &Scene) -> Result<StackTransfer, ViewError> {
        let stack = scene
            .stack
            .as_ref()
            .ok_or_else(|| not_live(scene, "not a stack"))?;
        // The Kubelka–Munk models are of one layer: a stack takes the
        // adding–doubling one the scene names, else the scene's boundary.
        let model = match scene.appearance.baseline.first() {
            Some(&m @ (Baseline::AddingDoubling | Baseline::AddingDoublingContact)) => m,
            _ => Baseline::AddingDoubling,
        };
        let mut layers = Vec::new();
        for i in 0..stack.layers.len() {
            let layer = scene
                .stack_layer(i)
                .ok_or_else(|| not_live(scene, "a stack layer could not be made"))?;
            let input = baseline_input(&layer)
                .map_err(|e| not_live(scene, &e.to_string()))?
                .ok_or_else(|| not_live(scene, "the baselines need paper of one albedo"))?;
            let names = layer.species.iter().map(|s| s.name.clone()).collect();
            layers.push((input, names));
        }
        Ok(StackTransfer {
            name: scene.output.name.clone(),
            model,
            layers,
            coverage: stack.layers.iter().map(|l| l.coverage).collect(),
            yule_nielsen_n: stack.yule_nielsen_n,
            observer: Observer::standard(scene.appearance.illuminant, scene.appearance.observer),
        })
    }
}

impl LiveModel for StackTransfer {
    fn describe(&self) -> String {
        format!(
            "radiative transfer of a stack of {} layers ({}, the layers added under the \
             surface), recomputed live; drawn as a Lambertian body of its 45°/0° colour under \
             the top binder's Fresnel surface",
            self.layers.len(),
            self.model.name()
        )
    }

    fn params(&self) -> Vec<Param> {
        let mut p = Vec::new();
        for (l, (input, names)) in self.layers.iter().enumerate() {
            let layer = l + 1;
            for (k, (s, name)) in input.species.iter().zip(names).enumerate() {
                p.push(Param::volume_fraction(
                    format!("layer{layer}_pvc{k}"),
                    format!("layer {layer}: volume fraction of {name}"),
                    s.volume_fraction,
                ));
            }
            p.push(Param::thickness(
                format!("layer{layer}_thickness_nm"),
                format!("layer {layer}: thickness"),
                input.thickness_nm,
            ));
            p.push(Param::ranged(
                format!("layer{layer}_coverage"),
                format!("layer {layer}: area coverage"),
                "1",
                (0.0, 1.0, 0.01),
                self.coverage[l],
            ));
        }
        p.push(Param::paper_albedo(self.layers[0].0.paper_albedo));
        p
    }

    fn compute(&self, values: &[f64]) -> Result<PageResult, ViewError> {
        let mut at = 0;
        let mut next = |default: f64| {
            let v = values.get(at).copied().unwrap_or(default);
            at += 1;
            v
        };
        let mut recipes = Vec::new();
        for (l, (input, _)) in self.layers.iter().enumerate() {
            let fractions: Vec<f64> = input
                .species
                .iter()
                .map(|s| next(s.volume_fraction))
                .collect();
            let thickness = next(input.thickness_nm);
            let coverage = next(self.coverage[l]);
            recipes.push((fractions, thickness, coverage));
        }
        let albedo = next(self.layers[0].0.paper_albedo);
        let inputs: Vec<BaselineInput> = self
            .layers
            .iter()
            .zip(&recipes)
            .map(|((input, _), (f, t, _))| input.with_recipe(f, *t, albedo))
            .collect();
        let coverage: Vec<f64> = recipes.iter().map(|r| r.2).collect();
        let colours = baseline::stack_baseline_colours(
            self.model,
            &inputs,
            (&coverage, self.yule_nielsen_n),
            &Measurement::ALL,
            &|_| None,
            &self.observer,
        )
        .map_err(|e| ViewError::Live(e.to_string()))?;
        baseline_page(
            &self.name,
            self.describe(),
            self.model,
            &inputs[0],
            &colours,
            &self.observer,
        )
    }
}
