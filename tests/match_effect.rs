//! `inksim match` of an effect paint: round trips on synthetic multi-angle
//! targets (a known pearl's flake concentration and coating thickness, a
//! known metallic's flake concentration with a black pigment → the fast
//! flake model's colours with instrument noise → match), the forward model
//! against `inksim run` of the same paint, and the command's files, its
//! config errors and its refusals, each one line.

mod common;

use common::cli::inksim_in;
use inksim::optics::colour::Observer;
use inksim::optics::flakes::multiangle::{self, AngleColour};
use inksim::r#match::effect::forward::{EffectModel, Setting};
use inksim::r#match::effect::{run, EffectSpec};
use rand::{Rng, SeedableRng};
use std::path::Path;

fn gaussian(rng: &mut impl Rng) -> f64 {
    let (u, v): (f64, f64) = (rng.gen_range(1e-12..1.0), rng.gen());
    (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
}

/// A coarse paint for the tests (11 wavelengths, 4 + 8 nodes): a clear
/// coat, a base coat with `flakes` (and `pigments`), a black primer.
fn paint(flakes: &str, pigments: &str) -> String {
    format!(
        r#"[base.paint]
wavelength_range_nm = {{ start = 400.0, stop = 700.0, step = 30.0 }}
illuminant = "D65"
observer_deg = 10
ground = {{ kind = "black" }}

[base.paint.model]
trapped_nodes = 4
escape_nodes = 8

[[base.paint.layer]]
name = "clearcoat"
thickness_um = 40.0
lacquer = {{ index = [1.5, 0.0] }}

[[base.paint.layer]]
name = "basecoat"
thickness_um = 15.0
lacquer = {{ index = [1.5, 0.0] }}

[base.paint.layer.flakes]
volume_fraction = 0.04
diameter_um = 15.0
diameter_sd_um = 5.0
orientation_sd_deg = 12.0
reflector = {flakes}
{pigments}
[[base.paint.layer]]
name = "primer"
thickness_um = 20.0
lacquer = {{ index = [1.5, 0.0] }}

[[base.paint.layer.pigment]]
name = "black"
material = {{ library = "soot" }}
pvc = 0.03
diameter_nm = 100.0
"#
    )
}

const PEARL: &str = r#"{ kind = "coated", substrate = { material = { index = [1.58, 0.0] }, thickness_nm = 400.0, thickness_sd_nm = 40.0 }, coating = { material = { library = "anatase" }, thickness_nm = 120.0, thickness_sd_nm = 5.0 } }"#;
const ALUMINIUM: &str = r#"{ kind = "metal", material = { library = "aluminium" }, thickness_nm = 200.0, thickness_sd_nm = 40.0 }"#;
const BASE_BLACK: &str = r#"
[[base.paint.layer.pigment]]
name = "tint"
material = { library = "soot" }
pvc = 0.005
diameter_nm = 100.0
"#;

/// An effect match file: `settings` lines in `[match]`, the target
/// `colour` lines, the base paint and the `unknowns` tables.
fn match_text(
    settings: &str,
    colour: &[(f64, f64, [f64; 3])],
    base: &str,
    unknowns: &str,
) -> String {
    let colour: Vec<String> = colour
        .iter()
        .map(|(i, a, l)| {
            format!(
                "  {{ illumination_deg = {i:?}, aspecular_deg = {a:?}, lab = [{:?}, {:?}, {:?}] }},",
                l[0], l[1], l[2]
            )
        })
        .collect();
    format!(
        "[match]\noutput_dir = \"out\"\n{settings}\n\n[target]\nkind = \"multi-angle\"\n\
         illuminant = \"D65\"\nobserver_deg = 10\nnoise_lab = [0.02, 0.02, 0.02]\ncolour = [\n{}\n]\n\n\
         {base}\n{unknowns}",
        colour.join("\n")
    )
}

fn spec_of(text: &str) -> EffectSpec {
    EffectSpec::parse(Path::new("effect.toml"), text).unwrap_or_else(|e| panic!("{e}"))
}

/// The known recipe's colours in every geometry (the forward model of the
/// file's base), with noise of σ `noise` per L*, a*, b* when given.
fn target_of(
    text: &str,
    settings: &[Setting],
    noise: Option<(f64, u64)>,
) -> Vec<(f64, f64, [f64; 3])> {
    let spec = spec_of(text);
    let obs = Observer::standard(spec.target.illuminant, spec.target.observer);
    let colours = EffectModel::new(&spec.paint)
        .colours(&obs, settings)
        .unwrap();
    let mut rng = rand::rngs::StdRng::seed_from_u64(noise.map_or(0, |n| n.1));
    colours
        .iter()
        .map(|c| {
            let lab = c
                .lab
                .map(|v| v + noise.map_or(0.0, |n| n.0 * gaussian(&mut rng)));
            (c.geometry.illumination_deg, c.geometry.aspecular_deg, lab)
        })
        .collect()
}

fn quiet(_: &str) {}

const PLACEHOLDER: [(f64, f64, [f64; 3]); 1] = [(45.0, 15.0, [50.0, 0.0, 0.0])];

#[test]
fn round_trip_recovers_a_pearl_coating_and_concentration() {
    let unknowns = "[[unknown]]\nkind = \"flakes\"\nlayer = \"basecoat\"\n\
                    concentration_range = [0.01, 0.08]\ncoating_nm_range = [60.0, 160.0]\n";
    let base = paint(PEARL, "");
    let settings = "tolerance_de00 = 0.1\nstarts = 2";
    let probe = match_text(settings, &PLACEHOLDER, &base, unknowns);
    let truth = [
        Setting::Concentration {
            layer: 1,
            fraction: 0.03,
        },
        Setting::Coating {
            layer: 1,
            nm: 132.0,
        },
    ];
    // Every geometry of both illuminations, each with noise 0.02.
    let target = target_of(&probe, &truth, Some((0.02, 7)));
    assert_eq!(target.len(), 11);
    let spec = spec_of(&match_text(settings, &target, &base, unknowns));
    let t0 = std::time::Instant::now();
    let r = run(&spec, &quiet).unwrap();
    let best = &r.recipes[0];
    eprintln!(
        "pearl: {:?} ± {:?}, ΔE00 {:?}, {} evaluations, {:.1} s",
        best.candidate.x,
        best.uncertainty.se,
        best.candidate.fit.de00,
        r.evaluations,
        t0.elapsed().as_secs_f64()
    );
    assert!(best.reached && r.reached());
    for (d, (g, _)) in best.candidate.fit.de00.iter().zip(&r.target) {
        assert!(*d < 0.1, "{}: ΔE00 {d}", g.label());
    }
    let se = best.uncertainty.se.as_ref().expect("determined");
    assert!(best.uncertainty.flags.iter().all(String::is_empty));
    let (c, t) = (best.candidate.x[0], best.candidate.x[1]);
    // Recovered within 1 % and 1 nm, and within 4 standard errors.
    assert!(
        (c - 0.03).abs() < 3e-4 && (c - 0.03).abs() < 4.0 * se[0],
        "{c} ± {}",
        se[0]
    );
    assert!(
        (t - 132.0).abs() < 1.0 && (t - 132.0).abs() < 4.0 * se[1],
        "{t} ± {}",
        se[1]
    );
    assert_eq!(best.coating_nm, vec![t]);
    // The flop index of the match is the target's to within the noise.
    let (fm, ft) = (best.flop_index.unwrap(), r.target_flop_index.unwrap());
    assert!((fm - ft).abs() < 0.05, "flop {fm} vs {ft}");
    // The ΔE00's standard error is of the noise's size in ΔE00.
    assert!(
        best.de00_se.iter().all(|s| *s > 0.002 && *s < 0.1),
        "{:?}",
        best.de00_se
    );
}

#[test]
fn round_trip_recovers_a_metallic_and_prefers_fewer_pigments_only_when_they_reach() {
    let unknowns = "[[unknown]]\nkind = \"flakes\"\nlayer = \"basecoat\"\n\
                    concentration_range = [0.005, 0.06]\n\n\
                    [[unknown]]\nkind = \"pigment\"\nlayer = \"basecoat\"\npigment = \"tint\"\n\
                    pvc_range = [0.0, 0.03]\n";
    let base = paint(ALUMINIUM, BASE_BLACK);
    let settings = "tolerance_de00 = 0.1\nstarts = 1\nrecipes = 2";
    let probe = match_text(settings, &PLACEHOLDER, &base, unknowns);
    let truth = [
        Setting::Pigment {
            layer: 1,
            pigment: 0,
            fraction: 0.008,
        },
        Setting::Concentration {
            layer: 1,
            fraction: 0.025,
        },
    ];
    // The 45° set only: a subset of the geometries.
    let target: Vec<_> = target_of(&probe, &truth, Some((0.02, 11)))
        .into_iter()
        .filter(|(i, _, _)| *i == 45.0)
        .collect();
    assert_eq!(target.len(), 6);
    let spec = spec_of(&match_text(settings, &target, &base, unknowns));
    let r = run(&spec, &quiet).unwrap();
    let best = &r.recipes[0];
    eprintln!(
        "metallic: {:?} {:?} ± {:?}, ΔE00 {:?}, {} evaluations",
        best.unknowns,
        best.candidate.x,
        best.uncertainty.se,
        best.candidate.fit.de00,
        r.evaluations
    );
    // The flakes alone (tried first) do not reach the tolerance, so the
    // tint is used; the flakes-only recipe is reported after it.
    assert_eq!(r.largest, 1);
    assert_eq!(best.candidate.subset, vec![0]);
    assert!(!r.recipes[1].reached && r.recipes[1].candidate.subset.is_empty());
    for d in &best.candidate.fit.de00 {
        assert!(*d < 0.1, "ΔE00 {d}");
    }
    // Recovered within 3 standard errors, and within 5 % (tint) and 4 %
    // (flakes) of the truth.
    let se = best.uncertainty.se.as_ref().expect("determined");
    let (p, c) = (best.candidate.x[0], best.candidate.x[1]);
    assert!(
        (p - 0.008).abs() < 3.0 * se[0] && (p - 0.008).abs() < 4e-4,
        "tint {p} ± {}",
        se[0]
    );
    assert!(
        (c - 0.025).abs() < 3.0 * se[1] && (c - 0.025).abs() < 1e-3,
        "flakes {c} ± {}",
        se[1]
    );
    assert_eq!(best.pvc, vec![p]);
    assert_eq!(best.concentration, vec![c]);
    assert!(best.coating_nm[0].is_nan(), "a metal flake has no coating");
}

#[test]
fn the_forward_model_is_inksim_runs_own() {
    // The colours the match computes for a paint are those `inksim run`
    // writes for it.
    let dir = tempfile::tempdir().unwrap();
    let base = paint(PEARL, "");
    let text = match_text(
        "tolerance_de00 = 0.1",
        &PLACEHOLDER,
        &base,
        "[[unknown]]\nkind = \"flakes\"\nlayer = \"basecoat\"\nconcentration_range = [0.01, 0.08]\n",
    );
    let ours: Vec<AngleColour> = {
        let spec = spec_of(&text);
        let obs = Observer::standard(spec.target.illuminant, spec.target.observer);
        EffectModel::new(&spec.paint).colours(&obs, &[]).unwrap()
    };
    let paint_file = base
        .replace("[base.paint", "[paint")
        .replace("[[base.paint", "[[paint");
    std::fs::write(dir.path().join("p.toml"), paint_file).unwrap();
    let (ok, _, err) = inksim_in(dir.path(), &["run", "p.toml", "--output-dir", "."]);
    assert!(ok, "{err}");
    let f = inksim::output::h5::open(dir.path().join("p.h5")).unwrap();
    let lab = f
        .dataset("paint/multiangle/lab")
        .unwrap()
        .read_2d::<f64>()
        .unwrap();
    assert_eq!(lab.nrows(), multiangle::geometries().len());
    for (g, c) in ours.iter().enumerate() {
        for k in 0..3 {
            assert!((lab[[g, k]] - c.lab[k]).abs() < 1e-9, "{g} {k}");
        }
    }
}

fn cli_text() -> String {
    match_text(
        "name = \"fx\"\ntolerance_de00 = 0.5\nstarts = 1\nrecipes = 1",
        &[
            (45.0, 15.0, [39.9, -7.3, -36.9]),
            (45.0, 45.0, [30.3, -13.2, -24.0]),
            (45.0, 110.0, [5.8, -3.6, -7.1]),
        ],
        &paint(PEARL, ""),
        "[[unknown]]\nkind = \"flakes\"\nlayer = \"basecoat\"\nconcentration_range = [0.01, 0.08]\n\
         coating_nm_range = [100.0, 160.0]\n",
    )
}

#[test]
fn command_writes_recipes_and_check_says_what_is_varied() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("fx.toml"), cli_text()).unwrap();
    let (ok, out, err) = inksim_in(dir.path(), &["check", "fx.toml"]);
    assert!(ok, "{err}");
    assert!(
        out.contains("effect match file OK") && out.contains("basecoat coating 100–160 nm"),
        "{out}"
    );
    let (ok, out, err) = inksim_in(dir.path(), &["match", "fx.toml"]);
    assert!(ok, "{err}");
    assert!(
        out.contains("flop index") && out.contains("45as110"),
        "{out}"
    );
    let o = dir.path().join("out");
    let csv = std::fs::read_to_string(o.join("fx-recipes.csv")).unwrap();
    assert!(csv.starts_with("rank,colourants,reached,composition,flop_index,target_flop_index"));
    assert!(
        csv.contains("de00_se 45as15") && csv.contains("coating_nm basecoat"),
        "{csv}"
    );
    assert_eq!(csv.lines().count(), 2);
    let html = std::fs::read_to_string(o.join("fx.html")).unwrap();
    assert!(html.contains("45as110") && html.contains("flop index"));
    let f = inksim::output::h5::open(o.join("fx.h5")).unwrap();
    assert_eq!(
        f.dataset("recipes/de00").unwrap().shape(),
        vec![1, 3],
        "recipe × geometry"
    );
    assert!(f.dataset("recipes/coating_nm").is_ok() && f.dataset("recipes/001/lab_all").is_ok());
}

#[test]
fn bad_effect_match_file_is_one_line_naming_file_and_key() {
    let dir = tempfile::tempdir().unwrap();
    let good = cli_text();
    for (bad, key) in [
        (
            good.replace(
                "concentration_range = [0.01, 0.08]",
                "concentration_range = [0.01, 0.5]",
            ),
            "unknown[0].concentration_range",
        ),
        (
            good.replace(
                "coating_nm_range = [100.0, 160.0]",
                "coating_nm_range = [5.0, 160.0]",
            ),
            "unknown[0].coating_nm_range",
        ),
        (
            good.replace("layer = \"basecoat\"\nconc", "layer = \"topcoat\"\nconc"),
            "unknown[0].layer",
        ),
        (
            good.replace("aspecular_deg = 110.0", "aspecular_deg = 100.0"),
            "target.colour[2].aspecular_deg",
        ),
        (
            good.replace(
                "kind = \"flakes\"",
                "kind = \"flakes\"\nconcentration = 0.1",
            ),
            "unknown field `concentration`",
        ),
        (
            good.replace(&paint(PEARL, ""), &paint(ALUMINIUM, "")),
            "unknown[0].coating_nm_range",
        ),
        (
            good.replace("orientation_sd_deg = 12.0", "orientation_sd_deg = 90.0"),
            "orientation_sd_deg",
        ),
    ] {
        std::fs::write(dir.path().join("bad.toml"), &bad).unwrap();
        for cmd in ["match", "check"] {
            let (ok, _, stderr) = inksim_in(dir.path(), &[cmd, "bad.toml"]);
            assert!(!ok, "{cmd} {key}");
            let lines: Vec<&str> = stderr
                .lines()
                .filter(|l| !l.contains("[inksim] match:"))
                .collect();
            assert_eq!(lines.len(), 1, "{cmd} {key}: {stderr}");
            assert!(
                lines[0].starts_with("error: ")
                    && lines[0].contains("bad.toml")
                    && lines[0].contains(key),
                "{cmd} {key}: {}",
                lines[0]
            );
        }
        assert!(
            !dir.path().join("out").exists(),
            "{key}: nothing is written"
        );
    }
}

#[test]
fn unsupported_effect_matches_are_refused_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let good = cli_text();
    for (bad, key, why) in [
        (
            good.replace("recipes = 1", "recipes = 1\n\n[match.verify]\nrecipes = 1"),
            "match.verify",
            "wave-optics verification is not supported for an effect paint",
        ),
        (
            good.replace(
                "recipes = 1",
                "recipes = 1\nthickness_range_nm = [10000.0, 20000.0]",
            ),
            "match.thickness_range_nm",
            "not supported for an effect paint",
        ),
    ] {
        std::fs::write(dir.path().join("bad.toml"), &bad).unwrap();
        for cmd in ["match", "check"] {
            let (ok, _, stderr) = inksim_in(dir.path(), &[cmd, "bad.toml"]);
            assert!(!ok, "{cmd} {key}");
            let lines: Vec<&str> = stderr
                .lines()
                .filter(|l| !l.contains("[inksim] match:"))
                .collect();
            assert_eq!(lines.len(), 1, "{cmd} {key}: {stderr}");
            assert!(
                lines[0].contains("bad.toml") && lines[0].contains(key) && lines[0].contains(why),
                "{cmd} {key}: {}",
                lines[0]
            );
        }
    }
}
