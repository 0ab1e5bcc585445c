//! The reflectance and transmittance of a flat multilayer between two media
//! by the characteristic (transfer) matrix, in s and p polarisation.
//!
//! Light arrives from an ambient medium of real index `n₀` at the angle whose
//! cosine is `cos θ₀`; the stack's layers have complex indices `N_j` and
//! thicknesses `d_j`; below lies the exit medium (complex index). In each
//! medium `cos θ_j = √(1 − (n₀ sin θ₀ / N_j)²)` on the branch that decays
//! into the medium, the phase thickness is `δ_j = k₀ N_j cos θ_j d_j` and the
//! tilted admittance `η_j = N_j cos θ_j` (s) or `N_j / cos θ_j` (p). The
//! layer's matrix is `[[cos δ, −i sin δ / η], [−i η sin δ, cos δ]]`; with
//! `M = Π M_j` and `B, C = M (1, η_exit)`, `r = (η₀ B − C)/(η₀ B + C)`,
//! `t = 2 η₀/(η₀ B + C)`, `R = |r|²` and `T = Re η_exit |t|² / η₀`
//! (Born & Wolf §1.6; Macleod, *Thin-film optical filters*, ch. 2).
//!
//! A layer whose single pass attenuates the field by more than `e^{−30}`
//! (`Im δ > 30`) transmits nothing that counts and would overflow `cos δ`:
//! it is taken as the exit medium itself (a semi-infinite absorber), and the
//! layers below it are not seen.

use crate::solver::green::sqrt_branch;
use num_complex::Complex64 as C64;

/// One layer of a stack: complex index and thickness (nm).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Film {
    pub index: C64,
    pub thickness_nm: f64,
}

/// Reflectance and transmittance of one polarisation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Powers {
    pub r: f64,
    pub t: f64,
}

/// The stack `films` (top first) between the ambient of real index
/// `ambient` and the `exit` medium, lit from the ambient at `cos_theta`
/// (0 < cos θ ≤ 1) with vacuum wavelength `wavelength_nm`; `p` picks the
/// polarisation. Returns the amplitude reflection coefficient as well.
pub fn stack(
    ambient: f64,
    films: &[Film],
    exit: C64,
    wavelength_nm: f64,
    cos_theta: f64,
    p: bool,
) -> (Powers, C64) {
    let k0 = 2.0 * std::f64::consts::PI / wavelength_nm;
    let sin0 = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    let kx = ambient * sin0; // n₀ sin θ₀, conserved
    let cos_in = |n: C64| sqrt_branch(C64::new(1.0, 0.0) - (kx / n) * (kx / n));
    let admittance = |n: C64, c: C64| if p { n / c } else { n * c };
    let eta0 = admittance(C64::new(ambient, 0.0), C64::new(cos_theta, 0.0));
    let one = C64::new(1.0, 0.0);
    let zero = C64::new(0.0, 0.0);
    let mut m = [[one, zero], [zero, one]];
    let mut exit_index = exit;
    for film in films {
        let c = cos_in(film.index);
        let delta = k0 * film.index * c * film.thickness_nm;
        if delta.im > 30.0 {
            exit_index = film.index;
            break;
        }
        let eta = admittance(film.index, c);
        let (cd, sd) = (delta.cos(), delta.sin());
        let layer = [[cd, -C64::i() * sd / eta], [-C64::i() * eta * sd, cd]];
        m = [
            [
                m[0][0] * layer[0][0] + m[0][1] * layer[1][0],
                m[0][0] * layer[0][1] + m[0][1] * layer[1][1],
            ],
            [
                m[1][0] * layer[0][0] + m[1][1] * layer[1][0],
                m[1][0] * layer[0][1] + m[1][1] * layer[1][1],
            ],
        ];
    }
    let eta_s = admittance(exit_index, cos_in(exit_index));
    let b = m[0][0] + m[0][1] * eta_s;
    let c = m[1][0] + m[1][1] * eta_s;
    let denominator = eta0 * b + c;
    let r = (eta0 * b - c) / denominator;
    let t = 2.0 * eta0 / denominator;
    let transmitted = if exit_index == exit {
        (eta_s.re / eta0.re) * t.norm_sqr()
    } else {
        0.0
    };
    (
        Powers {
            r: r.norm_sqr(),
            t: transmitted.max(0.0),
        },
        r,
    )
}

/// Natural light: the mean of the s and p powers.
pub fn unpolarised(
    ambient: f64,
    films: &[Film],
    exit: C64,
    wavelength_nm: f64,
    cos_theta: f64,
) -> Powers {
    let (s, _) = stack(ambient, films, exit, wavelength_nm, cos_theta, false);
    let (p, _) = stack(ambient, films, exit, wavelength_nm, cos_theta, true);
    Powers {
        r: 0.5 * (s.r + p.r),
        t: 0.5 * (s.t + p.t),
    }
}
