//! The one module that wires the stages together:
//! config → geometry → raster → solver → farfield → render → io.
//!
//! The geometry and the λ-independent raster (volume fractions) are built
//! once; per wavelength only ε is recomputed; per incidence only the solve.
//! The output folder is checked before any work so a bad path fails fast, and
//! results are written atomically (temp file + rename), so an interrupted run
//! leaves either the previous file or the complete new one.

pub mod accuracy;

use crate::config::{
    GrainOrientation, GrainShape, GrainSize, Incidence, Scene, Structure, Substrate,
};
use crate::config::{Material, Method};
use crate::geometry::{
    self, DynParams, DynSpecies, Geometry, Orientation, PackParams, Shape, SizeDistribution,
    SpeciesOptions, SpeciesParams, StatsParams,
};
use crate::optics::appearance::{self, Appearance, AppearanceSpec, SpectralProxy};
use crate::optics::colour::Observer;
use crate::optics::farfield::table::TableSpec;
use crate::optics::farfield::{self, Side, SolveEntry};
use crate::optics::substrate::Hemisphere;
use crate::output::atomic;
use crate::output::h5::{self, GeometrySummary, ResultSet};
use crate::output::merl;
use crate::output::progress::Progress;
use crate::output::render;
use crate::raster::structure::{self, EpsGrid};
use crate::raster::{self, Grid, Raster};
use crate::solver::{self, airy, Controls, Problem};
use ndarray::{s, Array3};
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
    Io(#[from] h5::IoError),
    #[error("render: {0}")]
    Render(#[from] render::RenderError),
    #[error(transparent)]
    Appearance(#[from] appearance::AppearanceError),
    #[error("MERL export: {0}")]
    Merl(#[from] merl::MerlError),
    #[error("structure: {0}")]
    Structure(#[from] structure::StructureError),
    #[error("{0}")]
    NoGrains(String),
}

/// What a finished run produced.
pub struct RunReport {
    pub result_path: PathBuf,
    /// The tile (or the orders picture when no tile was asked for).
    pub picture_path: PathBuf,
    /// Every reflected order of every solve, drawn per wavelength and angle.
    pub orders_picture_path: PathBuf,
    /// Geometry of realisation 0 (None for a molecular mixture).
    pub geometry: Option<Geometry>,
    pub entries: Vec<SolveEntry>,
    pub appearance: Option<Appearance>,
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

/// Build the particle set of a scene (realisation 0) with the packer it needs.
pub fn build_geometry(scene: &Scene) -> Result<Geometry, PipelineError> {
    build_geometry_seeded(scene, scene.seed)
}

/// Build the particle set of a scene from a given seed.
pub fn build_geometry_seeded(scene: &Scene, seed: u64) -> Result<Geometry, PipelineError> {
    let l = &scene.layer;
    let size_nm = [l.fragment_x_nm, l.fragment_y_nm, l.thickness_nm];
    let options: Vec<SpeciesOptions> = scene
        .species
        .iter()
        .map(|s| SpeciesOptions {
            size: match s.size {
                GrainSize::Fixed => SizeDistribution::Fixed,
                GrainSize::Normal { sigma } => SizeDistribution::Normal { sigma },
                GrainSize::LogNormal { sigma } => SizeDistribution::LogNormal { sigma },
            },
            cluster_size: s.cluster_size,
        })
        .collect();
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
            options,
            relief_fraction: l.relief_fraction,
            equilibrate_sweeps: l.equilibrate_sweeps,
            ..PackParams::default()
        };
        return Ok(geometry::pack_rsa(&params, seed)?);
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
    let params = DynParams {
        options,
        relief_fraction: l.relief_fraction,
        equilibrate_sweeps: l.equilibrate_sweeps,
        ..DynParams::new(size_nm, species)
    };
    Ok(geometry::pack_dynamics(&params, seed)?)
}

/// The raster grid of a scene: the configured cells over the layer, plus,
/// with surface relief, whole cells above it reaching the highest point a
/// grain may have (relief fraction × largest possible diameter, +1 % for
/// the packer's overlap tolerance), the same for every realisation.
pub fn grid_of(scene: &Scene) -> Grid {
    let l = &scene.layer;
    let grid = Grid {
        nx: scene.grid.nx,
        ny: scene.grid.ny,
        nz: scene.grid.nz,
        size_nm: [l.fragment_x_nm, l.fragment_y_nm, l.thickness_nm],
    };
    let d_max = scene
        .species
        .iter()
        .map(|s| s.size.max_diameter(s.diameter_nm))
        .fold(0.0, f64::max);
    grid.with_top_nm(1.01 * l.relief_fraction * d_max)
}

/// Seed of realisation `r`: the scene's seed for r = 0 (so a
/// one-realisation run equals the plain scene), else SplitMix64 of
/// `seed + r · 0x9E3779B97F4A7C15` — fixed by (seed, r), never by scheduling.
pub fn realisation_seed(seed: u64, r: usize) -> u64 {
    if r == 0 {
        return seed;
    }
    let mut z = seed.wrapping_add((r as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15));
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// What a run computes and what it skips, derived from what the scene asks
/// for (issue #6: only the effects a scene calls for).
#[derive(Debug, Clone)]
pub struct RunPlan {
    /// Homogeneous layer in closed form: no geometry, grid or iteration.
    pub analytic: bool,
    /// Realisations actually run (1 for a deterministic homogeneous layer).
    pub realisations: usize,
    pub seeds: Vec<u64>,
    /// Polar angles solved from above.
    pub above_deg: Vec<f64>,
    /// Quadrature for light from below (paper term), if needed.
    pub below: Option<Hemisphere>,
    pub table: TableSpec,
    /// One line per decision: what runs, what is skipped, and why.
    pub lines: Vec<String>,
}

impl RunPlan {
    /// Derive the plan of a scene.
    pub fn of(scene: &Scene) -> RunPlan {
        let mut lines = Vec::new();
        let products = scene.appearance.products;
        let explicit = scene.structure.is_some();
        let (above, extra) = above_angles(scene);
        let paper = matches!(scene.substrate, Substrate::Paper { .. });
        let below =
            (products.tile && paper).then(|| Hemisphere::new(scene.appearance.quadrature_points));
        let shortcut = if scene.is_molecular() || explicit {
            None
        } else {
            let mut angles = above.clone();
            angles.extend(below.iter().flat_map(|h| h.polar_deg()));
            Some(effective_medium_shortcut(scene, &angles))
        };
        let analytic = scene.is_molecular() || matches!(shortcut, Some(Ok(_)));
        if scene.is_molecular() {
            lines.push(
                "geometry: none — molecular mixture: the homogeneous slab with the \
                 volume-averaged ε, solved in closed form (Airy); no grid, no iteration"
                    .to_string(),
            );
        } else if let Some(Ok(why)) = &shortcut {
            lines.push(format!(
                "geometry: none — effective-medium shortcut: {why}; the homogeneous slab with \
                 the volume-averaged ε, solved in closed form (Airy); no packing, no grid, no iteration"
            ));
        } else if let Some(st) = &scene.structure {
            lines.push(match st {
                Structure::Primitives(ps) => format!(
                    "geometry: explicit structure, {} primitive bodies rasterised by volume fraction; no packing",
                    ps.len()
                ),
                Structure::Hdf5(p) => format!(
                    "geometry: explicit structure, ε grid from {}; no packing, no raster",
                    p.display()
                ),
            });
        } else {
            let (packer, why) = packer_of(scene);
            lines.push(format!("geometry: {packer} ({why})"));
            if let Some(Err(why)) = &shortcut {
                lines.push(format!("effective-medium shortcut: refused — {why}"));
            }
        }
        if !analytic && !explicit {
            let rf = scene.layer.relief_fraction;
            lines.push(if rf > 0.0 {
                format!(
                    "surface relief: grains may protrude up to {:.0} % of their size through the top; \
                     the grid extends above the binder (vacuum around the grains, binder surface flat)",
                    rf * 100.0
                )
            } else {
                "surface relief: none (grains stay inside the binder)".to_string()
            });
            if scene.layer.equilibrate_sweeps > 0 {
                lines.push(format!(
                    "equilibration: {} hard-particle Monte Carlo sweeps after packing \
                     (Brownian settling; agglomerates move as a whole)",
                    scene.layer.equilibrate_sweeps
                ));
            }
            for s in &scene.species {
                if s.cluster_size > 1 {
                    lines.push(format!(
                        "agglomeration: `{}` grains seeded in clusters of ~{}",
                        s.name, s.cluster_size
                    ));
                }
            }
        }
        let realisations = if analytic || explicit {
            1
        } else {
            scene.realisations
        };
        if (analytic || explicit) && scene.realisations > 1 {
            lines.push(format!(
                "realisations: 1 of {} requested — {} is deterministic",
                scene.realisations,
                if analytic {
                    "a homogeneous layer"
                } else {
                    "an explicit structure"
                }
            ));
        } else {
            lines.push(format!(
                "realisations: {realisations}{}",
                if realisations == 1 {
                    " (no standard errors; the specular split needs ≥ 2)"
                } else {
                    ""
                }
            ));
        }
        let seeds = (0..realisations)
            .map(|r| realisation_seed(scene.seed, r))
            .collect();
        lines.push(format!(
            "solves from above at {} polar angles {}{}",
            above.len(),
            fmt_list(&above),
            if extra > 0 {
                format!(" ({extra} viewing angles beyond the illumination angles: the tile needs R and T there)")
            } else {
                String::new()
            }
        ));
        if let Some(h) = &below {
            lines.push(format!(
                "solves from below (layer flipped) at {} Gauss–Legendre nodes {}: the paper term needs R_dd↑ and T_d",
                h.mu.len(),
                fmt_list(&h.polar_deg())
            ));
        } else if !paper {
            lines.push("solves from below: skipped — no substrate".to_string());
        } else {
            lines.push(
                "solves from below: skipped — no tile requested, nothing uses the paper term"
                    .to_string(),
            );
        }
        let max_wl = scene.wavelengths_nm.iter().copied().fold(0.0, f64::max);
        let l = &scene.layer;
        let cell = scene
            .appearance
            .brdf_cell
            .unwrap_or_else(|| TableSpec::default_cell(max_wl, [l.fragment_x_nm, l.fragment_y_nm]));
        let table = TableSpec::new(cell);
        lines.push(format!(
            "BRDF table: cell {cell:.4} in sin θ ({}), {}×{} nodes",
            if scene.appearance.brdf_cell.is_some() {
                "set"
            } else {
                "default 2 λ_max / L"
            },
            table.n(),
            table.n()
        ));
        lines.push(if products.btdf {
            "BTDF table: computed (requested)".to_string()
        } else {
            "BTDF table: skipped — not requested".to_string()
        });
        lines.push(if products.tile {
            "tile: computed (sky strip + BRDF square, CIE 1931 2°, D65, sRGB)".to_string()
        } else {
            "tile and colours: skipped — not requested".to_string()
        });
        if products.merl {
            lines.push(
                "MERL export: written beside the result (approximation: see docs)".to_string(),
            );
        }
        RunPlan {
            analytic,
            realisations,
            seeds,
            above_deg: above,
            below,
            table,
            lines,
        }
    }

    /// Solves per realisation and wavelength.
    pub fn solves_per_wavelength(&self) -> usize {
        self.above_deg.len() + self.below.as_ref().map_or(0, |h| h.mu.len())
    }

    /// Total solves of a run.
    pub fn solves(&self, scene: &Scene) -> usize {
        self.realisations * scene.wavelengths_nm.len() * self.solves_per_wavelength()
    }
}

/// Polar angles solved from above (the illumination angles, plus the
/// viewing angles when the tile needs R and T there), and how many of them
/// are viewing-only.
fn above_angles(scene: &Scene) -> (Vec<f64>, usize) {
    let illum: Vec<f64> = scene.incidence.iter().map(|i| i.polar_deg).collect();
    let mut above = illum.clone();
    if scene.appearance.products.tile {
        for &v in &scene.appearance.viewing_deg {
            if !above.contains(&v) {
                above.push(v);
            }
        }
        above.sort_by(f64::total_cmp);
    }
    let extra = above.len() - illum.len();
    (above, extra)
}

/// Whether a layer of generated grains may be replaced by the homogeneous
/// slab of the volume-averaged ε: `Ok(why)` when the measured estimate
/// ([`airy::effective_medium_error`]) at the scene's worst wavelength and
/// angle is within `[solver] effective_medium_tolerance`, `Err(why not)`
/// otherwise, or when the layer has something the slab cannot represent.
fn effective_medium_shortcut(scene: &Scene, polar_deg: &[f64]) -> Result<String, String> {
    let tol = scene.solver.effective_medium_tolerance;
    if tol <= 0.0 {
        return Err("solver.effective_medium_tolerance = 0".to_string());
    }
    let products = scene.appearance.products;
    if products.brdf || products.btdf {
        return Err(format!(
            "the {} table is the grains' diffuse scattering, which a homogeneous slab does not have \
             (outputs = [\"tile\"] allows the shortcut)",
            if products.brdf { "BRDF" } else { "BTDF" }
        ));
    }
    if scene.layer.relief_fraction > 0.0 {
        return Err("surface relief: grains protruding through the top are not a flat slab".into());
    }
    if let Some(s) = scene.species.iter().find(|s| s.shape != GrainShape::Sphere) {
        return Err(format!(
            "`{}` grains are not spheres; the estimate was measured on sphere layers",
            s.name
        ));
    }
    if let Some(s) = scene.species.iter().find(|s| s.cluster_size > 1) {
        return Err(format!(
            "`{}` grains agglomerate (clusters scatter as larger grains); the estimate was \
             measured on dispersed grains",
            s.name
        ));
    }
    if scene.total_pvc() > RSA_MAX_PVC {
        return Err(format!(
            "PVC {:.3} > {RSA_MAX_PVC}: the estimate was measured on random-sequential-addition \
             layers up to PVC {RSA_MAX_PVC}",
            scene.total_pvc()
        ));
    }
    let d_max = scene
        .species
        .iter()
        .map(|s| s.size.max_diameter(s.diameter_nm))
        .fold(0.0, f64::max);
    let lambda_min = scene
        .wavelengths_nm
        .iter()
        .copied()
        .fold(f64::INFINITY, f64::min);
    let x = 2.0 * std::f64::consts::PI / lambda_min * d_max;
    if x > airy::EFFECTIVE_MAX_SIZE_PARAMETER {
        return Err(format!(
            "grains up to {d_max:.3} nm are beyond λ/20 at {lambda_min} nm (k0 d = {x:.3}), \
             outside the range where the effective-medium error was measured"
        ));
    }
    let eps_b = scene.layer.binder_index.powi(2);
    let mut worst = (0.0, 0.0, 0.0);
    for &lambda in &scene.wavelengths_nm {
        let eps = species_eps(scene, lambda).map_err(|e| e.to_string())?;
        let grains: Vec<airy::GrainTerm> = scene
            .species
            .iter()
            .zip(&eps)
            .map(|(s, e)| airy::GrainTerm {
                volume_fraction: s.volume_fraction,
                diameter_nm: s.size.max_diameter(s.diameter_nm),
                delta_eps: e - eps_b,
            })
            .collect();
        for &p in polar_deg {
            let est =
                airy::effective_medium_error(&grains, eps_b, scene.layer.thickness_nm, lambda, p);
            if est >= worst.0 {
                worst = (est, lambda, p);
            }
        }
    }
    let (est, lambda, p) = worst;
    let at = format!(
        "estimated error in R/T/A {est:.1e} (grains ≤ {d_max:.3} nm, worst at {lambda} nm, \
         {}°)",
        (p * 100.0).round() / 100.0
    );
    if est <= tol {
        Ok(format!("{at} ≤ tolerance {tol:.1e}"))
    } else {
        Err(format!(
            "{at} > solver.effective_medium_tolerance {tol:.1e}: full solve"
        ))
    }
}

fn fmt_list(v: &[f64]) -> String {
    let items: Vec<String> = v
        .iter()
        .map(|x| format!("{}", (x * 100.0).round() / 100.0))
        .collect();
    format!("[{}]°", items.join(", "))
}

/// Number of Helmholtz solves a run of `scene` performs (what `inksim plan`
/// reports; a run's result holds exactly this many `/solves` entries).
pub fn planned_solves(scene: &Scene) -> usize {
    RunPlan::of(scene).solves(scene)
}

/// Permittivity of every species at a wavelength.
fn species_eps(scene: &Scene, lambda: f64) -> Result<Vec<C64>, PipelineError> {
    scene
        .species
        .iter()
        .map(|s| material_eps(&s.material, lambda))
        .collect()
}

/// ε = n² of a material at a wavelength.
fn material_eps(m: &Material, lambda: f64) -> Result<C64, PipelineError> {
    m.index_at(lambda)
        .map(|n| n * n)
        .ok_or_else(|| PipelineError::Material {
            material: m.name.clone(),
            wavelength_nm: lambda,
        })
}

/// The volume-averaged permittivity of the layer, `Σ f ε_s + (1 − Σ f) ε_b`
/// (the molecular-mixture slab).
fn mean_eps(scene: &Scene, lambda: f64) -> Result<C64, PipelineError> {
    let eps_b = C64::new(scene.layer.binder_index.powi(2), 0.0);
    let eps_s = species_eps(scene, lambda)?;
    Ok(scene
        .species
        .iter()
        .zip(&eps_s)
        .fold(eps_b * (1.0 - scene.total_pvc()), |acc, (s, e)| {
            acc + e * s.volume_fraction
        }))
}

/// The polar angles and sides solved per wavelength, in solve order.
fn incidences(scene: &Scene, plan: &RunPlan) -> Vec<(Side, Incidence)> {
    let az = scene.incidence.first().map_or(0.0, |i| i.azimuth_deg);
    let mut out: Vec<(Side, Incidence)> = plan
        .above_deg
        .iter()
        .map(|&p| {
            (
                Side::Above,
                Incidence {
                    polar_deg: p,
                    azimuth_deg: az,
                },
            )
        })
        .collect();
    if let Some(h) = &plan.below {
        for p in h.polar_deg() {
            out.push((
                Side::Below,
                Incidence {
                    polar_deg: p,
                    azimuth_deg: az,
                },
            ));
        }
    }
    out
}

fn log_solve(progress: &Progress, e: &SolveEntry) {
    let eff = &e.efficiencies;
    progress.inc(
        1,
        &format!(
            "{} nm, {}° {}{}: R {:.4} T {:.4} A {:.4} ({} {} it, balance {:.1e})",
            e.wavelength_nm,
            (e.incidence.polar_deg * 100.0).round() / 100.0,
            e.side,
            if e.realisation > 0 {
                format!(" #{}", e.realisation)
            } else {
                String::new()
            },
            eff.total_reflectance,
            eff.total_transmittance,
            eff.absorption,
            e.record.method,
            e.record.iterations,
            eff.energy_balance
        ),
    );
}

/// Solve every (wavelength, incidence, side) of one realisation on a raster.
pub fn solve_realisation(
    scene: &Scene,
    plan: &RunPlan,
    raster: &Raster,
    realisation: usize,
    progress: &Progress,
) -> Result<Vec<SolveEntry>, PipelineError> {
    solve_layer(scene, plan, LayerEps::Raster(raster), realisation, progress)
}

/// Where the permittivity of each wavelength comes from.
#[derive(Clone, Copy)]
pub enum LayerEps<'a> {
    /// Volume fractions (grains or primitives) and the materials' n(λ).
    Raster(&'a Raster),
    /// A permittivity grid read from a file.
    Grid(&'a EpsGrid, Grid),
}

/// Permittivity of each fraction array of the raster at a wavelength: the
/// pigments', or the structure primitives' materials.
fn fraction_eps(scene: &Scene, lambda: f64) -> Result<Vec<C64>, PipelineError> {
    match &scene.structure {
        Some(Structure::Primitives(ps)) => {
            ps.iter()
                .map(|p| {
                    p.material.index_at(lambda).map(|n| n * n).ok_or_else(|| {
                        PipelineError::Material {
                            material: p.material.name.clone(),
                            wavelength_nm: lambda,
                        }
                    })
                })
                .collect()
        }
        _ => species_eps(scene, lambda),
    }
}

/// Solve every (wavelength, incidence, side) on one layer.
pub fn solve_layer(
    scene: &Scene,
    plan: &RunPlan,
    layer: LayerEps,
    realisation: usize,
    progress: &Progress,
) -> Result<Vec<SolveEntry>, PipelineError> {
    let g = match layer {
        LayerEps::Raster(r) => r.grid,
        LayerEps::Grid(_, g) => g,
    };
    let eps_b = scene.layer.binder_index.powi(2);
    let ctl = controls(scene);
    let incs = incidences(scene, plan);
    let mut eps = Array3::from_elem((g.nz, g.ny, g.nx), C64::new(0.0, 0.0));
    let mut flipped = plan
        .below
        .as_ref()
        .map(|_| Array3::from_elem((g.nz, g.ny, g.nx), C64::new(0.0, 0.0)));
    let mut entries = Vec::new();
    for &lambda in &scene.wavelengths_nm {
        match layer {
            LayerEps::Raster(raster) => {
                let eps_species = fraction_eps(scene, lambda)?;
                raster.epsilon_into(C64::new(eps_b, 0.0), &eps_species, &mut eps);
            }
            LayerEps::Grid(grid_eps, _) => grid_eps.epsilon_into(lambda, &mut eps),
        }
        if let Some(f) = flipped.as_mut() {
            f.assign(&eps.slice(s![..;-1, .., ..]));
        }
        for (side, inc) in &incs {
            let lattice = Problem::lattice(
                [g.nx, g.ny, g.nz],
                g.size_nm,
                lambda,
                inc.polar_deg,
                inc.azimuth_deg,
            );
            let grid_eps = match (side, flipped.as_ref()) {
                (Side::Below, Some(f)) => f,
                _ => &eps,
            };
            let p = Problem {
                lattice,
                eps: grid_eps,
                eps_binder: eps_b,
            };
            let sol = solver::solve(&p, scene.solver.method, &ctl).map_err(|source| {
                PipelineError::Solve {
                    wavelength_nm: lambda,
                    polar_deg: inc.polar_deg,
                    source,
                }
            })?;
            let entry = SolveEntry {
                wavelength_nm: lambda,
                incidence: *inc,
                side: *side,
                realisation,
                efficiencies: farfield::efficiencies(&sol),
                record: sol.record,
            };
            log_solve(progress, &entry);
            entries.push(entry);
        }
    }
    Ok(entries)
}

/// The solver's iteration controls of a scene.
fn controls(scene: &Scene) -> Controls {
    Controls {
        tolerance: scene.solver.tolerance,
        max_iterations: scene.solver.max_iterations,
        precision: scene.solver.precision,
    }
}

/// The homogeneous slab of a molecular mixture (or of grains fine enough for
/// the effective-medium shortcut), `⟨ε⟩ = Σ f ε_s + (1 − Σ f) ε_b`, in closed
/// form (the `airy` method) for every (wavelength, incidence, side).
pub fn solve_analytic(
    scene: &Scene,
    plan: &RunPlan,
    progress: &Progress,
) -> Result<Vec<SolveEntry>, PipelineError> {
    let incs = incidences(scene, plan);
    let ctl = controls(scene);
    let eps_b = scene.layer.binder_index.powi(2);
    let why = if scene.is_molecular() {
        "molecular mixture"
    } else {
        "effective-medium shortcut (grains fine against λ)"
    };
    let mut entries = Vec::new();
    for &lambda in &scene.wavelengths_nm {
        let mean = Array3::from_elem((1, 1, 1), mean_eps(scene, lambda)?);
        for (side, inc) in &incs {
            // A homogeneous slab is symmetric (from below = from above) and
            // the same at every azimuth: one cell, lit at azimuth 0.
            let size = [1.0, 1.0, scene.layer.thickness_nm];
            let lattice = Problem::lattice([1, 1, 1], size, lambda, inc.polar_deg, 0.0);
            let p = Problem {
                lattice,
                eps: &mean,
                eps_binder: eps_b,
            };
            let mut sol =
                solver::solve(&p, Method::Airy, &ctl).map_err(|source| PipelineError::Solve {
                    wavelength_nm: lambda,
                    polar_deg: inc.polar_deg,
                    source,
                })?;
            sol.record.note = format!("{why}: {}", sol.record.note);
            let entry = SolveEntry {
                wavelength_nm: lambda,
                incidence: *inc,
                side: *side,
                realisation: 0,
                efficiencies: farfield::slab_efficiencies(&sol.slab_response(), inc),
                record: sol.record,
            };
            log_solve(progress, &entry);
            entries.push(entry);
        }
    }
    Ok(entries)
}

/// The appearance assembly parameters of a scene under its plan.
pub fn appearance_spec(scene: &Scene, plan: &RunPlan) -> AppearanceSpec {
    AppearanceSpec {
        wavelengths_nm: scene.wavelengths_nm.clone(),
        azimuth_deg: scene.incidence.first().map_or(0.0, |i| i.azimuth_deg),
        illumination_deg: scene.incidence.iter().map(|i| i.polar_deg).collect(),
        viewing_deg: scene.appearance.viewing_deg.clone(),
        above_deg: plan.above_deg.clone(),
        below: plan.below.clone(),
        paper_albedo: match scene.substrate {
            Substrate::Paper { albedo } => Some(albedo),
            Substrate::None => None,
        },
        table: plan.table,
        realisations: plan.realisations,
        btdf: scene.appearance.products.btdf,
        tile: scene.appearance.products.tile,
        proxy: spectral_proxy(scene),
        measurements: Vec::new(),
    }
}

/// Fine grid of the colour proxy, nm.
pub const PROXY_STEP_NM: f64 = 5.0;

/// The molecular-mixture slab on a 5 nm grid (plus every solved wavelength)
/// over the scene's band, for colour with a substrate; None for a single
/// wavelength or when a material lacks data on the grid.
fn spectral_proxy(scene: &Scene) -> Option<SpectralProxy> {
    let wl = &scene.wavelengths_nm;
    // An explicit structure has no pigment mixture to stand in for it.
    if wl.len() < 2 || matches!(scene.substrate, Substrate::None) || scene.structure.is_some() {
        return None;
    }
    let (lo, hi) = (wl[0], wl[wl.len() - 1]);
    let mut fine: Vec<f64> = wl.clone();
    let mut x = (lo / PROXY_STEP_NM).ceil() * PROXY_STEP_NM;
    while x < hi {
        if !fine.contains(&x) {
            fine.push(x);
        }
        x += PROXY_STEP_NM;
    }
    fine.sort_by(f64::total_cmp);
    let eps = fine
        .iter()
        .map(|&l| mean_eps(scene, l).ok())
        .collect::<Option<Vec<_>>>()?;
    Some(SpectralProxy {
        wavelengths_nm: fine,
        eps,
        thickness_nm: scene.layer.thickness_nm,
    })
}

/// Run a scene end to end and write its result files, with a progress bar
/// (terminal) or log lines.
pub fn run(scene: &Scene) -> Result<RunReport, PipelineError> {
    run_with(scene, false)
}

/// [`run`], optionally without any progress output (variants of a study
/// running side by side report through the study's own bar).
pub fn run_with(scene: &Scene, quiet: bool) -> Result<RunReport, PipelineError> {
    let (result_path, picture_path) = result_paths(scene);
    let orders_path = scene
        .output
        .dir
        .join(format!("{}-orders.png", scene.output.name));
    check_output_dir(&scene.output.dir)?;
    let plan = RunPlan::of(scene);
    let total = plan.solves(scene) as u64;
    let progress = if quiet {
        Progress::hidden(total, &scene.output.name)
    } else {
        Progress::new(total, &scene.output.name)
    };
    for l in &plan.lines {
        progress.log(l);
    }
    let mut entries = Vec::new();
    let mut realisations = Vec::new();
    let mut first: Option<(Geometry, Raster)> = None;
    let mut explicit_raster: Option<Raster> = None;
    if plan.analytic {
        entries = solve_analytic(scene, &plan, &progress)?;
        realisations.push((scene.seed, scene.total_pvc()));
    } else if let Some(st) = &scene.structure {
        let grid = grid_of(scene);
        match st {
            Structure::Primitives(ps) => {
                let raster = structure::rasterize_primitives(ps, &grid);
                let f: f64 = raster.mean_fractions().iter().sum();
                entries = solve_layer(scene, &plan, LayerEps::Raster(&raster), 0, &progress)?;
                realisations.push((scene.seed, f));
                explicit_raster = Some(raster);
            }
            Structure::Hdf5(path) => {
                let eg = EpsGrid::read(path, &grid, &scene.wavelengths_nm)?;
                entries = solve_layer(scene, &plan, LayerEps::Grid(&eg, grid), 0, &progress)?;
                realisations.push((scene.seed, 0.0));
            }
        }
    } else {
        let grid = grid_of(scene);
        for (r, &seed) in plan.seeds.iter().enumerate() {
            let geometry = build_geometry_seeded(scene, seed)?;
            let st = &geometry.stats;
            let pvc: f64 = st.achieved_fraction.iter().sum();
            progress.log(&format!(
                "geometry{}: {} particles, PVC {:.4} (target {:.4}), worst overlap {:.3} nm{}",
                if plan.realisations > 1 {
                    format!(" #{r} (seed {seed})")
                } else {
                    String::new()
                },
                geometry.particles.len(),
                pvc,
                scene.total_pvc(),
                st.worst_overlap_nm,
                st.order_parameter
                    .map(|o| format!(", order parameter S = {o:.3}"))
                    .unwrap_or_default()
            ));
            let raster = raster::rasterize(&geometry, &grid, SUPERSAMPLE);
            if r == 0 {
                progress.log(&format!(
                    "raster: {} × {} × {} voxels",
                    grid.nx, grid.ny, grid.nz
                ));
            }
            entries.extend(solve_realisation(scene, &plan, &raster, r, &progress)?);
            realisations.push((seed, pvc));
            if first.is_none() {
                first = Some((geometry, raster));
            }
        }
    }
    progress.finish("all solves done");

    let above: Vec<SolveEntry> = entries
        .iter()
        .filter(|e| e.side == Side::Above)
        .cloned()
        .collect();
    let orders_png = render::diffuse_brdf_png(&above, &scene.output.name)?;
    let products = scene.appearance.products;
    let wants_appearance = products.brdf || products.btdf || products.tile || products.merl;
    let appearance = if wants_appearance {
        let obs = Observer::cie1931_d65();
        Some(appearance::assemble(
            &appearance_spec(scene, &plan),
            &entries,
            &obs,
        )?)
    } else {
        None
    };
    let tile_png = match appearance.as_ref() {
        Some(
            a @ Appearance {
                colours: Some(c), ..
            },
        ) => Some(render::tile::tile_png(
            &c.tile_srgb8,
            &a.spec.viewing_deg,
            &a.spec.illumination_deg,
            &scene.output.name,
        )?),
        _ => None,
    };
    if let (Some(a), true) = (appearance.as_ref(), products.merl) {
        let merl = merl::encode(a)?;
        atomic::write_atomic(
            &scene
                .output
                .dir
                .join(format!("{}.binary", scene.output.name)),
            &merl,
        )?;
    }
    atomic::write_atomic(&orders_path, &orders_png)?;
    atomic::write_atomic(&picture_path, tile_png.as_deref().unwrap_or(&orders_png))?;
    let plan_text = plan_text(&plan, &entries);
    write_result(
        scene,
        first.as_ref().map(|f| &f.0),
        first.as_ref().map(|f| &f.1).or(explicit_raster.as_ref()),
        &entries,
        &realisations,
        &plan_text,
        Pictures {
            orders: &orders_png,
            tile: tile_png.as_deref(),
        },
        appearance.as_ref(),
        &result_path,
    )?;
    Ok(RunReport {
        result_path,
        picture_path,
        orders_picture_path: orders_path,
        geometry: first.map(|f| f.0),
        entries,
        appearance,
    })
}

struct Pictures<'a> {
    orders: &'a [u8],
    tile: Option<&'a [u8]>,
}

#[allow(clippy::too_many_arguments)]
fn write_result(
    scene: &Scene,
    geometry: Option<&Geometry>,
    raster: Option<&Raster>,
    entries: &[SolveEntry],
    realisations: &[(u64, f64)],
    plan: &str,
    pictures: Pictures,
    appearance: Option<&Appearance>,
    path: &Path,
) -> Result<(), PipelineError> {
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
    let achieved = geometry.map_or_else(|| targets.clone(), |g| g.stats.achieved_fraction.clone());
    let raster_fraction = match raster {
        Some(r) => r.mean_fractions(),
        None if scene.structure.is_some() => Vec::new(),
        None => targets.clone(),
    };
    let min_gap = geometry.map(|g| g.stats.min_gap_nm);
    let grid = match raster {
        Some(r) => [r.grid.nx, r.grid.ny, r.grid.nz],
        None if scene.structure.is_some() => {
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
    let l = &scene.layer;
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
        size_nm: [l.fragment_x_nm, l.fragment_y_nm, l.thickness_nm],
        entries,
        picture_png: Some(pictures.orders),
        realisations,
        appearance,
        tile_png: pictures.tile,
    };
    h5::write_result(path, &set)?;
    Ok(())
}

/// What `inksim geometry` produced.
pub struct GeometryReport {
    pub result_path: PathBuf,
    pub picture_path: PathBuf,
    /// The particle set (None for an explicit structure).
    pub geometry: Option<Geometry>,
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
    match &scene.structure {
        Some(Structure::Primitives(ps)) => {
            // Draw the explicit layer's raster: what the solver will see.
            let raster = structure::rasterize_primitives(ps, &grid_of(scene));
            let fr = raster.mean_fractions();
            let mut lines = vec![format!(
                "explicit structure: {} bodies; volume fraction {:.4} in all",
                ps.len(),
                fr.iter().sum::<f64>()
            )];
            for (i, (p, f)) in ps.iter().zip(&fr).enumerate() {
                lines.push(format!("body {i}: {} fraction {f:.4}", p.material.name));
            }
            write_geometry_only(
                scene,
                None,
                &raster,
                fr.iter().sum(),
                &lines,
                (&result_path, &picture_path),
            )?;
            return Ok(GeometryReport {
                result_path,
                picture_path,
                geometry: None,
                lines,
            });
        }
        Some(Structure::Hdf5(p)) => {
            return Err(PipelineError::NoGrains(format!(
                "{}: the layer is an ε grid from {}: nothing to build; use `inksim run`",
                scene.path().display(),
                p.display()
            )))
        }
        None if scene.is_molecular() => {
            return Err(PipelineError::NoGrains(format!(
                "{}: the pigments are dissolved (molecular): the layer is homogeneous, \
                 there are no grains to build",
                scene.path().display()
            )))
        }
        None => {}
    }
    let geometry = build_geometry(scene)?;
    let grid = grid_of(scene);
    let raster = raster::rasterize(&geometry, &grid, SUPERSAMPLE);
    let s = &geometry.stats;
    let (packer, _) = packer_of(scene);
    let mut lines = vec![format!(
        "{} particles by {packer}; PVC {:.4} (target {:.4}; raster {:.4})",
        geometry.particles.len(),
        s.achieved_fraction.iter().sum::<f64>(),
        scene.total_pvc(),
        raster.mean_fractions().iter().sum::<f64>()
    )];
    // Worst overlap, S, relief, clusters (the PVC line is the one above).
    let stats = geometry::analyse(&geometry, &StatsParams::default());
    lines.extend(stats.lines().into_iter().skip(1));
    let pvc = geometry.stats.achieved_fraction.iter().sum();
    let layer = (geometry, raster);
    write_geometry_only(
        scene,
        Some(&layer.0),
        &layer.1,
        pvc,
        &lines,
        (&result_path, &picture_path),
    )?;
    Ok(GeometryReport {
        result_path,
        picture_path,
        geometry: Some(layer.0),
        lines,
    })
}

/// The picture and the result file of `inksim geometry`: the raster drawn
/// with `lines` under it, and a result set without solves.
fn write_geometry_only(
    scene: &Scene,
    geometry: Option<&Geometry>,
    raster: &Raster,
    pvc: f64,
    lines: &[String],
    (result_path, picture_path): (&Path, &Path),
) -> Result<(), PipelineError> {
    let png = render::geometry_png(raster, &scene.output.name, lines)?;
    atomic::write_atomic(picture_path, &png)?;
    write_result(
        scene,
        geometry,
        Some(raster),
        &[],
        &[(scene.seed, pvc)],
        &plan_text(&RunPlan::of(scene), &[]),
        Pictures {
            orders: &png,
            tile: None,
        },
        None,
        result_path,
    )
}

/// The run's plan as stored with the results: one line per decision, then
/// one line per solve (method and why).
pub fn plan_text(plan: &RunPlan, entries: &[SolveEntry]) -> String {
    let mut lines = plan.lines.clone();
    if entries.is_empty() {
        lines.push("solves: none (geometry only)".to_string());
        return lines.join("\n");
    }
    for e in entries {
        lines.push(format!(
            "solve {} nm, {}°/{}° {} #{}: {} ({})",
            e.wavelength_nm,
            e.incidence.polar_deg,
            e.incidence.azimuth_deg,
            e.side,
            e.realisation,
            e.record.method,
            e.record.note
        ));
    }
    lines.join("\n")
}
