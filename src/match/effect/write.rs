//! An effect match's files in its output folder, as a scene's match writes
//! them: `<name>.h5` (the match file, the target per geometry and every
//! reported recipe: its unknowns with standard errors, correlations and
//! flags, ΔE00 per geometry with its standard error, its multi-angle
//! colours and flop index; layout in docs/MATCH.md, "Effect paints"),
//! `<name>-recipes.csv` (one row per recipe) and the page `<name>.html`
//! ([`super::page`]), written atomically under the output lock.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use hdf5::Group;
use ndarray::Array2;

use crate::optics::flakes::multiangle;
use crate::output::atomic::{write_atomic, write_atomic_with};
use crate::output::h5::{about, dim, write_scalar_attr, write_str_attr, IoError, Scales};
use crate::output::lock::OutputLock;

use super::super::write::{strings, write_unknowns, RecipeUnknowns};
use super::super::MatchError;
use super::config::EffectSpec;
use super::report::{EffectRecipe, EffectReport};

const RECIPE: &str = "recipe";
const GEOMETRY: &str = "geometry";
const ANGLE: &str = "multi_angle_geometry";
const PIGMENT: &str = "pigment";
const FLAKES: &str = "flake_layer";
const BOUND: &str = "bound";

/// The files written.
#[derive(Debug, Clone)]
pub struct Written {
    pub h5: PathBuf,
    pub csv: PathBuf,
    pub page: PathBuf,
}

/// Write the report of `spec` into `dir`.
pub fn write_outputs(
    spec: &EffectSpec,
    report: &EffectReport,
    dir: &Path,
) -> Result<Written, MatchError> {
    let h5 = dir.join(format!("{}.h5", spec.name));
    let csv = dir.join(format!("{}-recipes.csv", spec.name));
    let page = dir.join(format!("{}.html", spec.name));
    let lock = OutputLock::acquire(&h5)?;
    write_atomic_with(&h5, |tmp| -> Result<(), IoError> {
        write_h5(spec, report, tmp).map_err(|source| IoError::Hdf5 {
            path: tmp.to_path_buf(),
            source,
        })
    })?;
    write_atomic(&csv, recipes_csv(spec, report).as_bytes())?;
    write_atomic(&page, super::page::html(spec, report).as_bytes())?;
    drop(lock);
    Ok(Written { h5, csv, page })
}

fn write_h5(spec: &EffectSpec, r: &EffectReport, path: &Path) -> hdf5::Result<()> {
    let f = crate::output::h5::create(path)?;
    let text = &spec.text;
    for (k, v) in [
        ("inksim_version", crate::VERSION),
        ("match_file", &spec.path.display().to_string()),
        ("match_toml", text.as_str()),
        ("kind", "effect"),
        ("model", "fast flake model (METHOD §10)"),
        ("objective", spec.search.objective.name()),
        ("illuminant", spec.target.illuminant.name()),
        ("observer", spec.target.observer.name()),
    ] {
        write_str_attr(&f, k, v)?;
    }
    write_scalar_attr(&f, "tolerance_de00", spec.search.tolerance_de00)?;
    write_scalar_attr(&f, "reached", u8::from(r.reached()))?;
    write_scalar_attr(&f, "subsets_tried", r.subsets as u64)?;
    write_scalar_attr(&f, "largest_subset", r.largest as u64)?;
    write_scalar_attr(&f, "model_evaluations", r.evaluations as u64)?;
    write_scalar_attr(&f, "seconds", r.seconds)?;
    let mut sc = Scales::default();
    sc.coordinate(
        &f,
        "wavelength_nm",
        &r.wavelengths_nm,
        about(
            "nm",
            "the base paint's wavelengths (vacuum)",
            &[dim::WAVELENGTH],
        ),
    )?;
    let geoms: Vec<String> = r.target.iter().map(|(g, _)| g.label()).collect();
    sc.coordinate(
        &f,
        GEOMETRY,
        &strings(&geoms)?,
        about(
            "",
            "the target's geometries: <illumination>as<aspecular> (degrees)",
            &[GEOMETRY],
        ),
    )?;
    let all: Vec<String> = multiangle::geometries().iter().map(|g| g.label()).collect();
    sc.coordinate(
        &f,
        ANGLE,
        &strings(&all)?,
        about(
            "",
            "every multi-angle geometry (ASTM E2194 / E2539): <illumination>as<aspecular>",
            &[ANGLE],
        ),
    )?;
    let pigments: Vec<String> = spec
        .pigments
        .iter()
        .map(|p| format!("{}.{}", p.layer, p.pigment))
        .collect();
    sc.coordinate(
        &f,
        PIGMENT,
        &strings(&pigments)?,
        about(
            "",
            "the optional pigments: <layer>.<pigment>, in file order",
            &[PIGMENT],
        ),
    )?;
    let layers: Vec<String> = spec.flakes.iter().map(|u| u.layer.clone()).collect();
    sc.coordinate(
        &f,
        FLAKES,
        &strings(&layers)?,
        about(
            "",
            "the layers whose flakes are varied, in file order",
            &[FLAKES],
        ),
    )?;

    let t = f.create_group("target")?;
    let lab = Array2::from_shape_fn((r.target.len(), 3), |(g, c)| r.target[g].1[c]);
    sc.write(&t, "lab", lab.view(), about("1", "the target's CIELAB L*, a*, b* per geometry, under the file's illuminant and observer; geometry × lab", &[GEOMETRY, dim::LAB]))?;
    let ill: Vec<f64> = r.target.iter().map(|(g, _)| g.illumination_deg).collect();
    let asp: Vec<f64> = r.target.iter().map(|(g, _)| g.aspecular_deg).collect();
    sc.write(
        &t,
        "illumination_deg",
        &ill[..],
        about(
            "deg",
            "illumination angle from the normal; geometry",
            &[GEOMETRY],
        ),
    )?;
    sc.write(
        &t,
        "aspecular_deg",
        &asp[..],
        about(
            "deg",
            "aspecular angle of the view, from the mirror direction towards the normal; geometry",
            &[GEOMETRY],
        ),
    )?;
    sc.write(&t, "noise_lab", &spec.target.noise_lab[..], about("1", "measurement noise (1σ) of L*, a*, b* propagated into the recipes' standard errors; lab", &[dim::LAB]))?;
    if let Some(fi) = r.target_flop_index {
        write_scalar_attr(&t, "flop_index", fi)?;
    }

    let p = f.create_group("palette")?;
    if !spec.pigments.is_empty() {
        let b = Array2::from_shape_fn((spec.pigments.len(), 2), |(i, k)| {
            spec.pigments[i].pvc_range[k]
        });
        sc.write(&p, "pvc_range", b.view(), about("1", "least and most volume fraction of each optional pigment; pigment × bound (min, max)", &[PIGMENT, BOUND]))?;
    }
    if !spec.flakes.is_empty() {
        let b = Array2::from_shape_fn((spec.flakes.len(), 2), |(i, k)| {
            spec.flakes[i].concentration_range[k]
        });
        sc.write(&p, "concentration_range", b.view(), about("1", "least and most flake volume fraction of each varied layer; flake_layer × bound (min, max)", &[FLAKES, BOUND]))?;
        let b = Array2::from_shape_fn((spec.flakes.len(), 2), |(i, k)| {
            spec.flakes[i].coating_nm_range.map_or(f64::NAN, |c| c[k])
        });
        sc.write(&p, "coating_nm_range", b.view(), about("nm", "least and most coating thickness of each varied layer's coated flakes (NaN: not varied); flake_layer × bound (min, max)", &[FLAKES, BOUND]))?;
    }

    let g = f.create_group("recipes")?;
    let n = r.recipes.len();
    let rank: Vec<u64> = r.recipes.iter().map(|x| x.rank as u64).collect();
    sc.coordinate(&g, "rank", &rank, about("1", "rank of each recipe (1 the best; within the tolerance first, fewest colourants, then by the objective); recipe", &[RECIPE]))?;
    if !spec.pigments.is_empty() {
        let pvc = Array2::from_shape_fn((n, spec.pigments.len()), |(i, s)| r.recipes[i].pvc[s]);
        sc.write(&g, "pvc", pvc.view(), about("1", "volume fraction of each optional pigment in each recipe (0: not used); recipe × pigment", &[RECIPE, PIGMENT]))?;
    }
    if !spec.flakes.is_empty() {
        let c = Array2::from_shape_fn((n, spec.flakes.len()), |(i, s)| {
            r.recipes[i].concentration[s]
        });
        sc.write(
            &g,
            "concentration",
            c.view(),
            about(
                "1",
                "flake volume fraction of each varied layer in each recipe; recipe × flake_layer",
                &[RECIPE, FLAKES],
            ),
        )?;
        let c = Array2::from_shape_fn((n, spec.flakes.len()), |(i, s)| r.recipes[i].coating_nm[s]);
        sc.write(&g, "coating_nm", c.view(), about("nm", "coating thickness of each varied layer's coated flakes in each recipe (the base's where not varied; NaN: no coating); recipe × flake_layer", &[RECIPE, FLAKES]))?;
    }
    let de = Array2::from_shape_fn((n, geoms.len()), |(i, k)| {
        r.recipes[i].candidate.fit.de00[k]
    });
    sc.write(
        &g,
        "de00",
        de.view(),
        about(
            "1",
            "CIEDE2000 of each recipe to the target in each geometry; recipe × geometry",
            &[RECIPE, GEOMETRY],
        ),
    )?;
    let se = Array2::from_shape_fn((n, geoms.len()), |(i, k)| r.recipes[i].de00_se[k]);
    sc.write(&g, "de00_se", se.view(), about("1", "standard error of each ΔE00 from the target's measurement noise (docs/MATCH.md); recipe × geometry", &[RECIPE, GEOMETRY]))?;
    let fi: Vec<f64> = r
        .recipes
        .iter()
        .map(|x| x.flop_index.unwrap_or(f64::NAN))
        .collect();
    sc.write(
        &g,
        "flop_index",
        &fi[..],
        about(
            "1",
            "flop index of each recipe (45° illumination at 15°, 45°, 110° aspecular); recipe",
            &[RECIPE],
        ),
    )?;
    let reached: Vec<u8> = r.recipes.iter().map(|x| u8::from(x.reached)).collect();
    sc.write(&g, "reached", &reached[..], about("1", "1 where every geometry is within the tolerance, 0 where the recipe is only the closest reachable; recipe", &[RECIPE]))?;
    for x in &r.recipes {
        let rg = g.create_group(&format!("{:03}", x.rank))?;
        write_recipe(&mut sc, &rg, x)?;
    }
    Ok(())
}

fn write_recipe(sc: &mut Scales, g: &Group, x: &EffectRecipe) -> hdf5::Result<()> {
    if let Some(fi) = x.flop_index {
        write_scalar_attr(g, "flop_index", fi)?;
    }
    write_unknowns(
        sc,
        g,
        &RecipeUnknowns {
            rank: x.rank,
            reached: x.reached,
            candidate: &x.candidate,
            unknowns: &x.unknowns,
            uncertainty: &x.uncertainty,
        },
        [
            "the recipe's unknowns: optional pigments' volume fractions (<layer>.<pigment> pvc), then per varied layer its flake concentration and coating thickness (nm); unknown",
            "each unknown's value: volume fraction (1) or coating thickness (nm); unknown",
            "standard error of each unknown from the target's measurement noise (first-order propagation through the fast flake model's Jacobian), units of the unknown; unknown",
            "the recipe's CIELAB in each target geometry on the fast flake model; geometry × lab",
        ],
    )?;
    let all = Array2::from_shape_fn((x.colours.len(), 3), |(a, b)| x.colours[a].lab[b]);
    sc.write(
        g,
        "lab_all",
        all.view(),
        about(
            "1",
            "the recipe's CIELAB in every multi-angle geometry; multi_angle_geometry × lab",
            &[ANGLE, dim::LAB],
        ),
    )?;
    Ok(())
}

/// CSV text of the recipes: one row per recipe.
pub fn recipes_csv(spec: &EffectSpec, r: &EffectReport) -> String {
    let mut s = String::new();
    let geoms: Vec<String> = r.target.iter().map(|(g, _)| g.label()).collect();
    s.push_str("rank,colourants,reached,composition,flop_index,target_flop_index");
    for g in &geoms {
        let _ = write!(s, ",de00 {g},de00_se {g},L* {g},a* {g},b* {g}");
    }
    s.push_str(",condition_number,not_determined");
    for p in &spec.pigments {
        let _ = write!(s, ",pvc {0}.{1}", p.layer, p.pigment);
    }
    for f in &spec.flakes {
        let _ = write!(s, ",concentration {0},coating_nm {0}", f.layer);
    }
    s.push('\n');
    let opt = |v: Option<f64>| v.map_or(String::new(), |v| format!("{v:.4}"));
    for x in &r.recipes {
        let se = |k: usize| x.uncertainty.se.as_ref().map(|v| v[k]);
        let composition: Vec<String> = x
            .unknowns
            .iter()
            .enumerate()
            .map(|(k, name)| match se(k) {
                Some(e) => format!("{name} {:.5} ± {:.5}", x.candidate.x[k], e),
                None => format!("{name} {:.5}", x.candidate.x[k]),
            })
            .collect();
        let _ = write!(
            s,
            "{},{},{},\"{}\",{},{}",
            x.rank,
            x.candidate.subset.len(),
            u8::from(x.reached),
            composition.join("; "),
            opt(x.flop_index),
            opt(r.target_flop_index)
        );
        for k in 0..geoms.len() {
            let l = x.candidate.fit.lab[k];
            let _ = write!(
                s,
                ",{:.4},{:.4},{:.3},{:.3},{:.3}",
                x.candidate.fit.de00[k], x.de00_se[k], l[0], l[1], l[2]
            );
        }
        let _ = write!(s, ",{}", opt(x.uncertainty.condition));
        let flagged = x.not_determined().join(" | ").replace('"', "'");
        let _ = write!(s, ",\"{flagged}\"");
        for v in &x.pvc {
            let _ = write!(s, ",{v:.6}");
        }
        for (c, t) in x.concentration.iter().zip(&x.coating_nm) {
            let _ = write!(s, ",{c:.6},{t:.3}");
        }
        s.push('\n');
    }
    s
}
