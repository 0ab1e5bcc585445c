//! Grounds under the layer and the hiding power a lab measures over a
//! hiding chart: exact checks of the contrast ratio against a closed form,
//! of Kubelka's S and K against his forward formula, of a chart against its
//! two halves run apart, and of a measured (CSV) ground against a white one.
use inksim::optics::appearance::hiding::kubelka;
use inksim::optics::appearance::{Appearance, MeasuredColour};
use inksim::optics::colour::{xyz_from_reflectance, Observer};
use num_complex::Complex64 as C64;
use std::f64::consts::PI;
use std::path::Path;

mod common;
use common::airy::{airy_power, hemispherical};
use common::scene::{PigmentToml, SceneToml};

/// A dissolved absorbing dye (n = 1.6 + 0.05i, 20 %) in a 1 µm binder of
/// index 1.5: a homogeneous slab, solved in closed form.
fn dye_slab(dir: &Path) -> SceneToml {
    SceneToml::slab()
        .seed(3)
        .fragment_nm(1000.0)
        .binder_index(1.5)
        .pigment(PigmentToml::index("dye", 1.6, 0.05).pvc(0.2).molecular())
        .cell_nm(50.0)
        .polar_deg(&[0.0])
        .quadrature_points(32)
        .outputs(&["tile"])
        .output(dir, "dye")
}

fn chart(scene: SceneToml, white_albedo: f64) -> SceneToml {
    scene
        .set("substrate.kind", "chart")
        .set("substrate.white_albedo", white_albedo)
}

fn appearance(scene: &SceneToml, dir: &Path) -> Appearance {
    scene.run(dir).appearance.expect("an appearance")
}

fn d8_sci(m: &[MeasuredColour]) -> &MeasuredColour {
    m.iter()
        .find(|c| c.geometry.name() == "d/8 SCI")
        .expect("d/8 SCI measured")
}

#[test]
fn contrast_ratio_of_a_homogeneous_layer_is_its_closed_form() {
    // Over black the d/8° SCI reflectance factor is the slab's own R(8°);
    // over a white ground of albedo ρ behind an air gap it adds
    // ρ T_d T(8°) / (1 − ρ R_dd) (T_d, R_dd: the slab's cosine-weighted
    // hemispherical averages). Both on the colour grid, the colour of each,
    // and CR = Y_b / Y_w.
    let dir = tempfile::tempdir().unwrap();
    let rho = 0.8;
    let a = appearance(&chart(dye_slab(dir.path()), rho), dir.path());
    let h = a
        .hiding
        .iter()
        .find(|h| h.geometry.name() == "d/8 SCI")
        .expect("hiding in d/8 SCI");
    let eps = 0.2 * C64::new(1.6, 0.05).powi(2) + 0.8 * 1.5f64.powi(2);
    let rt = |wl: f64, polar_deg: f64| {
        let k0 = 2.0 * PI / wl;
        airy_power(k0, eps, k0 * polar_deg.to_radians().sin(), 1000.0)
    };
    let fine: Vec<f64> = (0..=40).map(|k| 450.0 + 5.0 * k as f64).collect();
    let mut black = Vec::new();
    let mut white = Vec::new();
    for &wl in &fine {
        let at = |mu: f64| rt(wl, mu.clamp(0.0, 1.0).acos().to_degrees());
        let r_dd = hemispherical(|mu| at(mu).0);
        let t_d = hemispherical(|mu| at(mu).1);
        let (r8, t8) = rt(wl, 8.0);
        black.push(r8);
        white.push(r8 + rho * t_d * t8 / (1.0 - rho * r_dd));
    }
    let (ill, so) = a.colour_conditions.unwrap();
    let obs = Observer::standard(ill, so);
    let y_b = xyz_from_reflectance(&obs, &fine, &black).unwrap()[1];
    let y_w = xyz_from_reflectance(&obs, &fine, &white).unwrap()[1];
    let cr = y_b / y_w;
    eprintln!(
        "CR closed form {cr:.8}, inksim {:.8} (Y {y_b:.5} / {y_w:.5})",
        h.contrast_ratio.value
    );
    assert!(cr < 0.5, "a thin dye layer hides little: CR {cr}");
    assert!(
        (h.contrast_ratio.value - cr).abs() < 1e-6,
        "CR {} against {cr}",
        h.contrast_ratio.value
    );
    assert!((h.y_black - y_b).abs() < 1e-4 && (h.y_white - y_w).abs() < 1e-4);
    // Nothing random: the standard error is exactly 0.
    assert_eq!(h.contrast_ratio.se, Some(0.0));
    assert!((h.y_ground - 100.0 * rho).abs() < 1e-12);
}

/// Kubelka's forward solution written out here: a layer of S, K and
/// thickness X over black, `R0 = sinh(bSX) / (a sinh(bSX) + b cosh(bSX))`,
/// and its transmittance `T = b / (a sinh + b cosh)`; over a ground R_g the
/// inter-reflections add `T² R_g / (1 − R0 R_g)`.
fn kubelka_forward(s: f64, k: f64, x: f64, r_g: f64) -> f64 {
    let a = 1.0 + k / s;
    let b = (a * a - 1.0).sqrt();
    let (sh, ch) = ((b * s * x).sinh(), (b * s * x).cosh());
    let d = a * sh + b * ch;
    let (r0, t) = (sh / d, b / d);
    r0 + t * t * r_g / (1.0 - r0 * r_g)
}

#[test]
fn kubelka_s_and_k_are_recovered_from_synthetic_reflectances() {
    let (mut worst, mut checked, mut skipped): (f64, usize, usize) = (0.0, 0, 0);
    for &(s, k) in &[
        (0.5, 0.01),
        (3.0, 0.2),
        (10.0, 1.0),
        (1.2, 2.5),
        (0.05, 0.001),
    ] {
        for &x in &[0.3, 1.0, 5.0] {
            let bsx = ((1.0f64 + k / s).powi(2) - 1.0).sqrt() * s * x;
            if bsx > 4.0 {
                // Nearly complete hiding: R_b and R_w agree to e^(−2bSX)
                // and S is not determined by them (in a lab as here).
                skipped += 1;
                continue;
            }
            for &r_g in &[0.5, 0.8, 0.95] {
                checked += 1;
                let rb = kubelka_forward(s, k, x, 0.0);
                let rw = kubelka_forward(s, k, x, r_g);
                let got = kubelka(rb, rw, r_g, x);
                let a = 1.0 + k / s;
                let r_inf = a - (a * a - 1.0).sqrt();
                let e = [
                    (got.s - s).abs() / s,
                    (got.k - k).abs() / k,
                    (got.r_inf - r_inf).abs(),
                ];
                assert!(
                    e.iter().all(|v| *v < 1e-8),
                    "S {s} K {k} X {x} R_g {r_g}: {got:?}, errors {e:?}"
                );
                worst = e.iter().copied().fold(worst, f64::max);
            }
        }
    }
    eprintln!(
        "worst relative error of S, K (absolute of R∞): {worst:.1e} over {checked} cases \
         ({skipped} layers hiding almost completely skipped)"
    );
    assert!(checked >= 30, "{checked} cases");
}

/// A grain layer (2 realisations) on `substrate`, written as TOML.
fn grains(dir: &Path, name: &str, substrate: &str) -> SceneToml {
    SceneToml::tiny()
        .realisations(2)
        .polar_deg(&[0.0])
        .quadrature_points(3)
        .outputs(&["tile"])
        .raw("substrate", substrate)
        .output(dir, name)
}

fn assert_same_colours(a: &[MeasuredColour], b: &[MeasuredColour], what: &str) {
    assert_eq!(a.len(), b.len(), "{what}");
    for (x, y) in a.iter().zip(b) {
        assert_eq!(x.geometry, y.geometry);
        let d = (&x.reflectance.mean - &y.reflectance.mean)
            .iter()
            .chain((x.reflectance.se.as_ref().unwrap() - y.reflectance.se.as_ref().unwrap()).iter())
            .fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(d < 1e-12, "{what} {}: reflectance off by {d}", x.geometry);
        for k in 0..3 {
            assert!(
                (x.xyz[k] - y.xyz[k]).abs() < 1e-12 && (x.lab[k] - y.lab[k]).abs() < 1e-12,
                "{what} {}: {:?} {:?}",
                x.geometry,
                x.lab,
                y.lab
            );
            assert!((x.lab_se.unwrap()[k] - y.lab_se.unwrap()[k]).abs() < 1e-12);
        }
    }
}

#[test]
fn a_chart_is_its_black_and_white_halves_run_apart() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let chart = appearance(
        &grains(d, "chart", "{ kind = \"chart\", white_albedo = 0.7 }"),
        d,
    );
    let white = appearance(&grains(d, "white", "{ kind = \"white\", albedo = 0.7 }"), d);
    let black = appearance(&grains(d, "black", "{ kind = \"black\" }"), d);
    assert!(white.measured_black.is_empty() && white.hiding.is_empty());
    assert_same_colours(&chart.measured, &white.measured, "over white");
    assert_same_colours(&chart.measured_black, &black.measured, "over black");
    // The tile shows the white half.
    let (tc, tw) = (chart.colours.unwrap(), white.colours.unwrap());
    assert!(
        tc.tile_lab
            .iter()
            .zip(tw.tile_lab.iter())
            .all(|(p, q)| (p - q).abs() < 1e-12),
        "tile"
    );
    // The contrast ratio from the two runs, and its spread over the
    // realisations from each realisation's pair.
    let h = d8_sci(&chart.measured);
    let hb = d8_sci(&black.measured);
    let hid = chart
        .hiding
        .iter()
        .find(|x| x.geometry == h.geometry)
        .unwrap();
    let cr = hb.xyz[1] / d8_sci(&white.measured).xyz[1];
    assert!((hid.contrast_ratio.value - cr).abs() < 1e-12, "{hid:?}");
    let per: Vec<f64> = (0..2)
        .map(|r| hb.realisation_xyz[r][1] / d8_sci(&white.measured).realisation_xyz[r][1])
        .collect();
    let se = (per[0] - per[1]).abs() / 2.0;
    assert!((hid.contrast_ratio.se.unwrap() - se).abs() < 1e-12);
    assert!(hid.contrast_ratio.value > 0.0 && hid.contrast_ratio.value < 1.0);
    // S and K per wavelength from the same two spectra.
    for l in 0..hid.s_per_um.mean.len() {
        let k = kubelka(
            hb.reflectance.mean[l],
            d8_sci(&white.measured).reflectance.mean[l],
            0.7,
            0.4,
        );
        assert!((hid.s_per_um.mean[l] - k.s).abs() <= 1e-12 * k.s.abs().max(1.0));
        assert!((hid.k_per_um.mean[l] - k.k).abs() <= 1e-12 * k.k.abs().max(1.0));
    }
}

#[test]
fn a_constant_csv_ground_is_the_white_ground_of_that_albedo() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(
        d.join("grey.csv"),
        "wavelength_nm,reflectance\n400,0.65\n550,0.65\n700,0.65\n",
    )
    .unwrap();
    let csv = appearance(
        &grains(d, "csv", "{ kind = \"csv\", file = \"grey.csv\" }"),
        d,
    );
    let white = appearance(
        &grains(d, "white", "{ kind = \"white\", albedo = 0.65 }"),
        d,
    );
    assert_same_colours(&csv.measured, &white.measured, "csv against white");
    let (tc, tw) = (csv.colours.unwrap(), white.colours.unwrap());
    assert!(tc
        .tile_lab
        .iter()
        .zip(tw.tile_lab.iter())
        .all(|(p, q)| (p - q).abs() < 1e-12));
    assert_eq!(tc.tile_srgb8, tw.tile_srgb8);
}

#[test]
fn ground_keys_are_checked_with_the_key_and_range_named() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scene.toml");
    for (substrate, want) in [
        (
            "{ kind = \"black\", albedo = 0.1 }",
            "unknown field `albedo`",
        ),
        (
            "{ kind = \"white\", albedo = 1.5 }",
            "key `substrate.albedo`: must be in [0, 1], got 1.5",
        ),
        (
            "{ kind = \"chart\", white_albedo = -0.1 }",
            "key `substrate.white_albedo`: must be in [0, 1]",
        ),
        (
            "{ kind = \"chart\", white_albedo = 0.8, white_csv = \"w.csv\" }",
            "key `substrate.white_csv`: give the white half's albedo",
        ),
        (
            "{ kind = \"csv\", file = \"missing.csv\" }",
            "key `substrate.file`: cannot read",
        ),
    ] {
        let e = SceneToml::tiny()
            .raw("substrate", substrate)
            .parse(&path)
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with(&path.display().to_string()) && e.contains(want) && !e.contains('\n'),
            "{substrate}: {e}"
        );
    }
    // The defaults: white 0.8, a chart's white half 0.8, paper 0.9.
    for (substrate, albedo) in [
        ("{ kind = \"white\" }", 0.8),
        ("{ kind = \"chart\" }", 0.8),
        ("{ kind = \"paper\" }", 0.9),
    ] {
        let s = SceneToml::tiny()
            .raw("substrate", substrate)
            .parse(&path)
            .unwrap();
        assert_eq!(s.substrate.ground().unwrap().constant(), Some(albedo));
    }
}
