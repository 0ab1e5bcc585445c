//! How far a layer of fine grains is from the homogeneous slab of the
//! volume-averaged ε (the effective-medium shortcut, docs/ACCURACY.md).
//!
//! For random-sequential-addition sphere layers of a range of grain
//! diameters, PVCs and pigments, every (wavelength, incidence) is solved in
//! full on the raster and compared with the closed-form slab of
//! `⟨ε⟩ = f ε_p + (1 − f) ε_b` (the target PVC: what the shortcut uses).
//! One CSV line per solve: the errors in R, T, A, the diffuse (non-specular)
//! power, and the two terms of [`inksim::solver::airy::effective_medium_error`]'s estimate.
//!
//! ```sh
//! cargo run --release --example effective_medium              # every material
//! cargo run --release --example effective_medium -- white red # some of them
//! cargo run --release --example effective_medium -- refine    # grid check
//! ```

use inksim::config::{Material, Method, Precision};
use inksim::geometry::{pack_rsa, PackParams, SpeciesParams};
use inksim::optics::farfield::efficiencies;
use inksim::raster::{rasterize, Grid};
use inksim::solver::airy::{self, GrainTerm};
use inksim::solver::{self, Controls, Problem};
use ndarray::Array3;
use num_complex::Complex64 as C64;

const BINDER: f64 = 1.558;
const FRAGMENT_NM: f64 = 800.0;

struct Case {
    material: &'static str,
    diameter_nm: f64,
    pvc: f64,
    thickness_nm: f64,
}

fn material(name: &str) -> Material {
    match name {
        "strong" => {
            Material::from_csv_text("strong", "wavelength_nm,n,k\n380,1.4,0.8\n780,1.4,0.8\n")
                .expect("constant table")
        }
        // A lossless high-index grain (rutile-like): all error is scattering.
        "white" => Material::from_csv_text("white", "wavelength_nm,n,k\n380,2.6,0\n780,2.6,0\n")
            .expect("constant table"),
        _ => Material::builtin(name).expect("builtin"),
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let refine = args.iter().any(|a| a == "refine");
    let all = ["strong", "blue", "red", "white"];
    let chosen: Vec<&str> = all
        .into_iter()
        .filter(|m| args.is_empty() || refine || args.iter().any(|a| a == m))
        .collect();
    let mut cases = Vec::new();
    if refine {
        for d in [10.0, 20.0, 40.0, 80.0] {
            cases.push(Case {
                material: "strong",
                diameter_nm: d,
                pvc: 0.3,
                thickness_nm: 400.0,
            });
        }
    } else {
        for &material in &chosen {
            for pvc in [0.1, 0.3] {
                for d in [10.0, 20.0, 40.0, 80.0, 160.0] {
                    cases.push(Case {
                        material,
                        diameter_nm: d,
                        pvc,
                        thickness_nm: 400.0,
                    });
                }
            }
        }
        for d in [20.0, 80.0, 160.0] {
            if !chosen.contains(&"strong") {
                break;
            }
            cases.push(Case {
                material: "strong",
                diameter_nm: d,
                pvc: 0.3,
                thickness_nm: 1000.0,
            });
        }
    }
    // Cells (lateral, z): the base grid, or half of it for the check.
    let (cell, cell_z) = if refine { (6.25, 5.0) } else { (12.5, 10.0) };
    let grids: Vec<(f64, f64)> = if refine {
        vec![(12.5, 10.0), (cell, cell_z)]
    } else {
        vec![(cell, cell_z)]
    };
    let ctl = Controls {
        tolerance: 1e-7,
        max_iterations: 20_000,
        precision: Precision::F64,
        background: inksim::config::Background::DEFAULT,
    };
    // Per layer and grid: worst k0·d, error, diffuse power, error / coherent
    // term, diffuse / incoherent term, and the smallest estimate / error.
    let mut summary: Vec<(String, [f64; 6])> = Vec::new();
    println!(
        "material,d_nm,pvc,H_nm,cell_nm,cell_z_nm,wl_nm,polar_deg,achieved_pvc,\
         dR,dT,dA,err,diffuse,balance,coherent_term,incoherent_term,estimate"
    );
    for c in &cases {
        let m = material(c.material);
        let size = [FRAGMENT_NM, FRAGMENT_NM, c.thickness_nm];
        let params = PackParams::new(
            size,
            vec![SpeciesParams {
                diameter_nm: c.diameter_nm,
                volume_fraction: c.pvc,
            }],
        );
        let geom = pack_rsa(&params, 7).expect("packing");
        for &(cl, cz) in &grids {
            let mut worst = [0.0, 0.0, 0.0, 0.0, 0.0, f64::INFINITY];
            let grid = Grid {
                nx: (FRAGMENT_NM / cl).round() as usize,
                ny: (FRAGMENT_NM / cl).round() as usize,
                nz: (c.thickness_nm / cz).round() as usize,
                size_nm: size,
            };
            let raster = rasterize(&geom, &grid, 4);
            let eps_b = BINDER * BINDER;
            let mut eps = Array3::zeros((grid.nz, grid.ny, grid.nx));
            for wl in [400.0, 550.0, 700.0] {
                let n = m.index_at(wl).expect("visible");
                let eps_p = n * n;
                raster.epsilon_into(C64::new(eps_b, 0.0), &[eps_p], &mut eps);
                let mean = eps_p * c.pvc + eps_b * (1.0 - c.pvc);
                for polar in [0.0, 60.0] {
                    let lat = Problem::lattice([grid.nx, grid.ny, grid.nz], size, wl, polar, 0.0);
                    let p = Problem {
                        tensor: None,
                        lattice: lat,
                        eps: &eps,
                        eps_binder: eps_b,
                        wave: inksim::solver::Wave::Scalar,
                    };
                    let sol = solver::solve(&p, Method::Auto, &ctl).expect("solve");
                    let e = efficiencies(&sol);
                    let s = airy::slab(mean, c.thickness_nm, wl, polar);
                    let (r0, t0) = (s.r.norm_sqr(), s.t.norm_sqr());
                    let (dr, dt, da) = (
                        e.total_reflectance - r0,
                        e.total_transmittance - t0,
                        e.absorption - s.absorption,
                    );
                    let err = dr.abs().max(dt.abs()).max(da.abs());
                    let spec: f64 = e
                        .orders
                        .iter()
                        .filter(|o| o.m == 0 && o.n == 0)
                        .map(|o| o.reflectance + o.transmittance)
                        .sum();
                    let diffuse = e.total_reflectance + e.total_transmittance - spec;
                    let term = GrainTerm {
                        volume_fraction: c.pvc,
                        diameter_nm: c.diameter_nm,
                        delta_eps: eps_p - eps_b,
                    };
                    let (coh, inc) =
                        airy::effective_medium_terms(&[term], eps_b, c.thickness_nm, wl, polar);
                    let est =
                        airy::effective_medium_error(&[term], eps_b, c.thickness_nm, wl, polar);
                    let k0d = 2.0 * std::f64::consts::PI / wl * c.diameter_nm;
                    worst[0] = f64::max(worst[0], k0d);
                    worst[1] = worst[1].max(err);
                    worst[2] = worst[2].max(diffuse);
                    worst[3] = worst[3].max(err / coh);
                    worst[4] = worst[4].max(diffuse / inc);
                    worst[5] = worst[5].min(est / err);
                    println!(
                        "{},{},{},{},{},{},{},{},{:.4},{:.3e},{:.3e},{:.3e},{:.3e},{:.3e},{:.1e},{:.3e},{:.3e},{:.3e}",
                        c.material,
                        c.diameter_nm,
                        c.pvc,
                        c.thickness_nm,
                        cl,
                        cz,
                        wl,
                        polar,
                        raster.mean_fractions()[0],
                        dr,
                        dt,
                        da,
                        err,
                        diffuse,
                        e.energy_balance,
                        coh,
                        inc,
                        est
                    );
                }
            }
            summary.push((
                format!(
                    "| {} | {} | {} | {} | {}/{} ",
                    c.material, c.diameter_nm, c.pvc, c.thickness_nm, cl, cz
                ),
                worst,
            ));
        }
    }
    eprintln!(
        "| grains | d nm | PVC | H nm | cells nm | max k0·d | max err R/T/A | max diffuse | \
         max err / coherent | max diffuse / incoherent | min estimate / err |"
    );
    eprintln!("|---|---|---|---|---|---|---|---|---|---|---|");
    for (head, w) in &summary {
        eprintln!(
            "{head}| {:.3} | {:.2e} | {:.2e} | {:.3} | {:.3} | {:.2} |",
            w[0], w[1], w[2], w[3], w[4], w[5]
        );
    }
    let all = |i: usize| summary.iter().map(|(_, w)| w[i]).fold(0.0, f64::max);
    eprintln!(
        "all: max err / coherent {:.3}, max diffuse / incoherent {:.3}",
        all(3),
        all(4)
    );
}
