//! One application of the background Green's operator `G_b` and of the
//! shifted operator `G_s` (what the iterative methods apply; on the CBS
//! shift and on a pigment layer's mean background) against the
//! batched 2-D FFTs they contain (forward + inverse over every z-slice). The ratio
//! operator/FFT is the figure of merit (docs/PERFORMANCE.md). Maxwell's
//! shifted operator (`maxwell_apply_shifted*`, both grids up to 256²)
//! against the scalar one on the same grid and shift: the goal is ≤ 3.5×.
//! `maxwell_system[_tensor]`: the whole shifted application a Krylov step
//! makes (`V' x` and `G_s` of it) on a layer of 200 nm spheres at 30 % of
//! the 60 × 60 × 50 grid (40 % by volume), with volume-averaged and with anisotropic cut
//! voxels (their tensor terms). `maxwell_step_parts` / `maxwell_step_fused`:
//! what a BiCGStab step applies on the mean background (`P A x`, its norm
//! and one inner product), step by step and fused into the transforms.
//!
//! `cargo bench --bench operator` (60 × 60 × 50, the standard profile's
//! grid (1.4 µm fragments, 20 nm z cells), 256 × 256 × 64 and 512 × 512 × 96;
//! the largest needs about 3 GB). Each is measured twice: wall time
//! (`operator`) and the CPU time of all the process's threads together
//! (`operator_cpu`, Linux), which other processes competing for the cores
//! disturb much less.

use criterion::measurement::{Measurement, ValueFormatter, WallTime};
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use inksim::config::Background;
use inksim::geometry::{Geometry, Particle, Sphere};
use inksim::raster::{rasterize, Anisotropy, Grid};
use inksim::solver::fft::Fft2;
use inksim::solver::maxwell::VectorOperator;
use inksim::solver::operator::{GreenTable, Operator};
use inksim::solver::shift::ShiftTable;
use inksim::solver::storage::{dot, norm_sqr};
use inksim::solver::{Jones, Problem, System, Wave};
use ndarray::Array3;
use num_complex::Complex64 as C64;

fn field(nz: usize, ny: usize, nx: usize) -> Array3<C64> {
    Array3::from_shape_fn((nz, ny, nx), |(k, j, i)| {
        C64::new((i + 2 * j) as f64 * 0.01, (k as f64 * 0.1).sin())
    })
}

fn bench<M: Measurement>(c: &mut Criterion<M>, name: &str) {
    let mut g = c.benchmark_group(name);
    g.sample_size(10);
    for &(n, nz, period) in &[
        (60usize, 50usize, 1400.0),
        (256, 64, 2560.0),
        (512, 96, 5120.0),
    ] {
        let lat = Problem::lattice([n, n, nz], [period, period, 1000.0], 500.0, 30.0, 0.0);
        let op = Operator::new(lat);
        let table = GreenTable::new(&lat, C64::new(1.558f64.powi(2), 0.0));
        let mut ws = op.workspace();
        let mut u = field(nz, n, n);
        g.bench_with_input(
            BenchmarkId::new("apply", format!("{n}x{n}x{nz}")),
            &(),
            |b, _| b.iter(|| op.apply(&table, &mut u, &mut ws)),
        );
        drop(table);
        // The CBS shift of a pigment layer, and its mean background: little
        // loss, so the rows of harmonics propagating in it keep all cells.
        for (name, bg) in [
            ("apply_shifted", C64::new(2.0, 0.8)),
            ("apply_shifted_mean", C64::new(2.45, 0.05)),
        ] {
            let c = lat.k0 * lat.k0 * (bg - 1.558f64.powi(2));
            let shifted = ShiftTable::new(&lat, 1.558f64.powi(2), c);
            g.bench_with_input(
                BenchmarkId::new(name, format!("{n}x{n}x{nz}")),
                &(),
                |b, _| b.iter(|| op.apply_shifted_green(&shifted, &mut u, &mut ws)),
            );
        }
        // Maxwell's shifted operator on the same grid and shift: three
        // components, so three times the FFTs (the floor of the ratio).
        if n <= 256 {
            drop(u);
            let vop = VectorOperator::new(lat, 1.558f64.powi(2), 0.0);
            let mut vws = vop.workspace();
            let mut e = field(3 * nz, n, n);
            for (name, bg) in [
                ("maxwell_apply_shifted", C64::new(2.0, 0.8)),
                ("maxwell_apply_shifted_mean", C64::new(2.45, 0.05)),
            ] {
                let c = lat.k0 * lat.k0 * (bg - 1.558f64.powi(2));
                let tables = vop.shift_tables(c);
                g.bench_with_input(
                    BenchmarkId::new(name, format!("{n}x{n}x{nz}")),
                    &(),
                    |b, _| b.iter(|| vop.apply_shifted(&tables, &mut e, &mut vws)),
                );
            }
        }
        let fft = Fft2::new(n, n);
        let mut scr = fft.scratch(nz);
        let mut spec = Array3::zeros((nz, n, n));
        let mut v = field(nz, n, n);
        g.bench_with_input(
            BenchmarkId::new("fft_pair", format!("{n}x{n}x{nz}")),
            &(),
            |b, _| {
                b.iter(|| {
                    fft.forward(&mut v, &mut spec, &mut scr);
                    fft.inverse(&mut spec, &mut v, &mut scr);
                })
            },
        );
    }
    system(&mut g);
    g.finish();
}

/// The Maxwell system's shifted application on a sphere layer, without and
/// with the anisotropic cut voxels' tensor.
fn system<M: Measurement>(g: &mut criterion::BenchmarkGroup<M>) {
    let (n, nz, l, h) = (60usize, 50usize, 1400.0, 1000.0);
    // 198 nm spheres, 7 × 7 per plane in 4 shifted planes: 40 % by volume.
    let mut particles = vec![];
    for i in 0..7 {
        for j in 0..7 {
            for k in 0..4 {
                let c = [
                    100.0 + 200.0 * i as f64 + 7.0 * k as f64,
                    100.0 + 200.0 * j as f64 + 11.0 * k as f64,
                    125.0 + 250.0 * k as f64,
                ];
                particles.push(Particle {
                    species: 0,
                    spheres: vec![Sphere {
                        center: c,
                        radius: 99.0,
                    }],
                });
            }
        }
    }
    let geom = Geometry {
        size_nm: [l, l, h],
        particles,
        stats: Default::default(),
    };
    let raster = rasterize(&geom, &Grid::new(n, n, nz, [l, l, h]).unwrap(), 4);
    let (eb, es) = (C64::new(1.558f64.powi(2), 0.0), C64::new(1.4, 0.7).powi(2));
    let mut eps = Array3::zeros((nz, n, n));
    raster.epsilon_into(eb, &[es], &mut eps);
    let mut tensor = Anisotropy::default();
    raster.anisotropy_into(eb, &[es], &[], true, &mut eps, &mut tensor);
    let lat = Problem::lattice([n, n, nz], [l, l, h], 500.0, 30.0, 0.0);
    for (name, t) in [
        ("maxwell_system", None),
        ("maxwell_system_tensor", Some(&tensor)),
    ] {
        let p = Problem {
            lattice: lat,
            eps: &eps,
            tensor: t,
            eps_binder: eb.re,
            wave: Wave::Vector {
                polarisation: Jones::from(inksim::config::Linear::P),
                azimuth_deg: 0.0,
            },
        };
        let sys = System::new(&p, Background::Binder).unwrap();
        let mut scr = sys.scratch();
        let x = field(3 * nz, n, n);
        let mut out = Array3::<C64>::zeros(x.dim());
        g.bench_with_input(
            BenchmarkId::new(name, format!("{n}x{n}x{nz}")),
            &(),
            |b, _| b.iter(|| sys.apply_a_shifted(&mut scr, &x, &mut out)),
        );
    }
    // What a BiCGStab step applies, on the mean background the study's
    // solves take: `P A x` with `‖·‖²` and `⟨·, w⟩`, step by step against
    // the fused application (`System::apply_pa_sums`).
    let p = Problem {
        lattice: lat,
        eps: &eps,
        tensor: Some(&tensor),
        eps_binder: eb.re,
        wave: Wave::Vector {
            polarisation: Jones::from(inksim::config::Linear::P),
            azimuth_deg: 0.0,
        },
    };
    let sys = System::new(&p, Background::Mean).unwrap();
    let mut scr = sys.scratch();
    let (x, w) = (field(3 * nz, n, n), field(3 * nz, n, n).mapv(|v| v.conj()));
    let mut out = Array3::<C64>::zeros(x.dim());
    g.bench_with_input(
        BenchmarkId::new("maxwell_step_parts", format!("{n}x{n}x{nz}")),
        &(),
        |b, _| {
            b.iter(|| {
                sys.apply_a_shifted(&mut scr, &x, &mut out);
                sys.precondition(&mut out);
                (norm_sqr(&out), dot(&out, &w))
            })
        },
    );
    g.bench_with_input(
        BenchmarkId::new("maxwell_step_fused", format!("{n}x{n}x{nz}")),
        &(),
        |b, _| b.iter(|| sys.apply_pa_sums(&mut scr, &x, &mut out, &w)),
    );
}

/// CPU time of every thread of this process (ns), from
/// `/proc/self/task/*/schedstat`; 0 where that is not available.
fn process_cpu_ns() -> u64 {
    let Ok(tasks) = std::fs::read_dir("/proc/self/task") else {
        return 0;
    };
    tasks
        .filter_map(|t| std::fs::read_to_string(t.ok()?.path().join("schedstat")).ok())
        .filter_map(|s| s.split_whitespace().next()?.parse::<u64>().ok())
        .sum()
}

/// Criterion measurement: CPU time summed over threads.
struct CpuTime;

struct CpuFormatter;

impl ValueFormatter for CpuFormatter {
    fn scale_values(&self, _typical: f64, values: &mut [f64]) -> &'static str {
        values.iter_mut().for_each(|v| *v *= 1e-6);
        "ms cpu"
    }
    fn scale_throughputs(&self, _t: f64, _tp: &Throughput, values: &mut [f64]) -> &'static str {
        values.iter_mut().for_each(|v| *v *= 1e-6);
        "ms cpu"
    }
    fn scale_for_machines(&self, _values: &mut [f64]) -> &'static str {
        "ns"
    }
}

impl Measurement for CpuTime {
    type Intermediate = u64;
    type Value = u64;
    fn start(&self) -> u64 {
        process_cpu_ns()
    }
    fn end(&self, i: u64) -> u64 {
        process_cpu_ns().saturating_sub(i)
    }
    fn add(&self, a: &u64, b: &u64) -> u64 {
        a + b
    }
    fn zero(&self) -> u64 {
        0
    }
    fn to_f64(&self, v: &u64) -> f64 {
        *v as f64
    }
    fn formatter(&self) -> &dyn ValueFormatter {
        &CpuFormatter
    }
}

fn wall(c: &mut Criterion<WallTime>) {
    bench(c, "operator");
}

fn cpu(c: &mut Criterion<CpuTime>) {
    bench(c, "operator_cpu");
}

criterion_group!(walls, wall);
criterion_group! {
    name = cpus;
    config = Criterion::default().with_measurement(CpuTime);
    targets = cpu
}
criterion_main!(walls, cpus);
