//! Reciprocity of the order efficiencies (METHOD §7): the efficiency of
//! reflected order m for incidence with lateral wave vector q equals that of
//! the same order for incidence along the reversed diffracted direction,
//! q' = −(q + G_m). It holds for absorbing layers. Discretely it holds up to
//! the Fourier truncation: the reciprocal problem keeps the harmonic window
//! shifted by m (and aliases the product V u accordingly), which costs about
//! 1e-6 relative here (measured; independent of the solver tolerance), so
//! the bound is 1e-4 — a real asymmetry (a wrong sign, a missing term) shows
//! up at 1e-3 or worse.
use inksim::config::Method;
use inksim::optics::farfield::efficiencies;
use inksim::solver::{self, Controls, Problem};
use num_complex::Complex64 as C64;

mod common;
use common::layers::{in_binder, layer_eps, packed_rsa};

#[test]
fn reflected_orders_are_reciprocal() {
    let size = [900.0, 700.0, 500.0];
    let geom = packed_rsa(size, 150.0, 0.2, 8);
    let (eps, _) = layer_eps(&geom, [45, 27, 50], C64::new(1.4, 0.4));
    let ctl = Controls {
        tolerance: 1e-10,
        max_iterations: 20000,
        precision: inksim::config::Precision::F64,
        background: inksim::config::Background::DEFAULT,
    };
    let lambda = 520.0;
    let lat = Problem::lattice([45, 27, 50], size, lambda, 25.0, 30.0);
    let sol = solver::solve(&in_binder(lat, &eps), Method::Auto, &ctl).unwrap();
    let ff = efficiencies(&sol);
    let mut checked = 0;
    for o in ff
        .orders
        .iter()
        .filter(|o| (o.m, o.n) != (0, 0) && o.theta_deg < 70.0)
        .take(4)
    {
        // Incidence along the reversed direction of order (m, n).
        let ix = o.m.rem_euclid(45) as usize;
        let iy = o.n.rem_euclid(27) as usize;
        let [kx, ky] = lat.kappa(ix, iy);
        let polar = (kx.hypot(ky) / lat.k0).asin().to_degrees();
        let azimuth = (-ky).atan2(-kx).to_degrees();
        let lat2 = Problem::lattice([45, 27, 50], size, lambda, polar, azimuth);
        let sol2 = solver::solve(&in_binder(lat2, &eps), Method::Auto, &ctl).unwrap();
        let ff2 = efficiencies(&sol2);
        let back = ff2
            .orders
            .iter()
            .find(|p| (p.m, p.n) == (o.m, o.n))
            .expect("order propagates");
        let rel = (back.reflectance - o.reflectance).abs() / o.reflectance;
        eprintln!(
            "order ({}, {}): R {:.6e} vs reciprocal {:.6e} (rel {rel:.1e})",
            o.m, o.n, o.reflectance, back.reflectance
        );
        assert!(
            rel < 1e-4,
            "order ({}, {}): {} vs {}",
            o.m,
            o.n,
            o.reflectance,
            back.reflectance
        );
        checked += 1;
    }
    assert!(checked >= 3);
}
