//! Stage 1, high PVC: sphere-cluster shapes and the first-order dynamics
//! packer, checked by brute force (all pairs, 3×3 periodic images).

mod common;
use common::layers::brute_min_gap;
use common::threads::on_threads;
use inksim::geometry::{
    analyse, axis_from_uniforms, order_parameter, pack_dynamics, particle_axis, union_volume,
    DynParams, DynSpecies, Geometry, GeometryError, Orientation, Shape, ShapeTemplate,
    SizeDistribution, SpeciesOptions, StatsParams, PARALLEL_MIN_PARTICLES,
};
use std::f64::consts::PI;
use std::time::Instant;

fn sp(shape: Shape, d: f64, f: f64, orientation: Orientation, field: f64) -> DynSpecies {
    DynSpecies {
        shape,
        effective_diameter_nm: d,
        volume_fraction: f,
        orientation,
        field,
    }
}

const RICE: Shape = Shape::Rice {
    aspect: 3.0,
    spheres: 7,
};

/// Deepest overlap between spheres of different particles, all pairs and the
/// 3×3 periodic images in x, y: minus the smallest brute-force gap.
fn brute_worst_overlap(g: &Geometry) -> f64 {
    -brute_min_gap(g)
}

/// Checks walls (within `tol`), lateral wrapping and rigid shapes.
fn check_inside_and_rigid(g: &Geometry, tol: f64) {
    let [lx, ly, h] = g.size_nm;
    for p in &g.particles {
        for s in &p.spheres {
            assert!((0.0..lx).contains(&s.center[0]), "x outside: {s:?}");
            assert!((0.0..ly).contains(&s.center[1]), "y outside: {s:?}");
            assert!(s.center[2] - s.radius >= -tol, "crosses z = 0: {s:?}");
            assert!(s.center[2] + s.radius <= h + tol, "crosses z = H: {s:?}");
        }
    }
}

fn min_radius(g: &Geometry) -> f64 {
    g.particles
        .iter()
        .flat_map(|p| &p.spheres)
        .map(|s| s.radius)
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn union_volume_matches_lens_formula() {
    let (r1, r2, d) = (1.0f64, 0.7f64, 1.2f64);
    let lens = PI
        * (r1 + r2 - d).powi(2)
        * (d * d + 2.0 * d * r2 - 3.0 * r2 * r2 + 2.0 * d * r1 + 6.0 * r1 * r2 - 3.0 * r1 * r1)
        / (12.0 * d);
    let v = |r: f64| 4.0 / 3.0 * PI * r.powi(3);
    let exact = v(r1) + v(r2) - lens;
    let got = union_volume(&[(0.0, r1), (d, r2)]);
    assert!((got - exact).abs() < 1e-12, "{got} vs {exact}");
    // Disjoint spheres add; a sphere inside another adds nothing.
    let got = union_volume(&[(0.0, 1.0), (2.5, 0.5)]);
    assert!((got - v(1.0) - v(0.5)).abs() < 1e-12);
    let got = union_volume(&[(0.0, 1.0), (0.2, 0.5)]);
    assert!((got - v(1.0)).abs() < 1e-12);
    // Three spheres: inclusion–exclusion with pairwise lenses (the outer two
    // do not touch, so there is no triple term).
    let l = |r1: f64, r2: f64, d: f64| {
        PI * (r1 + r2 - d).powi(2)
            * (d * d + 2.0 * d * r2 - 3.0 * r2 * r2 + 2.0 * d * r1 + 6.0 * r1 * r2 - 3.0 * r1 * r1)
            / (12.0 * d)
    };
    let got = union_volume(&[(0.0, 1.0), (1.5, 0.8), (2.9, 0.9)]);
    let exact = v(1.0) + v(0.8) + v(0.9) - l(1.0, 0.8, 1.5) - l(0.8, 0.9, 1.4);
    assert!((got - exact).abs() < 1e-12, "{got} vs {exact}");
}

#[test]
fn templates_have_unit_effective_diameter_and_documented_proportions() {
    for shape in [
        Shape::Sphere,
        Shape::DEFAULT_CYLINDER,
        Shape::Cylinder {
            aspect: 4.0,
            spheres: 9,
        },
        RICE,
    ] {
        let t = ShapeTemplate::new(shape).unwrap();
        assert!((t.volume() - PI / 6.0).abs() < 1e-12, "{shape:?}");
    }
    let c = ShapeTemplate::new(Shape::DEFAULT_CYLINDER).unwrap();
    assert!((c.half_length() / c.max_radius() - 3.0).abs() < 1e-12);
    let r = ShapeTemplate::new(RICE).unwrap();
    assert!((r.half_length() / r.max_radius() - 3.0).abs() < 1e-12);
    // Ends: radius 2ab²/(a²+b²) = 0.6 b at aspect 3.
    assert!((r.min_radius() / r.max_radius() - 0.6).abs() < 1e-12);
    // Tapers monotonically to both ends.
    let radii: Vec<f64> = r.spheres.iter().map(|s| s.1).collect();
    assert!(radii[..4].windows(2).all(|w| w[0] < w[1]));
    assert!(radii[3..].windows(2).all(|w| w[0] > w[1]));
}

#[test]
fn orientation_modes_and_order_parameter() {
    let n = 200;
    let mut axes = Vec::new();
    for mode in [
        Orientation::Random,
        Orientation::InPlane,
        Orientation::Perpendicular,
    ] {
        axes.clear();
        for i in 0..n {
            for j in 0..n {
                let a = axis_from_uniforms(mode, (i as f64 + 0.5) / n as f64, j as f64 / n as f64);
                assert!((a[0] * a[0] + a[1] * a[1] + a[2] * a[2] - 1.0).abs() < 1e-12);
                axes.push(a);
            }
        }
        let s = order_parameter(&axes).unwrap();
        let want = match mode {
            Orientation::Random => 0.0,
            Orientation::InPlane => -0.5,
            Orientation::Perpendicular => 1.0,
        };
        assert!((s - want).abs() < 1e-4, "{mode:?}: S = {s}");
    }
    assert_eq!(order_parameter(&[]), None);
}

#[test]
fn small_packings_have_no_overlap_and_respect_walls() {
    for (shape, d, f) in [
        (Shape::Sphere, 60.0, 0.45),
        (Shape::DEFAULT_CYLINDER, 60.0, 0.35),
        (RICE, 60.0, 0.35),
    ] {
        let params = DynParams::new(
            [600.0, 600.0, 300.0],
            vec![sp(shape, d, f, Orientation::Random, 0.0)],
        );
        let g = pack_dynamics(&params, 7).unwrap();
        let tol = params.overlap_tolerance * min_radius(&g);
        let worst = brute_worst_overlap(&g);
        assert!(g.particles.len() > 100, "{shape:?}");
        assert!(worst < tol, "{shape:?}: overlap {worst} ≥ {tol}");
        assert!((g.stats.worst_overlap_nm - worst.max(0.0)).abs() < 1e-9);
        check_inside_and_rigid(&g, tol);
        let achieved = g.stats.achieved_fraction[0];
        assert!((achieved - f).abs() <= 0.005 * f, "{achieved} vs {f}");
        // Rigid bodies: first-to-last sphere distance as in the template.
        let t = ShapeTemplate::new(shape).unwrap();
        let span = (t.spheres.last().unwrap().0 - t.spheres[0].0) * d;
        for p in &g.particles {
            if let Some(a) = particle_axis(&g, p) {
                assert!((a[0] * a[0] + a[1] * a[1] + a[2] * a[2] - 1.0).abs() < 1e-12);
                let (s0, s1) = (p.spheres[0].center, p.spheres.last().unwrap().center);
                let mut dd = 0.0;
                for (ax, l) in g.size_nm.iter().enumerate() {
                    let mut x = s1[ax] - s0[ax];
                    if ax < 2 {
                        x -= l * (x / l).round();
                    }
                    dd += x * x;
                }
                assert!((dd.sqrt() - span).abs() < 1e-9 * span, "{shape:?}");
            }
        }
    }
}

#[test]
fn spheres_reach_half_pvc_in_a_slab() {
    let params = DynParams::new(
        [1000.0, 1000.0, 500.0],
        vec![sp(Shape::Sphere, 100.0, 0.5, Orientation::Random, 0.0)],
    );
    let t = Instant::now();
    let g = pack_dynamics(&params, 1).unwrap();
    eprintln!(
        "spheres 50 %: {} particles, {} steps, {:.2} s",
        g.particles.len(),
        g.stats.relax_steps,
        t.elapsed().as_secs_f64()
    );
    let worst = brute_worst_overlap(&g);
    assert!(worst < 0.01 * 50.0, "worst overlap {worst} nm");
    check_inside_and_rigid(&g, 0.5);
    let a = g.stats.achieved_fraction[0];
    assert!((a - 0.5).abs() <= 0.005 * 0.5, "achieved {a}");
}

#[test]
fn alignment_modes_give_expected_order_parameter() {
    let size = [1000.0, 1000.0, 600.0];
    let run = |o: Orientation, field: f64, f: f64| {
        let params = DynParams::new(size, vec![sp(RICE, 50.0, f, o, field)]);
        let g = pack_dynamics(&params, 3).unwrap();
        let s = g.stats.order_parameter.unwrap();
        // Recomputed from the spheres.
        let axes: Vec<_> = g
            .particles
            .iter()
            .filter_map(|p| particle_axis(&g, p))
            .collect();
        assert!((order_parameter(&axes).unwrap() - s).abs() < 1e-9);
        eprintln!(
            "{o:?} field {field} PVC {f}: S = {s:.4}, {} grains, {} steps",
            axes.len(),
            g.stats.relax_steps
        );
        (s, axes.len())
    };
    let (s, n) = run(Orientation::InPlane, 1.0, 0.3);
    assert!((s + 0.5).abs() < 0.05, "in-plane S = {s} ({n} grains)");
    let (s, _) = run(Orientation::Perpendicular, 1.0, 0.3);
    assert!(s > 0.95, "perpendicular S = {s}");
    let (s, n) = run(Orientation::Random, 0.0, 0.2);
    assert!(n > 1500);
    assert!(s.abs() < 0.05, "random S = {s} ({n} grains)");
}

#[test]
fn same_seed_same_result() {
    let params = DynParams::new(
        [500.0, 500.0, 300.0],
        vec![
            sp(RICE, 50.0, 0.25, Orientation::Random, 0.0),
            sp(Shape::Sphere, 40.0, 0.15, Orientation::Random, 0.0),
        ],
    );
    let a = pack_dynamics(&params, 11).unwrap();
    let b = pack_dynamics(&params, 11).unwrap();
    let c = pack_dynamics(&params, 12).unwrap();
    assert_eq!(a.particles, b.particles);
    assert_eq!(a.stats.relax_steps, b.stats.relax_steps);
    assert_ne!(a.particles, c.particles);
    assert!(a.particles.iter().any(|p| p.species == 1));
}

#[test]
fn unreachable_pvc_reports_reached_density() {
    let mut params = DynParams::new(
        [400.0, 400.0, 200.0],
        vec![sp(Shape::Sphere, 50.0, 0.7, Orientation::Random, 0.0)],
    );
    params.max_steps_per_batch = 3000;
    match pack_dynamics(&params, 5) {
        Err(GeometryError::DynamicsNotReached {
            target, reached, ..
        }) => {
            eprintln!("PVC 0.7 not reached: {reached:.3} overlap-free");
            assert_eq!(target, 0.7);
            assert!(reached > 0.3 && reached < 0.7, "reached {reached}");
        }
        other => panic!("expected DynamicsNotReached, got {other:?}"),
    }
    params.species[0].volume_fraction = 0.75;
    assert!(matches!(
        pack_dynamics(&params, 5),
        Err(GeometryError::Invalid(_))
    ));
}

#[test]
fn bad_input_is_rejected() {
    let size = [1000.0, 1000.0, 100.0];
    let bad = |s: DynSpecies| pack_dynamics(&DynParams::new(size, vec![s]), 1).unwrap_err();
    let zero = Shape::Rice {
        aspect: 3.0,
        spheres: 0,
    };
    assert!(matches!(
        bad(sp(zero, 50.0, 0.1, Orientation::Random, 0.0)),
        GeometryError::Invalid(m) if m.contains("spheres")
    ));
    assert!(matches!(
        bad(sp(Shape::Sphere, 150.0, 0.1, Orientation::Random, 0.0)),
        GeometryError::GrainTooLarge { .. }
    ));
    // Standing rice grain of 60 nm effective diameter is longer than 100 nm.
    assert!(matches!(
        bad(sp(RICE, 60.0, 0.1, Orientation::Perpendicular, 0.0)),
        GeometryError::GrainTooLarge { .. }
    ));
    assert!(matches!(
        bad(sp(RICE, 50.0, 0.1, Orientation::Random, 1.0)),
        GeometryError::Invalid(_)
    ));
    assert!(matches!(
        bad(sp(Shape::Sphere, -1.0, 0.1, Orientation::Random, 0.0)),
        GeometryError::Invalid(_)
    ));
}

/// CPU seconds of this process, all threads (Linux `/proc`, 10 ms ticks; 0
/// elsewhere), so the timings do not depend on other load on the machine.
fn cpu_seconds() -> f64 {
    std::fs::read_to_string("/proc/self/stat")
        .ok()
        .and_then(|s| {
            let rest = s.rsplit_once(')')?.1;
            let f: Vec<&str> = rest.split_whitespace().collect();
            Some((f[11].parse::<f64>().ok()? + f[12].parse::<f64>().ok()?) / 100.0)
        })
        .unwrap_or(0.0)
}

/// Cost per relaxation step against the number of particles (spheres, 50 %
/// PVC, 1 µm thick): `cargo test --release --test dynamics -- --ignored --nocapture`.
#[test]
#[ignore]
fn scaling_report() {
    for l in [500.0, 1000.0, 2000.0, 4000.0, 8000.0] {
        let params = DynParams::new(
            [l, l, 1000.0],
            vec![sp(Shape::Sphere, 100.0, 0.5, Orientation::Random, 0.0)],
        );
        let (t, c) = (Instant::now(), cpu_seconds());
        let g = pack_dynamics(&params, 1).unwrap();
        let (w, s) = (t.elapsed().as_secs_f64(), cpu_seconds() - c);
        let n = g.particles.len();
        eprintln!(
            "L = {l} nm: {n} particles, {} steps, {s:.2} s CPU ({w:.2} s wall), \
             {:.3} µs CPU per particle-step",
            g.stats.relax_steps,
            1e6 * s / (n as f64 * g.stats.relax_steps as f64)
        );
    }
}

/// Order parameter against the alignment field (rice, 45 % PVC):
/// `cargo test --release --test dynamics -- --ignored --nocapture`.
#[test]
#[ignore]
fn field_report() {
    for o in [Orientation::InPlane, Orientation::Perpendicular] {
        for field in [0.0, 0.01, 0.1, 1.0] {
            let params = DynParams::new(
                [2000.0, 2000.0, 1000.0],
                vec![sp(RICE, 100.0, 0.45, o, field)],
            );
            let g = pack_dynamics(&params, 1).unwrap();
            eprintln!(
                "{o:?} field {field}: S = {:.3}, {} steps",
                g.stats.order_parameter.unwrap(),
                g.stats.relax_steps
            );
        }
    }
}

/// Timings for the report: `cargo test --release --test dynamics -- --ignored --nocapture`.
#[test]
#[ignore]
fn timing_report() {
    for (name, shape, f) in [
        ("spheres", Shape::Sphere, 0.5),
        ("spheres", Shape::Sphere, 0.55),
        ("rice", RICE, 0.4),
        ("rice", RICE, 0.45),
        ("rice", RICE, 0.5),
    ] {
        let params = DynParams::new(
            [2000.0, 2000.0, 1000.0],
            vec![sp(shape, 100.0, f, Orientation::Random, 0.0)],
        );
        let (t, c) = (Instant::now(), cpu_seconds());
        match pack_dynamics(&params, 1) {
            Ok(g) => eprintln!(
                "{name} PVC {f}: {} particles, {} steps, worst overlap {:.3} nm, S = {:?}, \
                 {:.2} s CPU ({:.2} s wall)",
                g.particles.len(),
                g.stats.relax_steps,
                g.stats.worst_overlap_nm,
                g.stats.order_parameter,
                cpu_seconds() - c,
                t.elapsed().as_secs_f64()
            ),
            Err(e) => eprintln!("{name} PVC {f}: {e} ({:.2} s)", t.elapsed().as_secs_f64()),
        }
    }
}

/// The issue-3 benchmark: rice grains of 100 nm, 10 × 10 × 1 µm, 50 % PVC
/// (~95 000 grains): `cargo test --release --test dynamics big -- --ignored --nocapture`.
#[test]
#[ignore]
fn big_rice_report() {
    let params = DynParams::new(
        [10_000.0, 10_000.0, 1000.0],
        vec![sp(RICE, 100.0, 0.5, Orientation::Random, 0.0)],
    );
    let (t, c) = (Instant::now(), cpu_seconds());
    let g = pack_dynamics(&params, 1).unwrap();
    eprintln!(
        "rice 10×10×1 µm PVC 0.5: {} grains, {} steps, worst overlap {:.3} nm (tol {:.3}), \
         {:.1} s CPU ({:.1} s wall)",
        g.particles.len(),
        g.stats.relax_steps,
        g.stats.worst_overlap_nm,
        0.01 * min_radius(&g),
        cpu_seconds() - c,
        t.elapsed().as_secs_f64()
    );
    assert!(g.stats.worst_overlap_nm < 0.01 * min_radius(&g));
    let params = DynParams::new(
        [10_000.0, 10_000.0, 1000.0],
        vec![sp(Shape::Sphere, 100.0, 0.55, Orientation::Random, 0.0)],
    );
    let (t, c) = (Instant::now(), cpu_seconds());
    let g = pack_dynamics(&params, 1).unwrap();
    eprintln!(
        "spheres 10×10×1 µm PVC 0.55: {} spheres, {} steps, worst overlap {:.3} nm, \
         {:.1} s CPU ({:.1} s wall)",
        g.particles.len(),
        g.stats.relax_steps,
        g.stats.worst_overlap_nm,
        cpu_seconds() - c,
        t.elapsed().as_secs_f64()
    );
    assert!(g.stats.worst_overlap_nm < 0.5);
}

fn opts(size: SizeDistribution, cluster_size: usize) -> SpeciesOptions {
    SpeciesOptions { size, cluster_size }
}

#[test]
fn size_distribution_packs_without_overlap() {
    let mut params = DynParams::new(
        [700.0, 700.0, 300.0],
        vec![sp(RICE, 60.0, 0.4, Orientation::Random, 0.0)],
    );
    params.options = vec![opts(SizeDistribution::LogNormal { sigma: 0.25 }, 1)];
    let g = pack_dynamics(&params, 4).unwrap();
    let tol = params.overlap_tolerance * min_radius(&g);
    let worst = brute_worst_overlap(&g);
    assert!(worst < tol, "overlap {worst} ≥ {tol}");
    check_inside_and_rigid(&g, tol);
    let s = analyse(&g, &StatsParams::default());
    // Exact union volumes agree with what the packer placed, and with the
    // target within half a grain.
    let a = g.stats.achieved_fraction[0];
    assert!((s.pvc[0] - a).abs() < 1e-9 * a, "{} vs {a}", s.pvc[0]);
    assert!((a - 0.4).abs() < 0.005 * 0.4, "{a}");
    // Effective diameters spread as drawn (ln d within ±3σ of ln 60).
    let ds: Vec<f64> = g
        .particles
        .iter()
        .map(|p| {
            let v = union_volume(
                &p.spheres
                    .iter()
                    .enumerate()
                    .map(|(k, sph)| {
                        let o = p.spheres[0].center;
                        let mut dd = 0.0f64;
                        for (ax, l) in g.size_nm.iter().enumerate() {
                            let mut x = sph.center[ax] - o[ax];
                            if ax < 2 {
                                x -= l * (x / l).round();
                            }
                            dd += x * x;
                        }
                        (if k == 0 { 0.0 } else { dd.sqrt() }, sph.radius)
                    })
                    .collect::<Vec<_>>(),
            );
            (6.0 * v / PI).cbrt()
        })
        .collect();
    let lo = ds.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = ds.iter().copied().fold(0.0, f64::max);
    eprintln!(
        "log-normal rice: {} grains, d in [{lo:.1}, {hi:.1}] nm",
        ds.len()
    );
    assert!(
        lo >= 60.0 * (-0.75f64).exp() * (1.0 - 1e-9) && hi <= 60.0 * 0.75f64.exp() * (1.0 + 1e-9)
    );
    assert!(hi / lo > 1.8);
}

/// Agglomeration at 15 % PVC, 50 nm spheres. Straight out of the packer,
/// non-mates that were pushed apart rest exactly touching, so contact
/// clusters link many grains whether or not clusters were asked for. A few
/// Monte Carlo sweeps (mates stick, agglomerates move as a whole too, the
/// rest equilibrates) open those contacts: then clusters of 8 give a mean
/// cluster size near 8 and no clusters near 1.
#[test]
fn agglomeration_keeps_seeded_clusters_together() {
    let run = |c: usize, sweeps: u64| {
        let mut params = DynParams::new(
            [1000.0, 1000.0, 400.0],
            vec![sp(Shape::Sphere, 50.0, 0.15, Orientation::Random, 0.0)],
        );
        params.options = vec![opts(SizeDistribution::Fixed, c)];
        params.equilibrate_sweeps = sweeps;
        let g = pack_dynamics(&params, 6).unwrap();
        let worst = brute_worst_overlap(&g);
        assert!(worst < 0.01 * 25.0, "overlap {worst}");
        check_inside_and_rigid(&g, 0.01 * 25.0);
        analyse(&g, &StatsParams::default())
    };
    let (free0, clumped0) = (run(1, 0), run(8, 0));
    let (free, clumped) = (run(1, 100), run(8, 100));
    eprintln!(
        "dynamics 15 %, no MC: clusters of 1 → mean {:.2} (weighted {:.2}); of 8 → mean {:.2} \
         (weighted {:.2}); 100 MC sweeps: of 1 → mean {:.2} (weighted {:.2}); of 8 → mean {:.2} \
         (weighted {:.2}), largest {}",
        free0.cluster_mean(),
        free0.cluster_weighted_mean(),
        clumped0.cluster_mean(),
        clumped0.cluster_weighted_mean(),
        free.cluster_mean(),
        free.cluster_weighted_mean(),
        clumped.cluster_mean(),
        clumped.cluster_weighted_mean(),
        clumped.cluster_sizes[0]
    );
    assert!(clumped0.cluster_weighted_mean() > 2.0 * free0.cluster_weighted_mean());
    assert!(free.cluster_mean() < 1.3, "{}", free.cluster_mean());
    // Measured 9.55: a few agglomerates still touch after 100 sweeps.
    assert!(
        (6.5..=10.5).contains(&clumped.cluster_mean()),
        "{}",
        clumped.cluster_mean()
    );
}

#[test]
fn relief_lets_grains_protrude_and_raster_covers_them() {
    let mut params = DynParams::new(
        [800.0, 800.0, 300.0],
        vec![sp(RICE, 60.0, 0.5, Orientation::Random, 0.0)],
    );
    params.relief_fraction = 0.3;
    let g = pack_dynamics(&params, 2).unwrap();
    let tol = params.overlap_tolerance * min_radius(&g);
    assert!(brute_worst_overlap(&g) < tol);
    let s = analyse(&g, &StatsParams::default());
    eprintln!(
        "rice 50 %, relief 0.3: protrusion {:.2} nm",
        s.protrusion_nm
    );
    assert!(s.protrusion_nm <= 0.3 * 60.0 + tol);
    assert!(s.protrusion_nm > 0.2 * 60.0);
    assert!(s.bottom_excess_nm <= tol);
    // The profile starts above z = 0 and holds grains there.
    assert!(s.profile_z_nm[0] < 0.0 && s.profile_fraction[0] > 0.0);
    let grid = inksim::raster::Grid::new(40, 40, 30, g.size_nm)
        .unwrap()
        .covering_relief(&g);
    assert_eq!(grid.nz, 30 + (s.protrusion_nm / 10.0).ceil() as usize);
    let r = inksim::raster::rasterize(&g, &grid, 4);
    let f = r.mean_fractions()[0];
    assert!(
        (f - s.pvc_total).abs() < 0.01,
        "raster {f} vs {}",
        s.pvc_total
    );
}

/// Packs `params` with `seed` on 1 and on 2 threads, checks that both give
/// bit-identical particles after the same number of steps, and returns the
/// packing.
fn pack_thread_independent(params: &DynParams, seed: u64) -> Geometry {
    let run = |threads| on_threads(threads, || pack_dynamics(params, seed).unwrap());
    let (a, b) = (run(1), run(2));
    assert_eq!(a.particles, b.particles);
    assert_eq!(a.stats.relax_steps, b.stats.relax_steps);
    a
}

/// No overlap beyond the tolerance (brute force below
/// `PARALLEL_MIN_PARTICLES` particles, the grid above), every grain inside
/// the walls and rigid.
fn assert_overlap_free(g: &Geometry, params: &DynParams) {
    let tol = params.overlap_tolerance * min_radius(g);
    let worst = if g.particles.len() >= PARALLEL_MIN_PARTICLES {
        g.stats.worst_overlap_nm
    } else {
        brute_worst_overlap(g)
    };
    assert!(worst < tol, "overlap {worst} ≥ {tol}");
    check_inside_and_rigid(g, tol);
}

/// Same seed ⇒ bit-identical particles with 1 and 2 threads (mixture, size
/// distribution, clusters, alignment field).
#[test]
fn thread_count_does_not_change_the_packing() {
    let mut params = DynParams::new(
        [700.0, 700.0, 300.0],
        vec![
            sp(RICE, 50.0, 0.25, Orientation::InPlane, 0.5),
            sp(Shape::Sphere, 40.0, 0.2, Orientation::Random, 0.0),
        ],
    );
    params.options = vec![
        opts(SizeDistribution::Normal { sigma: 0.1 }, 1),
        opts(SizeDistribution::Fixed, 4),
    ];
    let a = pack_thread_independent(&params, 9);
    assert!(a.particles.len() > 1000);
}

/// The FIRE stage (forced from the first step here) gives overlap-free
/// packings inside the walls and bit-identical particles with 1 and 2
/// threads, for rice grains (torques, generic pair path) and for spheres
/// (fast path), below `PARALLEL_MIN_PARTICLES` (serial passes, half
/// Verlet list) and above it (parallel passes, full list).
#[test]
fn fire_stage_packs_and_is_thread_count_independent() {
    for (shape, d, f, side, parallel) in [
        (RICE, 40.0, 0.45, 600.0, false),
        (Shape::Sphere, 40.0, 0.55, 600.0, false),
        (RICE, 40.0, 0.45, 1100.0, true),
        (Shape::Sphere, 40.0, 0.55, 1100.0, true),
    ] {
        let mut params = DynParams::new(
            [side, side, 300.0],
            vec![sp(shape, d, f, Orientation::Random, 0.0)],
        );
        params.fire_after_steps = 0;
        let a = pack_thread_independent(&params, 5);
        assert!(a.particles.len() > 1000);
        assert_eq!(a.particles.len() >= PARALLEL_MIN_PARTICLES, parallel);
        assert_overlap_free(&a, &params);
    }
}

/// First-order dynamics alone (no FIRE) for one-sphere particles, whose
/// steps take every force from the Verlet list while many particles move:
/// overlap-free and bit-identical with 1 and 2 threads, below and above
/// `PARALLEL_MIN_PARTICLES`.
#[test]
fn first_order_verlet_steps_pack_and_are_thread_count_independent() {
    for (side, parallel) in [(600.0, false), (1100.0, true)] {
        let mut params = DynParams::new(
            [side, side, 300.0],
            vec![sp(Shape::Sphere, 40.0, 0.45, Orientation::Random, 0.0)],
        );
        params.fire_after_steps = u64::MAX;
        let a = pack_thread_independent(&params, 3);
        assert_eq!(a.particles.len() >= PARALLEL_MIN_PARTICLES, parallel);
        assert_overlap_free(&a, &params);
    }
}

/// g(r) of the dynamics packer at 25 % (for the docs):
/// `cargo test --release --test dynamics rdf_report -- --ignored --nocapture`.
#[test]
#[ignore]
fn rdf_report() {
    let params = DynParams::new(
        [1600.0, 1600.0, 480.0],
        vec![sp(Shape::Sphere, 40.0, 0.25, Orientation::Random, 0.0)],
    );
    let g = pack_dynamics(&params, 1).unwrap();
    let s = analyse(&g, &StatsParams::default());
    eprintln!(
        "dynamics φ = 0.25: g(σ+) = {:?}, first bins {:?}",
        s.contact_value(40.0, 4.0),
        &s.rdf[48..56]
    );
}

/// Overlap-free density ladder in slabs 3, 5 and 10 diameters thick (100 nm
/// spheres, 20 × 20 diameters laterally, default parameters), for the
/// LAMMPS side-by-side of scripts/lammps_compare.py, which runs and parses
/// this: `cargo test --release --test dynamics slab_density_ladder --
/// --ignored --nocapture`. Seeds 1 to `INKSIM_LADDER_SEEDS` (default 5).
/// Prints `SLAB t phi seed ok|fail reached seconds worst_overlap_nm` per
/// run and stops a seed's ladder at its first failure.
#[test]
#[ignore]
fn slab_density_ladder() {
    let seeds: u64 = std::env::var("INKSIM_LADDER_SEEDS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(5);
    for t in [3.0, 5.0, 10.0] {
        for seed in 1..=seeds {
            for k in 0..8 {
                let phi = 0.50 + 0.02 * k as f64;
                let params = DynParams::new(
                    [2000.0, 2000.0, 100.0 * t],
                    vec![sp(Shape::Sphere, 100.0, phi, Orientation::Random, 0.0)],
                );
                let start = Instant::now();
                let result = pack_dynamics(&params, seed);
                let secs = start.elapsed().as_secs_f64();
                match result {
                    Ok(g) => println!(
                        "SLAB {t} {phi:.2} {seed} ok {:.4} {secs:.3} {:.4}",
                        g.stats.achieved_fraction[0], g.stats.worst_overlap_nm
                    ),
                    Err(GeometryError::DynamicsNotReached {
                        reached,
                        worst_overlap_nm,
                        ..
                    }) => {
                        println!(
                            "SLAB {t} {phi:.2} {seed} fail {reached:.4} {secs:.3} \
                             {worst_overlap_nm:.4}"
                        );
                        break;
                    }
                    Err(e) => panic!("{e}"),
                }
            }
        }
    }
}
