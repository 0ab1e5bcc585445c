//! The run plan: what a run computes and what it skips, and why, derived
//! from what the scene asks for — how the layer is made (closed-form slab,
//! explicit structure or generated grains, and which packer), how many
//! realisations with which seeds, which solves from above and below, and
//! which appearance products. Every decision is one line of the plan that is
//! logged and stored with the results.

use crate::config::{GrainShape, Incidence, Scene, Structure, Substrate, Surface};
use crate::optics::baseline::ordinates::{OrdinateParams, Ordinates};
use crate::optics::effective_medium::{self, GrainClass, WorstError};
use crate::optics::farfield::table::TableSpec;
use crate::optics::farfield::{Side, SolveEntry};
use crate::optics::substrate::Hemisphere;

use super::eps::species_eps;
use super::grains::{largest_grain_nm, realisation_seed, stack_layer_seed, Packer, RSA_MAX_PVC};
use super::surface::surface_line;

/// What a run computes and what it skips, derived from what the scene asks
/// for: only the effects a scene calls for.
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
    /// Solved inside its binder (a layer of an incoherent stack): the
    /// medium above and below is the binder, not air, so the problem is
    /// solved at the wavelength in the binder `λ/n_b` with `ε/ε_b`, and the
    /// orders' angles are angles in the binder.
    pub embedded: bool,
    /// The plans of an incoherent stack's layers, from the top (empty for
    /// one layer, or a stack solved as one fragment); then the fields above
    /// describe the stack as a whole.
    pub layers: Vec<RunPlan>,
}

impl RunPlan {
    /// Derive the plan of a scene.
    pub fn of(scene: &Scene) -> RunPlan {
        if scene.is_incoherent_stack() {
            return stack_plan(scene);
        }
        let explicit = scene.structure.is_some();
        let (above, extra) = above_angles(scene);
        // Only a ground that reflects needs the layer's terms from below.
        let paper = scene.substrate.ground().is_some();
        // The paper term: for the tile's colours and the preview.
        let products = scene.appearance.products;
        let below = ((products.tile || products.preview) && paper)
            .then(|| Hemisphere::new(scene.appearance.quadrature_points));
        // A stack in one fragment is never one homogeneous slab.
        let shortcut = if scene.is_molecular() || explicit || scene.stack.is_some() {
            None
        } else {
            let mut angles = above.clone();
            angles.extend(below.iter().flat_map(|h| h.polar_deg()));
            Some(effective_medium_shortcut(scene, &angles))
        };
        let analytic =
            (scene.is_molecular() && scene.stack.is_none()) || matches!(shortcut, Some(Ok(_)));
        let mut lines = layer_lines(scene, shortcut.as_ref());
        if !analytic && !explicit {
            lines.extend(grain_lines(scene));
        }
        let (realisations, line) = realisations_of(scene, analytic, explicit);
        lines.push(line);
        let seeds = (0..realisations)
            .map(|r| realisation_seed(scene.seed, r))
            .collect();
        lines.extend(solve_lines(&above, extra, below.as_ref(), &scene.substrate));
        let (table, line) = table_of(scene);
        lines.push(line);
        lines.extend(product_lines(scene));
        RunPlan {
            analytic,
            realisations,
            seeds,
            above_deg: above,
            below,
            table,
            lines,
            embedded: false,
            layers: Vec::new(),
        }
    }

    /// Solves per realisation and wavelength.
    pub fn solves_per_wavelength(&self) -> usize {
        self.above_deg.len() + self.below.as_ref().map_or(0, |h| h.mu.len())
    }

    /// Permittivity of the medium above and below the layer as solved:
    /// the binder's when `embedded` (then the problem is solved at `λ/n_b`
    /// with `ε/ε_b`), else vacuum's, 1.
    pub fn outside_eps(&self, scene: &Scene) -> f64 {
        if self.embedded {
            scene.layer.binder_index.powi(2)
        } else {
            1.0
        }
    }

    /// Total solves of a run.
    pub fn solves(&self, scene: &Scene) -> usize {
        let per_layer = |p: &RunPlan| p.realisations * p.solves_per_wavelength();
        let per_wavelength = if self.layers.is_empty() {
            per_layer(self)
        } else {
            self.layers.iter().map(per_layer).sum()
        };
        scene.wavelengths_nm.len() * per_wavelength
    }
}

/// How the layer is made: a closed-form slab (molecular mixture or the
/// effective-medium shortcut), an explicit structure, or packed grains (and,
/// when the shortcut was weighed, why it was refused).
fn layer_lines(scene: &Scene, shortcut: Option<&Result<String, String>>) -> Vec<String> {
    let mut lines = Vec::new();
    if scene.is_molecular() {
        lines.push(
            "geometry: none — molecular mixture: the homogeneous slab with the \
             volume-averaged ε, solved in closed form (Airy); no grid, no iteration"
                .to_string(),
        );
    } else if let Some(Ok(why)) = shortcut {
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
        lines.extend(super::fine_bodies::fine_body_lines(scene));
    } else {
        let (packer, why) = Packer::of(scene);
        lines.push(format!("geometry: {packer} ({why})"));
        if let Some(Err(why)) = shortcut {
            lines.push(format!("effective-medium shortcut: refused — {why}"));
        }
    }
    lines
}

/// What the packed grains go through: surface relief, equilibration,
/// agglomeration.
fn grain_lines(scene: &Scene) -> Vec<String> {
    let mut lines = Vec::new();
    let rf = scene.layer.relief_fraction;
    lines.push(if rf > 0.0 {
        format!(
            "surface relief: grains may protrude up to {:.0} % of their size through the top; \
             the grid extends above the binder (vacuum around the grains above the binder surface)",
            rf * 100.0
        )
    } else {
        "surface relief: none (grains stay inside the binder)".to_string()
    });
    lines.push(surface_line(scene));
    let vp = scene.grid.voxel_permittivity;
    lines.push(format!(
        "voxels cut by a grain surface: {}{}",
        vp.describe(scene.solver.equation),
        if vp.anisotropic(scene.solver.equation) {
            format!(
                ", about {:.0} % of the voxels",
                100.0 * super::memory::cut_share(scene)
            )
        } else if scene.solver.equation == crate::config::Equation::Maxwell {
            " (grid.voxel_permittivity = \"average\"; \"auto\" would make them anisotropic, \
             the smaller grid error)"
                .to_string()
        } else {
            String::new()
        }
    ));
    for s in scene.species.iter().filter(|s| s.material.axes().is_some()) {
        lines.push(format!(
            "crystal grains: `{}` {}",
            s.name,
            if scene.solver.equation == crate::config::Equation::Maxwell {
                "as a tensor per grain (ordinary and extraordinary ε, the c axis along a \
                 rod's length or uniform at random for a sphere)"
            } else {
                "as its orientation average (2ε_o + ε_e)/3 (the scalar equation has no \
                 direction; Maxwell's takes a tensor per grain)"
            }
        ));
    }
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
    lines
}

/// Realisations actually run (one for a deterministic layer), and the line
/// that says so.
fn realisations_of(scene: &Scene, analytic: bool, explicit: bool) -> (usize, String) {
    let realisations = if analytic || explicit {
        1
    } else {
        scene.realisations
    };
    let line = if (analytic || explicit) && scene.realisations > 1 {
        format!(
            "realisations: 1 of {} requested — {} is deterministic",
            scene.realisations,
            if analytic {
                "a homogeneous layer"
            } else {
                "an explicit structure"
            }
        )
    } else if let Some(t) = scene.realisation_target {
        format!(
            "realisations: {} to {realisations}, added until every measured colour's ΔE00 \
             standard error is ≤ {}",
            t.min, t.de00
        )
    } else {
        format!(
            "realisations: {realisations}{}",
            if realisations == 1 {
                " (no standard errors; the specular split needs ≥ 2)"
            } else {
                ""
            }
        )
    };
    (realisations, line)
}

/// The solves from above and from below, or why those from below are
/// skipped.
fn solve_lines(
    above: &[f64],
    extra: usize,
    below: Option<&Hemisphere>,
    substrate: &Substrate,
) -> Vec<String> {
    let mut lines = vec![format!(
        "solves from above at {} polar angles {}{}",
        above.len(),
        fmt_list(above),
        if extra > 0 {
            format!(" ({extra} angles beyond the illumination angles: the tile's viewing angles and the measurement geometries need R and T there)")
        } else {
            String::new()
        }
    )];
    if let Some(h) = below {
        lines.push(format!(
            "solves from below (layer flipped) at {} Gauss–Legendre nodes {}: the paper term needs R_dd↑ and T_d",
            h.mu.len(),
            fmt_list(&h.polar_deg())
        ));
        if substrate.is_chart() {
            lines.push(format!(
                "substrate: {substrate}; both halves from the same solves (the ground enters \
                 after them), with the contrast ratio and Kubelka's S and K"
            ));
        }
    } else if *substrate == Substrate::None {
        lines.push("solves from below: skipped — no substrate".to_string());
    } else if *substrate == Substrate::Black {
        lines.push("solves from below: skipped — the black ground reflects nothing".to_string());
    } else {
        lines.push(
            "solves from below: skipped — no tile or preview requested, nothing uses the paper term"
                .to_string(),
        );
    }
    lines
}

/// The angular table of the BRDF/BTDF, and the line describing it.
fn table_of(scene: &Scene) -> (TableSpec, String) {
    let max_wl = scene.wavelengths_nm.iter().copied().fold(0.0, f64::max);
    let l = &scene.layer;
    let cell = scene
        .appearance
        .brdf_cell
        .unwrap_or_else(|| TableSpec::default_cell(max_wl, [l.fragment_x_nm, l.fragment_y_nm]));
    let table = TableSpec::new(cell);
    let line = format!(
        "BRDF table: cell {cell:.4} in sin θ ({}), {}×{} nodes",
        if scene.appearance.brdf_cell.is_some() {
            "set"
        } else {
            "default 2 λ_max / L"
        },
        table.n(),
        table.n()
    );
    (table, line)
}

/// Which appearance products run and which are skipped.
fn product_lines(scene: &Scene) -> Vec<String> {
    let products = scene.appearance.products;
    let mut lines = vec![
        if products.btdf {
            "BTDF table: computed (requested)".to_string()
        } else {
            "BTDF table: skipped — not requested".to_string()
        },
        if products.tile {
            let a = &scene.appearance;
            let geometries: Vec<&str> = a.measurements.iter().map(|m| m.name()).collect();
            format!(
                "tile and colours: computed (sky strip + BRDF square; measurement geometries: {}; \
                 {} illuminant, {} observer; shown in sRGB, Bradford-adapted to D65)",
                if geometries.is_empty() {
                    "none".to_string()
                } else {
                    geometries.join(", ")
                },
                a.illuminant,
                a.observer
            )
        } else {
            "tile and colours: skipped — not requested".to_string()
        },
    ];
    for &b in &scene.appearance.baseline {
        let grains = crate::optics::baseline::grain::GrainModel::of(scene.solver.equation);
        let surfaces = crate::optics::baseline::surfaces(b, scene.solver.equation);
        lines.push(format!(
            "baseline: {} computed beside the measured colours (equal-volume spheres in the \
             binder, {}, independent scattering; {}; {} surfaces; shapes and clusters not seen)",
            b.name(),
            grains.name(),
            b.summary(),
            surfaces.name()
        ));
    }
    if products.merl {
        lines.push("MERL export: written beside the result (approximation: see docs)".to_string());
    }
    if products.preview {
        lines.push("preview: a rendered sphere, <name>-preview.png".to_string());
    }
    lines
}

/// Polar angles solved from above (the illumination angles, plus the
/// viewing angles and the measurement geometries' angles when the tile needs
/// colour), and how many of them are not illumination angles.
fn above_angles(scene: &Scene) -> (Vec<f64>, usize) {
    let illum: Vec<f64> = scene.incidence.iter().map(|i| i.polar_deg).collect();
    let mut above = illum.clone();
    if scene.appearance.products.tile {
        let measured = scene
            .appearance
            .measurements
            .iter()
            .flat_map(|m| m.above_deg());
        for &v in scene.appearance.viewing_deg.iter().chain(measured) {
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
/// slab of the volume-averaged ε: `Ok(why)` when the estimated error
/// ([`effective_medium::worst_error`]) at the scene's worst wavelength and
/// angle is within `[solver] effective_medium_tolerance`, `Err(why not)`
/// otherwise, or when the layer has something the slab cannot represent or
/// lies outside what the estimate was measured on.
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
    if scene.layer.surface != Surface::Flat {
        return Err("the binder surface is not flat, so the layer is not a flat slab".into());
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
    let d_max = largest_grain_nm(scene);
    let lambda_min = scene
        .wavelengths_nm
        .iter()
        .copied()
        .fold(f64::INFINITY, f64::min);
    let x = effective_medium::size_parameter(d_max, lambda_min);
    if effective_medium::beyond_measured_size(x) {
        return Err(format!(
            "grains up to {d_max:.3} nm are beyond λ/20 at {lambda_min} nm (k0 d = {x:.3}), \
             outside the range where the effective-medium error was measured"
        ));
    }
    let grains: Vec<GrainClass> = scene
        .species
        .iter()
        .map(|s| GrainClass {
            volume_fraction: s.volume_fraction,
            max_diameter_nm: s.size.max_diameter(s.diameter_nm),
        })
        .collect();
    let WorstError {
        error: est,
        wavelength_nm: lambda,
        polar_deg: p,
    } = effective_medium::worst_error(
        &grains,
        scene.layer.binder_index.powi(2),
        scene.layer.thickness_nm,
        &scene.wavelengths_nm,
        polar_deg,
        |lambda| species_eps(scene, lambda).map_err(|e| e.to_string()),
    )?;
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

/// The polar angles and sides solved per wavelength, in solve order.
pub fn incidences(scene: &Scene, plan: &RunPlan) -> Vec<(Side, Incidence)> {
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
            "solve {}{} nm, {}°/{}° {} #{}: {} ({})",
            if plan.layers.is_empty() {
                String::new()
            } else {
                format!("stack[{}] ", e.layer)
            },
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

/// The air angles a stack reports at: the illumination and viewing angles
/// and every measurement geometry's, increasing (the single layer's solves
/// from above).
pub(super) fn stack_air_angles(scene: &Scene) -> Vec<f64> {
    let mut air: Vec<f64> = scene
        .appearance
        .measurements
        .iter()
        .flat_map(|m| m.above_deg().iter().copied())
        .chain(scene.appearance.viewing_deg.iter().copied())
        .chain(scene.incidence.iter().map(|i| i.polar_deg))
        .collect();
    air.sort_by(f64::total_cmp);
    air.dedup();
    air
}

/// The adding method's directions for a stack: the stack's binder, its
/// direction counts, and every air angle a measurement or the white sky
/// reads among the nodes.
pub fn stack_ordinates(scene: &Scene) -> Ordinates {
    let st = scene.stack.as_ref().expect("a stack");
    let air = stack_air_angles(scene);
    let params = OrdinateParams {
        trapped_nodes: st.trapped_directions,
        escape_nodes: st.escape_directions,
    };
    // The config holds the binder at ≥ 1 and the counts at ≥ 1, polar < 90°.
    Ordinates::new(scene.layer.binder_index, params, &air)
        .expect("a checked stack has valid directions")
}

/// Polar angle in the binder of each node.
pub(super) fn node_deg(ords: &Ordinates) -> Vec<f64> {
    ords.mu.iter().map(|m| m.acos().to_degrees()).collect()
}

/// The plan of an incoherent stack: the stack as a whole, with each
/// layer's plan in `layers` (layer `i`'s scene is `scene.stack_layer(i)`).
pub fn stack_plan(scene: &Scene) -> RunPlan {
    let st = scene.stack.as_ref().expect("a stack");
    let ords = stack_ordinates(scene);
    let nodes = node_deg(&ords);
    let mut plans = Vec::with_capacity(st.layers.len());
    let mut lines = vec![format!(
        "stack: {} layer{} from the top ({}), coupled incoherently: each solved on its own \
         inside the binder (n = {}: at λ/n with ε/n²), from above and from below at {} \
         directions ({} trapped by the surface, {} escaping; binder polar angles {}), combined \
         by adding under the flat binder surface ({}) on {}",
        st.layers.len(),
        if st.layers.len() == 1 { "" } else { "s" },
        st.layers
            .iter()
            .map(|l| format!(
                "{} nm of {}{}",
                l.layer.thickness_nm,
                l.species
                    .iter()
                    .map(|s| s.name.as_str())
                    .collect::<Vec<_>>()
                    .join(" + "),
                if l.coverage < 1.0 {
                    format!(" on {}% of the area", 100.0 * l.coverage)
                } else {
                    String::new()
                }
            ))
            .collect::<Vec<_>>()
            .join(", "),
        scene.layer.binder_index,
        ords.len(),
        ords.mu_air.iter().filter(|m| m.is_none()).count(),
        ords.mu_air.iter().filter(|m| m.is_some()).count(),
        nodes
            .iter()
            .map(|d| format!("{d:.1}"))
            .collect::<Vec<_>>()
            .join(", "),
        match scene.solver.equation {
            crate::config::Equation::Helmholtz => "s-like Fresnel reflectance, as Helmholtz's",
            crate::config::Equation::Maxwell =>
                "natural light's Fresnel reflectance; Maxwell's layers combined as natural \
                 light's fluxes",
        },
        match scene.substrate.ground().and_then(|g| g.constant()) {
            Some(albedo) => format!("a ground of albedo {albedo} in air"),
            None => "air".to_string(),
        }
    )];
    if st.layers.iter().any(|l| l.coverage < 1.0) {
        let primaries = crate::optics::baseline::halftone::primaries(
            &st.layers.iter().map(|l| l.coverage).collect::<Vec<_>>(),
        );
        lines.push(format!(
            "halftone: {} primaries (Demichel's areas {}), each added from the same layer \
             solves, mixed by Yule–Nielsen n = {}{} on the paper and by area in air",
            primaries.len(),
            primaries
                .iter()
                .map(|p| format!(
                    "{}: {:.3}",
                    if p.layers.is_empty() {
                        "paper".to_string()
                    } else {
                        p.layers
                            .iter()
                            .map(|i| format!("stack[{i}]"))
                            .collect::<Vec<_>>()
                            .join("+")
                    },
                    p.area
                ))
                .collect::<Vec<_>>()
                .join(", "),
            st.yule_nielsen_n,
            if st.yule_nielsen_n == 1.0 {
                " (Murray–Davies)"
            } else {
                ""
            }
        ));
    }
    lines.push(if scene.appearance.products.tile {
        format!(
            "tile: the BRDF square in the plane of incidence from {} azimuthal Fourier terms of \
             each layer, added term by term (each layer taken as isotropic in its plane); not \
             made for an incoherent stack: the orders picture and the BRDF plots, which need \
             every azimuth (coupling \"coherent\" makes them)",
            crate::optics::stack::AZIMUTHAL_TERMS
        )
    } else {
        "no tile asked for: the adding carries each layer's azimuthal mean only, which gives \
         the measurement geometries and the white sky exactly"
            .to_string()
    });
    for i in 0..st.layers.len() {
        let ls = scene.stack_layer(i).expect("a layer of the stack");
        let mut p = RunPlan::of(&ls);
        p.above_deg = nodes.clone();
        p.below = Some(Hemisphere {
            mu: ords.mu.clone(),
            weight: ords.weight.clone(),
        });
        p.embedded = true;
        p.seeds = (0..p.realisations)
            .map(|r| stack_layer_seed(realisation_seed(scene.seed, r), i))
            .collect();
        // The layer's own decisions (geometry, realisations); its solves and
        // products are the stack's, stated here and above.
        let own = p
            .lines
            .iter()
            .position(|l| l.starts_with("realisations"))
            .map_or(p.lines.len(), |k| k + 1);
        lines.extend(p.lines[..own].iter().map(|l| format!("stack[{i}]: {l}")));
        lines.push(format!(
            "stack[{i}]: solves from above and from below at the {} directions: {} per \
             wavelength and realisation{}",
            nodes.len(),
            2 * nodes.len(),
            if p.analytic { ", in closed form" } else { "" }
        ));
        plans.push(p);
    }
    let realisations = plans.iter().map(|p| p.realisations).max().unwrap_or(1);
    let cell = st
        .layers
        .iter()
        .map(|l| {
            TableSpec::default_cell(
                scene.wavelengths_nm.last().copied().unwrap_or(1.0) / scene.layer.binder_index,
                [l.layer.fragment_x_nm, l.layer.fragment_y_nm],
            )
        })
        .fold(0.0, f64::max);
    lines.push(format!(
        "stack tables: each solve's orders spread on a table of cell {cell:.4} in sin θ (binder) \
         and integrated over each direction's bin"
    ));
    RunPlan {
        analytic: plans.iter().all(|p| p.analytic),
        realisations,
        seeds: (0..realisations)
            .map(|r| realisation_seed(scene.seed, r))
            .collect(),
        above_deg: nodes,
        below: plans.first().and_then(|p| p.below.clone()),
        table: TableSpec::new(cell),
        lines,
        embedded: true,
        layers: plans,
    }
}
