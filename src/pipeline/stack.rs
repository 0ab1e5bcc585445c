//! A stack solved layer by layer (`stacking.coupling = "incoherent"`):
//! each layer made and solved on its own, inside its binder, from above and
//! from below at the directions of the adding method; per realisation and
//! wavelength the layers' flux matrices combined by adding under the flat
//! binder surface on the paper (`optics::stack`), a halftone's primaries
//! mixed by area; colours through the spectral proxy of the stack of
//! homogeneous slabs (`stack_proxy`). A stack solved as one
//! fragment (`coherent`) is an ordinary run whose geometry is the layers'
//! fragments on top of each other (`grains::build_geometry_seeded`).

use ndarray::{Array1, Array2, Array3};

use crate::config::Scene;
use crate::optics::appearance::{self, MeasuredColour, TileSpectra};
use crate::optics::baseline::fresnel::Fresnel;
use crate::optics::colour::Observer;
use crate::optics::farfield::Side;
use crate::optics::stack::{self, Below, BinQuadrature, Views};
use crate::output::h5::{LayerMatrices, StackTables};
use crate::output::{atomic, render};

use super::grains::stacked_geometry;
use super::layer::{self, SolvedLayer};
use super::memory::{self, MemoryLimit};
use super::plan::{node_deg, plan_text, stack_air_angles, stack_ordinates, stack_plan, RunPlan};
use super::result::{ResultParts, RunReport};
use super::stack_proxy::proxy_factors;
use super::{check_output_dir, check_output_files, result_paths, started, PipelineError};

/// Run an incoherent stack end to end and write its result file.
pub fn run(
    scene: &Scene,
    quiet: bool,
    limit: Option<MemoryLimit>,
) -> Result<RunReport, PipelineError> {
    let (result_path, picture_path) = result_paths(scene);
    check_output_files(scene)?;
    check_output_dir(&scene.output.dir)?;
    let mut plan = stack_plan(scene);
    let scenes: Vec<Scene> = (0..plan.layers.len())
        .map(|i| scene.stack_layer(i).expect("a layer of the stack"))
        .collect();
    for ls in &scenes {
        memory::preflight(ls, limit)?;
    }
    super::disk::preflight(
        &scene.output.dir,
        scenes
            .iter()
            .zip(&plan.layers)
            .map(|(ls, p)| super::disk::estimate_bytes(ls, p))
            .sum(),
    )?;
    let total = plan.solves(scene) as u64;
    let progress = started(scene, total, quiet, &plan.lines);
    let mut solved: Vec<SolvedLayer> = Vec::with_capacity(scenes.len());
    let mut entries = Vec::new();
    for (i, (ls, p)) in scenes.iter().zip(&plan.layers).enumerate() {
        progress.log(&format!("stack[{i}]: solving"));
        let mut s = layer::solve(ls, p, &progress)?;
        for e in &mut s.entries {
            e.layer = i;
        }
        entries.extend(s.entries.iter().cloned());
        solved.push(s);
    }
    progress.finish("all solves done");
    let tables = combine(scene, &plan, &scenes, &solved)?;
    // Realisation 0 of every layer as one fragment.
    let geometry = stacked_geometry(
        solved
            .iter()
            .zip(&scenes)
            .map(|(s, ls)| (s.geometry.clone(), ls.clone()))
            .collect(),
    );
    let thickness = scene.layer.thickness_nm;
    let realisations: Vec<(u64, f64)> = (0..plan.realisations)
        .map(|r| {
            let pvc = scenes
                .iter()
                .zip(&solved)
                .map(|(ls, s)| {
                    let n = s.realisations.len().max(1);
                    s.realisations.get(r % n).map_or(0.0, |x| x.1) * ls.layer.thickness_nm
                        / thickness
                })
                .sum();
            (plan.seeds[r], pvc)
        })
        .collect();
    plan.lines.push(format!(
        "stack colours: {} realisation{} of the whole stack (realisation r of every layer)",
        plan.realisations,
        if plan.realisations == 1 { "" } else { "s" }
    ));
    let tile_png = match &tables.colours {
        Some(c) => Some(render::tile::tile_png(
            &c.tile_srgb8,
            &c.tile_lab,
            &tables.viewing_deg,
            &tables.illumination_deg,
            &render::tile::TileCaption {
                name: &scene.output.name,
                observer: &Observer::standard(
                    scene.appearance.illuminant,
                    scene.appearance.observer,
                ),
                ground: &scene.substrate.on_phrase(),
                hiding: None,
                azimuth_deg: scene.incidence.first().map_or(0.0, |i| i.azimuth_deg),
            },
        )?),
        None => None,
    };
    let picture_path = match &tile_png {
        Some(png) => {
            atomic::write_atomic(&picture_path, png)?;
            Some(picture_path)
        }
        None => None,
    };
    ResultParts {
        scene,
        geometry: Some(&geometry),
        raster: None,
        entries: &entries,
        realisations: &realisations,
        realisation_stop: None,
        plan: &plan_text(&plan, &entries),
        orders_png: &[],
        tile_png: tile_png.as_deref(),
        appearance: None,
        stack: Some(&tables),
    }
    .write(&result_path)?;
    Ok(RunReport {
        result_path,
        picture_path,
        orders_picture_path: None,
        plot_paths: Vec::new(),
        geometry: Some(geometry),
        entries,
        appearance: None,
    })
}

/// The solves of the layers combined: per realisation and wavelength the
/// stack's reflection, its measured colours, white sky and R, T, A.
fn combine(
    scene: &Scene,
    plan: &RunPlan,
    scenes: &[Scene],
    solved: &[SolvedLayer],
) -> Result<StackTables, PipelineError> {
    let ords = stack_ordinates(scene);
    let nodes = node_deg(&ords);
    let k = ords.len();
    let q = BinQuadrature::new(&ords, plan.table);
    // The check leaves a stack only grounds of one albedo (or none).
    let below = match scene.substrate.ground().and_then(|g| g.constant()) {
        Some(albedo) => Below::Paper { albedo },
        None => Below::Air,
    };
    let wl = &scene.wavelengths_nm;
    let measurements = &scene.appearance.measurements;
    let viewing = &scene.appearance.viewing_deg;
    let above = stack_air_angles(scene);
    let illumination: Vec<f64> = scene.incidence.iter().map(|i| i.polar_deg).collect();
    let tile = scene.appearance.products.tile;
    let terms = if tile { stack::AZIMUTHAL_TERMS } else { 1 };
    let views = Views {
        measurements,
        viewing_deg: viewing,
        illumination_deg: tile.then_some(&illumination[..]),
        above_deg: &above,
        surfaces: Fresnel::of(scene.solver.equation),
    };
    let (coverage, yn) = halftone_of(scene);
    let rr = plan.realisations;
    // The diffuse BRDF in the plane of incidence, 1/sr, (wavelength,
    // illumination, viewing), per realisation.
    let mut brdf = vec![
        Array3::zeros((wl.len(), illumination.len(), viewing.len()));
        if tile { rr } else { 0 }
    ];
    let mut factors = vec![vec![Array1::zeros(wl.len()); rr]; measurements.len()];
    let mut natural = vec![Array2::zeros((wl.len(), viewing.len())); rr];
    let mut rta = vec![[(); 3].map(|_| Array2::zeros((wl.len(), above.len()))); rr];
    let mut means: Vec<[Array3<f64>; 4]> = solved
        .iter()
        .map(|_| [(); 4].map(|_| Array3::zeros((wl.len(), k, k))))
        .collect();
    for r in 0..rr {
        for (l, &w) in wl.iter().enumerate() {
            let mut slabs = Vec::with_capacity(solved.len());
            for (i, s) in solved.iter().enumerate() {
                let n = s.realisations.len().max(1);
                let find = |side: Side, j: usize| {
                    appearance::find_entry(&s.entries, side, r % n, w, nodes[j])
                        .map(|e| &e.efficiencies)
                };
                let slab = stack::layer_slab(&q, k, terms, &find)?;
                let t = &slab.total;
                for (acc, m) in means[i]
                    .iter_mut()
                    .zip([&t.r_down, &t.t_down, &t.r_up, &t.t_up])
                {
                    for a in 0..k {
                        for b in 0..k {
                            acc[[l, a, b]] += m[(a, b)] / rr as f64;
                        }
                    }
                }
                slabs.push(slab);
            }
            let look = stack::halftone(&ords, &slabs, &coverage, yn, below, &views)?;
            for (g, f) in look.factors.iter().enumerate() {
                factors[g][r][l] = *f;
            }
            for (v, f) in look.natural.iter().enumerate() {
                natural[r][[l, v]] = *f;
            }
            if let Some(f) = look.plane {
                brdf[r]
                    .index_axis_mut(ndarray::Axis(0), l)
                    .assign(&(f / std::f64::consts::PI));
            }
            for (a, t) in look.totals.iter().enumerate() {
                for (c, x) in t.iter().enumerate() {
                    rta[r][c][[l, a]] = *x;
                }
            }
        }
    }
    let observer = Observer::standard(scene.appearance.illuminant, scene.appearance.observer);
    let proxy = proxy_factors(scene, scenes, &ords, below, &views, (&coverage, yn))?;
    let mut measured: Vec<MeasuredColour> = Vec::with_capacity(measurements.len());
    for (g, &m) in measurements.iter().enumerate() {
        let p = proxy.as_ref().map(|p| (&p.fine[..], &p.factors[g][..]));
        measured.push(appearance::colour_of_samples(
            m,
            wl,
            &factors[g],
            p,
            plan.analytic,
            &observer,
        )?);
    }
    let baseline = super::baseline::baseline_colours(scene, &measured, &observer)?;
    let natural_mean = appearance::reduce(&natural);
    let (brdf_total, colours) = if tile {
        let mean = appearance::reduce(&brdf);
        let per: Vec<TileSpectra> = if rr >= 2 {
            brdf.into_iter().zip(natural).collect()
        } else {
            Vec::new()
        };
        let c = appearance::tile_colours(
            wl,
            (&mean.mean, &natural_mean.mean),
            &per,
            &observer,
            proxy.as_ref().map(|p| (&p.fine[..], &p.brdf, &p.sky)),
        )?;
        (Some(mean), Some(c))
    } else {
        (None, None)
    };
    let pick = |c: usize| appearance::reduce(&rta.iter().map(|x| x[c].clone()).collect::<Vec<_>>());
    Ok(StackTables {
        coupling: "incoherent".to_string(),
        layer_thickness_nm: scenes.iter().map(|s| s.layer.thickness_nm).collect(),
        layer_coverage: coverage,
        yule_nielsen_n: yn,
        layer_pigments: scenes
            .iter()
            .map(|s| {
                s.species
                    .iter()
                    .map(|x| x.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            })
            .collect(),
        binder_polar_deg: nodes,
        air_polar_deg: ords
            .mu_air
            .iter()
            .map(|m| m.map_or(f64::NAN, |m| m.clamp(-1.0, 1.0).acos().to_degrees()))
            .collect(),
        flux_weight: ords.flux_weight.clone(),
        wavelengths_nm: wl.clone(),
        layers: means
            .into_iter()
            .map(|[r_down, t_down, r_up, t_up]| LayerMatrices {
                r_down,
                t_down,
                r_up,
                t_up,
            })
            .collect(),
        realisations: rr,
        above_deg: above,
        reflectance: pick(0),
        transmittance: pick(1),
        absorption: pick(2),
        viewing_deg: viewing.clone(),
        natural: natural_mean,
        illumination_deg: illumination,
        brdf_total,
        colours,
        measured,
        baseline,
        conditions: (scene.appearance.illuminant, scene.appearance.observer),
    })
}

/// Each layer's coverage and Yule–Nielsen's n of the stack of `scene`.
fn halftone_of(scene: &Scene) -> (Vec<f64>, f64) {
    let st = scene.stack.as_ref().expect("a stack");
    (
        st.layers.iter().map(|l| l.coverage).collect(),
        st.yule_nielsen_n,
    )
}
