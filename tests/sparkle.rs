//! Sparkle (METHOD §10): flakes thrown at random places with normals drawn
//! from D give glint counts per resolution cell that are Poisson with the
//! mean the model predicts from its cone integral; none under diffuse
//! light.

use inksim::optics::flakes::normals::Orientation;
use inksim::optics::flakes::sparkle::{self, cone_probability, half_vector_tilt};
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

#[test]
fn glints_per_cell_are_poisson_with_the_predicted_mean() {
    let sigma = 10f64.to_radians();
    let orientation = Orientation { sigma_rad: sigma };
    let (lacquer, gamma) = (1.5, 2f64.to_radians());
    let (cells, flakes_per_cell) = (4000usize, 150usize);
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
    // Tilt density ∝ exp(−θ²/2σ²) sin θ on [0, 6σ], by rejection.
    let f = |t: f64| (-(t * t) / (2.0 * sigma * sigma)).exp() * t.sin();
    let f_max = (0..10_000)
        .map(|i| f(6.0 * sigma * i as f64 / 10_000.0))
        .fold(0.0, f64::max)
        * 1.01;
    for deg in [15.0, 45.0, 75.0] {
        let tilt = half_vector_tilt(deg, lacquer);
        let h = [tilt.sin(), 0.0, tilt.cos()];
        let mut counts = vec![0usize; cells];
        for _ in 0..cells * flakes_per_cell {
            let cell = rng.gen_range(0..cells);
            let t = loop {
                let t = rng.gen_range(0.0..6.0 * sigma);
                if rng.gen_range(0.0..f_max) < f(t) {
                    break t;
                }
            };
            let phi = rng.gen_range(0.0..std::f64::consts::TAU);
            let m = [t.sin() * phi.cos(), t.sin() * phi.sin(), t.cos()];
            let c = m[0] * h[0] + m[1] * h[1] + m[2] * h[2];
            if c >= gamma.cos() {
                counts[cell] += 1;
            }
        }
        let p = cone_probability(&orientation, tilt, gamma);
        let predicted = flakes_per_cell as f64 * p;
        let s = sparkle::sparkle(
            flakes_per_cell as f64,
            &orientation,
            lacquer,
            1.0,
            gamma,
            Some(deg),
        );
        assert!((s.glints_per_cell - predicted).abs() < 1e-12);
        let n = cells as f64;
        let mean = counts.iter().sum::<usize>() as f64 / n;
        let var = counts
            .iter()
            .map(|&k| (k as f64 - mean).powi(2))
            .sum::<f64>()
            / (n - 1.0);
        // Poisson: the mean within 4 standard errors, variance = mean.
        let se = (predicted / n).sqrt();
        assert!(
            (mean - predicted).abs() < 4.0 * se,
            "{deg}°: {mean} vs {predicted} ± {se}"
        );
        assert!(
            (var / mean - 1.0).abs() < 0.1,
            "{deg}°: dispersion {}",
            var / mean
        );
        // χ² of the count histogram against Poisson(predicted), bins with ≥ 5 expected.
        let pmf = |k: usize| {
            (-predicted + k as f64 * predicted.ln() - (1..=k).map(|i| (i as f64).ln()).sum::<f64>())
                .exp()
        };
        let (mut chi2, mut dof) = (0.0, 0usize);
        let mut tail_expected = n;
        let mut tail_observed = n;
        for k in 0..60 {
            let e = n * pmf(k);
            if e < 5.0 {
                continue;
            }
            let o = counts.iter().filter(|&&c| c == k).count() as f64;
            chi2 += (o - e).powi(2) / e;
            dof += 1;
            tail_expected -= e;
            tail_observed -= o;
        }
        if tail_expected >= 5.0 {
            chi2 += (tail_observed - tail_expected).powi(2) / tail_expected;
            dof += 1;
        }
        eprintln!(
            "{deg}°: predicted {predicted:.3} glints per cell, counted {mean:.3} (dispersion {:.3}), χ² {chi2:.1} on {dof} bins",
            var / mean
        );
        // 99.9 % point of χ² is below 3 × dof + 10 for these few bins.
        assert!(chi2 < 3.0 * dof as f64 + 10.0, "{deg}°: χ² {chi2} on {dof}");
    }
    // Diffuse light: no glints, graininess 1/√N.
    let s = sparkle::sparkle(100.0, &orientation, lacquer, 1.0, gamma, None);
    assert_eq!(s.glints_per_cell, 0.0);
    assert!((s.graininess - 0.1).abs() < 1e-15);
    // A finish seen from 500 mm: cells of (0.145 mm)².
    let cell = sparkle::cell_area_mm2(500.0, sparkle::ARCMINUTE_RAD);
    assert!((cell.sqrt() - 0.14544).abs() < 1e-5, "{cell}");
}
