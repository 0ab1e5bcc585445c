//! Where the fast effect-paint model's time goes for a `[paint]` config:
//! per layer, the size of each azimuthal Fourier term of its kernel (over
//! all node pairs and over the pairs with an escaping node), the doublings
//! its slab needs, and the time of the whole BRDF per wavelength.
//!
//! Then the whole BRDF at every wavelength of the config at a few
//! resolutions (mode tolerance, thin-layer start), its time (all threads)
//! and the multi-angle colours' largest ΔE00 against a converged setting
//! (every term kept, start 1e-7).
//!
//! `cargo run --release --example paint_cost [config.toml] [tol:start ...]`
//! (default configs/metallic.toml; settings e.g. `1e-3:1e-4 1e-3:1e-2`).

use inksim::config::paint::PaintScene;
use inksim::optics::baseline::ordinates::Ordinates;
use inksim::optics::colour::{delta_e2000, Observer};
use inksim::optics::flakes::kernel::layer_kernels;
use inksim::optics::flakes::multiangle::{self, geometries};
use inksim::optics::flakes::paint::{self as model, ModelParams};
use inksim::pipeline::paint::{
    ground_at, lacquer_index, layers_at, model_params, paint_air_directions, reflect_at,
};
use rayon::prelude::*;
use std::path::Path;
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let path = args
        .first()
        .cloned()
        .unwrap_or_else(|| "configs/metallic.toml".into());
    let text = std::fs::read_to_string(&path).expect("config");
    let scene = inksim::config::parse_paint(Path::new(&path), &text).expect("paint config");
    let params = model_params(&scene);
    let air = paint_air_directions(&scene);
    let wl = 550.0;
    let n = lacquer_index(&scene, wl).unwrap();
    let layers = layers_at(&scene, wl).unwrap();
    let ords = Ordinates::new(n, params.ordinates, &air).unwrap();
    let escape: Vec<bool> = ords.mu_air.iter().map(|m| m.is_some()).collect();
    println!("{} nodes, smallest μ {:.4}", ords.len(), ords.mu[0]);
    for (l, layer) in layers.iter().enumerate() {
        let t = Instant::now();
        let k = layer_kernels(
            &ords,
            &layer.pigments,
            layer.flakes.as_ref(),
            params.max_terms,
            params.normals,
        );
        let secs = t.elapsed().as_secs_f64();
        let rate_max = k[0].rate.iter().copied().fold(0.0, f64::max);
        let doublings = (layer.thickness_nm * rate_max / params.start).log2().ceil();
        println!(
            "layer {l}: kernels {:.1} ms, largest e·d {:.3}, {doublings} doublings",
            secs * 1e3,
            layer.thickness_nm * rate_max
        );
        let size = |m: usize, only_escape: bool| {
            let mut s = 0.0f64;
            for i in 0..ords.len() {
                for j in 0..ords.len() {
                    if only_escape && !(escape[i] || escape[j]) {
                        continue;
                    }
                    s = s
                        .max(k[m].same[(i, j)].abs())
                        .max(k[m].opposite[(i, j)].abs());
                }
            }
            s
        };
        let (all0, esc0) = (size(0, false), size(0, true));
        if all0 == 0.0 {
            continue;
        }
        let line: Vec<String> = (0..k.len())
            .step_by(4)
            .map(|m| {
                format!(
                    "{m}:{:.0e}/{:.0e}",
                    size(m, false) / all0,
                    size(m, true) / esc0
                )
            })
            .collect();
        println!("  term size (all / escaping): {}", line.join(" "));
    }
    let ground = ground_at(&scene, wl).unwrap();
    for _ in 0..2 {
        let t = Instant::now();
        let r = model::reflect(n, &layers, ground, wl, &air, &params).unwrap();
        println!(
            "reflect at {wl} nm: {:.1} ms, {} terms",
            t.elapsed().as_secs_f64() * 1e3,
            r.terms.len()
        );
    }
    let reference = ModelParams {
        mode_tolerance: 0.0,
        start: 1e-7,
        ..params
    };
    let (_, lab_ref) = colours(&scene, &reference);
    let settings: Vec<(f64, f64)> = if args.len() > 1 {
        args[1..]
            .iter()
            .map(|a| {
                let (t, s) = a.split_once(':').expect("tol:start");
                (t.parse().unwrap(), s.parse().unwrap())
            })
            .collect()
    } else {
        vec![(params.mode_tolerance, params.start)]
    };
    for (tol, start) in settings {
        let p = ModelParams {
            mode_tolerance: tol,
            start,
            ..params
        };
        let (secs, lab) = colours(&scene, &p);
        let worst = lab
            .iter()
            .zip(&lab_ref)
            .map(|(a, b)| delta_e2000(*a, *b))
            .fold(0.0, f64::max);
        println!(
            "tolerance {tol:.0e}, start {start:.0e}: {secs:.3} s, largest ΔE00 {worst:.2e} over {} geometries",
            lab.len()
        );
    }
}

/// The whole BRDF at every wavelength (timed) and the multi-angle L*a*b*.
fn colours(scene: &PaintScene, params: &ModelParams) -> (f64, Vec<[f64; 3]>) {
    let air = paint_air_directions(scene);
    let wl = &scene.wavelengths_nm;
    let t = Instant::now();
    let reflections: Vec<_> = wl
        .par_iter()
        .map(|&w| reflect_at(scene, params, &air, w).unwrap())
        .collect();
    let secs = t.elapsed().as_secs_f64();
    let rows: Vec<Vec<f64>> = geometries()
        .iter()
        .map(|g| {
            let (view, az) = g.view();
            reflections
                .iter()
                .map(|r| r.factor(g.illumination_deg, view, az).unwrap())
                .collect()
        })
        .collect();
    let obs = Observer::standard(scene.illuminant, scene.observer);
    let c = multiangle::colours(&obs, wl, &rows).unwrap();
    (secs, c.iter().map(|c| c.lab).collect())
}
