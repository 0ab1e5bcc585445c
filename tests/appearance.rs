//! From solves to what a person sees: the paper substrate against
//! closed forms, energy and power preservation of the tables, BRDF
//! reciprocity within the statistical error, 1/√R convergence of the
//! ensemble, the plan computing only what a scene asks for, and the MERL
//! export.

use inksim::config::parse_scene;
use inksim::config::Method;
use inksim::optics::farfield::Side;
use inksim::pipeline::{self, RunPlan, RunReport};
use num_complex::Complex64 as C64;
use std::f64::consts::PI;
use std::path::Path;

mod common;
use common::airy::{airy_power, airy_rt, hemispherical};
use common::scene::{constant_material, PigmentToml, SceneToml};

/// A homogeneous (molecular) layer of index `n` in a binder of the same
/// index: a plain slab, on paper of albedo 0.9.
fn slab_scene(dir: &Path, binder: f64, quadrature: i64) -> SceneToml {
    let csv = constant_material(dir, "plain", binder);
    SceneToml::slab()
        .seed(3)
        .fragment_nm(1000.0)
        .binder_index(binder)
        .pigment(PigmentToml::csv("dissolved", &csv).pvc(0.2).molecular())
        .cell_nm(50.0)
        .polar_deg(&[0.0, 20.0, 40.0, 60.0])
        .quadrature_points(quadrature)
        .paper(0.9)
        .output(dir, "slab")
}

#[test]
fn bare_paper_renders_its_albedo_as_grey() {
    // A vacuum "layer" (binder and pigment of index 1) transmits everything:
    // what is seen is the paper alone, 0.9 at every angle and wavelength.
    let dir = tempfile::tempdir().unwrap();
    let rep = slab_scene(dir.path(), 1.0, 6).run(dir.path());
    let a = rep.appearance.unwrap();
    let grey = (inksim::optics::colour::srgb_encode(0.9) * 255.0).round() as u8;
    assert_eq!(grey, 243);
    let c = a.colours.unwrap();
    assert!(
        c.tile_srgb8.iter().all(|&v| v == grey),
        "{:?}",
        c.tile_srgb8
    );
    for lab in &c.natural_lab {
        let l_expect = 116.0 * 0.9f64.cbrt() - 16.0;
        assert!((lab[0] - l_expect).abs() < 1e-6 && lab[1].abs() < 1e-6 && lab[2].abs() < 1e-6);
    }
    for v in a.brdf_total.unwrap().iter() {
        assert!((v - 0.9 / PI).abs() < 1e-12);
    }
    assert!(rep.entries.iter().all(|e| e.record.method == Method::Airy));
}

#[test]
fn clear_binder_on_paper_matches_the_closed_form_at_every_angle() {
    // f = ρ T(θi) T(θo) / (π (1 − ρ R_dd↑)) and the sky strip
    // R(θo) + ρ T_d T(θo) / (1 − ρ R_dd↑), with Airy R, T and R_dd↑, T_d by
    // fine Simpson quadrature. The clear slab's thin-film fringes in R(μ)
    // are the hardest case for the Gauss–Legendre rule in cos θ: measured
    // worst relative errors 4.6e-10 (32 nodes), 3.8e-4 (12), 2.0e-2 (6,
    // the default; scattering and absorption damp the fringes of real layers).
    let dir = tempfile::tempdir().unwrap();
    let eps = 1.558f64.powi(2);
    for (nodes, tol) in [(32, 1e-9), (12, 1e-3), (6, 2.5e-2)] {
        let rep = slab_scene(dir.path(), 1.558, nodes).run(dir.path());
        let a = rep.appearance.unwrap();
        let sp = &a.spec;
        let total = a.brdf_total.as_ref().unwrap();
        let sky = a.natural.as_ref().unwrap();
        let mut worst: f64 = 0.0;
        for (l, &wl) in sp.wavelengths_nm.iter().enumerate() {
            let rdd = hemispherical(|mu| airy_rt(eps, 1000.0, wl, mu.acos().to_degrees()).0);
            let td = 1.0 - rdd;
            let denom = 1.0 - 0.9 * rdd;
            for (i, &ti) in sp.illumination_deg.iter().enumerate() {
                for (o, &to) in sp.viewing_deg.iter().enumerate() {
                    let expect =
                        0.9 * airy_rt(eps, 1000.0, wl, ti).1 * airy_rt(eps, 1000.0, wl, to).1
                            / (PI * denom);
                    worst = worst.max((total[[l, i, o]] - expect).abs() / expect);
                }
            }
            for (o, &to) in sp.viewing_deg.iter().enumerate() {
                let (r, t) = airy_rt(eps, 1000.0, wl, to);
                let expect = r + 0.9 * td * t / denom;
                worst = worst.max((sky[[l, o]] - expect).abs() / expect);
            }
        }
        assert!(
            worst < tol,
            "{nodes} nodes: worst relative error {worst:.3e}"
        );
        eprintln!("{nodes} Gauss–Legendre nodes: worst relative error {worst:.3e}");
    }
}

/// A small random layer of absorbing spheres.
fn grains_scene(dir: &Path, realisations: i64) -> SceneToml {
    SceneToml::grains()
        .seed(11)
        .realisations(realisations)
        .thickness_nm(300.0)
        .fragment_nm(800.0)
        .pigment(PigmentToml::builtin("blue").pvc(0.15).diameter_nm(120.0))
        .grid_n([16, 16, 10])
        .wavelengths_nm(&[500.0, 620.0])
        .polar_deg(&[0.0, 25.0, 50.0])
        .tolerance(1e-8)
        .output(dir, "grains")
}

#[test]
fn ensemble_balances_energy_and_tables_preserve_power() {
    let dir = tempfile::tempdir().unwrap();
    let rep = grains_scene(dir.path(), 3).run(dir.path());
    let a = rep.appearance.as_ref().unwrap();
    let sum = &a.reflectance.mean + &a.transmittance.mean + &a.absorption.mean;
    assert!(sum.iter().all(|v| (v - 1.0).abs() < 1e-6), "{sum:?}");
    // Tables hold exactly the diffuse reflected power of each solve.
    let cell2 = a.spec.table.cell.powi(2);
    let nt = a.spec.table.n();
    for (l, &wl) in a.spec.wavelengths_nm.iter().enumerate() {
        for (i, &polar) in a.spec.illumination_deg.iter().enumerate() {
            let diffuse: f64 = rep
                .entries
                .iter()
                .filter(|e| {
                    e.side == Side::Above && e.wavelength_nm == wl && e.incidence.polar_deg == polar
                })
                .map(|e| e.efficiencies.total_reflectance - e.efficiencies.r00.norm_sqr())
                .sum::<f64>()
                / 3.0;
            let mut table = 0.0;
            for j in 0..nt {
                for q in 0..nt {
                    table += a.brdf_table.mean[[l, i, j, q]] * cell2;
                }
            }
            assert!((table - diffuse).abs() < 1e-12, "{table} vs {diffuse}");
        }
    }
    // Specular split: coherent + incoherent = mean |r00|².
    for (l, &wl) in a.spec.wavelengths_nm.iter().enumerate() {
        for (k, &polar) in a.spec.above_deg.iter().enumerate() {
            let mean_sq: f64 = rep
                .entries
                .iter()
                .filter(|e| {
                    e.side == Side::Above && e.wavelength_nm == wl && e.incidence.polar_deg == polar
                })
                .map(|e| e.efficiencies.r00.norm_sqr())
                .sum::<f64>()
                / 3.0;
            let split = a.specular_coherent[[l, k]] + a.specular_incoherent[[l, k]];
            assert!((split - mean_sq).abs() < 1e-14);
            assert!(a.specular_incoherent[[l, k]] > 0.0);
        }
    }
    assert_eq!(
        rep.entries.len(),
        pipeline::planned_solves(&scene_of(dir.path()))
    );
}

fn scene_of(dir: &Path) -> inksim::config::Scene {
    let path = dir.join("scene.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    parse_scene(&path, &text).unwrap()
}

#[test]
fn diffuse_brdf_is_reciprocal_within_its_standard_error() {
    // f(θi → θo) = f(θo → θi) in the plane of incidence holds for the
    // ensemble (reciprocity plus statistical isotropy), not per fragment.
    let dir = tempfile::tempdir().unwrap();
    let rep = grains_scene(dir.path(), 8).no_substrate().run(dir.path());
    let a = rep.appearance.unwrap();
    let (f, se) = (&a.brdf_diffuse.mean, a.brdf_diffuse.se.as_ref().unwrap());
    let n = a.spec.illumination_deg.len();
    assert_eq!(a.spec.viewing_deg, a.spec.illumination_deg);
    let mut checked = 0;
    for l in 0..a.spec.wavelengths_nm.len() {
        for i in 0..n {
            for o in i + 1..n {
                let d = (f[[l, i, o]] - f[[l, o, i]]).abs();
                let s = (se[[l, i, o]].powi(2) + se[[l, o, i]].powi(2)).sqrt();
                assert!(
                    d <= 4.0 * s,
                    "λ {l}: f({i},{o}) {} vs f({o},{i}) {} ± {s}",
                    f[[l, i, o]],
                    f[[l, o, i]]
                );
                checked += 1;
            }
        }
    }
    assert_eq!(checked, 6);
}

#[test]
fn standard_errors_follow_one_over_root_r() {
    // 32 independent realisations in 8 batches of 4: the scatter of the
    // batch means must match σ/√4 with σ from all 32 (ratio in [0.5, 1.6],
    // wider than the χ²₇ 98 % band). Equal seeds or correlated
    // realisations would make the batch means collapse or spread.
    let dir = tempfile::tempdir().unwrap();
    let rep = grains_scene(dir.path(), 32)
        .outputs(&["brdf"])
        .run(dir.path());
    let a = rep.appearance.as_ref().unwrap();
    let x: Vec<f64> = (0..32)
        .map(|r| {
            let e = rep
                .entries
                .iter()
                .find(|e| {
                    e.realisation == r && e.wavelength_nm == 500.0 && e.incidence.polar_deg == 0.0
                })
                .unwrap();
            e.efficiencies.total_reflectance
        })
        .collect();
    let mean = x.iter().sum::<f64>() / 32.0;
    let sd = (x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / 31.0).sqrt();
    let se = a.reflectance.se.as_ref().unwrap()[[0, 0]];
    assert!((se - sd / 32f64.sqrt()).abs() < 1e-15);
    assert!((a.reflectance.mean[[0, 0]] - mean).abs() < 1e-15);
    let batch: Vec<f64> = x.chunks(4).map(|c| c.iter().sum::<f64>() / 4.0).collect();
    let bsd = (batch.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / 7.0).sqrt();
    let ratio = bsd / (sd / 2.0);
    eprintln!("batch scatter ratio {ratio:.3}");
    assert!((0.5..1.6).contains(&ratio), "batch scatter ratio {ratio}");
    assert!(sd > 0.0);
}

#[test]
fn a_scene_that_asks_for_less_runs_less_and_gets_the_same_answer() {
    let dir = tempfile::tempdir().unwrap();
    let full = grains_scene(dir.path(), 2)
        .viewing_deg(&[0.0, 10.0, 25.0, 50.0])
        .quadrature_points(4)
        .measurements(&[])
        .run(dir.path());
    let s = scene_of(dir.path());
    let plan = RunPlan::of(&s);
    // From above: illumination ∪ viewing; from below: the 4 nodes.
    assert_eq!(plan.above_deg, vec![0.0, 10.0, 25.0, 50.0]);
    assert_eq!(full.entries.len(), 2 * 2 * (4 + 4));

    // No substrate: no solves from below, same layer BRDF bit for bit.
    let bare = grains_scene(dir.path(), 2)
        .viewing_deg(&[0.0, 10.0, 25.0, 50.0])
        .measurements(&[])
        .no_substrate()
        .run(dir.path());
    assert!(bare.entries.iter().all(|e| e.side == Side::Above));
    assert_eq!(bare.entries.len(), 2 * 2 * 4);
    let plan_text = &RunPlan::of(&scene_of(dir.path())).lines.join("\n");
    assert!(
        plan_text.contains("solves from below: skipped — no substrate"),
        "{plan_text}"
    );

    // BRDF only: illumination angles only, no colours.
    let brdf = grains_scene(dir.path(), 2)
        .outputs(&["brdf"])
        .viewing_deg(&[0.0, 10.0, 25.0, 50.0])
        .run(dir.path());
    assert_eq!(brdf.entries.len(), 2 * 2 * 3);
    let b = brdf.appearance.unwrap();
    assert!(b.colours.is_none() && b.natural.is_none() && b.paper.is_none());
    let f = full.appearance.unwrap();
    assert_eq!(b.brdf_diffuse.mean, f.brdf_diffuse.mean);
    assert_eq!(b.brdf_table.mean, f.brdf_table.mean);
    assert_eq!(
        bare.appearance.unwrap().brdf_diffuse.mean,
        f.brdf_diffuse.mean
    );
}

#[test]
fn molecular_mixture_is_the_airy_slab_of_the_mean_permittivity() {
    let dir = tempfile::tempdir().unwrap();
    let rep = SceneToml::slab()
        .realisations(4)
        .thickness_nm(800.0)
        .fragment_nm(1000.0)
        .layer_pvc(0.3)
        .pigment(PigmentToml::builtin("yellow").molecular())
        .add_pigment(PigmentToml::builtin("blue").molecular())
        .cell_nm(50.0)
        .wavelengths_nm(&[450.0, 600.0])
        .polar_deg(&[0.0, 45.0])
        .outputs(&["brdf"])
        .output(dir.path(), "mol")
        .run(dir.path());
    let s = scene_of(dir.path());
    assert!(RunPlan::of(&s).lines[1].contains("1 of 4 requested"));
    assert_eq!(rep.entries.len(), 4);
    for e in &rep.entries {
        let eps_b = 1.558f64.powi(2);
        let mean = s
            .species
            .iter()
            .fold(C64::new(eps_b * 0.7, 0.0), |acc, sp| {
                let n = sp.material.index_at(e.wavelength_nm).unwrap();
                acc + n * n * 0.15
            });
        // The Airy slab with complex ε.
        let k0 = 2.0 * PI / e.wavelength_nm;
        let kx = k0 * e.incidence.polar_deg.to_radians().sin();
        let (r, _) = airy_power(k0, mean, kx, 800.0);
        let eff = &e.efficiencies;
        assert!((eff.total_reflectance - r).abs() < 1e-12);
        assert!(eff.energy_balance.abs() < 1e-12 && eff.absorption > 0.0);
        assert_eq!(eff.orders.len(), 1);
    }
}

#[test]
fn merl_export_of_bare_paper_is_albedo_over_pi_everywhere() {
    use inksim::output::merl;
    let dir = tempfile::tempdir().unwrap();
    slab_scene(dir.path(), 1.0, 4)
        .outputs(&["tile", "merl"])
        .run(dir.path());
    let bytes = std::fs::read(dir.path().join("slab.binary")).unwrap();
    assert_eq!(&bytes[..12], &[90, 0, 0, 0, 90, 0, 0, 0, 180, 0, 0, 0]);
    let mut valid = 0;
    for (ih, id, ip) in [
        (0, 0, 0),
        (10, 30, 45),
        (40, 20, 100),
        (60, 40, 179),
        (89, 89, 90),
    ] {
        let (ti, to, _) = merl::bin_angles(ih, id, ip);
        let rgb = merl::lookup(&bytes, ih, id, ip).unwrap();
        if ti < 90.0 && to < 90.0 {
            for c in rgb {
                assert!((c - 0.9 / PI).abs() < 1e-9, "{ih} {id} {ip}: {rgb:?}");
            }
            valid += 1;
        } else {
            assert_eq!(rgb, [0.0; 3]);
        }
    }
    assert!(valid >= 3);
}

#[test]
fn preview_of_bare_paper_shows_its_albedo_beside_the_white_diffuser() {
    // A clear slab of index 1 on paper of albedo 0.9 is the paper alone: a
    // Lambertian 0.9, so where the sphere faces the light (radiance 0.75 from
    // the light + 0.25 from the sky for albedo 1) it shows 0.9 of the white
    // diffuser's 1, and no specular reflection. The preview alone asks for
    // the paper term.
    use inksim::output::render::Canvas;
    let dir = tempfile::tempdir().unwrap();
    let scene = slab_scene(dir.path(), 1.0, 4).outputs(&["preview"]);
    scene.run(dir.path());
    let png = std::fs::read(dir.path().join("slab-preview.png")).unwrap();
    let files = pipeline::output_files(&scene.scene(dir.path()));
    assert!(files.iter().any(|f| f.ends_with("slab-preview.png")));
    let c = Canvas::decode_png(&png).unwrap();
    // Spheres of 220 px from (16, 16) and (252, 16); the normal towards the
    // light, 45° from the view towards the upper left, is at a quarter of
    // the diameter from the left and from the top.
    let at = |x0: i64| c.get(x0 + 55, 16 + 55).unwrap();
    let expect = inksim::optics::colour::encode_srgb8([0.9; 3]);
    for (got, want) in [(at(16), expect), (at(252), [255; 3])] {
        for ch in 0..3 {
            assert!(
                (got[ch] as i32 - want[ch] as i32).abs() <= 2,
                "{got:?} vs {want:?}"
            );
        }
    }
    // Grey: the paper is white, the slab clear.
    let g = at(16);
    assert!(
        g.iter().max().unwrap() - g.iter().min().unwrap() <= 1,
        "{g:?}"
    );
}

#[test]
fn preview_has_the_tiles_colour_where_the_solved_wavelengths_miss_the_band() {
    // A dye absorbing in a band at 550 nm, solved at 450 and 650 nm only:
    // the solved wavelengths see no absorption (linear weights would render
    // it grey), the tile's colour carries the band through the spectral
    // proxy (magenta). Viewed at 60°, the tile's one viewing angle, the
    // sphere's side away from the light is lit by the sky alone (radiance
    // 0.25 for white): there the preview must show 0.25 × the tile's sky
    // colour. Where it faces the viewer, lit by the light too, it is magenta.
    use inksim::optics::colour::{encode_srgb8, gamut, lab_to_lch, Observer};
    use inksim::output::render::Canvas;
    let dir = tempfile::tempdir().unwrap();
    let mut text = String::from("wavelength_nm,n,k\n");
    for wl in (380..=780).step_by(5) {
        let k = 0.4 * (-((wl as f64 - 550.0) / 30.0).powi(2)).exp();
        text.push_str(&format!("{wl},1.5,{k}\n"));
    }
    std::fs::write(dir.path().join("dye.csv"), text).unwrap();
    let rep = SceneToml::slab()
        .seed(3)
        .fragment_nm(1000.0)
        .binder_index(1.5)
        .pigment(PigmentToml::csv("dye", "dye.csv").pvc(0.3).molecular())
        .cell_nm(50.0)
        .wavelengths_nm(&[450.0, 650.0])
        .polar_deg(&[0.0, 20.0, 40.0, 60.0])
        .viewing_deg(&[60.0])
        .quadrature_points(4)
        .paper(0.9)
        .outputs(&["preview"])
        .output(dir.path(), "dye")
        .run(dir.path());
    let a = rep.appearance.unwrap();
    let lab = a.colours.as_ref().unwrap().natural_lab[0];
    let [_, chroma, hue] = lab_to_lch(lab);
    assert!(chroma > 20.0 && !(60.0..=300.0).contains(&hue), "{lab:?}");
    let (ill, std_obs) = a.colour_conditions.unwrap();
    let obs = Observer::standard(ill, std_obs);
    let target = gamut::lab_to_linear_srgb(&obs, gamut::map_lab(&obs, lab).lab);
    let png = std::fs::read(dir.path().join("dye-preview.png")).unwrap();
    assert!(
        !dir.path().join("dye.png").exists(),
        "no tile was asked for"
    );
    let c = Canvas::decode_png(&png).unwrap();
    // The normal at θo = 60° towards the lower right, (0.61, −0.61, 0.5),
    // faces away from the light: pixel (177, 177) of the first sphere.
    let shadow = c.get(16 + 177, 16 + 177).unwrap();
    let want = encode_srgb8(target.map(|v| 0.25 * v));
    for ch in 0..3 {
        assert!(
            (shadow[ch] as i32 - want[ch] as i32).abs() <= 3,
            "preview {shadow:?} vs tile × 0.25 {want:?}"
        );
    }
    let front = c.get(16 + 110, 16 + 110).unwrap();
    assert!(
        front[1] as i32 + 60 < front[0].min(front[2]) as i32,
        "{front:?}"
    );
}

#[test]
fn preview_shows_the_lights_mirror_image_only_where_the_layer_reflects() {
    // The light's mirror image lies where the normal bisects the light and
    // the view, 22.5° towards the upper left: pixel (80, 80) of the first
    // sphere. A clear binder of index 1.5 reflects ~4 % there, which the
    // 3° disc makes far brighter than white; a binder of index 1 nothing.
    use inksim::output::render::Canvas;
    let highlight = |binder: f64| {
        let dir = tempfile::tempdir().unwrap();
        slab_scene(dir.path(), binder, 4)
            .outputs(&["preview"])
            .run(dir.path());
        let png = std::fs::read(dir.path().join("slab-preview.png")).unwrap();
        Canvas::decode_png(&png)
            .unwrap()
            .get(16 + 80, 16 + 80)
            .unwrap()
    };
    assert_eq!(highlight(1.5), [255; 3]);
    let none = highlight(1.0);
    assert!(none.iter().all(|&c| c < 250), "{none:?}");
}

#[test]
fn merl_export_stays_bounded_at_grazing_angles() {
    // The BRDF is the table's density over its coverage, finite up to the
    // horizon: every one of the 90 × 90 × 180 bins is finite and ≥ 0, and
    // no bin at grazing angles exceeds the largest value seen at moderate
    // angles by more than the BRDF's own variation (a division by cos θo
    // put spikes of 100/sr and more there).
    use inksim::output::merl;
    let dir = tempfile::tempdir().unwrap();
    grains_scene(dir.path(), 2)
        .quadrature_points(4)
        .outputs(&["tile", "merl"])
        .run(dir.path());
    let bytes = std::fs::read(dir.path().join("grains.binary")).unwrap();
    let (mut moderate, mut grazing) = (0.0f64, 0.0f64);
    let mut bins = 0usize;
    for ih in 0..90 {
        for id in 0..90 {
            for ip in 0..180 {
                bins += 1;
                let (ti, to, _) = merl::bin_angles(ih, id, ip);
                let v = merl::lookup(&bytes, ih, id, ip).unwrap();
                if ti >= 90.0 || to >= 90.0 {
                    assert_eq!(v, [0.0; 3], "below the horizon: ({ih}, {id}, {ip})");
                    continue;
                }
                let m = v.iter().cloned().fold(0.0, f64::max);
                assert!(m.is_finite() && m >= 0.0);
                if ti.max(to) <= 60.0 {
                    moderate = moderate.max(m);
                } else if ti.max(to) >= 85.0 {
                    grazing = grazing.max(m);
                }
            }
        }
    }
    assert_eq!(bins, 90 * 90 * 180);
    assert!(moderate > 0.0 && grazing > 0.0);
    assert!(
        grazing < 1.5 * moderate,
        "grazing {grazing} vs moderate {moderate}"
    );
}

#[test]
fn colour_between_solved_wavelengths_follows_the_proxy() {
    // For a clear binder layer the spectral proxy (the molecular-mixture
    // slab) is the layer itself, so the colour from 3 solved wavelengths must
    // equal the colour of the closed-form spectrum on the proxy's 5 nm grid
    // (where linear interpolation of 3 samples would not).
    let dir = tempfile::tempdir().unwrap();
    let rep = slab_scene(dir.path(), 1.558, 32).run(dir.path());
    let a = rep.appearance.unwrap();
    let eps = 1.558f64.powi(2);
    let (ill, so) = a.colour_conditions.unwrap();
    let obs = inksim::optics::colour::Observer::standard(ill, so);
    let fine: Vec<f64> = (0..=40).map(|k| 450.0 + 5.0 * k as f64).collect();
    for (o, &view) in a.spec.viewing_deg.iter().enumerate() {
        let spectrum: Vec<f64> = fine
            .iter()
            .map(|&wl| {
                let rdd = hemispherical(|mu| airy_rt(eps, 1000.0, wl, mu.acos().to_degrees()).0);
                let (r, t) = airy_rt(eps, 1000.0, wl, view);
                r + 0.9 * (1.0 - rdd) * t / (1.0 - 0.9 * rdd)
            })
            .collect();
        let xyz = inksim::optics::colour::xyz_from_reflectance(&obs, &fine, &spectrum).unwrap();
        let lab = inksim::optics::colour::xyz_to_lab(xyz, obs.white_xyz());
        let got = a.colours.as_ref().unwrap().natural_lab[o];
        let de = inksim::optics::colour::delta_e2000(lab, got);
        assert!(de < 1e-3, "view {view}°: ΔE00 {de}");
        // Linear interpolation of the 3 solved samples is far off.
        let coarse: Vec<f64> = (0..3)
            .map(|l| a.natural.as_ref().unwrap()[[l, o]])
            .collect();
        let lin =
            inksim::optics::colour::xyz_from_reflectance(&obs, &a.spec.wavelengths_nm, &coarse)
                .unwrap();
        let de_lin = inksim::optics::colour::delta_e2000(
            lab,
            inksim::optics::colour::xyz_to_lab(lin, obs.white_xyz()),
        );
        assert!(
            de_lin > 10.0 * de.max(1e-4),
            "linear {de_lin} vs proxy {de}"
        );
    }
}

/// The standard error of each tile colour against a batch-means estimate:
/// 32 realisations in 8 batches of 4, each batch's colour assembled from its
/// own mean spectra; the batch colours scatter around the full colour by
/// √8 × the standard error. Over every cell and component of L*a*b*, and for
/// ΔE00, the root of the summed batch variance over the summed squared
/// standard error lies in [0.6, 1.5] (each estimate has 7 degrees of freedom;
/// summed over cells the band is wide enough for their correlation).
#[test]
fn colour_standard_errors_agree_with_batch_means() {
    use inksim::optics::appearance::assemble;
    use inksim::optics::colour::{delta_e2000, Observer};
    let dir = tempfile::tempdir().unwrap();
    let rep = grains_scene(dir.path(), 32)
        .quadrature_points(4)
        .run(dir.path());
    let a = rep.appearance.as_ref().unwrap();
    let c = a.colours.as_ref().unwrap();
    let spread = c.spread.as_ref().expect("32 realisations have a spread");
    let (nv, nc, _) = c.tile_lab.dim();
    assert_eq!(spread.realisation_lab.dim(), (32, nv, nc, 3));
    assert!(spread.lab_se.iter().all(|v| v.is_finite() && *v > 0.0));
    let (ill, so) = a.colour_conditions.unwrap();
    let obs = Observer::standard(ill, so);
    let mut batch_spec = a.spec.clone();
    batch_spec.realisations = 4;
    let batches: Vec<_> = (0..8)
        .map(|b| {
            let entries: Vec<_> = rep
                .entries
                .iter()
                .filter(|e| e.realisation / 4 == b)
                .map(|e| {
                    let mut e = e.clone();
                    e.realisation %= 4;
                    e
                })
                .collect();
            assemble(&batch_spec, &entries, &obs)
                .unwrap()
                .colours
                .unwrap()
                .tile_lab
        })
        .collect();
    let (mut lab_batch, mut lab_se, mut de_batch, mut de_se) = (0.0, 0.0, 0.0, 0.0);
    for o in 0..nv {
        for k in 0..nc {
            let at = |l: &ndarray::Array3<f64>| [l[[o, k, 0]], l[[o, k, 1]], l[[o, k, 2]]];
            let full = at(&c.tile_lab);
            for ch in 0..3 {
                let mean = batches.iter().map(|b| at(b)[ch]).sum::<f64>() / 8.0;
                lab_batch += batches
                    .iter()
                    .map(|b| (at(b)[ch] - mean).powi(2))
                    .sum::<f64>()
                    / 7.0
                    / 8.0;
                lab_se += spread.lab_se[[o, k, ch]].powi(2);
            }
            de_batch += batches
                .iter()
                .map(|b| delta_e2000(at(b), full).powi(2))
                .sum::<f64>()
                / 8.0
                / 8.0;
            de_se += spread.de00_se[[o, k]].powi(2);
        }
    }
    let (r_lab, r_de) = ((lab_batch / lab_se).sqrt(), (de_batch / de_se).sqrt());
    eprintln!("batch / standard error: L*a*b* {r_lab:.3}, ΔE00 {r_de:.3}");
    assert!((0.6..1.5).contains(&r_lab), "L*a*b* ratio {r_lab}");
    assert!((0.6..1.5).contains(&r_de), "ΔE00 ratio {r_de}");
    // One realisation has no spread.
    let one = grains_scene(dir.path(), 1).run(dir.path());
    assert!(one.appearance.unwrap().colours.unwrap().spread.is_none());
}

/// Reassemble a run's solves with every measurement geometry and `obs`.
fn measured(
    rep: &RunReport,
    obs: &inksim::optics::colour::Observer,
) -> Vec<inksim::optics::appearance::MeasuredColour> {
    use inksim::optics::appearance::{assemble, Measurement};
    let mut spec = rep.appearance.as_ref().unwrap().spec.clone();
    spec.measurements = Measurement::ALL.to_vec();
    assemble(&spec, &rep.entries, obs).unwrap().measured
}

/// Bare paper (a vacuum layer) under every geometry, illuminant and observer:
/// reflectance factor exactly the albedo 0.9 at every wavelength, and its
/// colour the neutral L* = 116 · 0.9^(1/3) − 16, a* = b* = 0.
#[test]
fn bare_paper_measures_its_albedo_in_every_geometry_and_illuminant() {
    use inksim::optics::colour::{Illuminant, Observer, StandardObserver};
    let dir = tempfile::tempdir().unwrap();
    let rep = slab_scene(dir.path(), 1.0, 6)
        .polar_deg(&[0.0, 8.0, 45.0])
        .run(dir.path());
    let l_star = 116.0 * 0.9f64.cbrt() - 16.0;
    for ill in Illuminant::ALL {
        for so in StandardObserver::ALL {
            let m = measured(&rep, &Observer::standard(ill, so));
            assert_eq!(m.len(), 3);
            for c in &m {
                for v in &c.reflectance.mean {
                    assert!((v - 0.9).abs() < 1e-12, "{}: {v}", c.geometry);
                }
                assert!(
                    (c.lab[0] - l_star).abs() < 1e-9,
                    "{} {ill}: {:?}",
                    c.geometry,
                    c.lab
                );
                assert!(
                    c.lab[1].abs() < 1e-9 && c.lab[2].abs() < 1e-9,
                    "{:?}",
                    c.lab
                );
                assert_eq!(c.lch[0], c.lab[0]);
                assert!(c.lch[1] < 1e-9);
            }
        }
    }
}

/// A clear binder slab on paper against its closed form: 45°/0° is
/// `ρ T(45°) T(0°) / (1 − ρ R_dd↑)`, d/8° SCI `R(8°) + ρ T_d T(8°) / (1 − ρ R_dd↑)`
/// and SCE the same without the slab's mirror reflection `R(8°)`; Airy R, T
/// and Simpson R_dd↑ as above, with 32 Gauss–Legendre nodes (1e-9). The
/// slab's colour is the same whether the spectral proxy carries it or not.
#[test]
fn clear_binder_on_paper_measures_as_the_closed_form() {
    use inksim::optics::appearance::Measurement;
    use inksim::optics::colour::Observer;
    let dir = tempfile::tempdir().unwrap();
    let eps = 1.558f64.powi(2);
    let rep = slab_scene(dir.path(), 1.558, 32)
        .polar_deg(&[0.0, 8.0, 45.0])
        .run(dir.path());
    let m = measured(&rep, &Observer::cie1931_d65());
    let wls = &rep.appearance.as_ref().unwrap().spec.wavelengths_nm;
    for c in &m {
        for (l, &wl) in wls.iter().enumerate() {
            let rdd = hemispherical(|mu| airy_rt(eps, 1000.0, wl, mu.acos().to_degrees()).0);
            let denom = 1.0 - 0.9 * rdd;
            let at = |polar| airy_rt(eps, 1000.0, wl, polar);
            let expect = match c.geometry {
                Measurement::FortyFiveZero => 0.9 * at(45.0).1 * at(0.0).1 / denom,
                Measurement::DiffuseEightSci => at(8.0).0 + 0.9 * (1.0 - rdd) * at(8.0).1 / denom,
                Measurement::DiffuseEightSce => 0.9 * (1.0 - rdd) * at(8.0).1 / denom,
            };
            let got = c.reflectance.mean[l];
            assert!(
                (got - expect).abs() < 1e-9 * expect,
                "{} at {wl} nm: {got} vs {expect}",
                c.geometry
            );
        }
        assert!(c.lab.iter().all(|v| v.is_finite()));
        assert_eq!(c.spectrum.len(), c.spectrum_wavelengths_nm.len());
    }
    // SCI ≥ SCE: the slab's mirror reflection is what the trap removes.
    assert!(m[1].lab[0] > m[2].lab[0]);
}

/// A scene with a tile reports colour in every measurement geometry, under
/// the default D50 / 2° conditions, with standard errors from two
/// realisations; the geometries' angles (8° and 45°) are solved for it, and
/// the result file carries them with units.
#[test]
fn measurement_geometries_run_by_default_and_reach_the_result_file() {
    use inksim::config::{Illuminant, StandardObserver};
    let dir = tempfile::tempdir().unwrap();
    let rep = grains_scene(dir.path(), 2).run(dir.path());
    let a = rep.appearance.as_ref().unwrap();
    assert_eq!(a.spec.above_deg, [0.0, 8.0, 25.0, 45.0, 50.0]);
    assert_eq!(
        a.colour_conditions,
        Some((Illuminant::D50, StandardObserver::TwoDegree))
    );
    assert_eq!(a.measured.len(), 3);
    for m in &a.measured {
        assert!(m.lab_se.unwrap().iter().all(|v| v.is_finite() && *v >= 0.0));
        assert!(m.de00_se.unwrap() > 0.0);
        assert!(m.reflectance.mean.iter().all(|v| (0.0..=1.0).contains(v)));
    }
    let f = inksim::output::h5::open(&rep.result_path).unwrap();
    let g = f.group("appearance").unwrap();
    let ill: hdf5::types::VarLenUnicode = g.attr("illuminant").unwrap().read_scalar().unwrap();
    assert_eq!(ill.as_str(), "D50");
    for slug in ["45_0", "d8_sci", "d8_sce"] {
        let lab = g.dataset(&format!("measured/{slug}/lab")).unwrap();
        assert_eq!(lab.read_raw::<f64>().unwrap().len(), 3);
        let units: hdf5::types::VarLenUnicode = lab.attr("units").unwrap().read_scalar().unwrap();
        assert_eq!(units.as_str(), "1");
        assert!(g.link_exists(&format!("measured/{slug}/de00_se")));
        // Each realisation's own colour: its L*, a*, b* spread is the
        // standard error stored beside the colour (sample s.d. / √R), and
        // each is the CIELAB of its own XYZ under D50.
        let rows = |name: &str| -> Vec<f64> {
            g.dataset(&format!("measured/{slug}/{name}"))
                .unwrap()
                .read_raw()
                .unwrap()
        };
        let (labs, xyzs, se) = (
            rows("lab_realisations"),
            rows("xyz_realisations"),
            rows("lab_se"),
        );
        assert_eq!(labs.len(), 6, "2 realisations × L*, a*, b*");
        for c in 0..3 {
            let (x0, x1) = (labs[c], labs[3 + c]);
            // Two samples: s.d. = |x0 − x1| / √2, s.e. = s.d. / √2.
            assert!(((x0 - x1).abs() / 2.0 - se[c]).abs() < 1e-12 * (1.0 + se[c]));
        }
        let white = inksim::optics::colour::Observer::standard(
            Illuminant::D50,
            StandardObserver::TwoDegree,
        )
        .white_xyz();
        for r in 0..2 {
            let xyz = [xyzs[3 * r], xyzs[3 * r + 1], xyzs[3 * r + 2]];
            let lab = inksim::optics::colour::xyz_to_lab(xyz, white);
            for c in 0..3 {
                assert!((lab[c] - labs[3 * r + c]).abs() < 1e-12 * 100.0);
            }
        }
    }
    assert!(g.link_exists("tile_lab_se") && g.link_exists("tile_de00_se"));
    // Read back as the study grids do: the same colours and errors.
    let (records, ill, deg) = inksim::output::h5::read_measured(&rep.result_path)
        .unwrap()
        .unwrap();
    assert_eq!((ill.as_str(), deg), ("D50", 2));
    for m in &a.measured {
        let r = records
            .iter()
            .find(|r| r.geometry == m.geometry.name())
            .unwrap();
        assert_eq!(r.lab, m.lab);
        assert_eq!(r.lab_se, m.lab_se);
        assert_eq!(r.de00_se, m.de00_se);
    }
}
