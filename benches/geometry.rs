//! Cost of one relaxation step of the dynamics packer against the number of
//! moving particles (issue 3: linear over at least two decades).
//!
//! Each case throws `N` particles (30 % PVC, 1 µm thick, all in one batch,
//! so they start overlapping and all of them move) into a box of growing
//! area, takes 3 steps so the state is a typical early relaxation, and
//! times one step on a fresh copy of that state. Criterion's throughput is
//! then moving particles per second; time per moving particle-step should
//! stay flat. `cargo bench --bench geometry` (figures in docs/GEOMETRY.md).

use criterion::{criterion_group, criterion_main, BatchSize, BenchmarkId, Criterion, Throughput};
use inksim::geometry::{DynParams, DynSpecies, DynamicsPacker, Orientation, Shape};

fn packer(shape: Shape, side_nm: f64) -> DynamicsPacker {
    let mut params = DynParams::new(
        [side_nm, side_nm, 1000.0],
        vec![DynSpecies {
            shape,
            effective_diameter_nm: 100.0,
            volume_fraction: 0.3,
            orientation: Orientation::Random,
            field: 0.0,
        }],
    );
    params.batch_fraction = 1.0;
    let mut p = DynamicsPacker::new(&params, 1).expect("valid parameters");
    p.insert_batch();
    for _ in 0..3 {
        p.step();
    }
    p
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("relaxation_step");
    g.sample_size(10);
    let rice = Shape::Rice {
        aspect: 3.0,
        spheres: 7,
    };
    for (name, shape) in [("sphere", Shape::Sphere), ("rice", rice)] {
        // N ≈ 130, 1 000, 10 000, 100 000 particles.
        for side in [480.0, 1320.0, 4180.0, 13_200.0] {
            let p = packer(shape, side);
            g.throughput(Throughput::Elements(p.moving() as u64));
            g.bench_with_input(BenchmarkId::new(name, p.moving()), &p, |b, p| {
                b.iter_batched_ref(|| p.clone(), |q| q.step(), BatchSize::LargeInput)
            });
        }
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
