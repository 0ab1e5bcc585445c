//! The paper substrate: quadrature, and energy conservation of layer + paper
//! for a lossless scattering layer, from independent solves from above and
//! from below (the layer flipped).
use inksim::config::Method;
use inksim::optics::farfield::efficiencies;
use inksim::optics::substrate::{Hemisphere, Paper};
use inksim::solver::{self, Controls, Problem};
use ndarray::{s, Array3};

mod common;
use common::layers::{in_binder, layer_eps, packed_rsa};
use num_complex::Complex64 as C64;

#[test]
fn gauss_legendre_in_cos_theta_is_exact_for_polynomials() {
    for n in [1, 3, 6, 10] {
        let h = Hemisphere::new(n);
        assert!((h.weight.iter().sum::<f64>() - 1.0).abs() < 1e-14);
        for k in 0..2 * n {
            let q: f64 =
                h.mu.iter()
                    .zip(&h.weight)
                    .map(|(m, w)| w * m.powi(k as i32))
                    .sum();
            assert!((q - 1.0 / (k + 1) as f64).abs() < 1e-13, "n {n} k {k}: {q}");
        }
        assert!(h.mu.windows(2).all(|w| w[0] < w[1]) && h.mu[0] > 0.0 && h.mu[n - 1] < 1.0);
        assert!((h.diffuse(&vec![1.0; n]) - 1.0).abs() < 1e-14);
    }
}

#[test]
fn lossless_layer_on_white_paper_returns_all_light() {
    // Non-absorbing grains (n = 1.4) in the binder: R + T = 1 for every
    // incidence; from below, the diffuse albedo R_dd↑ plus the diffuse
    // transmittance T_d (reciprocity: from the solves from above) must be 1;
    // on a perfect white paper everything comes back out. Exact only for a
    // statistically isotropic layer: one fragment sampled at one azimuth
    // leaves 1.1e-3 (measured; unchanged from 6 to 12 quadrature nodes, so
    // not quadrature error), hence the 5e-3 bounds.
    let size = [600.0, 600.0, 400.0];
    let geom = packed_rsa(size, 150.0, 0.2, 4);
    let (eps, _) = layer_eps(&geom, [24, 24, 40], C64::new(1.4, 0.0));
    let flipped = eps.slice(s![..;-1, .., ..]).to_owned();
    let hemi = Hemisphere::new(6);
    let ctl = Controls {
        tolerance: 1e-9,
        max_iterations: 20000,
        precision: inksim::config::Precision::F64,
        background: inksim::config::Background::DEFAULT,
    };
    let solve = |e: &Array3<C64>, polar: f64| {
        let lat = Problem::lattice([24, 24, 40], size, 520.0, polar, 0.0);
        let sol = solver::solve(&in_binder(lat, e), Method::Auto, &ctl).unwrap();
        efficiencies(&sol)
    };
    let (mut r_top, mut t_top, mut r_bottom) = (vec![], vec![], vec![]);
    for polar in hemi.polar_deg() {
        let top = solve(&eps, polar);
        assert!(top.absorption.abs() < 1e-9 && top.energy_balance.abs() < 1e-8);
        r_top.push(top.total_reflectance);
        t_top.push(top.total_transmittance);
        r_bottom.push(solve(&flipped, polar).total_reflectance);
    }
    let r_dd_up = hemi.diffuse(&r_bottom);
    let t_d = hemi.diffuse(&t_top);
    eprintln!(
        "R_dd↑ {r_dd_up:.6}, T_d {t_d:.6}, sum {:.2e} off 1",
        r_dd_up + t_d - 1.0
    );
    assert!(
        (r_dd_up + t_d - 1.0).abs() < 5e-3,
        "R_dd↑ + T_d = {}",
        r_dd_up + t_d
    );
    let paper = Paper {
        albedo: 1.0,
        r_dd_up,
    };
    for (k, polar) in hemi.polar_deg().iter().enumerate() {
        let total = r_top[k] + paper.hemispherical(t_top[k], t_d);
        assert!((total - 1.0).abs() < 5e-3, "{polar}°: {total}");
        // And the paper term is the cosine-weighted integral of its BRDF.
        let brdf: Vec<f64> = t_top
            .iter()
            .map(|&t_out| paper.brdf(t_top[k], t_out))
            .collect();
        let integral = std::f64::consts::PI * hemi.diffuse(&brdf);
        assert!((integral - paper.hemispherical(t_top[k], t_d)).abs() < 1e-12);
    }
}
