//! What a grain-aware preconditioner does on high contrast: full
//! (unrestarted) GMRES on the mean background's equation, once plain and
//! once right-preconditioned by the exact inverse of each grain's own block
//! of the operator (block Jacobi over the grains' voxels), and the
//! operator applications each needs to a relative residual of 1e-3
//! (docs/PERFORMANCE.md, "What a grain-aware preconditioner does").
//!
//! Geometry: lossless spheres of index `n`, 200 nm across, packed to `pvc`
//! in a 1500 × 1500 × 1000 nm fragment of binder n = 1.5, 50 × 50 × 50
//! cells, 550 nm, 8°, s. Each block is built from the operator's own
//! kernel: the shifted Green's operator is a convolution in x and y, so one
//! probe per source cell row and component gives every entry (checked
//! against a direct probe of one column). `group` (`gx,gy,gz`) joins the
//! grains whose centres share a box of a `gx × gy × gz` division of the
//! fragment into one block; `floor` sets the background's loss Im ε_s
//! (default: the mean background's own).
//!
//! `cargo run --release --example grain_blocks [n] [pvc] [scalar|maxwell] [group] [floor]`

use inksim::config::{Background, Linear};
use inksim::geometry::{pack_dynamics, DynParams, DynSpecies, Orientation, Shape};
use inksim::raster::{rasterize, Grid};
use inksim::solver::{Jones, Problem, ShiftParams, System, Wave};
use ndarray::Array3;
use num_complex::Complex64 as C64;
use rayon::prelude::*;

fn dotc(a: &[C64], b: &[C64]) -> C64 {
    a.iter().zip(b).map(|(x, y)| x.conj() * y).sum()
}
fn nrm(a: &[C64]) -> f64 {
    a.iter().map(|x| x.norm_sqr()).sum::<f64>().sqrt()
}

struct Lu {
    n: usize,
    a: Vec<C64>,
    piv: Vec<usize>,
}
impl Lu {
    fn new(n: usize, mut a: Vec<C64>) -> Lu {
        let mut piv = vec![0; n];
        for k in 0..n {
            let p = (k..n)
                .max_by(|&i, &j| {
                    a[i * n + k]
                        .norm()
                        .partial_cmp(&a[j * n + k].norm())
                        .unwrap()
                })
                .unwrap();
            piv[k] = p;
            if p != k {
                for c in 0..n {
                    a.swap(k * n + c, p * n + c);
                }
            }
            let d = a[k * n + k];
            let (top, rest) = a.split_at_mut((k + 1) * n);
            let rowk = &top[k * n..];
            rest.par_chunks_mut(n).for_each(|row| {
                let f = row[k] / d;
                row[k] = f;
                for c in k + 1..n {
                    row[c] -= f * rowk[c];
                }
            });
        }
        Lu { n, a, piv }
    }
    fn solve(&self, x: &mut [C64]) {
        let n = self.n;
        for k in 0..n {
            x.swap(k, self.piv[k]);
        }
        for i in 0..n {
            let row = &self.a[i * n..i * n + i];
            let s: C64 = row.iter().zip(&x[..i]).map(|(a, v)| a * v).sum();
            x[i] -= s;
        }
        for i in (0..n).rev() {
            let row = &self.a[i * n + i + 1..(i + 1) * n];
            let s: C64 = row.iter().zip(&x[i + 1..]).map(|(a, v)| a * v).sum();
            x[i] = (x[i] - s) / self.a[i * n + i];
        }
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n_idx: f64 = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(2.67);
    let pvc: f64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(0.15);
    let maxwell = args.get(3).is_some_and(|s| s == "maxwell");
    let group: Vec<usize> = args
        .get(4)
        .map(|v| {
            v.split(',')
                .map(|t| t.parse().expect("group gx,gy,gz"))
                .collect()
        })
        .unwrap_or(vec![0]);
    let floor: Option<f64> = args.get(5).and_then(|s| s.parse().ok());
    let side = 1500.0;
    let size = [side, side, 1000.0];
    let species = vec![DynSpecies {
        shape: Shape::Sphere,
        effective_diameter_nm: 200.0,
        volume_fraction: pvc,
        orientation: Orientation::Random,
        field: 0.0,
    }];
    let geom = pack_dynamics(&DynParams::new(size, species), 7).expect("packing");
    let grid = Grid {
        nx: 50,
        ny: 50,
        nz: 50,
        size_nm: size,
    };
    let raster = rasterize(&geom, &grid, 4);
    let eb = 2.25;
    let mut eps = Array3::zeros((grid.nz, grid.ny, grid.nx));
    raster.epsilon_into(C64::new(eb, 0.0), &[C64::new(n_idx * n_idx, 0.0)], &mut eps);
    let lat = Problem::lattice([grid.nx, grid.ny, grid.nz], size, 550.0, 8.0, 0.0);
    let wave = if maxwell {
        Wave::Vector {
            polarisation: Jones::linear(Linear::S),
            azimuth_deg: 0.0,
        }
    } else {
        Wave::Scalar
    };
    let p = Problem {
        tensor: None,
        lattice: lat,
        eps: &eps,
        eps_binder: eb,
        wave,
    };
    let mut params = ShiftParams::for_wave(Background::Mean, &p.wave);
    if let Some(f) = floor {
        // min(100 r², (f / r) r) = f.
        let m = eps.iter().sum::<C64>() / eps.len() as f64;
        let r = eps.iter().map(|e| (e - m).norm()).fold(0.0, f64::max);
        params = ShiftParams {
            mean_loss_floor: 100.0,
            mean_loss_cap: f / r,
            mean_loss_dilute: 0.0,
            ..params
        };
    }
    let sys = System::with_params(&p, params).unwrap();
    let mut scr = sys.scratch();
    let dim = sys.unknown_dim();
    let nc = dim.0 / grid.nz;
    let (nz, ny, nx) = (grid.nz, grid.ny, grid.nx);
    let es = sys.background_eps();
    println!(
        "n {n_idx}, pvc {pvc}, {} grains, maxwell {maxwell}, eps_s {es}",
        geom.particles.len()
    );
    let zero = Array3::<C64>::zeros(dim);
    let mut b = Array3::<C64>::zeros(dim);
    sys.residual_shifted(&mut scr, &zero, &mut b);
    let nn = b.len();
    let idx = |c: usize, z: usize, y: usize, x: usize| ((c * nz + z) * ny + y) * nx + x;
    let mut apply = |x: &[C64], out: &mut [C64]| {
        let xa = Array3::from_shape_vec(dim, x.to_vec()).unwrap();
        let mut o = Array3::<C64>::zeros(dim);
        sys.apply_a_shifted(&mut scr, &xa, &mut o);
        out.copy_from_slice(o.as_slice().unwrap());
    };
    // Kernel probes: G_s e at a binder voxel of each z, per source component.
    let t0 = std::time::Instant::now();
    let mut kern: Vec<Vec<C64>> = Vec::new(); // [cs*nz+z'] -> field (shifted to origin)
    for cs in 0..nc {
        for zp in 0..nz {
            let (yp, xp) = (0..ny * nx)
                .map(|k| (k / nx, k % nx))
                .find(|&(y, x)| eps[[zp, y, x]] == C64::new(eb, 0.0))
                .expect("binder voxel");
            let mut e = vec![C64::new(0.0, 0.0); nn];
            e[idx(cs, zp, yp, xp)] = C64::new(1.0, 0.0);
            let mut col = vec![C64::new(0.0, 0.0); nn];
            apply(&e, &mut col);
            let v = C64::new(eb, 0.0) - es;
            let mut k = vec![C64::new(0.0, 0.0); nn];
            for c in 0..nc {
                for z in 0..nz {
                    for y in 0..ny {
                        for x in 0..nx {
                            let src = idx(c, z, (y + yp) % ny, (x + xp) % nx);
                            k[idx(c, z, y, x)] = (e[src] - col[src]) / v;
                        }
                    }
                }
            }
            kern.push(k);
        }
    }
    println!("kernel probes {:.1} s", t0.elapsed().as_secs_f64());
    // Grain blocks: voxels with ε ≠ ε_b, nearest particle.
    let d = [side / nx as f64, side / ny as f64, 1000.0 / nz as f64];
    let mut blocks: Vec<Vec<(usize, usize, usize)>> =
        vec![Vec::new(); geom.particles.len().max(64)];
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                if (eps[[z, y, x]] - eb).norm() < 1e-9 {
                    continue;
                }
                let r = [
                    (x as f64 + 0.5) * d[0],
                    (y as f64 + 0.5) * d[1],
                    (z as f64 + 0.5) * d[2],
                ];
                let best = geom
                    .particles
                    .iter()
                    .enumerate()
                    .map(|(i, pt)| {
                        let s = &pt.spheres[0];
                        let mut dx = (r[0] - s.center[0]).abs() % side;
                        dx = dx.min(side - dx);
                        let mut dy = (r[1] - s.center[1]).abs() % side;
                        dy = dy.min(side - dy);
                        let dz = r[2] - s.center[2];
                        (i, dx * dx + dy * dy + dz * dz)
                    })
                    .min_by(|a, b| a.1.partial_cmp(&b.1).unwrap())
                    .unwrap()
                    .0;
                let gr = &group;
                let key = if gr[0] == 0 {
                    best
                } else {
                    let c = geom.particles[best].spheres[0].center;
                    let bx = ((c[0].rem_euclid(side) / side) * gr[0] as f64) as usize % gr[0];
                    let by = ((c[1].rem_euclid(side) / side) * gr[1] as f64) as usize % gr[1];
                    let bz = (((c[2] / 1000.0) * gr[2] as f64) as usize).min(gr[2] - 1);
                    (bz * gr[1] + by) * gr[0] + bx
                };
                blocks[key].push((z, y, x));
            }
        }
    }
    blocks.retain(|b| !b.is_empty());
    let sizes: Vec<usize> = blocks.iter().map(|b| b.len() * nc).collect();
    println!(
        "{} blocks, unknowns per block {}..{}, total {}",
        blocks.len(),
        sizes.iter().min().unwrap(),
        sizes.iter().max().unwrap(),
        sizes.iter().sum::<usize>()
    );
    // Unknown indices of each block, its dense matrix from the kernel.
    let t1 = std::time::Instant::now();
    let units: Vec<(Vec<usize>, Lu)> = blocks
        .iter()
        .map(|bl| {
            let ids: Vec<(usize, usize, usize, usize)> = (0..nc)
                .flat_map(|c| bl.iter().map(move |&(z, y, x)| (c, z, y, x)))
                .collect();
            let n = ids.len();
            let mut a = vec![C64::new(0.0, 0.0); n * n];
            for (i, &(ci, zi, yi, xi)) in ids.iter().enumerate() {
                for (j, &(cj, zj, yj, xj)) in ids.iter().enumerate() {
                    let k = &kern[cj * nz + zj];
                    let g = k[idx(ci, zi, (yi + ny - yj) % ny, (xi + nx - xj) % nx)];
                    let v = eps[[zj, yj, xj]] - es;
                    a[i * n + j] = if i == j {
                        C64::new(1.0, 0.0)
                    } else {
                        C64::new(0.0, 0.0)
                    } - g * v;
                }
            }
            let flat = ids.iter().map(|&(c, z, y, x)| idx(c, z, y, x)).collect();
            (flat, Lu::new(n, a))
        })
        .collect();
    println!("blocks factored {:.1} s", t1.elapsed().as_secs_f64());
    // Check one block column against a direct probe.
    {
        let (ids, _) = &units[0];
        let j = ids[ids.len() / 2];
        let mut e = vec![C64::new(0.0, 0.0); nn];
        e[j] = C64::new(1.0, 0.0);
        let mut col = vec![C64::new(0.0, 0.0); nn];
        apply(&e, &mut col);
        // rebuild the kernel entries for column j
        let (cj, rem) = (j / (nz * ny * nx), j % (nz * ny * nx));
        let (zj, yj, xj) = (rem / (ny * nx), (rem / nx) % ny, rem % nx);
        let k = &kern[cj * nz + zj];
        let v = eps[[zj, yj, xj]] - es;
        let mut err: f64 = 0.0;
        let mut mag: f64 = 0.0;
        for (i, got) in col.iter().enumerate() {
            let (ci, rem) = (i / (nz * ny * nx), i % (nz * ny * nx));
            let (zi, yi, xi) = (rem / (ny * nx), (rem / nx) % ny, rem % nx);
            let g = k[idx(ci, zi, (yi + ny - yj) % ny, (xi + nx - xj) % nx)];
            let pred = if i == j {
                C64::new(1.0, 0.0)
            } else {
                C64::new(0.0, 0.0)
            } - g * v;
            err = err.max((pred - got).norm());
            mag = mag.max(got.norm());
        }
        println!("kernel check: max error {err:.2e} of max {mag:.2e}");
    }
    let precond = |x: &[C64], y: &mut [C64]| {
        y.copy_from_slice(x);
        let parts: Vec<Vec<C64>> = units
            .par_iter()
            .map(|(ids, lu)| {
                let mut v: Vec<C64> = ids.iter().map(|&i| x[i]).collect();
                lu.solve(&mut v);
                v
            })
            .collect();
        for ((ids, _), v) in units.iter().zip(parts) {
            for (&i, val) in ids.iter().zip(v) {
                y[i] = val;
            }
        }
    };
    let bv = b.as_slice().unwrap().to_vec();
    for use_p in [false, true] {
        let t = std::time::Instant::now();
        let beta = nrm(&bv);
        let mut basis: Vec<Vec<C64>> = vec![bv.iter().map(|v| v / beta).collect()];
        let mut h: Vec<Vec<C64>> = Vec::new();
        let (mut cs, mut sn) = (Vec::<C64>::new(), Vec::<C64>::new());
        let mut g = vec![C64::new(beta, 0.0)];
        let mut z = vec![C64::new(0.0, 0.0); nn];
        let mut w = vec![C64::new(0.0, 0.0); nn];
        let mut it = 0;
        loop {
            it += 1;
            if use_p {
                precond(&basis[it - 1], &mut z);
            } else {
                z.copy_from_slice(&basis[it - 1]);
            }
            apply(&z, &mut w);
            let mut col = Vec::new();
            for q in &basis {
                let hh = dotc(q, &w);
                w.iter_mut().zip(q).for_each(|(a, b)| *a -= hh * b);
                col.push(hh);
            }
            let hn = nrm(&w);
            col.push(C64::new(hn, 0.0));
            for k in 0..cs.len() {
                let (a, bb) = (col[k], col[k + 1]);
                col[k] = cs[k].conj() * a + sn[k].conj() * bb;
                col[k + 1] = -sn[k] * a + cs[k] * bb;
            }
            let (a, bb) = (col[it - 1], col[it]);
            let r = (a.norm_sqr() + bb.norm_sqr()).sqrt();
            let (c, s) = (a / r, bb / r);
            cs.push(c);
            sn.push(s);
            col[it - 1] = C64::new(r, 0.0);
            col[it] = C64::new(0.0, 0.0);
            let gk = g[it - 1];
            g[it - 1] = c.conj() * gk;
            g.push(-s * gk);
            h.push(col);
            let res = g[it].norm() / beta;
            if it % 20 == 0 {
                println!("  it {it} res {res:.2e}");
            }
            if res < 1e-3 || it >= 800 {
                println!(
                    "{}: {it} applications, residual {res:.2e}, {:.1} s",
                    if use_p {
                        "block-Jacobi GMRES"
                    } else {
                        "plain GMRES"
                    },
                    t.elapsed().as_secs_f64()
                );
                break;
            }
            basis.push(w.iter().map(|v| v / hn).collect());
        }
    }
}
