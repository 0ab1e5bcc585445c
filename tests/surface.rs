//! The binder surface: the rough surface keeps the binder's volume, each
//! realisation draws its own, and the surface keys are checked.

use inksim::raster::surface::{binder_share, rough};
use inksim::raster::{Grid, Raster};
use ndarray::Array3;
use num_complex::Complex64 as C64;
use std::path::Path;

mod common;
use common::scene::{PigmentToml, SceneToml};

#[test]
fn a_rough_surface_keeps_the_binder_volume_and_follows_its_heights() {
    // 32 × 32 columns, 400 nm of binder under 40 nm of added cells; the
    // binder in each column (from ε of a grain-free raster) is the depth
    // below its surface, and over the fragment the volume of the flat layer.
    let (dz, nz, top) = (5.0, 88, 8);
    let grid = Grid::new(32, 32, nz, [320.0, 320.0, nz as f64 * dz]).unwrap();
    let s = rough(&grid, 8.0, 40.0, 3);
    let raster = Raster {
        grid,
        fractions: vec![Array3::zeros((nz, 32, 32))],
        top_cells: top,
        surface_nm: Some(s.clone()),
        normals: Default::default(),
        crystal: Vec::new(),
    };
    let eps_b = C64::new(2.4, 0.0);
    let mut eps = Array3::zeros((nz, 32, 32));
    raster.epsilon_into(eps_b, &[C64::new(4.0, 0.0)], &mut eps);
    let h_layer = (nz - top) as f64 * dz;
    let mut total = 0.0;
    for iy in 0..32 {
        for ix in 0..32 {
            let binder: f64 = (0..nz)
                .map(|iz| ((eps[[iz, iy, ix]] - 1.0) / (eps_b - 1.0)).re * dz)
                .sum();
            assert!((binder - (h_layer - s[[iy, ix]])).abs() < 1e-9);
            total += binder;
        }
    }
    assert!(
        (total / 1024.0 - h_layer).abs() < 1e-9,
        "binder volume kept"
    );
    assert!(
        s.iter().any(|&d| d < -dz),
        "peaks reach into the added cells"
    );
    assert!((binder_share(-5.0, 5.0, -2.0) - 0.4).abs() < 1e-15);
}

#[test]
fn a_surface_map_at_the_plane_is_the_flat_surface() {
    // Top cells above z = 0 are vacuum either way: by the slices, or by a
    // surface map at depth 0 everywhere; identical ε.
    let (nz, top) = (12, 3);
    let grid = Grid::new(4, 4, nz, [40.0, 40.0, 120.0]).unwrap();
    let mut f = Array3::zeros((nz, 4, 4));
    f[[2, 1, 1]] = 0.5;
    f[[7, 2, 3]] = 1.0;
    let mut raster = Raster {
        grid,
        fractions: vec![f],
        top_cells: top,
        surface_nm: None,
        normals: Default::default(),
        crystal: Vec::new(),
    };
    let (eps_b, eps_s) = (C64::new(2.4, 0.0), [C64::new(4.0, 0.3)]);
    let mut a = Array3::zeros((nz, 4, 4));
    raster.epsilon_into(eps_b, &eps_s, &mut a);
    raster.surface_nm = Some(ndarray::Array2::zeros((4, 4)));
    let mut b = Array3::zeros((nz, 4, 4));
    raster.epsilon_into(eps_b, &eps_s, &mut b);
    assert_eq!(a, b);
    assert_eq!(a[[0, 0, 0]], C64::new(1.0, 0.0));
    assert_eq!(a[[top, 0, 0]], eps_b);
}

/// Red grains of 100 nm at 20 % PVC in a 400 nm layer whose binder surface
/// is `surface` (TOML text), one wavelength at normal incidence.
fn scene(dir: &Path, surface: &str) -> SceneToml {
    SceneToml::grains()
        .thickness_nm(400.0)
        .fragment_nm(400.0)
        .raw("layer.surface", surface)
        .diameter_nm(100.0)
        .z_cell_nm(20.0)
        .wavelengths_nm(&[550.0])
        .polar_deg(&[0.0])
        .set("output.dir", dir.display().to_string())
}

#[test]
fn surface_keys_are_checked_naming_the_key() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let cases = [
        (
            r#"{ kind = "conformal", film_nm = 0.0 }"#,
            false,
            "layer.surface.film_nm",
        ),
        (
            r#"{ kind = "conformal", film_nm = 250.0 }"#,
            false,
            "layer.surface.film_nm",
        ),
        (
            r#"{ kind = "rough", rms_nm = 150.0, correlation_nm = 50.0 }"#,
            false,
            "layer.surface.rms_nm",
        ),
        (
            r#"{ kind = "rough", rms_nm = 10.0, correlation_nm = 500.0 }"#,
            false,
            "layer.surface.correlation_nm",
        ),
        (r#"{ kind = "wavy" }"#, false, "wavy"),
        (
            r#"{ kind = "conformal", film_nm = 10.0, rms_nm = 3.0 }"#,
            false,
            "rms_nm",
        ),
        (
            r#"{ kind = "conformal", film_nm = 10.0 }"#,
            true,
            "layer.surface",
        ),
    ];
    for (surface, molecular, key) in cases {
        let mut text = scene(d, surface);
        if molecular {
            text = text.pigment(PigmentToml::builtin("red").pvc(0.2).molecular());
        }
        let msg = text.parse(&text.write(d)).unwrap_err().to_string();
        assert!(msg.contains(key), "{surface}: {msg}");
    }
    // The three valid kinds parse.
    for surface in [
        r#"{ kind = "flat" }"#,
        r#"{ kind = "conformal", film_nm = 20.0 }"#,
        r#"{ kind = "rough", rms_nm = 10.0, correlation_nm = 100.0 }"#,
    ] {
        scene(d, surface).scene(d);
    }
}

#[test]
fn each_realisation_draws_its_own_rough_surface_and_the_run_balances_energy() {
    let dir = tempfile::tempdir().unwrap();
    let rep = scene(
        dir.path(),
        r#"{ kind = "rough", rms_nm = 15.0, correlation_nm = 100.0 }"#,
    )
    .realisations(2)
    .run(dir.path());
    let r: Vec<f64> = rep
        .entries
        .iter()
        .filter(|e| e.side == inksim::optics::farfield::Side::Above && e.incidence.polar_deg == 0.0)
        .map(|e| {
            assert!(e.efficiencies.energy_balance.abs() < 1e-4);
            e.efficiencies.r00.norm_sqr()
        })
        .collect();
    assert_eq!(r.len(), 2);
    assert!(
        (r[0] - r[1]).abs() > 1e-6,
        "two realisations, two surfaces: {r:?}"
    );
}
