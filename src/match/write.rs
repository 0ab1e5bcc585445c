//! The match's files in its output folder: `<name>.h5` (the match file,
//! the target, the palette and every reported recipe with its colour,
//! uncertainty and metamerism; layout in docs/MATCH.md, every dataset with
//! its units, description and labelled axes) and `<name>-recipes.csv` (one
//! row per recipe), with the verification's part (`/verify`,
//! `<name>-verify.csv`) from [`super::write_verify`]. All are written
//! atomically under the output lock.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use hdf5::types::VarLenUnicode;
use hdf5::Group;
use ndarray::Array2;

use crate::output::atomic::{write_atomic, write_atomic_with};
use crate::output::h5::{about, dim, vlu, write_scalar_attr, write_str_attr, IoError, Scales};
use crate::output::lock::OutputLock;

use super::config::MatchSpec;
use super::report::MatchReport;
use super::MatchError;

const RECIPE: &str = "recipe";
const GEOMETRY: &str = "geometry";
const PIGMENT: &str = "pigment";
const UNKNOWN: &str = "unknown";
const SOURCE: &str = "test_source";
const BOUND: &str = "bound";

/// The files written.
#[derive(Debug, Clone)]
pub struct Written {
    pub h5: PathBuf,
    pub csv: PathBuf,
    /// `<name>-verify.csv`, when recipes were verified.
    pub verify_csv: Option<PathBuf>,
    /// `<name>.html` and its figure `<name>-spectra.png`.
    pub page: PathBuf,
    /// Why the spectra figure was not drawn (the page then goes without
    /// it), if it was not.
    pub figure_skipped: Option<String>,
}

/// Write the report of `spec` into `dir`.
pub fn write_outputs(
    spec: &MatchSpec,
    report: &MatchReport,
    dir: &Path,
) -> Result<Written, MatchError> {
    let h5 = dir.join(format!("{}.h5", spec.name));
    let csv = dir.join(format!("{}-recipes.csv", spec.name));
    let lock = OutputLock::acquire(&h5)?;
    write_atomic_with(&h5, |tmp| -> Result<(), IoError> {
        write_h5(spec, report, tmp).map_err(|source| IoError::Hdf5 {
            path: tmp.to_path_buf(),
            source,
        })
    })?;
    write_atomic(&csv, recipes_csv(spec, report).as_bytes())?;
    let verify_csv = if report.verified.is_empty() {
        None
    } else {
        let path = dir.join(format!("{}-verify.csv", spec.name));
        write_atomic(&path, super::write_verify::csv(spec, report).as_bytes())?;
        Some(path)
    };
    let png_name = format!("{}-spectra.png", spec.name);
    let (figure, figure_skipped) = match super::page::spectra_png(spec, report) {
        Ok(png) => {
            write_atomic(&dir.join(&png_name), &png)?;
            (Some(png_name.as_str()), None)
        }
        Err(e) => (None, Some(format!("the spectra figure was not drawn: {e}"))),
    };
    let page = dir.join(format!("{}.html", spec.name));
    let html = super::page::html(spec, report, figure);
    write_atomic(&page, html.as_bytes())?;
    drop(lock);
    Ok(Written {
        h5,
        csv,
        verify_csv,
        page,
        figure_skipped,
    })
}

pub(crate) fn strings(xs: &[String]) -> hdf5::Result<Vec<VarLenUnicode>> {
    xs.iter().map(|s| vlu(s)).collect()
}

fn write_h5(spec: &MatchSpec, r: &MatchReport, path: &Path) -> hdf5::Result<()> {
    let f = crate::output::h5::create(path)?;
    let text = &spec.text;
    for (k, v) in [
        ("inksim_version", crate::VERSION),
        ("match_file", &spec.path.display().to_string()),
        ("match_toml", text.as_str()),
        ("model", spec.model.name()),
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
            "the fast model's colour grid (vacuum wavelengths)",
            &[dim::WAVELENGTH],
        ),
    )?;
    let geoms: Vec<String> = r
        .target_lab
        .iter()
        .map(|(m, _)| m.name().to_string())
        .collect();
    sc.coordinate(
        &f,
        "geometry",
        &strings(&geoms)?,
        about(
            "",
            "the target's measurement geometries (names)",
            &[GEOMETRY],
        ),
    )?;
    let names: Vec<String> = spec.palette.iter().map(|p| p.name.clone()).collect();
    sc.coordinate(
        &f,
        "pigment",
        &strings(&names)?,
        about(
            "",
            "the palette's pigments (names), in palette order",
            &[PIGMENT],
        ),
    )?;
    let sources: Vec<String> = super::report::TEST_SOURCES
        .iter()
        .map(|s| s.name().to_string())
        .collect();
    sc.coordinate(
        &f,
        "test_source",
        &strings(&sources)?,
        about(
            "",
            "test light sources of the metamerism indices (CIE names)",
            &[SOURCE],
        ),
    )?;

    let t = f.create_group("target")?;
    let lab = Array2::from_shape_fn((r.target_lab.len(), 3), |(g, c)| r.target_lab[g].1[c]);
    sc.write(&t, "lab", lab.view(), about("1", "the target's CIELAB L*, a*, b* (a spectrum target's computed from it), under the file's illuminant and observer; geometry × lab", &[GEOMETRY, dim::LAB]))?;
    sc.write(&t, "noise_lab", &spec.target.noise_lab[..], about("1", "measurement noise (1σ) of L*, a*, b* propagated into the recipes' standard errors; lab", &[dim::LAB]))?;
    if let Some(tf) = &r.target_factor {
        sc.write(&t, "reflectance_factor", &tf[..], about("1", "the target's reflectance factor on the colour grid (linear interpolation of the CSV); wavelength", &[dim::WAVELENGTH]))?;
    }
    let p = f.create_group("palette")?;
    let bounds = Array2::from_shape_fn((spec.palette.len(), 2), |(i, b)| {
        spec.palette[i].pvc_range[b]
    });
    sc.write(
        &p,
        "pvc_range",
        bounds.view(),
        about(
            "1",
            "least and most volume fraction of each palette pigment; pigment × bound (min, max)",
            &[PIGMENT, BOUND],
        ),
    )?;

    let g = f.create_group("recipes")?;
    let n = r.recipes.len();
    let np = spec.palette.len();
    let rank: Vec<u64> = r.recipes.iter().map(|x| x.rank as u64).collect();
    sc.coordinate(&g, "rank", &rank, about("1", "rank of each recipe (1 the best; within the tolerance first, fewest colourants, then by the objective); recipe", &[RECIPE]))?;
    let pvc = Array2::from_shape_fn((n, np), |(i, s)| r.recipes[i].recipe.fractions[s]);
    sc.write(&g, "pvc", pvc.view(), about("1", "volume fraction of each palette pigment in each recipe (0: not used); recipe × pigment", &[RECIPE, PIGMENT]))?;
    let thick: Vec<f64> = r.recipes.iter().map(|x| x.recipe.thickness_nm).collect();
    sc.write(
        &g,
        "thickness_nm",
        &thick[..],
        about("nm", "layer thickness of each recipe; recipe", &[RECIPE]),
    )?;
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
    let reached: Vec<u8> = r.recipes.iter().map(|x| u8::from(x.reached)).collect();
    sc.write(&g, "reached", &reached[..], about("1", "1 where every geometry is within the tolerance, 0 where the recipe is only the closest reachable; recipe", &[RECIPE]))?;
    for x in &r.recipes {
        let rg = g.create_group(&format!("{:03}", x.rank))?;
        write_recipe(&mut sc, &rg, x)?;
    }
    super::write_verify::write_h5(&mut sc, &f, r)?;
    Ok(())
}

/// What [`write_unknowns`] writes of a recipe, whatever its problem.
pub(crate) struct RecipeUnknowns<'a> {
    pub rank: usize,
    pub reached: bool,
    pub candidate: &'a super::search::Candidate,
    pub unknowns: &'a [String],
    pub uncertainty: &'a super::uncertainty::Uncertainty,
}

/// A recipe's group in the result file, as both kinds of match write it:
/// its rank, whether it reached the tolerance, its objective and condition
/// number (attributes); its unknowns (coordinate), their values, standard
/// errors, correlation and flags; its CIELAB per target geometry. The
/// `descriptions` of the unknowns, the values, the standard errors and the
/// CIELAB name the problem's own unknowns and model.
pub(crate) fn write_unknowns(
    sc: &mut Scales,
    g: &Group,
    x: &RecipeUnknowns,
    [unknowns, values, errors, lab]: [&str; 4],
) -> hdf5::Result<()> {
    write_scalar_attr(g, "rank", x.rank as u64)?;
    write_scalar_attr(g, "reached", u8::from(x.reached))?;
    write_scalar_attr(g, "objective", x.candidate.objective)?;
    if let Some(c) = x.uncertainty.condition {
        write_scalar_attr(g, "condition_number", c)?;
    }
    sc.forget(UNKNOWN);
    sc.coordinate(
        g,
        "unknown",
        &strings(x.unknowns)?,
        about("", unknowns, &[UNKNOWN]),
    )?;
    sc.write(
        g,
        "value",
        &x.candidate.x[..],
        about("", values, &[UNKNOWN]),
    )?;
    if let (Some(se), Some(corr)) = (&x.uncertainty.se, &x.uncertainty.correlation) {
        sc.write(g, "standard_error", &se[..], about("", errors, &[UNKNOWN]))?;
        let k = corr.len();
        let c = Array2::from_shape_fn((k, k), |(a, b)| corr[a][b]);
        sc.write(
            g,
            "correlation",
            c.view(),
            about(
                "1",
                "correlation of the unknowns' errors; unknown × unknown",
                &[UNKNOWN, UNKNOWN],
            ),
        )?;
    }
    sc.write(
        g,
        "flags",
        &strings(&x.uncertainty.flags)?[..],
        about(
            "",
            "why an unknown is not determined by the target (empty: it is); unknown",
            &[UNKNOWN],
        ),
    )?;
    let fit = &x.candidate.fit.lab;
    let lab_of = Array2::from_shape_fn((fit.len(), 3), |(a, b)| fit[a][b]);
    sc.write(
        g,
        "lab",
        lab_of.view(),
        about("1", lab, &[GEOMETRY, dim::LAB]),
    )?;
    Ok(())
}

fn write_recipe(sc: &mut Scales, g: &Group, x: &super::report::RecipeReport) -> hdf5::Result<()> {
    if let Some(s) = x.candidate.fit.spectral_rms {
        write_scalar_attr(g, "spectral_rms", s)?;
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
            "the recipe's unknowns: its pigments' volume fractions, then `thickness` (nm) when free; unknown",
            "each unknown's value: volume fraction (1) or thickness (nm); unknown",
            "standard error of each unknown from the target's measurement noise (first-order propagation through the fast model's Jacobian), units of the unknown; unknown",
            "the recipe's CIELAB on the fast model; geometry × lab",
        ],
    )?;
    sc.write(
        g,
        "reflectance_factor",
        &x.factor[..],
        about(
            "1",
            "the recipe's reflectance factor in the target's (first) geometry; wavelength",
            &[dim::WAVELENGTH],
        ),
    )?;
    if !x.metamerism.is_empty() {
        let mi: Vec<f64> = x.metamerism.iter().map(|(_, m)| m.index).collect();
        sc.write(g, "metamerism_index", &mi[..], about("1", "special metamerism index (ISO 18314-4) against the target spectrum: CIEDE2000 under the test source after the multiplicative XYZ correction under the target's illuminant; test_source", &[SOURCE]))?;
        let raw: Vec<f64> = x.metamerism.iter().map(|(_, m)| m.de00_test).collect();
        sc.write(
            g,
            "de00_test_uncorrected",
            &raw[..],
            about(
                "1",
                "CIEDE2000 to the target under the test source without correction; test_source",
                &[SOURCE],
            ),
        )?;
    }
    Ok(())
}

/// CSV text of the recipes: one row per recipe.
pub fn recipes_csv(spec: &MatchSpec, r: &MatchReport) -> String {
    let mut s = String::new();
    let geoms: Vec<&str> = r.target_lab.iter().map(|(m, _)| m.name()).collect();
    s.push_str("rank,colourants,reached,composition,thickness_nm");
    for g in &geoms {
        let _ = write!(s, ",de00 {g},de00_se {g},L* {g},a* {g},b* {g}");
    }
    s.push_str(",spectral_rms");
    for t in super::report::TEST_SOURCES {
        let _ = write!(s, ",metamerism_index {}", t.name());
    }
    s.push_str(",condition_number,not_determined");
    for p in &spec.palette {
        let _ = write!(s, ",pvc {0},pvc_se {0}", p.name);
    }
    s.push('\n');
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
            "{},{},{},\"{}\",{:.1}",
            x.rank,
            x.candidate.subset.len(),
            u8::from(x.reached),
            composition.join("; "),
            x.recipe.thickness_nm
        );
        for (k, _) in geoms.iter().enumerate() {
            let l = x.candidate.fit.lab[k];
            let _ = write!(
                s,
                ",{:.4},{:.4},{:.3},{:.3},{:.3}",
                x.candidate.fit.de00[k], x.de00_se[k], l[0], l[1], l[2]
            );
        }
        match x.candidate.fit.spectral_rms {
            Some(v) => {
                let _ = write!(s, ",{v:.6}");
            }
            None => s.push(','),
        }
        for t in super::report::TEST_SOURCES {
            match x.metamerism.iter().find(|(src, _)| *src == t) {
                Some((_, m)) => {
                    let _ = write!(s, ",{:.4}", m.index);
                }
                None => s.push(','),
            }
        }
        match x.uncertainty.condition {
            Some(c) => {
                let _ = write!(s, ",{c:.3}");
            }
            None => s.push(','),
        }
        let flagged = x.not_determined().join(" | ").replace('"', "'");
        let _ = write!(s, ",\"{flagged}\"");
        for (p, _) in spec.palette.iter().enumerate() {
            let k = x.candidate.subset.iter().position(|&q| q == p);
            let v = x.recipe.fractions[p];
            match k.and_then(se) {
                Some(e) => {
                    let _ = write!(s, ",{v:.6},{e:.6}");
                }
                None => {
                    let _ = write!(s, ",{v:.6},");
                }
            }
        }
        s.push('\n');
    }
    s
}
