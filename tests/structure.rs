//! Explicit-structure input: primitives rasterised exactly where
//! they can be, a buried absorbing slab against an independent transfer
//! matrix, the HDF5 ε grid giving the same answer as the primitives it
//! holds, and clear errors.

use inksim::config::{Body, Material, Primitive};
use inksim::pipeline;
use inksim::raster::structure::rasterize_primitives;
use inksim::raster::Grid;
use num_complex::Complex64 as C64;
use std::f64::consts::PI;
use std::path::Path;

mod common;
use common::airy::tmm;

/// Held by the tests here that write an HDF5 file and open it again, and
/// by the one that starts `inksim` processes: a child started while a file
/// is open for writing (between HDF5's create and our close-on-exec) would
/// inherit its lock and make the reopen fail.
static FILES_AND_CHILDREN: std::sync::Mutex<()> = std::sync::Mutex::new(());

fn files_and_children() -> std::sync::MutexGuard<'static, ()> {
    FILES_AND_CHILDREN
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}
use common::scene::{PigmentToml, PrimitiveToml, SceneToml};

fn material() -> Material {
    Material::from_csv_text("m", "wavelength_nm,n,k\n1,2,0.1\n1000000,2,0.1\n").unwrap()
}

fn grid(n: [usize; 3], size: [f64; 3]) -> Grid {
    Grid {
        nx: n[0],
        ny: n[1],
        nz: n[2],
        size_nm: size,
    }
}

#[test]
fn boxes_are_exact_and_curved_bodies_keep_their_volume() {
    let g = grid([20, 10, 8], [200.0, 100.0, 80.0]);
    // A box from mid-cell to mid-cell, wrapping across x = Lx.
    let b = Primitive {
        body: Body::Box {
            min_nm: [185.0, 12.5, 20.0],
            max_nm: [215.0, 47.5, 40.0],
        },
        material: material(),
    };
    let r = rasterize_primitives(&[b], &g);
    let f = &r.fractions[0];
    assert!((f[[2, 1, 18]] - 0.5 * 0.75).abs() < 1e-12);
    assert!((f[[2, 2, 19]] - 1.0).abs() < 1e-12);
    assert!(
        (f[[3, 4, 1]] - 0.5 * 0.75).abs() < 1e-12,
        "wraps to x = 0..15"
    );
    let vol: f64 = f.sum() * 10.0 * 10.0 * 10.0;
    assert!((vol - 30.0 * 35.0 * 20.0).abs() < 1e-9);
    // A sphere across the periodic edge and a z cylinder: volume to 3e-3.
    for body in [
        Body::Sphere {
            center_nm: [195.0, 50.0, 40.0],
            radius_nm: 30.0,
        },
        Body::Cylinder {
            center_nm: [100.0, 50.0, 40.0],
            radius_nm: 25.0,
            length_nm: 50.0,
            axis: 2,
        },
    ] {
        let exact = match body {
            Body::Sphere { radius_nm: r, .. } => 4.0 / 3.0 * PI * r * r * r,
            Body::Cylinder {
                radius_nm: r,
                length_nm: l,
                ..
            } => PI * r * r * l,
            _ => unreachable!(),
        };
        let r = rasterize_primitives(
            &[Primitive {
                body: body.clone(),
                material: material(),
            }],
            &g,
        );
        let vol = r.fractions[0].sum() * 1000.0;
        assert!(
            (vol / exact - 1.0).abs() < 3e-3,
            "{body:?}: {vol} vs {exact}"
        );
    }
}

/// A 200 nm slab of n = 2 + 0.1i buried 300 nm deep.
fn buried_slab() -> PrimitiveToml {
    PrimitiveToml::slab(300.0, 500.0).index(2.0, 0.1)
}

/// `bodies` in a 1 µm layer on a 200 nm fragment, z cells of `z_cell`,
/// results in `dir`.
fn bodies_scene(dir: &Path, z_cell: f64, bodies: &[PrimitiveToml]) -> SceneToml {
    SceneToml::structure(bodies)
        .fragment_nm(200.0)
        .cell_nm(50.0)
        .z_cell_nm(z_cell)
        .wavelengths_nm(&[450.0, 600.0])
        .polar_deg(&[0.0, 40.0])
        .outputs(&[])
        .tolerance(1e-10)
        .output(dir, "slab")
}

/// The buried slab alone.
fn slab_scene(dir: &Path, z_cell: f64) -> SceneToml {
    bodies_scene(dir, z_cell, &[buried_slab()])
}

/// Largest |ΔR|, |ΔT| of the solves against the transfer matrix of
/// `stack`; every solve's energy balance within 1e-8.
fn worst_against_tmm(
    entries: &[inksim::optics::farfield::SolveEntry],
    stack: &[(C64, f64)],
) -> f64 {
    let mut worst = 0.0f64;
    for e in entries {
        let (r, t) = tmm(stack, e.wavelength_nm, e.incidence.polar_deg);
        let eff = &e.efficiencies;
        worst = worst
            .max((eff.total_reflectance - r).abs())
            .max((eff.total_transmittance - t).abs());
        assert!(eff.energy_balance.abs() < 1e-8);
    }
    worst
}

#[test]
fn buried_slab_matches_the_transfer_matrix() {
    let dir = tempfile::tempdir().unwrap();
    let eps_b = C64::new(1.558f64.powi(2), 0.0);
    let eps_s = C64::new(2.0, 0.1) * C64::new(2.0, 0.1);
    let stack = [(eps_b, 300.0), (eps_s, 200.0), (eps_b, 500.0)];
    let mut worst = [0.0f64; 2];
    for (k, z) in [10.0, 5.0].into_iter().enumerate() {
        let rep = slab_scene(dir.path(), z).run(dir.path());
        assert_eq!(rep.entries.len(), 4);
        worst[k] = worst_against_tmm(&rep.entries, &stack);
    }
    // Second order in the z cell (measured 3.0e-3 → 7.5e-4 for this strong,
    // absorbing slab, ε = 3.99 + 0.4i, at 450–600 nm).
    assert!(worst[1] < 1e-3 && worst[1] < 0.35 * worst[0], "{worst:?}");
    eprintln!("worst |ΔR|, |ΔT| at 10 and 5 nm z cells: {worst:?}");
}

#[test]
fn hdf5_grid_gives_the_answer_of_the_primitives_it_holds() {
    let _serial = files_and_children();
    let dir = tempfile::tempdir().unwrap();
    let text = bodies_scene(
        dir.path(),
        10.0,
        &[
            PrimitiveToml::sphere([60.0, 90.0, 700.0], 80.0).builtin("blue"),
            buried_slab(),
        ],
    );
    let prim = text.run(dir.path());
    // The same ε, written to a file, per wavelength.
    let scene = text.scene(dir.path());
    let g = pipeline::grid_of(&scene);
    let ps = match scene.structure.as_ref().unwrap() {
        inksim::config::Structure::Primitives(ps) => ps.clone(),
        _ => unreachable!(),
    };
    let raster = rasterize_primitives(&ps, &g);
    let mut re = ndarray::Array4::<f64>::zeros((2, g.nz, g.ny, g.nx));
    let mut im = re.clone();
    for (l, wl) in [450.0, 600.0].into_iter().enumerate() {
        let eps: Vec<C64> = ps
            .iter()
            .map(|p| p.material.index_at(wl).unwrap().powi(2))
            .collect();
        let mut e = ndarray::Array3::zeros((g.nz, g.ny, g.nx));
        raster.epsilon_into(C64::new(1.558f64.powi(2), 0.0), &eps, &mut e);
        for (k, v) in e.iter().enumerate() {
            let (iz, rest) = (k / (g.ny * g.nx), k % (g.ny * g.nx));
            re[[l, iz, rest / g.nx, rest % g.nx]] = v.re;
            im[[l, iz, rest / g.nx, rest % g.nx]] = v.im;
        }
    }
    let h5 = dir.path().join("eps.h5");
    {
        let f = inksim::output::h5::create(&h5).unwrap();
        f.new_dataset_builder()
            .with_data(&re)
            .create("eps_re")
            .unwrap();
        f.new_dataset_builder()
            .with_data(&im)
            .create("eps_im")
            .unwrap();
        f.new_dataset_builder()
            .with_data(&[450.0, 600.0][..])
            .create("wavelengths_nm")
            .unwrap();
    }
    let file_text = slab_scene(dir.path(), 10.0)
        .structure_file("eps.h5")
        .output_name("file");
    let from_file = file_text.run(dir.path());
    for (a, b) in prim.entries.iter().zip(&from_file.entries) {
        assert_eq!(
            a.efficiencies.total_reflectance.to_bits(),
            b.efficiencies.total_reflectance.to_bits()
        );
        assert_eq!(
            a.efficiencies.absorption.to_bits(),
            b.efficiencies.absorption.to_bits()
        );
    }

    // A grid of the wrong shape or without a wavelength is refused clearly.
    let bad = file_text.clone().cell_nm(40.0);
    let p = dir.path().join("bad.toml");
    std::fs::write(&p, bad.toml()).unwrap();
    let err = pipeline::run(&bad.parse(&p).unwrap())
        .err()
        .unwrap()
        .to_string();
    assert!(
        err.contains("eps.h5") && err.contains("scene's grid"),
        "{err}"
    );
    let bad = file_text.wavelengths_nm(&[450.0, 650.0]);
    let err = pipeline::run(&bad.parse(&p).unwrap())
        .err()
        .unwrap()
        .to_string();
    assert!(err.contains("650"), "{err}");
}

#[test]
fn check_reads_a_structure_file_as_a_run_would() {
    let _serial = files_and_children();
    let dir = tempfile::tempdir().unwrap();
    let text = slab_scene(dir.path(), 10.0)
        .structure_file("eps.h5")
        .wavelengths_nm(&[450.0, 600.0]);
    let cfg = text.write(dir.path());
    let h5 = dir.path().join("eps.h5");
    std::fs::write(&h5, "").unwrap();
    let g = pipeline::grid_of(&text.scene(dir.path()));
    let grid = |v: f64| ndarray::Array3::<f64>::from_elem((g.nz, g.ny, g.nx), v);
    let write = |sets: &[(&str, ndarray::Array3<f64>)]| {
        let f = inksim::output::h5::create(&h5).unwrap();
        for (name, a) in sets {
            f.new_dataset_builder().with_data(a).create(*name).unwrap();
        }
    };
    // A fresh output folder for the runs.
    let out = dir.path().join("fresh");
    let command = |verb: &str| {
        let mut args = vec![verb, cfg.to_str().unwrap()];
        if verb == "run" {
            args.extend(["--output-dir", out.to_str().unwrap()]);
        }
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_inksim"))
            .args(args)
            .current_dir(dir.path())
            .output()
            .unwrap();
        (
            o.status.success(),
            String::from_utf8_lossy(&o.stderr).into_owned(),
        )
    };
    let check = || command("check");
    write(&[("eps_re", grid(2.4)), ("eps_im", grid(0.0))]);
    let (ok, err) = check();
    assert!(ok, "{err}");
    let mut nan = grid(2.4);
    nan[[0, 0, 0]] = f64::NAN;
    let mut gain = grid(0.0);
    gain[[1, 0, 0]] = -0.1;
    type Case<'a> = (Box<dyn Fn() + 'a>, &'a str);
    let cases: Vec<Case> = vec![
        (
            Box::new(|| std::fs::write(&h5, "not hdf5").unwrap()),
            "HDF5",
        ),
        (Box::new(|| std::fs::write(&h5, "").unwrap()), "HDF5"),
        (Box::new(|| write(&[("eps_re", grid(2.4))])), "eps_im"),
        (
            Box::new(|| {
                let small = ndarray::Array3::<f64>::zeros((g.nz, g.ny, g.nx + 1));
                write(&[("eps_re", small.clone()), ("eps_im", small)])
            }),
            "scene's grid",
        ),
        (
            Box::new(|| write(&[("eps_re", nan.clone()), ("eps_im", grid(0.0))])),
            "must be finite",
        ),
        (
            Box::new(|| write(&[("eps_re", grid(2.4)), ("eps_im", gain.clone())])),
            "Im ε ≥ 0",
        ),
    ];
    for (make, said) in cases {
        make();
        let (ok, err) = check();
        assert!(!ok, "{said}");
        assert!(
            err.contains("eps.h5") && err.contains(said),
            "{said}: {err}"
        );
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        // A run refuses with the same one line after its plan (timestamped
        // progress), nothing after it, and leaves no folder or lock file.
        assert!(!out.exists(), "{}", out.display());
        let (ok, err) = command("run");
        assert!(!ok, "{said}");
        let errors: Vec<&str> = err
            .lines()
            .filter(|l| !l.starts_with(|c: char| c.is_ascii_digit()))
            .collect();
        assert_eq!(errors.len(), 1, "{said}: {err}");
        assert!(err.trim_end().lines().last() == Some(errors[0]), "{err}");
        assert!(errors[0].contains(said), "{said}: {err}");
        assert!(
            !out.exists(),
            "{said}: a refused run left {}",
            out.display()
        );
    }
}

#[test]
fn structure_input_errors_name_the_key() {
    let _serial = files_and_children();
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("s.toml");
    let base = slab_scene(dir.path(), 10.0);
    for (text, key) in [
        (
            base.clone().pigment(
                PigmentToml::builtin("red")
                    .named("r")
                    .pvc(0.1)
                    .diameter_nm(100.0),
            ),
            "structure",
        ),
        (
            base.clone()
                .raw("structure.primitive.0.shape.z_nm", "[300.0, 1500.0]"),
            "z_nm",
        ),
        (
            base.clone()
                .raw("structure.primitive.0.material.index", "[2.0]"),
            "index",
        ),
        (base.structure_file("none.h5"), "structure.file"),
    ] {
        let err = match text.parse(&p) {
            Ok(_) => panic!("{key}: accepted"),
            Err(e) => e.to_string(),
        };
        assert!(err.contains(key), "{key}: {err}");
    }
}

#[test]
fn geometry_command_draws_an_explicit_structure() {
    let dir = tempfile::tempdir().unwrap();
    let scene = slab_scene(dir.path(), 10.0).scene(dir.path());
    let rep = pipeline::run_geometry(&scene).unwrap();
    assert!(rep.geometry.is_none());
    assert!(
        rep.lines[0].starts_with("explicit structure: 1 bodies"),
        "{:?}",
        rep.lines
    );
    // The slab fills 200 of 1000 nm: fraction 0.2 exactly (cell-aligned).
    assert!(rep.lines[0].ends_with("0.2000 in all"), "{:?}", rep.lines);
    assert!(rep.picture_path.is_file() && rep.result_path.is_file());
}

/// The slab scene with a conformal binder surface of film `film_nm`.
fn conformal_slab_scene(dir: &Path, z_cell: f64, film_nm: f64) -> SceneToml {
    slab_scene(dir, z_cell).raw(
        "layer.surface",
        &format!("{{ kind = \"conformal\", film_nm = {film_nm:?} }}"),
    )
}

#[test]
fn conformal_film_over_a_slab_is_the_three_layer_airy_problem() {
    // The slab's top is at 300 nm; a 50 nm conformal film puts the binder
    // surface at 250 nm: air, 50 nm binder, 200 nm slab, 500 nm binder.
    let dir = tempfile::tempdir().unwrap();
    let eps_b = C64::new(1.558f64.powi(2), 0.0);
    let eps_s = C64::new(2.0, 0.1).powi(2);
    let stack = [(eps_b, 50.0), (eps_s, 200.0), (eps_b, 500.0)];
    let flat = [(eps_b, 300.0), (eps_s, 200.0), (eps_b, 500.0)];
    let mut worst = [0.0f64; 2];
    let mut apart = 0.0f64;
    for (k, z) in [10.0, 5.0].into_iter().enumerate() {
        let rep = conformal_slab_scene(dir.path(), z, 50.0).run(dir.path());
        worst[k] = worst_against_tmm(&rep.entries, &stack);
        for e in &rep.entries {
            let (r, _) = tmm(&stack, e.wavelength_nm, e.incidence.polar_deg);
            let (r_flat, _) = tmm(&flat, e.wavelength_nm, e.incidence.polar_deg);
            apart = apart.max((r - r_flat).abs());
        }
    }
    assert!(worst[1] < 1e-3 && worst[1] < 0.35 * worst[0], "{worst:?}");
    // The film is not the flat layer's 300 nm skin, by far more than the
    // discretisation error.
    assert!(apart > 10.0 * worst[1], "{apart} vs {worst:?}");
}

#[test]
fn bodies_thinner_than_a_cell_are_named_and_the_error_table_is_not_applied() {
    let dir = tempfile::tempdir().unwrap();
    // 200 nm fragment at 50 nm cells; z cells of 20 nm.
    let bodies = [
        buried_slab(),
        PrimitiveToml::sphere([100.0, 100.0, 100.0], 60.0).index(1.5, 0.0),
        PrimitiveToml::sphere([50.0, 50.0, 50.0], 8.0).index(1.5, 0.0),
    ];
    let scene = bodies_scene(dir.path(), 20.0, &bodies).scene(dir.path());
    let lines = pipeline::RunPlan::of(&scene).lines;
    let warnings: Vec<&String> = lines.iter().filter(|l| l.starts_with("WARNING")).collect();
    // Only the 16 nm sphere: thinner than the 50 nm cell along x and y and the
    // 20 nm cell along z; the 120 nm sphere and the slab are resolved.
    assert_eq!(warnings.len(), 1, "{lines:#?}");
    assert!(
        warnings[0].contains(
            "structure body 2 (sphere) is thinner than one grid cell along x (16.000 nm < cell \
             50.000 nm), y (16.000 nm < cell 50.000 nm), z (16.000 nm < cell 20.000 nm)"
        ),
        "{}",
        warnings[0]
    );
    let text = pipeline::accuracy::expected_error(&scene).join("\n");
    assert!(
        text.contains("not estimated for an explicit structure") && !text.contains("lateral cell"),
        "{text}"
    );
}

/// A layered structure (`kind = "layers"`) in the scene of `bodies_scene`:
/// material 1 is n = 2 + 0.1i, material 2 the builtin blue.
fn layers_scene(dir: &Path, slices: &str) -> SceneToml {
    bodies_scene(dir, 10.0, &[buried_slab()])
        .without("structure")
        .raw(
            "structure",
            &format!(
                "{{ kind = \"layers\", materials = [{{ index = [2.0, 0.1] }}, \
                 {{ builtin = \"blue\" }}], layer = [{slices}] }}"
            ),
        )
}

#[test]
fn a_layered_structure_is_the_boxes_its_maps_draw() {
    let dir = tempfile::tempdir().unwrap();
    // A map of one code over the whole fragment is the slab it fills.
    let slab = layers_scene(dir.path(), r#"{ z_nm = [300.0, 500.0], map = ["1"] }"#);
    let a = slab.run(dir.path());
    let b = slab_scene(dir.path(), 10.0).run(dir.path());
    for (x, y) in a.entries.iter().zip(&b.entries) {
        let (x, y) = (&x.efficiencies, &y.efficiencies);
        assert!((x.total_reflectance - y.total_reflectance).abs() < 1e-12);
        assert!((x.total_transmittance - y.total_transmittance).abs() < 1e-12);
    }
    // A staircased post over two slices, on a 4 × 4 map of the 200 nm
    // fragment (50 nm pixels, the grid's cells), and a blue strip: the
    // raster is that of the boxes drawn as primitives, cell for cell.
    let post = layers_scene(
        dir.path(),
        r#"{ z_nm = [100.0, 200.0], map = ["0000", "0110", "0110", "0000"] },
           { z_nm = [200.0, 400.0], map = ["1111", "1 1 1 1", "2222", "0000"] }"#,
    );
    let scene = post.scene(dir.path());
    let g = pipeline::grid_of(&scene);
    let layered = match scene.structure.as_ref().unwrap() {
        inksim::config::Structure::Primitives(ps) => rasterize_primitives(ps, &g),
        _ => unreachable!(),
    };
    assert_eq!(layered.fractions.len(), 2, "one body per material");
    let bx = |lo: [f64; 3], hi: [f64; 3], m: Material| Primitive {
        body: Body::Box {
            min_nm: lo,
            max_nm: hi,
        },
        material: m,
    };
    let explicit = rasterize_primitives(
        &[
            bx([50.0, 50.0, 100.0], [150.0, 150.0, 200.0], material()),
            bx([0.0, 0.0, 200.0], [200.0, 100.0, 400.0], material()),
            bx([0.0, 100.0, 200.0], [200.0, 150.0, 400.0], material()),
        ],
        &g,
    );
    let ones = &explicit.fractions[0] + &explicit.fractions[1];
    for (k, (x, y)) in layered.fractions[0].iter().zip(ones.iter()).enumerate() {
        assert!((x - y).abs() < 1e-12, "voxel {k}: {x} vs {y}");
    }
    for (x, y) in layered.fractions[1]
        .iter()
        .zip(explicit.fractions[2].iter())
    {
        assert!((x - y).abs() < 1e-12);
    }
    assert!((layered.fractions[1].sum() * 50.0 * 50.0 * 10.0 - 200.0 * 50.0 * 200.0).abs() < 1e-6);
}

#[test]
fn a_layered_structure_with_a_bad_map_is_refused_naming_the_key() {
    let dir = tempfile::tempdir().unwrap();
    for (slices, want) in [
        (
            r#"{ z_nm = [0.0, 100.0], map = ["01", "011"] }"#,
            "structure.layer[0].map[1]`: has 3 columns, the first row 2",
        ),
        (
            r#"{ z_nm = [0.0, 100.0], map = ["0x"] }"#,
            "`x` is not a material code: 0 (the binder) or 1–2",
        ),
        (
            r#"{ z_nm = [0.0, 100.0], map = ["03"] }"#,
            "`3` is not a material code",
        ),
        (
            r#"{ z_nm = [0.0, 300.0], map = ["1"] }, { z_nm = [200.0, 400.0], map = ["1"] }"#,
            "structure.layer[1].z_nm`: starts at 200 nm, above the end of the slice before (300 nm)",
        ),
        (
            r#"{ z_nm = [0.0, 2000.0], map = ["1"] }"#,
            "must be [z0, z1] with 0 <= z0 < z1 <= 1000",
        ),
        (r#"{ z_nm = [0.0, 100.0], map = ["00"] }"#, "every map is all binder"),
    ] {
        let text = layers_scene(dir.path(), slices).toml();
        let err = inksim::config::parse_scene(Path::new("s.toml"), &text)
            .unwrap_err()
            .to_string();
        assert!(err.contains(want), "{slices}: {err}");
        assert!(!err.contains('\n'), "{err}");
    }
}
