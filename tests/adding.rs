//! The adding–doubling baseline against closed forms: absorbing slabs and
//! Fresnel surfaces, the neutral layer, energy, doubling against adding,
//! single scattering, isotropic semi-infinite scattering (Chandrasekhar's
//! H function), the phase function's moments, and Kubelka–Munk on the wave
//! scene's boundary in its transparent limit.

use inksim::config::Measurement;
use inksim::optics::baseline::adding::{self, fresnel_scalar, Slab};
use inksim::optics::baseline::doubling::{self, Medium};
use inksim::optics::baseline::fresnel::Fresnel;
use inksim::optics::baseline::km;
use inksim::optics::baseline::matrix::Matrix;
use inksim::optics::baseline::ordinates::{gauss_legendre, OrdinateParams, Ordinates};
use inksim::optics::baseline::sphere;
use inksim::optics::baseline::transfer::{self, Boundary, AIR_DIRECTIONS_DEG};
use num_complex::Complex64 as C64;
use std::f64::consts::PI;

const NB: f64 = 1.558;

fn ords() -> Ordinates {
    Ordinates::new(NB, OrdinateParams::default(), &AIR_DIRECTIONS_DEG).unwrap()
}

fn absorber(mu_a: f64) -> Medium {
    Medium {
        mu_a,
        mu_s: 0.0,
        moments: Vec::new(),
    }
}

/// A real sphere's normalised phase moments (200 nm, n = 1.9 + 0.02i in the
/// binder at 500 nm: g ≈ 0.6).
fn sphere_moments() -> Vec<f64> {
    let k = 2.0 * PI * NB / 500.0;
    let m = sphere::phase_moments(k, C64::new(1.9, 0.02).powi(2) / (NB * NB), 100.0);
    m.iter().map(|v| v / m[0]).collect()
}

fn diag_of(m: &Matrix) -> Vec<f64> {
    (0..m.size()).map(|i| m[(i, i)]).collect()
}

fn off_diagonal_max(m: &Matrix) -> f64 {
    let mut worst = 0.0f64;
    for i in 0..m.size() {
        for j in 0..m.size() {
            if i != j {
                worst = worst.max(m[(i, j)].abs());
            }
        }
    }
    worst
}

#[test]
fn two_absorbing_slabs_are_the_incoherent_closed_form() {
    // air | surface | slab 1 | slab 2 | surface | air, each slab Beer's law
    // per direction, the surfaces scalar Fresnel, the inter-reflections a
    // geometric series: R = r + (1 − r)² r t² / (1 − r² t²),
    // T = (1 − r)² t / (1 − r² t²), t = e^{−(a₁X₁ + a₂X₂)/μ}.
    let o = ords();
    let (a1, x1, a2, x2) = (1.5e-3, 500.0, 4e-4, 1200.0);
    let s1 = doubling::homogeneous(&o, &absorber(a1), x1).unwrap();
    let s2 = doubling::homogeneous(&o, &absorber(a2), x2).unwrap();
    let inner = adding::add(&s1, &s2).unwrap();
    let lower = adding::add(
        &inner,
        &adding::surface_binder_over_air(&o, Fresnel::Scalar),
    )
    .unwrap();
    let stack = adding::add(
        &adding::surface_air_over_binder(&o, Fresnel::Scalar),
        &lower,
    )
    .unwrap();
    let (r, t) = (diag_of(&stack.r_down), diag_of(&stack.t_down));
    let mut worst = 0.0f64;
    for i in 0..o.len() {
        let Some(mu_air) = o.mu_air[i] else {
            // Trapped bins: no light from outside.
            assert_eq!((r[i], t[i]), (0.0, 0.0));
            continue;
        };
        let f = fresnel_scalar(NB, o.mu[i], mu_air);
        let tt = (-(a1 * x1 + a2 * x2) / o.mu[i]).exp();
        let d = 1.0 - f * f * tt * tt;
        let r_exact = f + (1.0 - f).powi(2) * f * tt * tt / d;
        let t_exact = (1.0 - f).powi(2) * tt / d;
        // Energy with absorption: the absorbed fraction summed pass by pass,
        // (1 − f)(1 − t)(1 + f t)/(1 − f² t²), closes R + T + A = 1.
        let a_exact = (1.0 - f) * (1.0 - tt) * (1.0 + f * tt) / d;
        assert!((r_exact + t_exact + a_exact - 1.0).abs() < 1e-14);
        worst = worst
            .max((r[i] - r_exact).abs())
            .max((t[i] - t_exact).abs())
            .max((r[i] + t[i] + a_exact - 1.0).abs());
    }
    eprintln!("two slabs: worst |AD − closed form| = {worst:.2e}");
    assert!(worst < 1e-10, "{worst}");
    assert!(off_diagonal_max(&stack.r_down) < 1e-15 && off_diagonal_max(&stack.t_down) < 1e-15);
    // From below the stack is the same (it is symmetric).
    assert!(stack.r_up.max_difference(&stack.r_down) < 1e-14);
}

fn scattering_stack(o: &Ordinates, mu_a: f64) -> Slab {
    let m = Medium {
        mu_a,
        mu_s: 4e-3,
        moments: sphere_moments(),
    };
    transfer::free_layer(o, &m, 1000.0, Fresnel::Scalar).unwrap()
}

#[test]
fn an_empty_layer_changes_nothing() {
    let o = ords();
    let stack = scattering_stack(&o, 1e-4);
    for thickness in [0.0, 1000.0] {
        let empty = doubling::homogeneous(&o, &absorber(0.0), thickness).unwrap();
        for combined in [
            adding::add(&stack, &empty).unwrap(),
            adding::add(&empty, &stack).unwrap(),
        ] {
            for (a, b) in [
                (&combined.r_down, &stack.r_down),
                (&combined.r_up, &stack.r_up),
                (&combined.t_down, &stack.t_down),
                (&combined.t_up, &stack.t_up),
            ] {
                let d = a.max_difference(b);
                assert!(d < 1e-12, "{thickness} nm: {d}");
            }
        }
    }
}

#[test]
fn energy_is_conserved() {
    let o = ords();
    // No absorption: R + T = 1 for every direction from air.
    let s = scattering_stack(&o, 0.0);
    let (r, t) = (s.r_down.column_sums(), s.t_down.column_sums());
    let mut worst = 0.0f64;
    for j in (0..o.len()).filter(|&j| o.mu_air[j].is_some()) {
        worst = worst.max((r[j] + t[j] - 1.0).abs());
    }
    eprintln!("conservative stack: worst |R + T − 1| = {worst:.2e}");
    assert!(worst < 1e-10, "{worst}");
    // The scattering layer alone, every bin (trapped ones too), both faces.
    let m = Medium {
        mu_a: 0.0,
        mu_s: 4e-3,
        moments: sphere_moments(),
    };
    let layer = doubling::homogeneous(&o, &m, 1000.0).unwrap();
    for (r, t) in [(&layer.r_down, &layer.t_down), (&layer.r_up, &layer.t_up)] {
        for (a, b) in r.column_sums().iter().zip(t.column_sums()) {
            assert!((a + b - 1.0).abs() < 1e-10, "{a} + {b}");
        }
    }
    // With absorption: what is not reflected or transmitted is absorbed,
    // 0 < A < 1 − e^{−μa X/μ}·(surface losses) bounds aside: A grows with μa.
    let (weak, strong) = (scattering_stack(&o, 1e-4), scattering_stack(&o, 1e-3));
    let a = |s: &Slab| -> Vec<f64> {
        let (r, t) = (s.r_down.column_sums(), s.t_down.column_sums());
        r.iter().zip(&t).map(|(r, t)| 1.0 - r - t).collect()
    };
    let (aw, as_) = (a(&weak), a(&strong));
    for j in (0..o.len()).filter(|&j| o.mu_air[j].is_some()) {
        assert!(
            aw[j] > 0.0 && as_[j] > aw[j] && as_[j] < 1.0,
            "{j}: {} {}",
            aw[j],
            as_[j]
        );
    }
}

#[test]
fn doubling_equals_adding_thin_layers_one_by_one() {
    let o = ords();
    let chi = sphere_moments();
    let thin = doubling::thin(&o, 0.8, &chi, 1e-3).unwrap();
    let mut doubled = thin.clone();
    for _ in 0..6 {
        doubled = doubling::double(&doubled).unwrap();
    }
    let (doubled, thin) = (doubled.to_slab(), thin.to_slab());
    let mut added = thin.clone();
    for _ in 1..64 {
        added = adding::add(&added, &thin).unwrap();
    }
    let d = doubled
        .r_down
        .max_difference(&added.r_down)
        .max(doubled.t_down.max_difference(&added.t_down));
    eprintln!("64 thin layers: |doubled − added| = {d:.2e}");
    assert!(d < 1e-12, "{d}");
}

#[test]
fn an_optically_thin_layer_scatters_once() {
    // Single scattering of a layer of optical thickness τ, flux basis:
    // R_ij = (ω/2) w_i p(−μ_i, μ_j) μ_i/(μ_i + μ_j) (1 − e^{−τ(1/μ_i + 1/μ_j)}),
    // T_ij = (ω/2) w_i p(μ_i, μ_j) (e^{−τ/μ_i} − e^{−τ/μ_j})/(1/μ_j − 1/μ_i)/μ_j
    // (+ e^{−τ/μ_j} on the diagonal); the rest is of relative order τ/μ.
    let o = ords();
    let chi = sphere_moments();
    let (albedo, tau) = (0.7, 1e-6);
    let slab = doubling::thin(&o, albedo, &chi, tau).unwrap().to_slab();
    let (same, opposite) = doubling::phase_matrices(&o, &chi);
    let n = o.len();
    let (mut worst, mut scale) = (0.0f64, 0.0f64);
    for i in 0..n {
        for j in 0..n {
            let (mi, mj, wi) = (o.mu[i], o.mu[j], o.weight[i]);
            let r = 0.5 * albedo * wi * opposite[(i, j)] * mi / (mi + mj)
                * (1.0 - (-tau * (1.0 / mi + 1.0 / mj)).exp());
            let path = if i == j {
                tau / mj * (-tau / mj).exp()
            } else {
                ((-tau / mi).exp() - (-tau / mj).exp()) / (1.0 / mj - 1.0 / mi) / mj
            };
            let t = 0.5 * albedo * wi * same[(i, j)] * path
                + if i == j { (-tau / mj).exp() } else { 0.0 };
            worst = worst
                .max((slab.r_down[(i, j)] - r).abs())
                .max((slab.t_down[(i, j)] - t).abs() * (i != j) as u8 as f64);
            scale = scale.max(r.abs());
            if i == j {
                // The diagonal's scattered part against its size.
                let ts = slab.t_down[(i, i)] - (-tau / mj).exp();
                let expect = t - (-tau / mj).exp();
                assert!(
                    (ts - expect).abs() < 2e-3 * expect.abs() + 1e-15,
                    "{i}: {ts} vs {expect}"
                );
            }
        }
    }
    let mu_min = o.mu[0];
    eprintln!(
        "thin layer: worst {worst:.2e} of {scale:.2e}, τ/μ_min {:.1e}",
        tau / mu_min
    );
    assert!(worst < 2e-3 * scale, "{worst} vs {scale}");
}

/// Chandrasekhar's H function for isotropic scattering of albedo ω, by
/// iterating `1/H(μ) = √(1 − ω) + (ω/2) ∫₀¹ μ' H(μ')/(μ + μ') dμ'` on a
/// fine Gauss grid (independent of the adding–doubling quadrature).
fn h_function(albedo: f64, mu: f64) -> f64 {
    let (x, w) = gauss_legendre(200);
    let nodes: Vec<f64> = x.iter().map(|x| 0.5 * (x + 1.0)).collect();
    let weights: Vec<f64> = w.iter().map(|w| 0.5 * w).collect();
    let mut h = vec![1.0; nodes.len()];
    let eval = |h: &[f64], m: f64| {
        let s: f64 = nodes
            .iter()
            .zip(&weights)
            .zip(h)
            .map(|((mp, wp), hp)| wp * mp * hp / (m + mp))
            .sum();
        1.0 / ((1.0 - albedo).sqrt() + 0.5 * albedo * s)
    };
    for _ in 0..2000 {
        let next: Vec<f64> = nodes.iter().map(|&m| eval(&h, m)).collect();
        let d = next
            .iter()
            .zip(&h)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        h = next;
        if d < 1e-15 {
            break;
        }
    }
    eval(&h, mu)
}

#[test]
fn isotropic_scattering_semi_infinite_and_conservative() {
    // No surfaces (index 1: every bin escapes, none is trapped).
    let o = Ordinates::new(1.0, OrdinateParams::default(), &AIR_DIRECTIONS_DEG).unwrap();
    let iso = |albedo: f64| Medium {
        mu_a: 1.0 - albedo,
        mu_s: albedo,
        moments: vec![1.0],
    };
    // Conservative, black backing: R + T = 1; thick: R → 1.
    for tau in [1.0, 1e4] {
        let s = doubling::homogeneous(&o, &iso(1.0), tau).unwrap();
        let (r, t) = (s.r_down.column_sums(), s.t_down.column_sums());
        for j in 0..o.len() {
            assert!(
                (r[j] + t[j] - 1.0).abs() < 1e-10,
                "τ {tau}: {} {}",
                r[j],
                t[j]
            );
            if tau > 1.0 {
                assert!(r[j] > 1.0 - 1e-3, "τ {tau}: R {}", r[j]);
            }
        }
    }
    // ω = 0.9, semi-infinite (τ = 200): the plane albedo is
    // 1 − H(μ₀) √(1 − ω) (Chandrasekhar, Radiative Transfer §§ 26, 47).
    let s = doubling::homogeneous(&o, &iso(0.9), 200.0).unwrap();
    let r = s.r_down.column_sums();
    let mut worst = 0.0f64;
    for (rj, mu) in r.iter().zip(&o.mu) {
        let exact = 1.0 - h_function(0.9, *mu) * 0.1f64.sqrt();
        worst = worst.max((rj - exact).abs());
    }
    eprintln!("isotropic ω = 0.9: worst |plane albedo − H-function value| = {worst:.2e}");
    assert!(worst < 1.5e-4, "{worst}");
    // The H function itself: its zeroth moment is exact,
    // ∫₀¹ H dμ = (2/ω)(1 − √(1 − ω)).
    let (x, w) = gauss_legendre(64);
    let h0: f64 = x
        .iter()
        .zip(&w)
        .map(|(x, w)| 0.5 * w * h_function(0.9, 0.5 * (x + 1.0)))
        .sum();
    let exact = 2.0 / 0.9 * (1.0 - 0.1f64.sqrt());
    // (H has a logarithmic derivative at μ → 0: the quadratures converge slowly.)
    assert!((h0 - exact).abs() < 1e-7, "{h0} vs {exact}");
}

#[test]
fn phase_moments_are_the_cross_section_and_the_asymmetry() {
    let k = 2.0 * PI * NB / 550.0;
    for (a, n) in [
        (30.0, C64::new(1.6, 0.01)),
        (100.0, C64::new(1.4, 0.6)),
        (225.0, C64::new(2.4, 0.05)),
    ] {
        let eps = n * n / (NB * NB);
        let c = sphere::cross_sections(k, eps, a);
        let m = sphere::phase_moments(k, eps, a);
        assert!(
            (m[0] - c.scattering).abs() < 1e-10 * c.scattering,
            "a {a}: {} vs {}",
            m[0],
            c.scattering
        );
        assert!(
            (m[1] / m[0] - c.asymmetry).abs() < 1e-10,
            "a {a}: {} vs {}",
            m[1] / m[0],
            c.asymmetry
        );
        // A phase function's moments are bounded by the zeroth.
        assert!(m.iter().all(|v| v.abs() <= m[0] * (1.0 + 1e-12)));
    }
}

#[test]
fn the_scene_stack_without_scattering_is_the_clear_slab_on_paper() {
    // A non-scattering absorbing binder slab, air gap, Lambertian paper:
    // 45°/0° = ρ T(45°) T(0°) / (1 − ρ R_dd↑), T and R the incoherent slab's
    // per direction, R_dd↑ its albedo for Lambertian light from below
    // (here summed over the same air bins; against a fine integral below),
    // with either surface law: the scalar wave's and natural light's (each
    // passage reflecting the mean of s and p).
    for fresnel in [Fresnel::Scalar, Fresnel::Unpolarised] {
        clear_slab_on_paper(fresnel);
    }
}

fn clear_slab_on_paper(fresnel: Fresnel) {
    let o = ords();
    let (mu_a, x, rho) = (2e-4, 1000.0, 0.9);
    let s = transfer::stack(o.clone(), &absorber(mu_a), x, rho, Boundary::Scene, fresnel).unwrap();
    let slab = |mu_air: f64| {
        let mu = (1.0 - (1.0 - mu_air * mu_air) / (NB * NB)).sqrt();
        let f = fresnel.between(NB, mu, mu_air);
        let t = (-mu_a * x / mu).exp();
        let d = 1.0 - f * f * t * t;
        (
            f + (1.0 - f).powi(2) * f * t * t / d,
            (1.0 - f).powi(2) * t / d,
        )
    };
    let rdd: f64 = (0..o.len())
        .filter_map(|i| o.mu_air[i].map(|m| o.air_flux_weight(i) * slab(m).0))
        .sum();
    let expect = rho * slab(45f64.to_radians().cos()).1 * slab(1.0).1 / (1.0 - rho * rdd);
    let got = s.factor(Measurement::FortyFiveZero).unwrap();
    eprintln!("clear slab on paper, {fresnel:?}, 45/0: AD {got:.12} vs closed form {expect:.12}");
    assert!((got - expect).abs() < 1e-10, "{got} vs {expect}");
    // The quadrature's own error: R_dd↑ by a fine integral.
    let (xg, wg) = gauss_legendre(400);
    let fine: f64 = xg
        .iter()
        .zip(&wg)
        .map(|(x, w)| {
            let m = 0.5 * (x + 1.0);
            0.5 * w * 2.0 * m * slab(m).0
        })
        .sum();
    let expect_fine = rho * slab(45f64.to_radians().cos()).1 * slab(1.0).1 / (1.0 - rho * fine);
    eprintln!(
        "  against the fine integral: {:.2e}",
        (got - expect_fine).abs()
    );
    assert!((got - expect_fine).abs() < 1e-6);
    // d/8 SCI is the hemispherical reflectance: mirror + paper term;
    // SCE leaves the mirror out.
    let td: f64 = (0..o.len())
        .filter_map(|i| o.mu_air[i].map(|m| o.air_flux_weight(i) * slab(m).1))
        .sum();
    let (r8, t8) = slab(8f64.to_radians().cos());
    let paper = rho * t8 * td / (1.0 - rho * rdd);
    let sci = s.factor(Measurement::DiffuseEightSci).unwrap();
    let sce = s.factor(Measurement::DiffuseEightSce).unwrap();
    assert!(
        (sci - (r8 + paper)).abs() < 1e-10,
        "{sci} vs {}",
        r8 + paper
    );
    assert!((sce - paper).abs() < 1e-10, "{sce} vs {paper}");
}

#[test]
fn km_on_the_scene_boundary_is_the_clear_slab_when_transparent() {
    // K = S = 0: the KM body reflects its backing, R = R_g. Built the other
    // way round — the clear binder slab (diffuse light inside, scalar
    // surfaces r_e, r_i from inside, r_ed from air) over the paper in air,
    // the slab–paper exchange a geometric series — the 45°/0° factor is
    // (1 − r_e)[r_i(1 − r_i)/(1 − r_i²) + T_in ρ T_out/(1 − ρ R_below)].
    let (rho, x) = (0.9, 1000.0);
    let r_i = km::internal_reflectance_scalar(NB);
    let r_ed = km::diffuse_external_reflectance_scalar(NB);
    let r_e = km::external_reflectance_scalar(NB, 45.0);
    // Étendue: 1 − r_i = (1 − r_ed)/n², and r_i beyond the critical angle.
    assert!(r_i > 1.0 - 1.0 / (NB * NB));
    let body = km::reflectance(0.0, 0.0, x, km::scene_backing(rho, r_i, r_ed));
    let kmscene = km::saunderson_excluded(body, r_e, r_i);
    let bounce = 1.0 - r_i * r_i;
    let t_in = (1.0 - r_i) / bounce;
    let t_out = (1.0 - r_ed) * (1.0 - r_i) / bounce;
    let below = r_ed + (1.0 - r_ed) * r_i * (1.0 - r_i) / bounce;
    let expect =
        (1.0 - r_e) * (r_i * (1.0 - r_i) / bounce + t_in * rho * t_out / (1.0 - rho * below));
    assert!((kmscene - expect).abs() < 1e-12, "{kmscene} vs {expect}");
    // The scalar surface at normal incidence: ((n − 1)/(n + 1))².
    let r0 = ((NB - 1.0) / (NB + 1.0)).powi(2);
    assert!((km::external_reflectance_scalar(NB, 0.0) - r0).abs() < 1e-15);
}
