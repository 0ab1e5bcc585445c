//! `airy`: the closed-form solve of a homogeneous layer ([`airy`]), as a
//! method. It reads the slab from the problem (its one permittivity, the
//! thickness, `k0` and `|κ|` of the lattice) and answers in the specular
//! order only, which is exact for a layer without grains; a layer with
//! grains is refused. The pipeline uses it for molecular mixtures and the
//! effective-medium shortcut; scenes cannot ask for it.

use super::{Solver, Validity};
use crate::config::{Background, Method, Precision};
use crate::solver::airy::{self, SlabField};
use crate::solver::system::{Scratch, System};
use crate::solver::{Controls, Problem, Solution, SolveError, SolveRecord, VectorAmplitudes, Wave};
use ndarray::{Array2, Array3};
use num_complex::Complex64 as C64;
use std::time::Instant;

/// The closed-form homogeneous slab.
pub struct Airy;

/// The one permittivity of a grid without grains.
fn homogeneous(eps: &Array3<C64>) -> Option<C64> {
    let first = *eps.iter().next()?;
    eps.iter().all(|e| *e == first).then_some(first)
}

impl Solver for Airy {
    fn method(&self) -> Method {
        Method::Airy
    }

    /// The returned field only.
    fn bytes_per_voxel(&self, _precision: Precision) -> f64 {
        16.0
    }

    /// None are applied; the study's time model still counts each solve as
    /// one application.
    fn applications_per_iteration(&self) -> f64 {
        1.0
    }

    fn validity(&self, sys: &mut System, _scr: &mut Scratch, _precision: Precision) -> Validity {
        match homogeneous(sys.eps()).filter(|_| sys.tensor().is_none()) {
            Some(_) => Validity::Always,
            None => Validity::Unlikely("the layer has grains".into()),
        }
    }

    /// The slab at the lattice's `k0` and `|κ| = |q|` (exactly the lateral
    /// wavenumber of the incidence when the lattice is built at azimuth 0).
    /// Field storage and a start field do not apply: the answer is a formula.
    fn solve_from(
        &self,
        p: &Problem,
        _ctl: &Controls,
        _start: Option<&Array3<C64>>,
    ) -> Result<Solution, SolveError> {
        let start = Instant::now();
        let isotropic = p.tensor.is_none_or(|a| a.is_empty());
        let eps = homogeneous(p.eps).filter(|_| isotropic).ok_or_else(|| {
            SolveError::Invalid("the closed form solves a layer without grains".into())
        })?;
        let lat = p.lattice;
        if p.eps.dim() != (lat.nz, lat.ny, lat.nx) {
            return Err(SolveError::Invalid(format!(
                "permittivity grid {:?} does not match lattice",
                p.eps.dim()
            )));
        }
        let kappa = lat.q[0].hypot(lat.q[1]);
        let nz = lat.nz;
        let specular = |amplitude| {
            let mut a = Array2::zeros((lat.nx, lat.ny));
            a[[0, 0]] = amplitude;
            a
        };
        let zero = C64::new(0.0, 0.0);
        let (field, r_s, t_s, vector, absorption) = match p.wave {
            Wave::Scalar => {
                let slab = SlabField::polarised(eps, lat.size_nm[2], lat.k0, kappa, false);
                let airy::SlabResponse { r, t, absorption } = slab.response;
                let cells = slab.cell_averages(nz);
                let field = Array3::from_shape_fn(p.eps.dim(), |(k, _, _)| cells[k]);
                (field, r, t, None, absorption)
            }
            Wave::Vector {
                polarisation,
                azimuth_deg,
            } => {
                // ê_κ along q (the azimuth at normal incidence), ê_s = ẑ × ê_κ.
                let [ux, uy] = if kappa > 0.0 {
                    [lat.q[0] / kappa, lat.q[1] / kappa]
                } else {
                    let a = azimuth_deg.to_radians();
                    [a.cos(), a.sin()]
                };
                // The s and p parts of the incident state superpose; their
                // fields are orthogonal (ŝ against the plane of incidence),
                // so the absorbed powers add.
                let mut rows = vec![zero; 3 * nz];
                let (mut amp, mut absorption) = ([zero; 4], 0.0);
                for (is_p, a) in [(false, polarisation.s), (true, polarisation.p)] {
                    if a == zero {
                        continue;
                    }
                    let slab = SlabField::polarised(eps, lat.size_nm[2], lat.k0, kappa, is_p);
                    let resp = &slab.response;
                    absorption += a.norm_sqr() * resp.absorption;
                    let k = if is_p { 2 } else { 0 };
                    amp[k] = a * resp.r;
                    amp[k + 1] = a * resp.t;
                    match slab.p_cell_averages(nz) {
                        Some((ek, ez)) => {
                            for j in 0..nz {
                                rows[j] += a * ux * ek[j];
                                rows[nz + j] += a * uy * ek[j];
                                rows[2 * nz + j] += a * ez[j];
                            }
                        }
                        None => {
                            for (j, es) in slab.cell_averages(nz).into_iter().enumerate() {
                                rows[j] += a * -uy * es;
                                rows[nz + j] += a * ux * es;
                            }
                        }
                    }
                }
                let field = Array3::from_shape_fn((3 * nz, lat.ny, lat.nx), |(k, _, _)| rows[k]);
                let v = VectorAmplitudes {
                    incident: polarisation,
                    r_p: specular(amp[2]),
                    t_p: specular(amp[3]),
                };
                (field, amp[0], amp[1], Some(v), absorption)
            }
        };
        Ok(Solution {
            lattice: lat,
            field,
            r: specular(r_s),
            t: specular(t_s),
            vector,
            absorption,
            record: SolveRecord {
                method: Method::Airy,
                background: Background::DEFAULT,
                iterations: 0,
                operator_applications: 0,
                residual: 0.0,
                seconds: start.elapsed().as_secs_f64(),
                note: format!(
                    "homogeneous slab, ⟨ε⟩ = {:.5}{:+.5}i, closed form{}",
                    eps.re,
                    eps.im,
                    match p.wave {
                        Wave::Scalar => String::new(),
                        Wave::Vector { polarisation, .. } =>
                            format!(", Maxwell, {} polarised", polarisation.name()),
                    }
                ),
            },
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::{solve, Problem};

    /// Through the entry point, at azimuth 0: the same bits as the slab
    /// formula; a grain is refused.
    #[test]
    fn solves_a_homogeneous_problem_exactly_and_refuses_grains() {
        let ctl = Controls {
            tolerance: 1e-6,
            max_iterations: 10,
            precision: Precision::F32,
            background: crate::config::Background::DEFAULT,
        };
        let eps = C64::new(2.2, 0.3);
        let lat = Problem::lattice([3, 2, 5], [400.0, 300.0, 700.0], 450.0, 40.0, 0.0);
        let mut grid = Array3::from_elem((5, 2, 3), eps);
        let p = Problem {
            tensor: None,
            lattice: lat,
            eps: &grid,
            eps_binder: 2.4,
            wave: crate::solver::Wave::Scalar,
        };
        let sol = solve(&p, Method::Airy, &ctl).unwrap();
        let want = airy::slab(eps, 700.0, 450.0, 40.0);
        assert_eq!((sol.r[[0, 0]], sol.t[[0, 0]]), (want.r, want.t));
        assert_eq!(sol.absorption, want.absorption);
        assert_eq!(sol.r.iter().filter(|r| r.norm() > 0.0).count(), 1);
        assert_eq!(sol.record.method, Method::Airy);
        // Thin cells at the faces hold the field there: 1 + r on top, t below.
        let thin = Problem::lattice([1, 1, 4000], [1.0, 1.0, 700.0], 450.0, 40.0, 0.0);
        let column = Array3::from_elem((4000, 1, 1), eps);
        let sol = solve(
            &Problem {
                tensor: None,
                lattice: thin,
                eps: &column,
                eps_binder: 2.4,
                wave: crate::solver::Wave::Scalar,
            },
            Method::Airy,
            &ctl,
        )
        .unwrap();
        assert!((sol.field[[0, 0, 0]] - (1.0 + want.r)).norm() < 1e-2);
        assert!((sol.field[[3999, 0, 0]] - want.t).norm() < 1e-2);
        grid[[2, 1, 1]] = C64::new(3.0, 0.1);
        let p = Problem {
            tensor: None,
            lattice: lat,
            eps: &grid,
            eps_binder: 2.4,
            wave: crate::solver::Wave::Scalar,
        };
        assert!(matches!(
            solve(&p, Method::Airy, &ctl),
            Err(SolveError::Invalid(_))
        ));
    }
}
