//! `[[stack]]` (layers from the top down, each a `layer` table and its
//! `pigment` tables, checked as `[layer]` and `[[pigment]]` are, errors
//! naming `stack[i].…`) and `[stacking]` (coupling and directions).

use super::{Checker, REL_EPS};
use crate::config::raw::{RawConfig, RawStacking};
use crate::config::{
    Baseline, ConfigError, GridSpec, Layer, Species, Stack, StackCoupling, StackLayer, Surface,
    DEFAULT_ESCAPE_DIRECTIONS, DEFAULT_TRAPPED_DIRECTIONS, MAX_STACK_DIRECTIONS, MAX_STACK_LAYERS,
    MAX_YULE_NIELSEN_N,
};

/// What a stack makes of the scene: the whole stack as one layer, every
/// layer's pigments (volume fractions of the whole), the grid, the stack.
pub(super) struct Stacked {
    pub layer: Layer,
    pub species: Vec<Species>,
    pub grid: GridSpec,
    pub stack: Stack,
}

impl Checker<'_> {
    pub(super) fn stack(&self, raw: &RawConfig) -> Result<Stacked, ConfigError> {
        if raw.layer.is_some() || !raw.pigment.is_empty() || raw.structure.is_some() {
            return Err(self.invalid(
                "stack",
                "[[stack]] gives the layers and their pigments: remove [layer], [[pigment]] and [structure]",
            ));
        }
        let n = raw.stack.len();
        if n > MAX_STACK_LAYERS {
            return Err(self.invalid(
                "stack",
                format!("at most {MAX_STACK_LAYERS} layers, got {n}"),
            ));
        }
        let (coupling, trapped_directions, escape_directions) =
            self.stacking(raw.stacking.as_ref())?;
        let yule_nielsen_n = match raw.stacking.as_ref().and_then(|s| s.yule_nielsen_n) {
            None => 1.0,
            Some(v) if (1.0..=MAX_YULE_NIELSEN_N).contains(&v) => v,
            Some(v) => {
                return Err(self.invalid(
                    "stacking.yule_nielsen_n",
                    format!("must be in [1, {MAX_YULE_NIELSEN_N}] (1: Murray–Davies), got {v}"),
                ))
            }
        };
        let mut layers: Vec<StackLayer> = Vec::with_capacity(n);
        for (i, rl) in raw.stack.iter().enumerate() {
            let c = Checker {
                file: self.file,
                prefix: format!("stack[{i}]."),
            };
            let layer = c.layer(&rl.layer)?;
            if layer.surface != Surface::Flat || layer.relief_fraction > 0.0 {
                return Err(c.invalid(
                    "layer",
                    "a stack's layers are flat slabs in one binder: remove surface and relief_fraction",
                ));
            }
            if let Some(top) = layers.first() {
                if layer.binder_index != top.layer.binder_index {
                    return Err(c.invalid(
                        "layer.binder_index",
                        format!(
                            "the layers of a stack share one binder: stack[0] has {}, this one {}",
                            top.layer.binder_index, layer.binder_index
                        ),
                    ));
                }
            }
            let species = c.pigments(&rl.pigment, &layer, rl.layer.pvc)?;
            for (j, s) in species.iter().enumerate() {
                let earlier = layers
                    .iter()
                    .enumerate()
                    .find(|(_, l)| l.species.iter().any(|o| o.name == s.name));
                if let Some((k, _)) = earlier {
                    return Err(c.invalid(
                        format!("pigment[{j}].name"),
                        format!("`{}` is already a pigment of stack[{k}]: names are unique across the stack", s.name),
                    ));
                }
            }
            let grid = self.grid(&raw.grid, &layer)?;
            let coverage = rl.coverage.unwrap_or(1.0);
            if !(coverage > 0.0 && coverage <= 1.0) {
                return Err(c.invalid(
                    "coverage",
                    format!("must be in (0, 1] (the share of the area printed), got {coverage}"),
                ));
            }
            if coverage < 1.0 && coupling == StackCoupling::Coherent {
                return Err(c.invalid(
                    "coverage",
                    "a halftone's dots (tens of µm) are far wider than a fragment: its areas \
                     mix whole stacks, which stacking.coupling = \"incoherent\" does; a \
                     coherent stack covers the whole area (coverage = 1)",
                ));
            }
            layers.push(StackLayer {
                layer,
                species,
                grid,
                coverage,
            });
        }
        let Some(top) = layers.first() else {
            return Err(self.invalid("stack", "at least one [[stack]] layer is required"));
        };
        let thickness_nm: f64 = layers.iter().map(|l| l.layer.thickness_nm).sum();
        let layer = Layer {
            thickness_nm,
            relief_fraction: 0.0,
            equilibrate_sweeps: 0,
            surface: Surface::Flat,
            ..top.layer.clone()
        };
        let species = layers
            .iter()
            .flat_map(|l| {
                let share = l.layer.thickness_nm / thickness_nm;
                l.species.iter().map(move |s| Species {
                    volume_fraction: s.volume_fraction * share,
                    ..s.clone()
                })
            })
            .collect();
        if coupling == StackCoupling::Coherent {
            for (i, l) in layers.iter().enumerate() {
                if let Some(j) = l
                    .species
                    .iter()
                    .position(|s| s.shape == crate::config::GrainShape::Molecular)
                {
                    return Err(self.invalid(
                        format!("stack[{i}].pigment[{j}].shape"),
                        "a coherent stack is one fragment of grains: a dissolved (molecular) \
                         pigment has none; use stacking.coupling = \"incoherent\", where such \
                         a layer is its homogeneous slab",
                    ));
                }
            }
        }
        let grid = match coupling {
            StackCoupling::Coherent => self.coherent_grid(&layers)?,
            // Each layer is solved on its own grid: the whole stack's cells
            // in z, the widest layer's across.
            StackCoupling::Incoherent => GridSpec {
                nz: layers.iter().map(|l| l.grid.nz).sum(),
                ..layers
                    .iter()
                    .map(|l| l.grid)
                    .max_by_key(|g| g.nx * g.ny)
                    .unwrap_or(top.grid)
            },
        };
        Ok(Stacked {
            layer,
            species,
            grid,
            stack: Stack {
                layers,
                coupling,
                trapped_directions,
                escape_directions,
                yule_nielsen_n,
            },
        })
    }

    /// `[stacking]`: the coupling and the adding method's directions.
    fn stacking(
        &self,
        raw: Option<&RawStacking>,
    ) -> Result<(StackCoupling, usize, usize), ConfigError> {
        let coupling = match raw.and_then(|s| s.coupling.as_deref()) {
            None | Some("incoherent") => StackCoupling::Incoherent,
            Some("coherent") => StackCoupling::Coherent,
            Some(other) => {
                return Err(self.invalid(
                    "stacking.coupling",
                    format!("must be \"incoherent\" or \"coherent\", got \"{other}\""),
                ))
            }
        };
        let count = |key: &str, v: Option<i64>, default: usize| {
            let v = v.unwrap_or(default as i64);
            if (1..=MAX_STACK_DIRECTIONS as i64).contains(&v) {
                Ok(v as usize)
            } else {
                Err(self.invalid(
                    key,
                    format!("must be in [1, {MAX_STACK_DIRECTIONS}], got {v}"),
                ))
            }
        };
        Ok((
            coupling,
            count(
                "stacking.trapped_directions",
                raw.and_then(|s| s.trapped_directions),
                DEFAULT_TRAPPED_DIRECTIONS,
            )?,
            count(
                "stacking.escape_directions",
                raw.and_then(|s| s.escape_directions),
                DEFAULT_ESCAPE_DIRECTIONS,
            )?,
        ))
    }

    /// A coherent stack is one grid: every layer on the same fragment and
    /// the same z cell, so their grids stack along z.
    fn coherent_grid(&self, layers: &[StackLayer]) -> Result<GridSpec, ConfigError> {
        let top = &layers[0];
        let dz = top.layer.thickness_nm / top.grid.nz as f64;
        for (i, l) in layers.iter().enumerate().skip(1) {
            if l.layer.fragment_x_nm != top.layer.fragment_x_nm
                || l.layer.fragment_y_nm != top.layer.fragment_y_nm
            {
                return Err(self.invalid(
                    format!("stack[{i}].layer.fragment_nm"),
                    "a coherent stack is one fragment: every layer needs stack[0]'s fragment_nm",
                ));
            }
            let dz_i = l.layer.thickness_nm / l.grid.nz as f64;
            if (dz_i - dz).abs() > REL_EPS * 1e3 * dz {
                return Err(self.invalid(
                    format!("stack[{i}].layer.thickness_nm"),
                    format!(
                        "a coherent stack is one grid: each layer must be a whole number of z \
                         cells of one size (stack[0]: {dz} nm, this layer: {dz_i} nm); make the \
                         thicknesses multiples of grid.z_cell_nm"
                    ),
                ));
            }
        }
        Ok(GridSpec {
            nz: layers.iter().map(|l| l.grid.nz).sum(),
            ..top.grid
        })
    }
}

impl Checker<'_> {
    /// What a stack can report: an incoherent stack's adding carries a few
    /// azimuthal Fourier terms of each layer's scattering, which give the
    /// measurement geometries, the white sky and the plane of incidence
    /// but not the BRDF at every azimuth; baselines are for one layer.
    pub(super) fn stack_products(
        &self,
        stack: &Stack,
        appearance: &crate::config::Appearance,
        target: bool,
    ) -> Result<(), ConfigError> {
        if let Some(b) = appearance
            .baseline
            .iter()
            .find(|b| matches!(b, Baseline::KubelkaMunk | Baseline::KubelkaMunkScene))
        {
            return Err(self.invalid(
                "appearance.baseline",
                format!(
                    "{} is a model of one layer: a stack takes \"adding-doubling\" or \
                     \"adding-doubling-contact\", which add the layers' radiative-transfer slabs",
                    b.name()
                ),
            ));
        }
        if stack.coupling == StackCoupling::Coherent {
            return Ok(());
        }
        let p = appearance.products;
        if p.brdf || p.btdf || p.merl || p.preview {
            return Err(self.invalid(
                "appearance.outputs",
                "an incoherent stack reports colours, spectra and its tile (\"tile\": the BRDF \
                 in the plane of incidence): its adding carries a few azimuthal Fourier terms \
                 of the scattering, not the BRDF at every azimuth that \"brdf\", \"btdf\", \
                 \"merl\" and \"preview\" need; use stacking.coupling = \"coherent\" for them",
            ));
        }
        if target {
            return Err(self.invalid(
                "realisations.target_de00",
                "an incoherent stack runs a count of realisations: give realisations = N",
            ));
        }
        Ok(())
    }
}
