//! A study whose base is an effect paint: plan, run, resume, merge; the
//! axis keys checked against the paint schema; and what the fast model
//! must show along the axes (independent of the study machinery: the flop
//! index of a metallic falls as its flakes' tilt spread widens; a pearl's
//! near-specular hue turns with its coating's optical thickness as thin-film
//! interference orders it).

use inksim::config::paint::PaintScene;
use inksim::optics::colour::delta_e2000;
use inksim::output::h5;
use inksim::pipeline::paint_files;
use inksim::study::run::{run_variants, RunOptions, RunScene, Shard, State};
use inksim::study::sweep::{Expansion, Variant};
use inksim::study::{effect, Study};
use std::path::Path;

/// A base paint: clear coat / base coat with flakes / black primer.
fn base(wavelengths: &str) -> String {
    format!(
        r#"[base.paint]
{wavelengths}
illuminant = "D65"
observer_deg = 10
ground = {{ kind = "black" }}
[[base.paint.layer]]
name = "clearcoat"
thickness_um = 40.0
lacquer = {{ index = [1.5, 0.0] }}
[[base.paint.layer]]
name = "basecoat"
thickness_um = 15.0
lacquer = {{ index = [1.5, 0.0] }}
[base.paint.layer.flakes]
volume_fraction = 0.03
diameter_um = 16.0
diameter_sd_um = 5.0
orientation_sd_deg = 10.0
reflector = {{ kind = "metal", material = {{ library = "aluminium" }}, thickness_nm = 200.0, thickness_sd_nm = 40.0 }}
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

const WAVELENGTHS: &str = "wavelength_range_nm = { start = 400.0, stop = 700.0, step = 20.0 }";

fn study(dir: &Path, axes: &str) -> Study {
    let text = format!(
        "[study]\nname = \"eff\"\noutput_dir = \"{}\"\n{}\n{axes}",
        dir.join("runs").display(),
        base(WAVELENGTHS)
    );
    Study::parse(&dir.join("sweep.toml"), &text).unwrap()
}

fn quiet() -> RunOptions {
    RunOptions {
        jobs: 1,
        shard: Shard::ALL,
        quiet: true,
        memory: None,
    }
}

fn record(v: &Variant<PaintScene>) -> h5::PaintRecord {
    h5::read_paint(&paint_files(&v.scene)[0]).unwrap()
}

fn find<'a>(exp: &'a Expansion<PaintScene>, name: &str) -> &'a Variant<PaintScene> {
    exp.variants.iter().find(|v| v.name == name).unwrap()
}

/// L*a*b* and L*C*h at 45° illumination, `asp` from the specular.
fn at45(r: &h5::PaintRecord, asp: f64) -> ([f64; 3], [f64; 3]) {
    let c = r
        .colours
        .iter()
        .find(|c| c.illumination_deg == 45.0 && c.aspecular_deg == asp)
        .unwrap();
    (c.lab, c.lch)
}

#[test]
fn a_paint_study_plans_runs_resumes_and_merges() {
    let dir = tempfile::tempdir().unwrap();
    let s = study(
        dir.path(),
        r#"
[[axis]]
name = "spread"
key = "paint.layer.basecoat.flakes.orientation_sd_deg"
values = [4.0, 20.0]
labels = ["sd4", "sd20"]

[[axis]]
name = "clearcoat"
[[axis.value]]
label = "clear"
[[axis.value]]
label = "none"
remove = ["paint.layer.clearcoat"]
"#,
    );
    assert!(s.is_paint());
    // A paint study is not a study of wave-optics layers.
    let e = s.expand(None).unwrap_err().to_string();
    assert!(e.contains("effect paint") && !e.contains('\n'), "{e}");
    let exp = s.expand_paint(None).unwrap();
    assert_eq!(exp.variants.len(), 4);
    // The axis reached the layer by its name, and `remove` took the clear
    // coat away.
    let none = find(&exp, "sd20_none");
    assert_eq!(none.scene.layers.len(), 2);
    assert_eq!(none.scene.layers[0].name, "basecoat");
    let flakes = none.scene.layers[0].flakes.as_ref().unwrap();
    assert_eq!(flakes.orientation_sd_deg, 20.0);
    assert_eq!(find(&exp, "sd4_clear").scene.layers.len(), 3);

    // Plan: measured, finite, positive.
    for v in &exp.variants {
        let e = effect::plan::estimate(v, 2).unwrap();
        assert_eq!(e.wavelengths, 16);
        assert!(e.terms > 0, "{e:?}");
        assert!(
            e.seconds.is_finite() && e.seconds > effect::plan::FIXED_S,
            "{e:?}"
        );
        assert!(e.bytes > effect::plan::BASE_BYTES, "{e:?}");
    }

    let first = run_variants(&exp.variants, &quiet());
    assert_eq!(first.ran().count(), 4, "{}", first.text());
    assert!(exp.variants.iter().all(|v| v.scene.state() == State::Done));
    // Resume: nothing is redone.
    let again = run_variants(&exp.variants, &quiet());
    assert_eq!((again.ran().count(), again.skipped()), (0, 4));
    // A variant whose picture went missing is redone, and only it.
    std::fs::remove_file(&paint_files(&find(&exp, "sd4_none").scene)[2]).unwrap();
    let third = run_variants(&exp.variants, &quiet());
    let ran: Vec<&str> = third.ran().map(|r| r.0).collect();
    assert_eq!(ran, ["sd4_none"]);

    let m = effect::merge(&s, &exp).unwrap();
    let html = std::fs::read_to_string(&m.summary_html).unwrap();
    let md = std::fs::read_to_string(&m.summary_md).unwrap();
    for page in [&html, &md] {
        assert!(page.contains("What the study finds"));
        assert!(page.contains("variants/sd20_clear-flop.png"));
    }
    assert!(md.contains("Along `spread`, sd4 → sd20 (2 pair(s)"), "{md}");
    assert!(html.contains("Along <code>spread</code>, sd4 → sd20 (2 pair(s)"));
    assert!(!m.grids.is_empty() && m.grids.iter().all(|g| g.is_file()));
    let f = inksim::output::h5::open(&m.summary_h5).unwrap();
    let flop: Vec<f64> = f.dataset("flop_index").unwrap().read_raw().unwrap();
    assert_eq!(flop.len(), 4);
    let lch = f.dataset("lch").unwrap().read_dyn::<f64>().unwrap();
    assert_eq!(lch.shape(), [4, 11, 3]);

    // Physics. A narrower tilt spread concentrates the flakes' light near
    // the specular: the flop index falls as the spread widens.
    for cc in ["clear", "none"] {
        let narrow = record(find(&exp, &format!("sd4_{cc}"))).flop_index.unwrap();
        let wide = record(find(&exp, &format!("sd20_{cc}")))
            .flop_index
            .unwrap();
        assert!(
            narrow > wide + 1.0,
            "{cc}: flop {narrow} at sd4, {wide} at sd20"
        );
    }
    // The fast model has one air–lacquer interface on top either way, and
    // a clear coat of the same index that absorbs nothing adds nothing.
    for sd in ["sd4", "sd20"] {
        let a = record(find(&exp, &format!("{sd}_clear")));
        let b = record(find(&exp, &format!("{sd}_none")));
        for (x, y) in a.colours.iter().zip(&b.colours) {
            assert!(delta_e2000(x.lab, y.lab) < 0.05, "{sd}: {x:?} {y:?}");
        }
    }
}

#[test]
fn axis_keys_the_paint_schema_lacks_are_refused_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let axis =
        |key: &str| format!("[[axis]]\nname = \"a\"\nkey = \"{key}\"\nvalues = [0.01, 0.02]\n");
    let e = study(
        dir.path(),
        &axis("paint.layer.basecoat.flakes.volume_fractoin"),
    )
    .expand_paint(None)
    .unwrap_err()
    .to_string();
    assert!(!e.contains('\n'), "{e}");
    assert!(e.contains("unknown field `volume_fractoin`"), "{e}");
    assert!(
        e.contains("key path `paint.layer.basecoat.flakes.volume_fractoin`"),
        "{e}"
    );
    let e = study(dir.path(), &axis("paint.layer.topcoat.thickness_um"))
        .expand_paint(None)
        .unwrap_err()
        .to_string();
    assert!(!e.contains('\n'), "{e}");
    assert!(
        e.contains("no element named `topcoat`") && e.contains("clearcoat, basecoat, primer"),
        "{e}"
    );
    // A value out of the paint's range names the key.
    let e = study(
        dir.path(),
        "[[axis]]\nname = \"a\"\nkey = \"paint.layer.basecoat.flakes.volume_fraction\"\nvalues = [0.5]\n",
    )
    .expand_paint(None)
    .unwrap_err()
    .to_string();
    assert!(!e.contains('\n') && e.contains("volume_fraction"), "{e}");
    let e = study(
        dir.path(),
        "[[axis]]\nname = \"a\"\n[[axis.value]]\nlabel = \"x\"\nremove = [\"paint.layer.topcoat\"]\n",
    )
    .expand_paint(None)
    .unwrap_err()
    .to_string();
    assert!(
        !e.contains('\n')
            && e.contains(
                "remove `paint.layer.topcoat`: `paint.layer.topcoat` is not in the scene"
            ),
        "{e}"
    );
}

#[test]
fn a_pearls_near_specular_hue_turns_with_its_coating_thickness() {
    // TiO2 (n ≈ 2.55) on mica: the reflectance's first minimum (n d = λ/2)
    // crosses the visible from blue (86 nm: gold) to green (102 nm: red),
    // then the second maximum (n d = 3λ/4) from violet-blue (132 nm: blue)
    // to green (156 nm): the hue angle turns clockwise, gold → red → blue
    // → green.
    let dir = tempfile::tempdir().unwrap();
    let s = study(
        dir.path(),
        r#"
[[axis]]
name = "coating"
key = "paint.layer.basecoat.flakes.reflector"
values = [
  { kind = "coated", substrate = { material = { index = [1.58, 0.0] }, thickness_nm = 400.0, thickness_sd_nm = 40.0 }, coating = { material = { library = "anatase" }, thickness_nm = 86.0, thickness_sd_nm = 5.0 } },
  { kind = "coated", substrate = { material = { index = [1.58, 0.0] }, thickness_nm = 400.0, thickness_sd_nm = 40.0 }, coating = { material = { library = "anatase" }, thickness_nm = 102.0, thickness_sd_nm = 5.0 } },
  { kind = "coated", substrate = { material = { index = [1.58, 0.0] }, thickness_nm = 400.0, thickness_sd_nm = 40.0 }, coating = { material = { library = "anatase" }, thickness_nm = 132.0, thickness_sd_nm = 5.0 } },
  { kind = "coated", substrate = { material = { index = [1.58, 0.0] }, thickness_nm = 400.0, thickness_sd_nm = 40.0 }, coating = { material = { library = "anatase" }, thickness_nm = 156.0, thickness_sd_nm = 5.0 } },
]
labels = ["gold", "red", "blue", "green"]
"#,
    );
    let exp = s.expand_paint(None).unwrap();
    let r = run_variants(&exp.variants, &quiet());
    assert_eq!(r.ran().count(), 4, "{}", r.text());
    let hue: Vec<f64> = ["gold", "red", "blue", "green"]
        .iter()
        .map(|n| {
            let (_, lch) = at45(&record(find(&exp, n)), 15.0);
            assert!(lch[1] > 8.0, "{n}: chroma {lch:?}");
            lch[2]
        })
        .collect();
    // Each step turns the hue clockwise by 30°–180°.
    for w in hue.windows(2) {
        let turn = (w[0] - w[1]).rem_euclid(360.0);
        assert!((30.0..180.0).contains(&turn), "hues {hue:?}");
    }
    // And the named hues where the thin-film estimate puts them.
    assert!((50.0..110.0).contains(&hue[0]), "gold {hue:?}");
    assert!((200.0..300.0).contains(&hue[2]), "blue {hue:?}");
}

/// `inksim slurm` of an effect study: the sbatch script of a job array
/// with its limits from the effect plan, whose task k runs the variants
/// of index k (mod N) and only those.
#[test]
fn an_effect_study_fans_out_as_a_slurm_job_array() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let text = format!(
        "[study]\nname = \"eff\"\noutput_dir = \"runs\"\n{}\n[[axis]]\nname = \"spread\"\n\
         key = \"paint.layer.1.flakes.orientation_sd_deg\"\nvalues = [6.0, 12.0, 18.0]\n",
        base("wavelengths_nm = [450.0, 550.0, 650.0]")
    );
    std::fs::write(d.join("sweep.toml"), &text).unwrap();
    let exe = env!("CARGO_BIN_EXE_inksim");
    let out = std::process::Command::new(exe)
        .current_dir(d)
        .args(["slurm", "sweep.toml", "--shards", "2", "--cpus", "1"])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("3 variants in 2 array tasks"), "{stdout}");
    let script = std::fs::read_to_string(d.join("runs/eff.sbatch")).unwrap();
    assert!(script.contains("#SBATCH --array=0-1\n"), "{script}");
    assert!(
        script.contains("run '") && script.contains("sweep.toml' --jobs 1"),
        "{script}"
    );
    // What task 1 of 2 runs: the second variant only.
    let run = std::process::Command::new(exe)
        .current_dir(d)
        .env("SLURM_ARRAY_TASK_ID", "1")
        .env("SLURM_ARRAY_TASK_COUNT", "2")
        .args(["run", "sweep.toml"])
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let s = Study::parse(&d.join("sweep.toml"), &text).unwrap();
    let mut exp = s.expand_paint(None).unwrap();
    exp.study_dir = d.join(&exp.study_dir);
    for v in &mut exp.variants {
        v.scene.output.dir = d.join(&v.scene.output.dir);
    }
    let done: Vec<usize> = exp
        .variants
        .iter()
        .filter(|v| inksim::study::run::state(v) == State::Done)
        .map(|v| v.index)
        .collect();
    assert_eq!(done, vec![1], "task 1 of 2 runs index 1 only");
}
