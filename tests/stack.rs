//! Stacks of layers: each layer solved inside the binder and the layers
//! combined by adding (`coupling = "incoherent"`), or all in one fragment
//! (`"coherent"`). Checked against the closed form of a stack of
//! homogeneous slabs, against energy conservation, and for solving the same
//! fragments under either coupling; bad stacks are refused naming the key.

mod common;
use common::scene::{PigmentToml, SceneToml};
use inksim::solver::airy;
use std::path::Path;

/// A layer of `pigment` `thickness_nm` thick in a binder of index 1.5.
fn layer(pigment: PigmentToml, thickness_nm: f64) -> SceneToml {
    SceneToml::grains()
        .thickness_nm(thickness_nm)
        .fragment_nm(600.0)
        .binder_index(1.5)
        .pigment(pigment)
}

/// Yellow spheres (150 nm, 20 %) 300 nm thick over blue ones `blue_nm`
/// thick.
fn yellow_over_blue(blue_nm: f64) -> [SceneToml; 2] {
    let ink = |name| PigmentToml::builtin(name).pvc(0.2).diameter_nm(150.0);
    [layer(ink("yellow"), 300.0), layer(ink("blue"), blue_nm)]
}

/// The stack's settings around `layers`: 50 nm cells, three wavelengths,
/// colours in the three geometries.
fn stack(dir: &Path, layers: &[SceneToml], coupling: &str, name: &str) -> SceneToml {
    SceneToml::grains()
        .seed(5)
        .realisations(2)
        .cell_nm(50.0)
        .z_cell_nm(50.0)
        .wavelengths_nm(&[450.0, 550.0, 650.0])
        .polar_deg(&[0.0])
        .outputs(&["tile"])
        .output(dir, name)
        .stack_of(layers, coupling)
}

/// A dataset of a result file, read whole.
fn read(path: &Path, name: &str) -> Vec<f64> {
    let f = inksim::output::h5::open(path).unwrap();
    f.dataset(name).unwrap().read_raw::<f64>().unwrap()
}

/// Reflection from above, from below and transmission of one direction
/// through two layers, incoherently: `a` on top of `b`.
fn on(a: (f64, f64, f64), b: (f64, f64, f64)) -> (f64, f64, f64) {
    let (ra, ra_up, ta) = a;
    let (rb, rb_up, tb) = b;
    let d = 1.0 - ra_up * rb;
    (
        ra + ta * ta * rb / d,
        rb_up + tb * tb * ra_up / d,
        ta * tb / d,
    )
}

#[test]
fn two_dissolved_layers_equal_the_incoherent_closed_form() {
    dissolved_layers_against_the_closed_form("helmholtz");
}

/// Beside Maxwell every flux of the chain is natural light's: the mean of
/// the s and p powers of each surface and each slab. The surfaces' p
/// reflectance is lower, so more light reaches the paper than in s.
#[test]
fn two_dissolved_layers_in_maxwell_equal_natural_lights_closed_form() {
    let vector = dissolved_layers_against_the_closed_form("maxwell");
    let scalar = dissolved_layers_against_the_closed_form("helmholtz");
    for (v, s) in vector.iter().zip(&scalar) {
        assert!(v > &(s * 1.005), "45°/0°: Maxwell {v} vs Helmholtz {s}");
    }
}

/// Returns the 45°/0° reflectance factor at each wavelength.
fn dissolved_layers_against_the_closed_form(equation: &str) -> Vec<f64> {
    // Each layer is a homogeneous slab (Airy inside the binder); between
    // them and at the binder's two flat surfaces only fluxes pass, so every
    // direction is a one-dimensional incoherent chain, and the paper in air
    // below sees the stack's diffuse reflectance and transmittance. Written
    // out here per direction, without the adding method's matrices.
    let dir = tempfile::tempdir().unwrap();
    let (h1, h2) = (300.0, 500.0);
    let layers = [
        layer(PigmentToml::builtin("yellow").pvc(0.2).molecular(), h1),
        layer(PigmentToml::builtin("blue").pvc(0.1).molecular(), h2),
    ];
    let scene = stack(dir.path(), &layers, "incoherent", "dissolved").equation(equation);
    let maxwell = equation == "maxwell";
    let report = scene.run(dir.path());
    let path = &report.result_path;

    let n: f64 = 1.5;
    let binder_deg = read(path, "stack/binder_polar_deg");
    let air_deg = read(path, "stack/air_polar_deg");
    let flux = read(path, "stack/flux_weight");
    let wl = read(path, "stack/wavelengths_nm");
    let sc = scene.scene(dir.path());
    let eps = |s: &str, pvc: f64, w: f64| {
        let sp = sc.species.iter().find(|x| x.name == s).unwrap();
        let m = sp.material.index_at(w).unwrap();
        // The layer's volume average in the binder, relative to the binder.
        (m * m * pvc + (1.0 - pvc) * n * n) / (n * n)
    };
    let albedo = 0.9;
    let mut forty_five = Vec::new();
    for (l, &w) in wl.iter().enumerate() {
        // (R↓, R↑, T) of every escaping direction, in air.
        let chain = |k: usize| {
            let (tb, ta) = (binder_deg[k].to_radians(), air_deg[k].to_radians());
            let rs = ((n * tb.cos() - ta.cos()) / (n * tb.cos() + ta.cos())).powi(2);
            let rp = ((tb.cos() - n * ta.cos()) / (tb.cos() + n * ta.cos())).powi(2);
            let rf = if maxwell { (rs + rp) / 2.0 } else { rs };
            let surface = (rf, rf, 1.0 - rf);
            let slab = |e, h| {
                let k0 = 2.0 * std::f64::consts::PI * n / w;
                let kx = k0 * binder_deg[k].to_radians().sin();
                let pol = |p| airy::SlabField::polarised(e, h, k0, kx, p).response;
                let (s, p) = (pol(false), pol(true));
                let (r, t) = if maxwell {
                    (
                        (s.r.norm_sqr() + p.r.norm_sqr()) / 2.0,
                        (s.t.norm_sqr() + p.t.norm_sqr()) / 2.0,
                    )
                } else {
                    (s.r.norm_sqr(), s.t.norm_sqr())
                };
                (r, r, t)
            };
            let l1 = slab(eps("yellow", 0.2, w), h1);
            let l2 = slab(eps("blue", 0.1, w), h2);
            on(on(on(surface, l1), l2), surface)
        };
        let escaping: Vec<usize> = (0..air_deg.len())
            .filter(|&k| air_deg[k].is_finite())
            .collect();
        // Lambertian flux weights in air: n² c.
        let rd: f64 = escaping.iter().map(|&k| n * n * flux[k] * chain(k).1).sum();
        let td: f64 = escaping.iter().map(|&k| n * n * flux[k] * chain(k).2).sum();
        let at = |deg: f64| {
            let k = *escaping
                .iter()
                .find(|&&k| (air_deg[k] - deg).abs() < 1e-9)
                .unwrap();
            chain(k)
        };
        let paper = |t: f64| albedo * t / (1.0 - albedo * rd);
        let expect = [
            ("45_0", paper(at(45.0).2 * at(0.0).2)),
            ("d8_sci", at(8.0).0 + paper(at(8.0).2 * td)),
            ("d8_sce", paper(at(8.0).2 * td)),
        ];
        for (slug, e) in expect {
            let got = read(
                path,
                &format!("appearance/measured/{slug}/reflectance_factor"),
            )[l];
            assert!(
                (got - e).abs() < 1e-12 * e.max(1e-3),
                "{slug} at {w} nm: {got} vs closed form {e}"
            );
            if slug == "45_0" {
                forty_five.push(got);
            }
        }
        // The tile's diffuse BRDF: the mirror reflection left out, only the
        // paper's light, π f = ρ T(θi) T(θo) / (1 − ρ R_d), in every cell.
        let ill = read(path, "appearance/illumination_deg");
        let view = read(path, "appearance/viewing_deg");
        let brdf = read(path, "appearance/brdf_total");
        for (c, &i) in ill.iter().enumerate() {
            for (v, &o) in view.iter().enumerate() {
                let got = std::f64::consts::PI * brdf[(l * ill.len() + c) * view.len() + v];
                let e = paper(at(i).2 * at(o).2);
                // The mirror part is taken out of 33 Fourier terms: the
                // diagonal cells round to 1e-11.
                assert!(
                    (got - e).abs() < 1e-10 * e,
                    "tile {i}°/{o}° at {w} nm: {got} vs closed form {e}"
                );
            }
        }
    }
    forty_five
}

#[test]
fn a_stack_that_absorbs_nothing_conserves_energy() {
    lossless_stack_conserves_energy("helmholtz");
}

/// The same in Maxwell: natural light's layer fluxes and surfaces.
#[test]
fn a_stack_in_maxwell_that_absorbs_nothing_conserves_energy() {
    lossless_stack_conserves_energy("maxwell");
}

fn lossless_stack_conserves_energy(equation: &str) {
    // Grains of a real index in a real binder: every solve conserves power,
    // and so must the flux matrices and their adding, in every direction.
    let dir = tempfile::tempdir().unwrap();
    let layers = [
        layer(
            PigmentToml::index("white", 2.0, 0.0)
                .pvc(0.2)
                .diameter_nm(150.0),
            300.0,
        ),
        layer(
            PigmentToml::index("clear", 1.7, 0.0)
                .pvc(0.3)
                .diameter_nm(100.0),
            200.0,
        ),
    ];
    let scene = stack(dir.path(), &layers, "incoherent", "lossless")
        .no_substrate()
        .equation(equation);
    let report = scene.run(dir.path());
    let r = read(&report.result_path, "stack/reflectance");
    let t = read(&report.result_path, "stack/transmittance");
    let a = read(&report.result_path, "stack/absorption");
    assert_eq!(r.len(), t.len());
    for k in 0..r.len() {
        assert!(
            (r[k] + t[k] - 1.0).abs() < 1e-5,
            "R {} + T {} ≠ 1",
            r[k],
            t[k]
        );
        assert!(a[k].abs() < 1e-5, "absorption {}", a[k]);
        // Something scatters: the stack reflects more than its two surfaces.
        assert!(r[k] > 0.0 && t[k] > 0.0);
    }
}

#[test]
fn both_couplings_solve_the_same_fragments() {
    let dir = tempfile::tempdir().unwrap();
    let layers = yellow_over_blue(200.0);
    let apart = stack(dir.path(), &layers, "incoherent", "apart").run(dir.path());
    let together = stack(dir.path(), &layers, "coherent", "together").run(dir.path());
    // The whole stack's grid: 12 × 12 across, 6 + 4 cells of 50 nm.
    for p in [&apart.result_path, &together.result_path] {
        let g: Vec<u64> = inksim::output::h5::open(p)
            .and_then(|f| f.attr("grid")?.read_raw())
            .unwrap();
        assert_eq!(g, [12, 12, 10], "{}", p.display());
    }
    let centres = |p: &Path| read(p, "geometry/centers_nm");
    let (a, b) = (centres(&apart.result_path), centres(&together.result_path));
    assert!(!a.is_empty());
    assert_eq!(a, b);
    // The lower layer's grains lie below the upper layer.
    let g = together.geometry.unwrap();
    for p in &g.particles {
        let z = p.spheres[0].center[2];
        assert!(if p.species == 0 { z < 300.0 } else { z > 300.0 }, "{z}");
    }
    // Both report colours in every geometry.
    for p in [&apart.result_path, &together.result_path] {
        let (m, _, _) = inksim::output::h5::read_measured(p).unwrap().unwrap();
        assert_eq!(m.len(), 3);
        assert!(m.iter().all(|c| c.lab_se.is_some() && c.lab[0] > 0.0));
    }
}

#[test]
fn bad_stacks_are_refused_naming_the_key() {
    let dir = tempfile::tempdir().unwrap();
    let red = |h| layer(PigmentToml::builtin("red").pvc(0.2).diameter_nm(100.0), h);
    let red2 = |h| {
        layer(
            PigmentToml::builtin("red")
                .named("red2")
                .pvc(0.2)
                .diameter_nm(100.0),
            h,
        )
    };
    let cases: Vec<(SceneToml, &str, &str)> = vec![
        (
            stack(
                dir.path(),
                &[red(300.0), red2(300.0).binder_index(1.6)],
                "incoherent",
                "a",
            ),
            "stack[1].layer.binder_index",
            "share one binder",
        ),
        (
            stack(dir.path(), &[red(300.0), red(300.0)], "incoherent", "b"),
            "stack[1].pigment[0].name",
            "unique across the stack",
        ),
        (
            stack(
                dir.path(),
                &[red(300.0), red2(300.0).fragment_nm(500.0)],
                "coherent",
                "c",
            ),
            "stack[1].layer.fragment_nm",
            "one fragment",
        ),
        (
            stack(dir.path(), &[red(300.0)], "incoherent", "d").outputs(&["tile", "brdf"]),
            "appearance.outputs",
            "not the BRDF at every azimuth",
        ),
        (
            stack(dir.path(), &[red(300.0)], "incoherent", "m")
                .equation("maxwell")
                .set("illumination.polarisation", "s"),
            "illumination.polarisation",
            "natural light's fluxes",
        ),
        (
            stack(dir.path(), &[red(300.0).coverage(0.0)], "incoherent", "f"),
            "stack[0].coverage",
            "(0, 1]",
        ),
        (
            stack(
                dir.path(),
                &[red(300.0).coverage(0.5), red2(300.0)],
                "coherent",
                "g",
            ),
            "stack[0].coverage",
            "far wider than a fragment",
        ),
        (
            stack(dir.path(), &[red(300.0)], "incoherent", "h").set("stacking.yule_nielsen_n", 0.5),
            "stacking.yule_nielsen_n",
            "[1, 10]",
        ),
        (
            stack(dir.path(), &[red(300.0)], "sideways", "e"),
            "stacking.coupling",
            "\"incoherent\" or \"coherent\"",
        ),
        (
            stack(
                dir.path(),
                &[red(300.0).relief_fraction(0.2)],
                "incoherent",
                "f",
            ),
            "stack[0].layer",
            "flat slabs",
        ),
        (
            stack(dir.path(), &[red(300.0)], "incoherent", "g").raw(
                "layer",
                "{ thickness_nm = 300.0, fragment_nm = [600.0, 600.0] }",
            ),
            "stack",
            "remove [layer]",
        ),
    ];
    for (scene, key, words) in cases {
        let e = scene
            .parse(&scene.write(dir.path()))
            .unwrap_err()
            .to_string();
        assert!(e.contains(key) && e.contains(words), "{key}: {e}");
    }
    // Without outputs given, an incoherent stack makes its tile alone (the
    // single layer's default "brdf" is not made there); a coherent one the
    // single layer's defaults.
    for (coupling, brdf) in [("incoherent", false), ("coherent", true)] {
        let s = stack(dir.path(), &[red(300.0)], coupling, "defaults")
            .without("appearance.outputs")
            .scene(dir.path());
        assert!(s.appearance.products.tile);
        assert_eq!(s.appearance.products.brdf, brdf, "{coupling}");
    }
    // A different second pigment name fixes the duplicate.
    let ok = stack(
        dir.path(),
        &[
            red(300.0),
            layer(
                PigmentToml::builtin("red")
                    .named("red2")
                    .pvc(0.2)
                    .diameter_nm(100.0),
                300.0,
            ),
        ],
        "incoherent",
        "h",
    );
    assert!(ok.parse(&ok.write(dir.path())).is_ok());
}

#[test]
fn without_surfaces_one_layer_as_a_stack_equals_the_layer_solved_whole() {
    // A binder of index 1 has no surfaces and makes no film: one layer
    // combined by adding and the same fragment solved as one differ only by
    // the adding method's discretisation (orders binned into its directions,
    // the azimuthal mean) against the single layer's paper term (table read
    // at the exact directions, Gauss–Legendre below). The same fragments:
    // no statistics in the difference.
    let dir = tempfile::tempdir().unwrap();
    let one = [layer(
        PigmentToml::builtin("yellow").pvc(0.2).diameter_nm(150.0),
        400.0,
    )
    .binder_index(1.0)
    .fragment_nm(1000.0)];
    let run = |coupling: &str, azimuth: f64| {
        stack(dir.path(), &one, coupling, &format!("{coupling}{azimuth}"))
            .realisations(1)
            .wavelengths_nm(&[450.0, 650.0])
            .polar_deg(&[0.0, 30.0])
            .azimuth_deg(azimuth)
            .run(dir.path())
            .result_path
    };
    let factors = |path: &Path| {
        ["45_0", "d8_sci", "d8_sce"]
            .map(|g| read(path, &format!("appearance/measured/{g}/reflectance_factor")))
    };
    let (apart, whole) = (run("incoherent", 0.0), run("coherent", 0.0));
    for (a, w) in factors(&apart).iter().zip(&factors(&whole)) {
        for (x, y) in a.iter().zip(w) {
            assert!((x - y).abs() < 0.02 * y + 0.002, "{a:?} vs {w:?}");
        }
    }
    // The tile's BRDF square in the plane of incidence (π f), against the
    // whole layer's read at two azimuths: one fragment is not isotropic in
    // its plane (its BRDF differs by up to 10 % between them at 450 nm,
    // where the 1 µm fragment has few orders), the stack's adding takes it
    // as isotropic.
    let pi_f = |p: &Path| -> Vec<f64> {
        read(p, "appearance/brdf_total")
            .iter()
            .map(|f| std::f64::consts::PI * f)
            .collect()
    };
    let (a, w0, w90) = (pi_f(&apart), pi_f(&whole), pi_f(&run("coherent", 90.0)));
    assert_eq!(a.len(), 8, "2 wavelengths × 2 illumination × 2 viewing");
    for k in 0..a.len() {
        let w = 0.5 * (w0[k] + w90[k]);
        assert!(
            (a[k] - w).abs() < 0.1 * w + 0.001,
            "cell {k}: {a:?} vs {w0:?}, {w90:?}"
        );
    }
    assert!(apart.with_extension("png").exists());
}

#[test]
fn a_stack_result_exports_its_solves_and_colours() {
    let dir = tempfile::tempdir().unwrap();
    let layers = [layer(
        PigmentToml::builtin("yellow").pvc(0.2).molecular(),
        300.0,
    )];
    let r = stack(dir.path(), &layers, "incoherent", "exported").run(dir.path());
    let (ok, _, err) =
        common::cli::inksim_in(dir.path(), &["export", r.result_path.to_str().unwrap()]);
    assert!(ok, "{err}");
    let colours = std::fs::read_to_string(dir.path().join("exported-colours.csv")).unwrap();
    let rows: Vec<&str> = colours.lines().collect();
    assert_eq!(rows.len(), 4, "{colours}");
    assert!(
        rows[1..].iter().any(|r| r.starts_with("45/0,")),
        "{colours}"
    );
    assert!(dir.path().join("exported-solves.csv").exists());
}

#[test]
fn a_study_sweeps_stacks_and_merges_them() {
    // Both couplings of a two-layer stack as a study's axis, then the top
    // ink's coverage: each variant finishes with its tile and the merge
    // compares them.
    let dir = tempfile::tempdir().unwrap();
    let layer = |name: &str| {
        format!(
            "[[base.stack]]\n[base.stack.layer]\nthickness_nm = 200.0\nfragment_nm = [400.0, 400.0]\n\
             binder_index = 1.5\n[[base.stack.pigment]]\nname = \"{name}\"\n\
             material = {{ builtin = \"{name}\" }}\npvc = 0.15\ndiameter_nm = 100.0\n"
        )
    };
    let text = format!(
        "[study]\nname = \"stacks\"\nseed = 3\noutput_dir = \"out\"\n\n[base]\nrealisations = 2\n\
         {}{}[base.grid]\ncell_nm = 50.0\nz_cell_nm = 50.0\n[base.illumination]\n\
         wavelengths_nm = [450.0, 600.0]\npolar_deg = [0.0]\n[base.appearance]\n\
         outputs = [\"tile\"]\n\n[[axis]]\nname = \"coupling\"\nkey = \"stacking.coupling\"\n\
         values = [\"incoherent\", \"coherent\"]\n",
        layer("yellow"),
        layer("blue")
    );
    std::fs::write(dir.path().join("stacks.toml"), &text).unwrap();
    let run = |args: &[&str]| {
        let (ok, out, err) = common::cli::inksim_in(dir.path(), args);
        assert!(ok, "{args:?}: {out}\n{err}");
    };
    run(&["run", "stacks.toml"]);
    run(&["merge", "stacks.toml"]);
    let summary = std::fs::read_to_string(dir.path().join("out/summary.md")).unwrap();
    for v in ["incoherent", "coherent"] {
        assert!(summary.contains(v), "{summary}");
        assert!(dir.path().join(format!("out/variants/{v}.png")).exists());
    }
    assert!(dir.path().join("out/summary.h5").exists());
    let halftone = text
        .replace("name = \"stacks\"", "name = \"dots\"")
        .replace("output_dir = \"out\"", "output_dir = \"dots\"")
        .replace(
            "name = \"coupling\"\nkey = \"stacking.coupling\"\nvalues = [\"incoherent\", \"coherent\"]",
            "name = \"cover\"\nkey = \"stack.0.coverage\"\nvalues = [0.5, 1.0]",
        );
    std::fs::write(dir.path().join("dots.toml"), halftone).unwrap();
    run(&["run", "dots.toml"]);
    run(&["merge", "dots.toml"]);
    let summary = std::fs::read_to_string(dir.path().join("dots/summary.md")).unwrap();
    assert!(summary.contains("cover0.5"), "{summary}");
    let f = inksim::output::h5::open(dir.path().join("dots/variants/cover0.5.h5")).unwrap();
    let c: Vec<f64> = f
        .dataset("stack/layer_coverage")
        .unwrap()
        .read_raw()
        .unwrap();
    assert_eq!(c, [0.5, 1.0]);
}

#[test]
fn the_adding_doubling_baseline_of_a_stack_adds_its_layers() {
    use inksim::config::{Baseline, Measurement};
    use inksim::optics::baseline;
    use inksim::optics::colour::Observer;
    // One layer 600 nm thick is the same radiative-transfer medium as two
    // layers of 300 nm of the same pigment stacked: adding the halves must
    // give the whole.
    let dir = tempfile::tempdir().unwrap();
    let whole = layer(
        PigmentToml::builtin("red").pvc(0.2).diameter_nm(200.0),
        600.0,
    )
    .wavelengths_nm(&[450.0, 550.0, 650.0])
    .scene(dir.path());
    let input = inksim::pipeline::baseline_input(&whole).unwrap().unwrap();
    let half = baseline::BaselineInput {
        thickness_nm: 300.0,
        ..input.clone()
    };
    let obs = Observer::standard(whole.appearance.illuminant, whole.appearance.observer);
    let m = [Measurement::FortyFiveZero, Measurement::DiffuseEightSci];
    for model in [Baseline::AddingDoubling, Baseline::AddingDoublingContact] {
        let one = baseline::baseline_colours(model, &input, &m, &|_| None, &obs).unwrap();
        let two = baseline::stack_baseline_colours(
            model,
            &[half.clone(), half.clone()],
            (&[1.0, 1.0], 1.0),
            &m,
            &|_| None,
            &obs,
        )
        .unwrap();
        for (a, b) in one.iter().zip(&two) {
            for (x, y) in a.reflectance_factor.iter().zip(&b.reflectance_factor) {
                assert!((x - y).abs() < 1e-9, "{model:?}: {x} vs {y}");
            }
        }
        // Printed on 30 % of the area: Murray–Davies with the bare paper.
        let dots = baseline::stack_baseline_colours(
            model,
            std::slice::from_ref(&input),
            (&[0.3], 1.0),
            &m,
            &|_| None,
            &obs,
        )
        .unwrap();
        for (a, b) in one.iter().zip(&dots) {
            for (x, y) in a.reflectance_factor.iter().zip(&b.reflectance_factor) {
                let e = 0.3 * x + 0.7 * input.paper_albedo;
                assert!((y - e).abs() < 1e-12, "{model:?}: {y} vs {e}");
            }
        }
    }
    // Kubelka–Munk is a model of one layer.
    let e = baseline::stack_baseline_colours(
        Baseline::KubelkaMunk,
        &[half],
        (&[1.0], 1.0),
        &m,
        &|_| None,
        &obs,
    )
    .unwrap_err();
    assert!(e.to_string().contains("one layer"), "{e}");
}

#[test]
fn a_stack_reports_its_adding_doubling_baseline_beside_its_colours() {
    let dir = tempfile::tempdir().unwrap();
    let layers = yellow_over_blue(300.0);
    for coupling in ["incoherent", "coherent"] {
        let r = stack(dir.path(), &layers, coupling, coupling)
            .raw("appearance.baseline", "\"adding-doubling\"")
            .run(dir.path());
        let b = inksim::output::h5::read_baseline(&r.result_path).unwrap();
        assert_eq!(b.len(), 3, "{coupling}");
        assert!(b.iter().all(|x| x.de00_to_wave.is_some_and(|d| d > 0.0)));
    }
    let km = stack(dir.path(), &layers, "incoherent", "km")
        .raw("appearance.baseline", "\"kubelka-munk\"");
    let e = km.parse(&km.write(dir.path())).unwrap_err().to_string();
    assert!(
        e.contains("appearance.baseline") && e.contains("one layer"),
        "{e}"
    );
}

#[test]
fn the_tile_of_a_stack_solved_layer_by_layer_is_reciprocal() {
    // Helmholtz reciprocity: f(θi → θo) = f(θo → θi) in the plane of
    // incidence. Each layer's solves obey it only to their discretisation
    // and the adding carries it through every Fourier term; a term weighed
    // by the wrong bin, or a wrong sign of the azimuth, breaks it.
    let dir = tempfile::tempdir().unwrap();
    let report = stack(dir.path(), &yellow_over_blue(200.0), "incoherent", "recip")
        .polar_deg(&[0.0, 30.0, 60.0])
        .run(dir.path());
    let path = &report.result_path;
    let ill = read(path, "appearance/illumination_deg");
    let view = read(path, "appearance/viewing_deg");
    assert_eq!(ill, view);
    let n = ill.len();
    let f = read(path, "appearance/brdf_total");
    let largest = f.iter().fold(0.0f64, |a, &b| a.max(b));
    for l in 0..f.len() / (n * n) {
        for i in 0..n {
            for o in 0..i {
                let (a, b) = (f[(l * n + i) * n + o], f[(l * n + o) * n + i]);
                assert!(
                    (a - b).abs() < 0.01 * largest,
                    "{}° → {}°: {a} vs {b}",
                    ill[i],
                    view[o]
                );
            }
        }
    }
    assert!(path.with_extension("png").exists());
}

#[test]
fn a_halftone_mixes_its_primaries_by_area() {
    // Two dissolved inks printed at 40 % and 70 % (nothing random: one
    // realisation is exact). The print is Demichel's four primaries —
    // paper, yellow alone, blue alone, yellow over blue — each a stack run
    // on its own, mixed by Yule–Nielsen (n = 2) on the paper and by area in
    // air.
    let dir = tempfile::tempdir().unwrap();
    let yellow = || layer(PigmentToml::builtin("yellow").pvc(0.2).molecular(), 300.0);
    let blue = || layer(PigmentToml::builtin("blue").pvc(0.1).molecular(), 500.0);
    let run = |layers: &[SceneToml], name: &str| {
        stack(dir.path(), layers, "incoherent", name)
            .realisations(1)
            .polar_deg(&[0.0, 30.0])
            .set("stacking.yule_nielsen_n", 2.0)
            .run(dir.path())
            .result_path
    };
    let print = run(&[yellow().coverage(0.4), blue().coverage(0.7)], "print");
    let both = run(&[yellow(), blue()], "both");
    let y = run(&[yellow()], "yellow");
    let b = run(&[blue()], "blue");
    let (a1, a2) = (0.4, 0.7);
    let parts = [
        ((1.0 - a1) * (1.0 - a2), None),
        (a1 * (1.0 - a2), Some(&y)),
        ((1.0 - a1) * a2, Some(&b)),
        (a1 * a2, Some(&both)),
    ];
    let albedo = 0.9;
    for (name, paper) in [
        ("appearance/measured/45_0/reflectance_factor", albedo),
        ("appearance/measured/d8_sci/reflectance_factor", albedo),
        ("appearance/measured/d8_sce/reflectance_factor", albedo),
        ("appearance/natural", albedo),
        ("appearance/brdf_total", albedo / std::f64::consts::PI),
    ] {
        let got = read(&print, name);
        let each: Vec<Vec<f64>> = parts
            .iter()
            .map(|(_, p)| p.map_or(vec![paper; got.len()], |p| read(p, name)))
            .collect();
        for (k, g) in got.iter().enumerate() {
            let e = parts
                .iter()
                .zip(&each)
                .map(|((w, _), v)| w * v[k].sqrt())
                .sum::<f64>()
                .powi(2);
            assert!((g - e).abs() < 1e-12 * e, "{name}[{k}]: {g} vs {e}");
        }
    }
    // The totals in air mix by area; the bare paper's share passes it all.
    for (name, bare) in [
        ("stack/reflectance", 0.0),
        ("stack/transmittance", 1.0),
        ("stack/absorption", 0.0),
    ] {
        let got = read(&print, name);
        for (k, g) in got.iter().enumerate() {
            let e: f64 = parts
                .iter()
                .map(|(w, p)| w * p.map_or(bare, |p| read(p, name)[k]))
                .sum();
            assert!((g - e).abs() < 1e-12, "{name}[{k}]: {g} vs {e}");
        }
    }
}
