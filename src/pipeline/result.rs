//! A run's result file assembled from its parts: the scene's identity and
//! plan, the layer (particles, statistics, fractions, grid), the solves, the
//! realisations, the pictures and the appearance, handed to the HDF5 writer.

use std::path::{Path, PathBuf};

use crate::config::{Scene, Structure};
use crate::geometry::{self, Geometry, StatsParams};
use crate::optics::appearance::Appearance;
use crate::optics::farfield::SolveEntry;
use crate::output::h5::{self, GeometrySummary, RealisationStop, ResultSet, StackTables};
use crate::raster::Raster;

use super::grains::{fragment_nm, grid_of};
use super::PipelineError;

/// What a finished run produced.
pub struct RunReport {
    pub result_path: PathBuf,
    /// The tile (or the orders picture when a BRDF or BTDF but no tile was
    /// asked for); None when `outputs` asks for neither.
    pub picture_path: Option<PathBuf>,
    /// Every reflected order of every solve, drawn per wavelength and angle
    /// (with a BRDF or BTDF output).
    pub orders_picture_path: Option<PathBuf>,
    /// The plots, when the run assembled its appearance:
    /// `<name>-spectra.png` (R, T, A against wavelength),
    /// `<name>-brdf-plane.png` (the BRDF in the plane of incidence) and
    /// `<name>-brdf-polar.png` (the BRDF as a polar map).
    pub plot_paths: Vec<PathBuf>,
    /// Geometry of realisation 0 (None for a molecular mixture).
    pub geometry: Option<Geometry>,
    pub entries: Vec<SolveEntry>,
    pub appearance: Option<Appearance>,
}

/// Everything a result file is made from.
#[derive(Clone, Copy)]
pub struct ResultParts<'a> {
    pub scene: &'a Scene,
    /// The particle set of realisation 0 (None without generated grains).
    pub geometry: Option<&'a Geometry>,
    /// The raster of realisation 0 or of explicit primitives.
    pub raster: Option<&'a Raster>,
    pub entries: &'a [SolveEntry],
    /// Seed and achieved PVC of each realisation.
    pub realisations: &'a [(u64, f64)],
    /// Why the realisations stopped, for a scene with a target.
    pub realisation_stop: Option<RealisationStop>,
    /// The plan as stored ([`super::plan_text`]).
    pub plan: &'a str,
    /// The orders picture (or the geometry picture of `inksim geometry`).
    pub orders_png: &'a [u8],
    pub tile_png: Option<&'a [u8]>,
    pub appearance: Option<&'a Appearance>,
    /// A stack solved layer by layer (then `appearance` is None).
    pub stack: Option<&'a StackTables>,
}

impl ResultParts<'_> {
    /// Write the result file to `path` (atomically, see [`h5::write_result`]).
    pub fn write(&self, path: &Path) -> Result<(), PipelineError> {
        let ResultParts {
            scene,
            geometry,
            raster,
            entries,
            realisations,
            realisation_stop,
            plan,
            orders_png,
            tile_png,
            appearance,
            stack,
        } = *self;
        let mut centers = Vec::new();
        let mut radii = Vec::new();
        let mut particle_of_sphere = Vec::new();
        let mut species_of_particle = Vec::new();
        let mut names: Vec<String> = scene.species.iter().map(|s| s.name.clone()).collect();
        let mut targets: Vec<f64> = scene.species.iter().map(|s| s.volume_fraction).collect();
        if let Some(Structure::Primitives(ps)) = &scene.structure {
            names = ps
                .iter()
                .enumerate()
                .map(|(i, p)| format!("primitive[{i}] {}", p.material.name))
                .collect();
            targets = raster.map(|r| r.mean_fractions()).unwrap_or_default();
        }
        if let Some(g) = geometry {
            for (i, p) in g.particles.iter().enumerate() {
                species_of_particle.push(p.species as u32);
                for s in &p.spheres {
                    centers.push(s.center);
                    radii.push(s.radius);
                    particle_of_sphere.push(i as u32);
                }
            }
        }
        let statistics = geometry.map(|g| geometry::analyse(g, &StatsParams::default()));
        // Grains: what the packer achieved; an explicit structure is its raster
        // (an ε grid has no fractions); a molecular mixture is exactly its
        // target composition, without a grid.
        let achieved =
            geometry.map_or_else(|| targets.clone(), |g| g.stats.achieved_fraction.clone());
        let raster_fraction = match raster {
            Some(r) => r.mean_fractions(),
            None if scene.structure.is_some() => Vec::new(),
            None => targets.clone(),
        };
        let min_gap = geometry.map(|g| g.stats.min_gap_nm);
        let grid = match raster {
            Some(r) => [r.grid.nx, r.grid.ny, r.grid.nz],
            None if scene.structure.is_some() || scene.stack.is_some() => {
                let g = grid_of(scene);
                [g.nx, g.ny, g.nz]
            }
            None => [0, 0, 0],
        };
        let created = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.as_secs())
            .unwrap_or(0);
        let config_path = scene.provenance.path.display().to_string();
        let set = ResultSet {
            version: crate::VERSION,
            config_path: &config_path,
            config_text: &scene.provenance.text,
            input_hash: &scene.provenance.input_hash,
            plan,
            seed: scene.seed,
            created_unix_s: created,
            geometry: GeometrySummary {
                species_names: &names,
                centers_nm: &centers,
                radii_nm: &radii,
                particle_of_sphere: &particle_of_sphere,
                species_of_particle: &species_of_particle,
                target_fraction: &targets,
                achieved_fraction: &achieved,
                raster_fraction: &raster_fraction,
                min_gap_nm: min_gap,
                statistics: statistics.as_ref(),
            },
            grid,
            size_nm: fragment_nm(scene),
            entries,
            picture_png: (!orders_png.is_empty()).then_some(orders_png),
            realisations,
            realisation_stop,
            appearance,
            tile_png,
            stack,
        };
        h5::write_result(path, &set)?;
        Ok(())
    }
}
