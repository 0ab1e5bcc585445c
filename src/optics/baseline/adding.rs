//! Adding: the reflection and transmission matrices of two layers on top
//! of each other from each layer's, with flat interfaces and the paper as
//! layers of their own.
//!
//! A [`Slab`] holds four flux matrices over the [`Ordinates`]' bins (column:
//! incident bin, row: outgoing bin): reflection and transmission for light
//! arriving from above (`r_down`, `t_down`) and from below (`r_up`, `t_up`).
//! For `top` over `bottom`, with the inter-reflections between them summed
//! as a geometric series (a matrix inverse):
//! - `R↓ = R↓₁ + T↑₁ R↓₂ (I − R↑₁ R↓₂)⁻¹ T↓₁`, `T↓ = T↓₂ (I − R↑₁ R↓₂)⁻¹ T↓₁`;
//! - `R↑ = R↑₂ + T↓₂ R↑₁ (I − R↓₂ R↑₁)⁻¹ T↑₂`, `T↑ = T↑₁ (I − R↓₂ R↑₁)⁻¹ T↑₂`.
//!
//! **Interfaces.** The scalar Helmholtz equation keeps `u` and `∂u/∂z`
//! continuous across a flat interface (`solver/airy`): that is the
//! s-polarised (TE) Fresnel coefficient, `r = (n₁μ₁ − n₂μ₂)/(n₁μ₁ + n₂μ₂)`,
//! reflectance `r²`, transmittance `1 − r²` — the scalar interface. Beside
//! a Maxwell solve the interface reflects natural light, the mean of the s
//! and p powers ([`Fresnel`]). Between the binder
//! (`n`) and air a bin keeps its flux across the surface (the bins are
//! matched by refraction, [`Ordinates`]), so an interface is diagonal:
//! `r(μ_i)` for an escaping bin, and total internal reflection (1 from
//! inside, no flux from outside) for a trapped one.

pub use super::fresnel::fresnel_scalar;
use super::fresnel::Fresnel;
use super::matrix::Matrix;
use super::ordinates::Ordinates;
use super::BaselineError;

/// Reflection and transmission flux matrices of a layer, both faces.
#[derive(Debug, Clone, PartialEq)]
pub struct Slab {
    /// Reflection of light arriving from above.
    pub r_down: Matrix,
    /// Reflection of light arriving from below.
    pub r_up: Matrix,
    /// Transmission of light arriving from above (leaving below).
    pub t_down: Matrix,
    /// Transmission of light arriving from below (leaving above).
    pub t_up: Matrix,
}

impl Slab {
    /// A layer that reflects and transmits alike from both faces.
    pub fn symmetric(r: Matrix, t: Matrix) -> Slab {
        Slab {
            r_up: r.clone(),
            r_down: r,
            t_up: t.clone(),
            t_down: t,
        }
    }

    /// Nothing at all: `R = 0`, `T = I`.
    pub fn transparent(n: usize) -> Slab {
        Slab::symmetric(Matrix::zeros(n), Matrix::identity(n))
    }

    /// The same layer upside down.
    pub fn flipped(&self) -> Slab {
        Slab {
            r_down: self.r_up.clone(),
            r_up: self.r_down.clone(),
            t_down: self.t_up.clone(),
            t_up: self.t_down.clone(),
        }
    }
}

/// `top` on `bottom`.
pub fn add(top: &Slab, bottom: &Slab) -> Result<Slab, BaselineError> {
    // Light from above, after the first pass through `top`.
    let down = top
        .r_up
        .mul(&bottom.r_down)
        .identity_minus()
        .solve(&top.t_down)?;
    // Light from below, after the first pass through `bottom`.
    let up = bottom
        .r_down
        .mul(&top.r_up)
        .identity_minus()
        .solve(&bottom.t_up)?;
    Ok(Slab {
        r_down: top.r_down.add(&top.t_up.mul(&bottom.r_down).mul(&down)),
        t_down: bottom.t_down.mul(&down),
        r_up: bottom.r_up.add(&bottom.t_down.mul(&top.r_up).mul(&up)),
        t_up: top.t_up.mul(&up),
    })
}

/// Reflection of `top` (from above) on a backing that only reflects,
/// `R↓₁ + T↑₁ R_b (I − R↑₁ R_b)⁻¹ T↓₁`: [`add`] without the transmissions.
pub fn on_backing(top: &Slab, backing: &Matrix) -> Result<Matrix, BaselineError> {
    let down = top.r_up.mul(backing).identity_minus().solve(&top.t_down)?;
    Ok(top.r_down.add(&top.t_up.mul(backing).mul(&down)))
}

/// The flat binder surface with air above and the binder below, reflecting
/// by `fresnel`.
pub fn surface_air_over_binder(ords: &Ordinates, fresnel: Fresnel) -> Slab {
    let n = ords.binder_index;
    let k = ords.len();
    let (mut r_air, mut r_binder, mut t) = (vec![0.0; k], vec![0.0; k], vec![0.0; k]);
    for i in 0..k {
        match ords.mu_air[i] {
            Some(mu_a) => {
                let r = fresnel.between(n, ords.mu[i], mu_a);
                r_air[i] = r;
                r_binder[i] = r;
                t[i] = 1.0 - r;
            }
            // Trapped: total internal reflection inside, nothing outside.
            None => r_binder[i] = 1.0,
        }
    }
    Slab {
        r_down: Matrix::diagonal(&r_air),
        r_up: Matrix::diagonal(&r_binder),
        t_down: Matrix::diagonal(&t),
        t_up: Matrix::diagonal(&t),
    }
}

/// The flat binder surface with the binder above and air below.
pub fn surface_binder_over_air(ords: &Ordinates, fresnel: Fresnel) -> Slab {
    surface_air_over_binder(ords, fresnel).flipped()
}

/// Reflection matrix of a Lambertian paper of albedo `albedo` under air:
/// every arriving flux leaves as `albedo` spread over the air bins
/// (`n² c_i` each; the trapped bins receive nothing).
pub fn lambertian_in_air(ords: &Ordinates, albedo: f64) -> Matrix {
    let k = ords.len();
    Matrix::from_fn(k, |i, _| albedo * ords.air_flux_weight(i))
}

/// Reflection matrix of a Lambertian paper in optical contact with the
/// binder: `albedo` spread over every binder bin (`c_i` each).
pub fn lambertian_in_binder(ords: &Ordinates, albedo: f64) -> Matrix {
    let k = ords.len();
    Matrix::from_fn(k, |i, _| albedo * ords.flux_weight[i])
}
