//! An effect paint end to end (`inksim run paint.toml`): the checked
//! [`PaintScene`] turned into the fast model's layers per wavelength
//! (lacquer absorption, the ordinary pigments' Mie medium, the flakes'
//! reflectance table and orientation), solved by `optics::flakes::paint`
//! (the wavelengths in parallel), then the in-plane BRDF, the multi-angle
//! colours and flop index, the sparkle figures and texture
//! (`paint_sparkle`), the pictures and the result file.

use std::path::PathBuf;
use std::time::{Instant, SystemTime, UNIX_EPOCH};

use ndarray::{Array2, Array3};
use rayon::prelude::*;

use crate::config::paint::{PaintGround, PaintScene};
use crate::config::Equation;
use crate::optics::baseline::doubling::Medium;
use crate::optics::baseline::ordinates::OrdinateParams;
use crate::optics::baseline::{transfer, BaselineInput, BaselineSpecies};
use crate::optics::colour::Observer;
use crate::optics::flakes::air::AirNodes;
use crate::optics::flakes::kernel::FlakeMedium;
use crate::optics::flakes::multiangle;
use crate::optics::flakes::normals::Orientation;
use crate::optics::flakes::paint::{
    self as model, Ground, ModelParams, PaintLayer, PaintReflection,
};
use crate::output::atomic;
use crate::output::h5::{self, AngleRecord, Identity, PaintResultSet, SparkleTable};
use crate::output::progress::Progress;
use crate::output::render::multiangle::{flop_png, patches_png, PatchCaption};

use super::paint_optics::index;
pub use super::paint_optics::{lacquer_index, reflector};
use super::{check_output_dir, paint_sparkle, PipelineError};

/// What a paint run wrote and found.
#[derive(Debug, Clone)]
pub struct PaintReport {
    pub result_path: PathBuf,
    pub picture_path: PathBuf,
    pub flop_path: PathBuf,
    pub sparkle_path: PathBuf,
    pub colours: Vec<AngleRecord>,
    pub flop_index: Option<f64>,
    pub sparkle: Option<SparkleTable>,
    pub seconds: f64,
}

/// The files a paint run writes: the result, the patches, the flop plot
/// and the sparkle texture.
pub fn paint_files(scene: &PaintScene) -> [PathBuf; 4] {
    let (d, n) = (&scene.output.dir, &scene.output.name);
    [
        d.join(format!("{n}.h5")),
        d.join(format!("{n}.png")),
        d.join(format!("{n}-flop.png")),
        d.join(format!("{n}-sparkle.png")),
    ]
}

/// The air directions the model solves on: the multi-angle geometries'
/// and the sparkle lights' (each an air node, so that the texture's colour
/// under each light is the BRDF's own).
pub fn paint_air_directions(scene: &PaintScene) -> Vec<f64> {
    let mut d = multiangle::air_directions();
    d.extend(scene.sparkle.illumination_deg.iter().copied());
    d.sort_by(f64::total_cmp);
    d.dedup();
    d
}

/// The plan of a paint run, one line per part.
pub fn paint_plan(scene: &PaintScene) -> Vec<String> {
    let wl = &scene.wavelengths_nm;
    let mut lines = vec![format!(
        "fast model (METHOD §9): {} layer(s) on {}, {} wavelengths {}–{} nm, in parallel",
        scene.layers.len(),
        scene.ground.describe(),
        wl.len(),
        wl[0],
        wl[wl.len() - 1]
    )];
    for l in &scene.layers {
        let flakes = match &l.flakes {
            Some(f) => format!(
                ", {} flakes {} µm across at volume fraction {}, tilt spread {}°{}",
                f.reflector.kind(),
                f.diameter_um,
                f.volume_fraction,
                f.orientation_sd_deg,
                if f.diffraction {
                    " with the diffraction lobe"
                } else {
                    ""
                }
            ),
            None => String::new(),
        };
        lines.push(format!(
            "layer {}: {} µm of {}, {} pigment(s){flakes}",
            l.name,
            l.thickness_um,
            l.lacquer,
            l.pigments.len()
        ));
    }
    lines.push(format!(
        "multi-angle colour: {} geometries, {} {}°; sparkle at {} mm under {:?}°",
        multiangle::geometries().len(),
        scene.illuminant.name(),
        scene.observer.degrees(),
        scene.sparkle.viewing_distance_mm,
        scene.sparkle.illumination_deg
    ));
    lines
}

/// The model's resolution from the scene's `[paint.model]`.
pub fn model_params(scene: &PaintScene) -> ModelParams {
    let d = ModelParams::default();
    let m = scene.model;
    ModelParams {
        ordinates: OrdinateParams {
            trapped_nodes: m.trapped_nodes.unwrap_or(d.ordinates.trapped_nodes),
            escape_nodes: m.escape_nodes.unwrap_or(d.ordinates.escape_nodes),
        },
        max_terms: m.max_terms.unwrap_or(d.max_terms),
        ..d
    }
}

/// The flakes' diffraction spread at a wavelength (that of a disc of the
/// mean diameter where asked, else 0).
fn diffraction(f: &crate::config::paint::FlakeSpec, wavelength_nm: f64, lacquer: f64) -> f64 {
    if f.diffraction {
        crate::optics::flakes::normals::diffraction_rad(
            f.diameter_um * 1000.0,
            wavelength_nm,
            lacquer,
        )
    } else {
        0.0
    }
}

/// The model's layers at one wavelength.
pub fn layers_at(scene: &PaintScene, wavelength_nm: f64) -> Result<Vec<PaintLayer>, PipelineError> {
    let n = lacquer_index(scene, wavelength_nm)?;
    let mut out = Vec::with_capacity(scene.layers.len());
    for l in &scene.layers {
        let thickness_nm = l.thickness_um * 1000.0;
        let species = l
            .pigments
            .iter()
            .map(|p| {
                let m = index(&p.material, wavelength_nm)?;
                Ok(BaselineSpecies {
                    volume_fraction: p.volume_fraction,
                    diameter_nm: p.diameter_nm,
                    size: p.size,
                    eps: vec![m * m],
                })
            })
            .collect::<Result<Vec<_>, PipelineError>>()?;
        let mut pigments = if species.is_empty() {
            Medium {
                mu_a: 0.0,
                mu_s: 0.0,
                moments: Vec::new(),
            }
        } else {
            transfer::medium(
                &BaselineInput {
                    wavelengths_nm: vec![wavelength_nm],
                    binder_index: n,
                    thickness_nm,
                    paper_albedo: 0.0,
                    species,
                    size_quadrature: Default::default(),
                    equation: Equation::Maxwell,
                },
                0,
            )
        };
        // The lacquer's own absorption, 4πk/λ, over the volume it fills.
        let filled: f64 = l.pigments.iter().map(|p| p.volume_fraction).sum::<f64>()
            + l.flakes.as_ref().map_or(0.0, |f| f.volume_fraction);
        let k = index(&l.lacquer, wavelength_nm)?.im;
        pigments.mu_a += (1.0 - filled) * 4.0 * std::f64::consts::PI * k / wavelength_nm;
        let flakes = match &l.flakes {
            None => None,
            Some(f) => Some(FlakeMedium {
                area_per_nm: f.area_per_nm(),
                orientation: Orientation {
                    sigma_rad: f.orientation_sd_deg.to_radians(),
                },
                diffraction_rad: diffraction(f, wavelength_nm, n),
                table: reflector(&f.reflector, wavelength_nm)?.table(n, wavelength_nm),
            }),
        };
        out.push(PaintLayer {
            thickness_nm,
            pigments,
            flakes,
        });
    }
    Ok(out)
}

/// What the paint lies on at one wavelength.
pub fn ground_at(scene: &PaintScene, wavelength_nm: f64) -> Result<Ground, PipelineError> {
    Ok(match &scene.ground {
        PaintGround::Black => Ground::Black,
        PaintGround::Lambertian(g) => Ground::Lambertian {
            albedo: g.at(wavelength_nm),
        },
        PaintGround::Metal(m) => Ground::Mirror {
            index: index(m, wavelength_nm)?,
        },
    })
}

/// The paint's reflection at every wavelength, in parallel, with progress.
fn solve(
    scene: &PaintScene,
    params: &ModelParams,
    progress: &Progress,
) -> Result<Vec<PaintReflection>, PipelineError> {
    let air = paint_air_directions(scene);
    scene
        .wavelengths_nm
        .par_iter()
        .map(|&wl| {
            let r = reflect_at(scene, params, &air, wl)?;
            progress.inc(1, &format!("{wl} nm: {} Fourier terms", r.terms.len()));
            Ok(r)
        })
        .collect()
}

/// The paint's reflection at one wavelength on the air directions `air`
/// ([`paint_air_directions`]).
pub fn reflect_at(
    scene: &PaintScene,
    params: &ModelParams,
    air: &[f64],
    wavelength_nm: f64,
) -> Result<PaintReflection, PipelineError> {
    Ok(model::reflect(
        lacquer_index(scene, wavelength_nm)?,
        &layers_at(scene, wavelength_nm)?,
        ground_at(scene, wavelength_nm)?,
        wavelength_nm,
        air,
        params,
    )?)
}

/// The in-plane BRDF (1/sr), mirror reflectance and albedo on the air
/// directions.
struct InPlane {
    directions_deg: Vec<f64>,
    view_deg: Vec<f64>,
    brdf: Array3<f64>,
    mirror: Array2<f64>,
    albedo: Array2<f64>,
}

fn in_plane(reflections: &[PaintReflection]) -> Result<InPlane, PipelineError> {
    let AirNodes {
        angles_deg: directions_deg,
        nodes,
        ..
    } = AirNodes::new(&reflections[0]);
    // `0 − d`, not `−d`: the normal reads 0, not −0.
    let mut view_deg: Vec<f64> = directions_deg.iter().rev().map(|&d| 0.0 - d).collect();
    view_deg.extend(directions_deg.iter().filter(|&&d| d > 0.0));
    view_deg.dedup();
    let (nl, nd, nv) = (reflections.len(), directions_deg.len(), view_deg.len());
    let mut brdf = Array3::zeros((nl, nd, nv));
    let mut mirror = Array2::zeros((nl, nd));
    let mut albedo = Array2::zeros((nl, nd));
    for (l, r) in reflections.iter().enumerate() {
        for (j, (&inc, &node)) in directions_deg.iter().zip(&nodes).enumerate() {
            mirror[[l, j]] = r.mirror[node];
            albedo[[l, j]] = r.albedo(node);
            for (v, &view) in view_deg.iter().enumerate() {
                let az = if view < 0.0 { 180.0 } else { 0.0 };
                brdf[[l, j, v]] = r.factor(inc, view.abs(), az)? / std::f64::consts::PI;
            }
        }
    }
    Ok(InPlane {
        directions_deg,
        view_deg,
        brdf,
        mirror,
        albedo,
    })
}

/// What the fast model did at one wavelength ([`probe_paint`]).
#[derive(Debug, Clone, Copy)]
pub struct PaintProbe {
    /// Fourier terms kept.
    pub terms: usize,
    /// Bytes of the reflection a run keeps for that wavelength until the
    /// colours are computed (its terms' flux matrices and mirror column).
    pub kept_bytes: f64,
}

/// The fast model of `scene` at one wavelength (what `plan` times).
pub fn probe_paint(scene: &PaintScene, wavelength_nm: f64) -> Result<PaintProbe, PipelineError> {
    let air = paint_air_directions(scene);
    let r = reflect_at(scene, &model_params(scene), &air, wavelength_nm)?;
    let square: usize = r.terms.iter().map(|m| m.size() * m.size()).sum();
    Ok(PaintProbe {
        terms: r.terms.len(),
        kept_bytes: 8.0 * (square + r.mirror.len()) as f64,
    })
}

/// Run an effect paint and write its files; progress lines unless `quiet`.
pub fn run_paint(scene: &PaintScene, quiet: bool) -> Result<PaintReport, PipelineError> {
    let start = Instant::now();
    check_output_dir(&scene.output.dir)?;
    let [result_path, picture_path, flop_path, sparkle_path] = paint_files(scene);
    let plan = paint_plan(scene);
    let total = scene.wavelengths_nm.len() as u64;
    let progress = if quiet {
        Progress::hidden(total, &scene.output.name)
    } else {
        Progress::new(total, &scene.output.name)
    };
    for l in &plan {
        progress.log(l);
    }
    let params = model_params(scene);
    let reflections = solve(scene, &params, &progress)?;
    progress.finish("every wavelength solved");

    let obs = Observer::standard(scene.illuminant, scene.observer);
    let geometries = multiangle::geometries();
    let wl = &scene.wavelengths_nm;
    let mut factors = Array2::zeros((geometries.len(), wl.len()));
    for (g, geo) in geometries.iter().enumerate() {
        let (view, az) = geo.view();
        for (l, r) in reflections.iter().enumerate() {
            factors[[g, l]] = r.factor(geo.illumination_deg, view, az)?;
        }
    }
    let rows: Vec<Vec<f64>> = factors.outer_iter().map(|r| r.to_vec()).collect();
    let angle_colours = multiangle::colours(&obs, wl, &rows)
        .map_err(crate::optics::baseline::BaselineError::from)?;
    let flop_index = multiangle::flop_index_of(&angle_colours);
    let colours: Vec<AngleRecord> = angle_colours
        .iter()
        .map(|c| AngleRecord {
            illumination_deg: c.geometry.illumination_deg,
            aspecular_deg: c.geometry.aspecular_deg,
            xyz: c.xyz,
            lab: c.lab,
            lch: c.lch,
        })
        .collect();
    let sparkle = paint_sparkle::sparkle_table(scene, &obs)?;
    let plane = in_plane(&reflections)?;
    let terms: Vec<u64> = reflections.iter().map(|r| r.terms.len() as u64).collect();

    let conditions = format!("{}, {}°", scene.illuminant.name(), scene.observer.degrees());
    let name = &scene.output.name;
    let flop = flop_png(&colours, name, &conditions, flop_index)?;
    let paint = format!(
        "{} layer(s) ({}) on {}",
        scene.layers.len(),
        scene
            .layers
            .iter()
            .map(|l| l.name.as_str())
            .collect::<Vec<_>>()
            .join(" / "),
        scene.ground.describe()
    );
    let tile = patches_png(
        &colours,
        &PatchCaption {
            name,
            observer: &obs,
            conditions: &conditions,
            paint: &paint,
            flop_index,
            sparkle: sparkle.as_ref(),
        },
    )?;
    atomic::write_atomic(&picture_path, &tile)?;
    atomic::write_atomic(&flop_path, &flop)?;
    let textures = paint_sparkle::textures(scene, &obs, &reflections)?;
    let graininess = sparkle.as_ref().map_or(0.0, |s| s.graininess);
    let texture = paint_sparkle::texture_png(scene, &obs, &conditions, &textures, graininess)?;
    atomic::write_atomic(&sparkle_path, &texture)?;
    let mut plan_lines = plan;
    plan_lines.push(format!(
        "Fourier terms kept per wavelength: {}–{}",
        terms.iter().min().copied().unwrap_or(0),
        terms.iter().max().copied().unwrap_or(0)
    ));
    let created_unix_s = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    let config_path = scene.provenance.path.display().to_string();
    h5::write_paint(
        &result_path,
        &PaintResultSet {
            identity: Identity {
                version: crate::VERSION,
                config_path: &config_path,
                input_hash: &scene.provenance.input_hash,
                created_unix_s,
            },
            config_text: &scene.provenance.text,
            plan: &plan_lines.join("\n"),
            wavelengths_nm: wl,
            directions_deg: &plane.directions_deg,
            brdf: &plane.brdf,
            view_deg: &plane.view_deg,
            mirror: &plane.mirror,
            albedo: &plane.albedo,
            terms: &terms,
            factors: &factors,
            colours: &colours,
            illuminant: scene.illuminant.name(),
            observer_deg: scene.observer.degrees(),
            flop_index,
            sparkle: sparkle.as_ref(),
            tile_png: &tile,
            flop_png: &flop,
        },
    )?;
    Ok(PaintReport {
        result_path,
        picture_path,
        flop_path,
        sparkle_path,
        colours,
        flop_index,
        sparkle,
        seconds: start.elapsed().as_secs_f64(),
    })
}
