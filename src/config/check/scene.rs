//! The whole scene: its parts checked in file order, every material checked
//! against every wavelength, the input hash, and the output folder and name.

use super::Checker;
use crate::config::raw::{RawConfig, RawOutput, RawProduct, RawRealisations};
use crate::config::{
    ConfigError, GrainShape, Material, OutputSpec, Provenance, RealisationTarget, Scene, Structure,
    Substrate, Surface,
};
use sha2::{Digest, Sha256};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

const DEFAULT_SEED: u64 = 1;

/// What of a config's text decides its results: the parsed tables without
/// `[output]` (where results go changes nothing in them), written back in
/// one canonical form (sorted keys, no comments or layout), so that moving
/// a study, `--output-dir`, comments and key order keep its results valid.
pub(super) fn result_defining_text(text: &str) -> String {
    match text.parse::<toml::Table>() {
        Ok(mut t) => {
            t.remove("output");
            toml::to_string(&t).unwrap_or_else(|_| text.to_string())
        }
        // Unreachable for a checked config (it parsed); hash the text as is.
        Err(_) => text.to_string(),
    }
}

/// The hasher's digest as lowercase hex.
pub(super) fn hex_digest(hasher: Sha256) -> String {
    let mut out = String::with_capacity(64);
    for b in hasher.finalize() {
        let _ = write!(out, "{b:02x}");
    }
    out
}

const MAX_REALISATIONS: i64 = 10_000;

impl Checker<'_> {
    pub(super) fn scene(
        &self,
        path: &Path,
        text: &str,
        raw: RawConfig,
    ) -> Result<Scene, ConfigError> {
        let seed = match raw.seed {
            None => DEFAULT_SEED,
            Some(s) if s >= 0 => s as u64,
            Some(s) => return Err(self.invalid("seed", format!("must be >= 0, got {s}"))),
        };
        let (realisations, realisation_target) = self.realisations(raw.realisations.as_ref())?;
        let (layer, structure, species, grid, stack) = match &raw.layer {
            _ if !raw.stack.is_empty() => {
                let s = self.stack(&raw)?;
                (s.layer, None, s.species, s.grid, Some(s.stack))
            }
            None => return Err(self.invalid(
                "layer",
                "missing: give [layer] (one layer) or [[stack]] tables (layers from the top down)",
            )),
            Some(raw_layer) => {
                if raw.stacking.is_some() {
                    return Err(self.invalid(
                        "stacking",
                        "goes with [[stack]]: a single [layer] has nothing to stack",
                    ));
                }
                let layer = self.layer(raw_layer)?;
                let structure = match &raw.structure {
                    None => None,
                    Some(st) => Some(self.structure(st, &layer)?),
                };
                let species = if structure.is_some() {
                    if !raw.pigment.is_empty() || raw_layer.pvc.is_some() {
                        return Err(self.invalid(
                            "structure",
                            "an explicit structure replaces the generated grains: remove [[pigment]] and layer.pvc",
                        ));
                    }
                    Vec::new()
                } else {
                    self.pigments(&raw.pigment, &layer, raw_layer.pvc)?
                };
                let grid = self.grid(&raw.grid, &layer)?;
                (layer, structure, species, grid, None)
            }
        };
        let (wavelengths_nm, wl_key) = self.wavelengths(&raw.illumination)?;
        let incidence = self.incidence(&raw.illumination)?;
        // Generated grains are random; an ensemble of them averages
        // random-phase natural light's cross term (and counts it).
        let random_layer = structure.is_none() && stack.is_none();
        let ensemble = random_layer && (realisations >= 2 || realisation_target.is_some());
        let solver = self.solver(
            raw.solver.as_ref(),
            raw.illumination.polarisation,
            random_layer,
            ensemble,
        )?;
        let output = self.output(path, raw.output.as_ref())?;
        // An incoherent stack's default outputs are its tile alone: the
        // BRDF at every azimuth (the default "brdf") is not made there.
        let default_outputs: &[RawProduct] = if stack
            .as_ref()
            .is_some_and(|s| s.coupling == crate::config::StackCoupling::Incoherent)
        {
            &[RawProduct::Tile]
        } else {
            &[RawProduct::Brdf, RawProduct::Tile]
        };
        let appearance = self.appearance(raw.appearance.as_ref(), &incidence, default_outputs)?;
        if realisation_target.is_some() && !appearance.products.tile {
            return Err(self.invalid(
                "realisations.target_de00",
                "a target uncertainty of colour needs the colours: add \"tile\" to appearance.outputs, or give a count",
            ));
        }
        let substrate = self.substrate(raw.substrate.as_ref(), &wavelengths_nm)?;
        if stack
            .as_ref()
            .is_some_and(|s| s.coupling == crate::config::StackCoupling::Incoherent)
            && matches!(substrate, Substrate::Csv(_) | Substrate::Chart { .. })
        {
            return Err(self.invalid(
                "substrate.kind",
                format!(
                    "a {} ground is not available for an incoherent [[stack]] yet (its adding \
                     method takes one constant albedo): use \"paper\", \"white\" or \"black\"",
                    substrate.kind()
                ),
            ));
        }
        if let Some(st) = &stack {
            self.stack_products(st, &appearance, realisation_target.is_some())?;
        }
        if solver.equation == crate::config::Equation::Helmholtz
            && grid.voxel_permittivity == crate::config::VoxelPermittivity::Anisotropic
        {
            return Err(self.invalid(
                "grid.voxel_permittivity",
                "\"anisotropic\" treats the field components along and across a grain surface \
                 apart, and the scalar Helmholtz equation has one component: use \
                 solver.equation = \"maxwell\", or \"average\" or \"auto\"",
            ));
        }
        if solver.equation == crate::config::Equation::Maxwell {
            // What does not honour both polarisations yet is refused rather
            // than mixed silently into a Maxwell result.
            // Layers solved one by one couple by natural light's fluxes.
            let incoherent = stack
                .as_ref()
                .is_some_and(|s| s.coupling == crate::config::StackCoupling::Incoherent);
            if incoherent && solver.polarisation != crate::config::Polarisation::Unpolarised {
                return Err(self.invalid(
                    "illumination.polarisation",
                    "a [[stack]] solved layer by layer combines natural light's fluxes \
                     between its layers: \"unpolarised\" only (or stacking.coupling = \
                     \"coherent\")",
                ));
            }
            // The baselines are computed for natural light (Mie grains,
            // unpolarised surfaces): beside an unpolarised solve only.
            let polarised = solver.polarisation != crate::config::Polarisation::Unpolarised;
            if !appearance.baseline.is_empty() && polarised {
                return Err(self.invalid(
                    "appearance.baseline",
                    "beside a Maxwell solve the radiative-transfer baselines are for natural \
                     light (Mie grains, unpolarised Fresnel surfaces) and cannot stand beside \
                     one linear polarisation: remove appearance.baseline or \
                     illumination.polarisation",
                ));
            }
        }
        if !appearance.baseline.is_empty() {
            let why = if structure.is_some() {
                Some("the baseline is computed from the pigments' grains: an explicit structure has none")
            } else if substrate.ground().and_then(|g| g.constant()).is_none() {
                Some(
                    "the baseline is a layer on a ground of one albedo: give substrate = \
                      { kind = \"paper\" } or { kind = \"white\" }, or a chart's white_albedo",
                )
            } else if !appearance.products.tile {
                Some("the baseline is reported beside the measured colours: add \"tile\" to appearance.outputs")
            } else {
                None
            };
            if let Some(why) = why {
                return Err(self.invalid("appearance.baseline", why));
            }
        }
        if layer.surface != Surface::Flat {
            let molecular =
                !species.is_empty() && species.iter().all(|s| s.shape == GrainShape::Molecular);
            if molecular || matches!(structure, Some(Structure::Hdf5(_))) {
                return Err(self.invalid(
                    "layer.surface",
                    if molecular {
                        "a molecular mixture is a homogeneous slab solved in closed form, whose surface is flat: remove layer.surface"
                    } else {
                        "an ε grid read from a file carries its own surface: remove layer.surface"
                    },
                ));
            }
        }

        let mut materials: Vec<(&Material, String)> = species
            .iter()
            .map(|s| (&s.material, format!("pigment `{}`", s.name)))
            .collect();
        if let Some(Structure::Primitives(ps)) = &structure {
            materials.extend(
                ps.iter()
                    .enumerate()
                    .map(|(i, p)| (&p.material, format!("structure.primitive[{i}]"))),
            );
        }
        self.coverage(wl_key, &wavelengths_nm, &materials)?;

        let mut hasher = Sha256::new();
        hasher.update(result_defining_text(text).as_bytes());
        for s in &species {
            hasher.update(s.material.table_bytes());
        }
        match &structure {
            Some(Structure::Primitives(ps)) => {
                for p in ps {
                    hasher.update(p.material.table_bytes());
                }
            }
            Some(Structure::Hdf5(path)) => {
                let bytes = std::fs::read(path).map_err(|source| ConfigError::Read {
                    file: path.clone(),
                    source,
                })?;
                hasher.update(&bytes);
            }
            None => {}
        }
        if let Some(g) = substrate.spectrum() {
            hasher.update(&g.bytes);
        }
        let input_hash = hex_digest(hasher);

        Ok(Scene {
            provenance: Provenance {
                path: path.to_path_buf(),
                text: text.to_string(),
                input_hash,
            },
            seed,
            realisations,
            realisation_target,
            layer,
            species,
            grid,
            wavelengths_nm,
            incidence,
            solver,
            output,
            appearance,
            substrate,
            structure,
            stack,
        })
    }

    /// `realisations`: a count, or a target ΔE00 standard error with the
    /// fewest and most realisations it may take. Returns the most
    /// realisations a run may make and the target, if any.
    fn realisations(
        &self,
        raw: Option<&RawRealisations>,
    ) -> Result<(usize, Option<RealisationTarget>), ConfigError> {
        let count = |key: &str, r: i64, lo: i64| {
            if (lo..=MAX_REALISATIONS).contains(&r) {
                Ok(r as usize)
            } else {
                Err(self.invalid(
                    key,
                    format!("must be in [{lo}, {MAX_REALISATIONS}], got {r}"),
                ))
            }
        };
        match raw {
            None => Ok((1, None)),
            Some(RawRealisations::Count(r)) => Ok((count("realisations", *r, 1)?, None)),
            Some(RawRealisations::Target(t)) => {
                let de00 = t.target_de00;
                if !(de00.is_finite() && de00 > 0.0) {
                    return Err(self.invalid(
                        "realisations.target_de00",
                        format!("must be a ΔE00 standard error > 0, got {de00}"),
                    ));
                }
                let min = count("realisations.min", t.min.unwrap_or(3), 2)?;
                let max = count("realisations.max", t.max, 2)?;
                if max < min {
                    return Err(self.invalid(
                        "realisations.max",
                        format!("must be at least realisations.min = {min}, got {max}"),
                    ));
                }
                Ok((max, Some(RealisationTarget { de00, min })))
            }
        }
    }

    /// Every material has data at every wavelength: the first gap (in
    /// wavelength order, then in `materials` order) is an error on `key`
    /// naming the material and whose it is.
    pub(super) fn coverage(
        &self,
        key: &str,
        wavelengths_nm: &[f64],
        materials: &[(&Material, String)],
    ) -> Result<(), ConfigError> {
        for &wl in wavelengths_nm {
            for (m, whose) in materials {
                if m.index_at(wl).is_none() {
                    let (lo, hi) = m.range_nm();
                    return Err(self.invalid(
                        key,
                        format!(
                            "wavelength {wl} nm is outside the data range [{lo}, {hi}] nm of \
                             material {m} ({whose})"
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    pub(super) fn output(
        &self,
        path: &Path,
        raw: Option<&RawOutput>,
    ) -> Result<OutputSpec, ConfigError> {
        let stem = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .filter(|s| !s.is_empty())
            .unwrap_or_else(|| "scene".to_string());
        let dir = match raw.and_then(|o| o.dir.as_deref()) {
            Some(d) if d.trim().is_empty() => {
                return Err(self.invalid("output.dir", "must not be empty"))
            }
            Some(d) => PathBuf::from(d),
            None => Path::new("runs").join(&stem),
        };
        let (name, from_stem) = match raw.and_then(|o| o.name.clone()) {
            Some(n) => (n, false),
            None => (stem, true),
        };
        let valid = !name.is_empty()
            && name != "."
            && name != ".."
            && name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '.' | '-'));
        if !valid {
            let origin = if from_stem {
                " (defaulted from the config file name; set output.name)"
            } else {
                ""
            };
            return Err(self.invalid(
                "output.name",
                format!("must be non-empty and use only A-Z a-z 0-9 _ . -, got `{name}`{origin}"),
            ));
        }
        Ok(OutputSpec { dir, name })
    }
}
