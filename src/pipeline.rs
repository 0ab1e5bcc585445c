//! The one module that wires the stages together:
//! config → geometry → raster → solver → farfield → render → io.
//!
//! The geometry and the λ-independent raster (volume fractions) are built
//! once; per wavelength only ε is recomputed; per incidence only the solve.
//! The output folder is checked before any work so a bad path fails fast, and
//! results are written atomically (temp file + rename), so an interrupted run
//! leaves either the previous file or the complete new one.

use crate::config::{GrainOrientation, GrainShape, Scene};
use crate::farfield::{self, SolveEntry};
use crate::geometry::{
    self, DynParams, DynSpecies, Geometry, Orientation, PackParams, Shape, SpeciesParams,
};
use crate::io::{self, GeometrySummary, ResultSet};
use crate::progress::Progress;
use crate::raster::{self, Grid, Raster};
use crate::render;
use crate::solver::{self, Controls, Problem};
use ndarray::Array3;
use num_complex::Complex64 as C64;
use std::path::{Path, PathBuf};

/// Sub-samples per voxel edge for partially filled voxels.
pub const SUPERSAMPLE: usize = 4;

/// Errors of a run, each naming what failed.
#[derive(Debug, thiserror::Error)]
pub enum PipelineError {
    #[error("output folder {path}: {message}")]
    Output { path: PathBuf, message: String },
    #[error("geometry: {0}")]
    Geometry(#[from] geometry::GeometryError),
    #[error("solve at {wavelength_nm} nm, polar {polar_deg}°: {source}")]
    Solve {
        wavelength_nm: f64,
        polar_deg: f64,
        source: solver::SolveError,
    },
    #[error("material `{material}` has no data at {wavelength_nm} nm")]
    Material {
        material: String,
        wavelength_nm: f64,
    },
    #[error(transparent)]
    Io(#[from] io::IoError),
    #[error("render: {0}")]
    Render(#[from] render::RenderError),
}

/// What a finished run produced.
pub struct RunReport {
    pub result_path: PathBuf,
    pub picture_path: PathBuf,
    pub geometry: Geometry,
    pub entries: Vec<SolveEntry>,
}

/// Paths of the result files of a scene.
pub fn result_paths(scene: &Scene) -> (PathBuf, PathBuf) {
    let d = &scene.output.dir;
    (
        d.join(format!("{}.h5", scene.output.name)),
        d.join(format!("{}.png", scene.output.name)),
    )
}

/// Make sure the output folder exists and accepts files.
pub fn check_output_dir(dir: &Path) -> Result<(), PipelineError> {
    let err = |m: String| PipelineError::Output {
        path: dir.to_path_buf(),
        message: m,
    };
    std::fs::create_dir_all(dir).map_err(|e| err(format!("cannot create: {e}")))?;
    let probe = dir.join(format!(".inksim-write-test-{}", std::process::id()));
    std::fs::write(&probe, b"").map_err(|e| err(format!("not writable: {e}")))?;
    let _ = std::fs::remove_file(&probe);
    Ok(())
}

/// Total PVC up to which random sequential addition of spheres is used: RSA
/// jams near 0.30–0.38 in thin slabs (METHOD §2), so above this the
/// dynamics packer runs.
pub const RSA_MAX_PVC: f64 = 0.30;

/// Which packer a scene needs, and why.
pub fn packer_of(scene: &Scene) -> (&'static str, String) {
    let spheres = scene.species.iter().all(|s| s.shape == GrainShape::Sphere);
    let pvc = scene.total_pvc();
    if spheres && pvc <= RSA_MAX_PVC {
        ("rsa", format!("spheres at PVC {pvc:.3} ≤ {RSA_MAX_PVC}: random sequential addition reaches it, no dynamics needed"))
    } else if !spheres {
        (
            "dynamics",
            "non-spherical grains: first-order dynamics packing".to_string(),
        )
    } else {
        ("dynamics", format!("PVC {pvc:.3} > {RSA_MAX_PVC}: beyond random sequential addition, first-order dynamics packing"))
    }
}

/// Build the particle set of a scene with the packer it needs.
pub fn build_geometry(scene: &Scene) -> Result<Geometry, PipelineError> {
    let l = &scene.layer;
    let size_nm = [l.fragment_x_nm, l.fragment_y_nm, l.thickness_nm];
    if packer_of(scene).0 == "rsa" {
        let params = PackParams {
            size_nm,
            species: scene
                .species
                .iter()
                .map(|s| SpeciesParams {
                    diameter_nm: s.diameter_nm,
                    volume_fraction: s.volume_fraction,
                })
                .collect(),
            ..PackParams::default()
        };
        return Ok(geometry::pack_rsa(&params, scene.seed)?);
    }
    let species = scene
        .species
        .iter()
        .map(|s| DynSpecies {
            shape: match s.shape {
                GrainShape::Sphere | GrainShape::Molecular => Shape::Sphere,
                GrainShape::Cylinder { aspect, spheres } => Shape::Cylinder { aspect, spheres },
                GrainShape::Rice { aspect, spheres } => Shape::Rice { aspect, spheres },
            },
            effective_diameter_nm: s.diameter_nm,
            volume_fraction: s.volume_fraction,
            orientation: match s.orientation {
                GrainOrientation::Random => Orientation::Random,
                GrainOrientation::InPlane => Orientation::InPlane,
                GrainOrientation::Perpendicular => Orientation::Perpendicular,
            },
            field: s.alignment_field,
        })
        .collect();
    Ok(geometry::pack_dynamics(
        &DynParams::new(size_nm, species),
        scene.seed,
    )?)
}

/// The raster grid of a scene.
pub fn grid_of(scene: &Scene) -> Grid {
    let l = &scene.layer;
    Grid {
        nx: scene.grid.nx,
        ny: scene.grid.ny,
        nz: scene.grid.nz,
        size_nm: [l.fragment_x_nm, l.fragment_y_nm, l.thickness_nm],
    }
}

/// Number of Helmholtz solves a run of `scene` performs (what `inksim plan`
/// reports; a run's result holds exactly this many `/solves` entries).
pub fn planned_solves(scene: &Scene) -> usize {
    scene.wavelengths_nm.len() * scene.incidence.len()
}

/// Solve every (wavelength, incidence) of a scene on a given raster.
pub fn solve_all(
    scene: &Scene,
    raster: &Raster,
    progress: &Progress,
) -> Result<Vec<SolveEntry>, PipelineError> {
    let g = raster.grid;
    let eps_b = scene.layer.binder_index.powi(2);
    let ctl = Controls {
        tolerance: scene.solver.tolerance,
        max_iterations: scene.solver.max_iterations,
    };
    let mut eps = Array3::from_elem((g.nz, g.ny, g.nx), C64::new(0.0, 0.0));
    let mut entries = Vec::new();
    for &lambda in &scene.wavelengths_nm {
        let eps_species = scene
            .species
            .iter()
            .map(|s| {
                s.material
                    .index_at(lambda)
                    .map(|n| n * n)
                    .ok_or_else(|| PipelineError::Material {
                        material: s.material.name.clone(),
                        wavelength_nm: lambda,
                    })
            })
            .collect::<Result<Vec<_>, _>>()?;
        raster.epsilon_into(C64::new(eps_b, 0.0), &eps_species, &mut eps);
        for inc in &scene.incidence {
            let lattice = Problem::lattice(
                [g.nx, g.ny, g.nz],
                g.size_nm,
                lambda,
                inc.polar_deg,
                inc.azimuth_deg,
            );
            let p = Problem {
                lattice,
                eps: &eps,
                eps_binder: eps_b,
            };
            let sol = solver::solve(&p, scene.solver.method, &ctl).map_err(|source| {
                PipelineError::Solve {
                    wavelength_nm: lambda,
                    polar_deg: inc.polar_deg,
                    source,
                }
            })?;
            let eff = farfield::efficiencies(&sol);
            progress.inc(
                1,
                &format!(
                    "{lambda} nm, {}°: R {:.4} T {:.4} A {:.4} ({} {} it, balance {:.1e})",
                    inc.polar_deg,
                    eff.total_reflectance,
                    eff.total_transmittance,
                    eff.absorption,
                    sol.record.method,
                    sol.record.iterations,
                    eff.energy_balance
                ),
            );
            entries.push(SolveEntry {
                wavelength_nm: lambda,
                incidence: *inc,
                efficiencies: eff,
                record: sol.record,
            });
        }
    }
    Ok(entries)
}

/// Run a scene end to end and write its result files.
pub fn run(scene: &Scene) -> Result<RunReport, PipelineError> {
    let (result_path, picture_path) = result_paths(scene);
    check_output_dir(&scene.output.dir)?;
    let total = (scene.wavelengths_nm.len() * scene.incidence.len()) as u64;
    let progress = Progress::new(total, &scene.output.name);
    let (packer, why) = packer_of(scene);
    progress.log(&format!("geometry: {packer} ({why})"));
    let geometry = build_geometry(scene)?;
    let s = &geometry.stats;
    progress.log(&format!(
        "geometry: {} particles, PVC {:.4} (target {:.4}), worst overlap {:.3} nm{}",
        geometry.particles.len(),
        s.achieved_fraction.iter().sum::<f64>(),
        scene.total_pvc(),
        s.worst_overlap_nm,
        s.order_parameter
            .map(|o| format!(", order parameter S = {o:.3}"))
            .unwrap_or_default()
    ));
    let grid = grid_of(scene);
    let raster = raster::rasterize(&geometry, &grid, SUPERSAMPLE);
    progress.log(&format!(
        "raster: {} × {} × {} voxels",
        grid.nx, grid.ny, grid.nz
    ));
    let entries = solve_all(scene, &raster, &progress)?;
    progress.finish("all solves done");

    let png = render::diffuse_brdf_png(&entries, &scene.output.name)?;
    io::write_atomic(&picture_path, &png)?;
    write_result(scene, &geometry, &raster, &entries, &png, &result_path)?;
    Ok(RunReport {
        result_path,
        picture_path,
        geometry,
        entries,
    })
}

fn write_result(
    scene: &Scene,
    geometry: &Geometry,
    raster: &Raster,
    entries: &[SolveEntry],
    png: &[u8],
    path: &Path,
) -> Result<(), PipelineError> {
    let mut centers = Vec::new();
    let mut radii = Vec::new();
    let mut particle_of_sphere = Vec::new();
    let mut species_of_particle = Vec::new();
    for (i, p) in geometry.particles.iter().enumerate() {
        species_of_particle.push(p.species as u32);
        for s in &p.spheres {
            centers.push(s.center);
            radii.push(s.radius);
            particle_of_sphere.push(i as u32);
        }
    }
    let names: Vec<String> = scene.species.iter().map(|s| s.name.clone()).collect();
    let raster_fraction = raster.mean_fractions();
    let created = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs())
        .unwrap_or(0);
    let config_path = scene.provenance.path.display().to_string();
    let plan = plan_text(scene, entries);
    let set = ResultSet {
        version: crate::VERSION,
        config_path: &config_path,
        config_text: &scene.provenance.text,
        input_hash: &scene.provenance.input_hash,
        plan: &plan,
        seed: scene.seed,
        created_unix_s: created,
        geometry: GeometrySummary {
            species_names: &names,
            centers_nm: &centers,
            radii_nm: &radii,
            particle_of_sphere: &particle_of_sphere,
            species_of_particle: &species_of_particle,
            target_fraction: &geometry.stats.target_fraction,
            achieved_fraction: &geometry.stats.achieved_fraction,
            raster_fraction: &raster_fraction,
            min_gap_nm: geometry.stats.min_gap_nm,
        },
        grid: [raster.grid.nx, raster.grid.ny, raster.grid.nz],
        size_nm: raster.grid.size_nm,
        entries,
        picture_png: Some(png),
    };
    io::write_result(path, &set)?;
    Ok(())
}

/// What `inksim geometry` produced.
pub struct GeometryReport {
    pub result_path: PathBuf,
    pub picture_path: PathBuf,
    pub geometry: Geometry,
    /// Human-readable statistics (also drawn under the picture).
    pub lines: Vec<String>,
}

/// Build and rasterise a scene's layer only: the particle set and its
/// statistics to `<name>-geometry.h5`, a top view and a cross-section to
/// `<name>-geometry.png`. No solves.
pub fn run_geometry(scene: &Scene) -> Result<GeometryReport, PipelineError> {
    let d = &scene.output.dir;
    let name = &scene.output.name;
    let result_path = d.join(format!("{name}-geometry.h5"));
    let picture_path = d.join(format!("{name}-geometry.png"));
    check_output_dir(d)?;
    let geometry = build_geometry(scene)?;
    let grid = grid_of(scene);
    let raster = raster::rasterize(&geometry, &grid, SUPERSAMPLE);
    let s = &geometry.stats;
    let (packer, _) = packer_of(scene);
    let mut lines = vec![
        format!(
            "{} particles by {packer}; PVC {:.4} (target {:.4}; raster {:.4})",
            geometry.particles.len(),
            s.achieved_fraction.iter().sum::<f64>(),
            scene.total_pvc(),
            raster.mean_fractions().iter().sum::<f64>()
        ),
        format!(
            "worst overlap {:.3} nm; min gap {:.3} nm",
            s.worst_overlap_nm, s.min_gap_nm
        ),
    ];
    if let Some(o) = s.order_parameter {
        lines.push(format!("order parameter S = {o:.3}"));
    }
    let png = render::geometry_png(&raster, name, &lines)?;
    io::write_atomic(&picture_path, &png)?;
    write_result(scene, &geometry, &raster, &[], &png, &result_path)?;
    Ok(GeometryReport {
        result_path,
        picture_path,
        geometry,
        lines,
    })
}

/// The run's plan as stored with the results: one line per decision.
pub fn plan_text(scene: &Scene, entries: &[SolveEntry]) -> String {
    let (packer, why) = packer_of(scene);
    let mut lines = vec![format!("geometry: {packer} ({why})")];
    if entries.is_empty() {
        lines.push("solves: none (geometry only)".to_string());
        return lines.join("\n");
    }
    lines.push(format!(
        "solves: {} wavelengths × {} incidence directions, method {:?}, tolerance {:.0e}",
        scene.wavelengths_nm.len(),
        scene.incidence.len(),
        scene.solver.method,
        scene.solver.tolerance
    ));
    for e in entries {
        lines.push(format!(
            "solve {} nm, {}°/{}°: {} ({})",
            e.wavelength_nm,
            e.incidence.polar_deg,
            e.incidence.azimuth_deg,
            e.record.method,
            e.record.note
        ));
    }
    lines.join("\n")
}
