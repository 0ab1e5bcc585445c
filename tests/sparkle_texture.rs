//! The sparkle texture (METHOD §10): the glints a tile draws are Poisson
//! per resolution cell with the model's mean, so their count over a tile
//! lies within Poisson error of the mean times the cells, spread evenly;
//! their added light follows the flakes' area distribution; none under
//! diffuse light; the same seed draws the same texture.

use inksim::optics::flakes::sparkle_texture::{glint_factor, texture, GlintPopulation};

const BASE: [f64; 3] = [20.0, 21.0, 22.0];

fn population(per_cell: f64) -> GlintPopulation {
    GlintPopulation {
        per_cell,
        diameter_um: 18.0,
        diameter_sd_um: 6.0,
        xyz_per_um2: [0.01, 0.01, 0.012],
    }
}

#[test]
fn the_glints_of_a_tile_are_poisson_with_the_model_mean() {
    let (w, h) = (150, 150);
    for (per_cell, seed) in [(0.5, 1), (0.2, 2), (0.076, 3), (0.003, 4)] {
        let t = texture(w, h, BASE, &[population(per_cell)], seed);
        let mean = per_cell * (w * h) as f64;
        let z = (t.glints as f64 - mean) / mean.sqrt();
        eprintln!(
            "{per_cell} per cell: {} glints, mean {mean:.0}, z {z:.2}",
            t.glints
        );
        assert!(z.abs() < 4.0, "{} glints for a mean of {mean}", t.glints);
        // The cells that gained light are the glints' cells: no more than
        // the glints, and as many as Poisson cells with at least one.
        let lit = t.xyz.iter().filter(|c| c[1] > BASE[1]).count();
        assert!(lit <= t.glints);
        let expected = (1.0 - (-per_cell).exp()) * (w * h) as f64;
        assert!(
            (lit as f64 - expected).abs() < 4.0 * expected.sqrt() + 1.0,
            "{lit} lit cells, expected {expected:.0}"
        );
    }
}

#[test]
fn glints_spread_evenly_over_the_tile() {
    let (w, h) = (160, 160);
    let t = texture(w, h, BASE, &[population(0.3)], 11);
    let mut quarters = [0usize; 4];
    for (k, c) in t.xyz.iter().enumerate() {
        if c[1] > BASE[1] {
            let (x, y) = (k % w, k / w);
            quarters[(x >= w / 2) as usize + 2 * (y >= h / 2) as usize] += 1;
        }
    }
    let mean = quarters.iter().sum::<usize>() as f64 / 4.0;
    let chi2: f64 = quarters
        .iter()
        .map(|&q| (q as f64 - mean).powi(2) / mean)
        .sum();
    eprintln!("lit cells per quarter {quarters:?}, χ² {chi2:.2} (3 degrees of freedom)");
    // χ²₃ exceeds 16.3 with chance 0.001.
    assert!(chi2 < 16.3, "{quarters:?}");
}

#[test]
fn the_light_added_follows_the_flakes_area() {
    // Mean light per glint: k π/4 E[d²] = k π/4 (mean² + sd²) for a normal
    // diameter (its cut at zero is 1.4·10⁻³ of the draws at 3 sd, negligible).
    let p = population(0.4);
    let t = texture(200, 200, BASE, &[p], 5);
    let added: f64 = t.xyz.iter().map(|c| c[1] - BASE[1]).sum();
    let per_glint = added / t.glints as f64;
    let exact = p.xyz_per_um2[1] * std::f64::consts::PI / 4.0
        * (p.diameter_um.powi(2) + p.diameter_sd_um.powi(2));
    // The area's spread over the glints: sd of d² ≈ 2 mean sd.
    let se = p.xyz_per_um2[1] * std::f64::consts::PI / 4.0 * 2.0 * p.diameter_um * p.diameter_sd_um
        / (t.glints as f64).sqrt();
    eprintln!("light per glint {per_glint:.4}, expected {exact:.4} ± {se:.4}");
    assert!(
        (per_glint - exact).abs() < 4.0 * se,
        "{per_glint} vs {exact}"
    );
}

#[test]
fn no_glints_under_diffuse_light() {
    let t = texture(100, 80, BASE, &[], 9);
    assert_eq!(t.glints, 0);
    assert!(t.xyz.iter().all(|c| *c == BASE));
    let none = texture(100, 80, BASE, &[population(0.0)], 9);
    assert_eq!(none.glints, 0);
}

#[test]
fn the_same_seed_draws_the_same_texture() {
    let a = texture(120, 90, BASE, &[population(0.2), population(0.05)], 42);
    let b = texture(120, 90, BASE, &[population(0.2), population(0.05)], 42);
    let c = texture(120, 90, BASE, &[population(0.2), population(0.05)], 43);
    assert_eq!(a, b);
    assert_ne!(a.xyz, c.xyz);
}

#[test]
fn a_glint_spreads_its_flux_over_the_cone_and_the_cell() {
    // Along the normal (θ = 0, no refraction) through a lossless surface: a
    // flake of 1 mm² in a 1 mm² cell reflecting into a cone of 2γ in the
    // lacquer, n² π (2γ)² sr in air, has π L/E = π / (n² π 4γ²) = 1/(4 n² γ²).
    let (n, gamma) = (1.5, 0.01);
    let f = glint_factor(1e6, 1.0, gamma, n, 0.0, 1.0);
    let exact = 1.0 / (4.0 * n * n * gamma * gamma);
    assert!((f / exact - 1.0).abs() < 1e-12, "{f} vs {exact}");
    // Twice the flake, twice the light; twice the cell, half.
    assert!((glint_factor(2e6, 1.0, gamma, n, 0.0, 1.0) / f - 2.0).abs() < 1e-12);
    assert!((glint_factor(1e6, 2.0, gamma, n, 0.0, 1.0) / f - 0.5).abs() < 1e-12);
}
