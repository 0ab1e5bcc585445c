//! Tints: colour pigments let down in a white over a hiding chart. A tint
//! with no colour pigment is the white itself; a study of tints merges with
//! its hiding columns (CR, S, K, K/S max), its relative tinting strength per
//! step, read back against the variants' own result files, and its hiding
//! plots.
use inksim::output::h5::{read_hiding, HidingRecord};
use std::path::Path;

mod common;
use common::cli::inksim_in;
use common::scene::{PigmentToml, SceneToml};
use common::study::StudyToml;

/// A white of index 2.6, 150 nm grains at `pvc`.
fn white(pvc: f64) -> PigmentToml {
    PigmentToml::index("white", 2.6, 0.0)
        .pvc(pvc)
        .diameter_nm(150.0)
}

/// `scene` on a hiding chart, lit at 8° for d/8° SCI, at 450/550/650 nm.
fn on_chart(scene: SceneToml) -> SceneToml {
    scene
        .wavelengths_nm(&[450.0, 550.0, 650.0])
        .polar_deg(&[8.0])
        .quadrature_points(3)
        .outputs(&["tile"])
        .measurements(&["d/8 SCI"])
        .set("substrate.kind", "chart")
}

/// A colour pigment (`colour`, first) and the white (second) in a 400 nm
/// layer on a hiding chart, 20 × 20 × 20 cells, two realisations.
fn tint(colour_pvc: f64, white_pvc: f64) -> SceneToml {
    on_chart(
        SceneToml::tiny()
            .realisations(2)
            .pigment(
                PigmentToml::builtin("red")
                    .named("colour")
                    .pvc(colour_pvc)
                    .diameter_nm(100.0),
            )
            .add_pigment(white(white_pvc)),
    )
}

fn d8(path: &Path) -> HidingRecord {
    read_hiding(path)
        .unwrap()
        .into_iter()
        .find(|h| h.geometry == "d/8 SCI")
        .expect("hiding in d/8 SCI")
}

#[test]
fn a_tint_without_colour_pigment_is_the_white() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // The white alone, and the same white beside a colour pigment at 0 %.
    on_chart(SceneToml::tiny().realisations(2).pigment(white(0.15)))
        .output(d, "white")
        .run(d);
    tint(0.0, 0.15).output(d, "tint0").run(d);
    let (a, b) = (d8(&d.join("white.h5")), d8(&d.join("tint0.h5")));
    assert!(a.contrast_ratio > 0.0 && a.contrast_ratio < 1.0, "{a:?}");
    assert_eq!(a.contrast_ratio, b.contrast_ratio);
    assert_eq!(a.contrast_ratio_se, b.contrast_ratio_se);
    // Bit for bit, NaN (no Kubelka layer at a wavelength) included.
    let bits = |h: &HidingRecord| -> Vec<u64> {
        let mut v: Vec<f64> = h.at_y.iter().map(|x| x.0).collect();
        for (m, se) in &h.spectral {
            v.extend(m);
            v.extend(se.iter().flatten());
        }
        v.iter().map(|x| x.to_bits()).collect()
    };
    assert_eq!(bits(&a), bits(&b));
}

/// 100 % × K/S of `b` over `a` at `a`'s maximum, with the linear
/// propagation of both standard errors (docs/STUDY.md, "A tint study").
fn strength(a: &HidingRecord, b: &HidingRecord) -> (f64, f64) {
    let i = a
        .wavelengths_nm
        .iter()
        .position(|&l| l == a.k_over_s_max_wavelength_nm)
        .unwrap();
    let (ka, sa) = (a.spectral[3].0[i], a.spectral[3].1.as_ref().unwrap()[i]);
    let (kb, sb) = (b.spectral[3].0[i], b.spectral[3].1.as_ref().unwrap()[i]);
    assert_eq!(ka, a.k_over_s_max);
    let t = 100.0 * kb / ka;
    let se = t * ((sa / ka).powi(2) + (sb / kb).powi(2)).sqrt();
    (t, se)
}

#[test]
fn a_tint_study_reports_hiding_and_tinting_strength() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let out = d.join("out");
    let study = StudyToml::new("tints", 9, out.to_str().unwrap(), &tint(0.05, 0.1))
        .compound_axis(
            "pigment",
            &[
                ("red", r#"{ "pigment.0.material" = { builtin = "red" } }"#),
                ("blue", r#"{ "pigment.0.material" = { builtin = "blue" } }"#),
            ],
        )
        .compound_axis(
            "ratio",
            &[
                (
                    "1:2",
                    r#"{ "pigment.0.pvc" = 0.05, "pigment.1.pvc" = 0.1 }"#,
                ),
                (
                    "1:5",
                    r#"{ "pigment.0.pvc" = 0.025, "pigment.1.pvc" = 0.125 }"#,
                ),
            ],
        );
    let p = d.join("tints.toml");
    std::fs::write(&p, study.toml()).unwrap();
    let (ok, o, err) = inksim_in(d, &["--threads", "2", "run", p.to_str().unwrap()]);
    assert!(ok, "{o}\n{err}");
    let h = |name: &str| d8(&out.join(format!("variants/{name}.h5")));
    let md = std::fs::read_to_string(out.join("summary.md")).unwrap();
    let html = std::fs::read_to_string(out.join("summary.html")).unwrap();
    for text in [&md, &html] {
        for head in [
            "CR",
            "S (1/µm)",
            "K (1/µm)",
            "K/S max",
            "tinting strength (%)",
        ] {
            assert!(text.contains(head), "{head}: {text}");
        }
    }
    // The variants table: each variant's S ± s.e. at Y, from its own file.
    let red = h("red_1-2");
    let (s, s_se) = red.at_y[1];
    let cell = format!("{s:.3} ± {:.3}", s_se.unwrap());
    let line = md.lines().find(|l| l.contains("[red_1-2]")).unwrap();
    assert!(line.contains(&cell), "{cell}: {line}");
    assert!(s > 0.0 && red.k_over_s_max > 0.0, "{red:?}");

    // red → blue: the mean over the two ratios of blue's K/S at red's
    // absorption maximum over red's; the pairs are independent variants.
    let pairs: Vec<(f64, f64)> = ["1-2", "1-5"]
        .iter()
        .map(|r| strength(&h(&format!("red_{r}")), &h(&format!("blue_{r}"))))
        .collect();
    let mean = (pairs[0].0 + pairs[1].0) / 2.0;
    let se = pairs[0].1.hypot(pairs[1].1) / 2.0;
    let want = format!("{mean:.1} ± {se:.1}");
    let row = md
        .lines()
        .find(|l| l.starts_with("| pigment |") && l.contains("red → blue"))
        .unwrap();
    assert!(
        row.trim_end().ends_with(&format!("{want} |")),
        "{want}: {row}"
    );
    // Diluting the red 1:2 → 1:5 lowers its K/S at its maximum.
    let dilute = strength(&h("red_1-2"), &h("red_1-5")).0;
    assert!(dilute < 100.0, "{dilute}");

    // The hiding plots: S per pigment volume and CR against the ratio, one
    // line per pigment.
    let f = "hiding-ratio.png";
    let png = std::fs::read(out.join("plots").join(f)).unwrap();
    let c = inksim::output::render::canvas::Canvas::decode_png(&png).unwrap();
    assert!(c.w > 300 && c.h > 200, "{f}: {} × {}", c.w, c.h);
    assert!(md.contains(&format!("(plots/{f})")), "{f}");
}
