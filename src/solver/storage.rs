//! How the iterative methods store their fields.
//!
//! Every Krylov vector, iterate and residual is an `Array3<S>` with `S` a
//! [`Storage`]: complex f64 (default) or complex f32 (half the memory, the
//! `precision = "f32"` option). Values are loaded into f64 for every
//! arithmetic step; operator applications, inner products and norms run in
//! f64 and only the stored result is rounded, so f32 storage costs about one
//! f32 rounding (6e-8 relative) per stored vector and nothing else.
//!
//! The object-safe method interface passes a field as a [`Field`] (either
//! storage); `on_field!` and `with_storage!` turn it, or a [`Precision`],
//! back into a call of a generic function.

use crate::config::Precision;
use ndarray::{Array3, ArrayView3};
use num_complex::{Complex32 as C32, Complex64 as C64};
use rayon::prelude::*;

/// A field, (nz, ny, nx), in the storage of its [`Precision`].
pub enum Field {
    F64(Array3<C64>),
    F32(Array3<C32>),
}

impl Field {
    /// Zeros in the storage of `precision`.
    pub fn zeros(precision: Precision, dim: (usize, usize, usize)) -> Field {
        match precision {
            Precision::F64 => Field::F64(Array3::default(dim)),
            Precision::F32 => Field::F32(Array3::default(dim)),
        }
    }

    pub fn precision(&self) -> Precision {
        match self {
            Field::F64(_) => Precision::F64,
            Field::F32(_) => Precision::F32,
        }
    }

    /// Every entry from `src` (same shape), rounded to this storage.
    pub fn load_from(&mut self, src: &Array3<C64>) {
        on_field!(self, u => ndarray::Zip::from(u).and(src).par_for_each(|u, s| *u = Storage::store(*s)))
    }
}

/// `$body` with `$u` bound to the array inside a [`Field`] (by value,
/// reference or mutable reference, as `$field` is), whatever its storage.
macro_rules! on_field {
    ($field:expr, $u:ident => $body:expr) => {
        match $field {
            $crate::solver::storage::Field::F64($u) => $body,
            $crate::solver::storage::Field::F32($u) => $body,
        }
    };
}
pub(crate) use on_field;

/// `$body` with the type `$s` standing for the [`Storage`] of a [`Precision`].
macro_rules! with_storage {
    ($precision:expr, $s:ident => $body:expr) => {
        match $precision {
            $crate::config::Precision::F64 => {
                type $s = num_complex::Complex64;
                $body
            }
            $crate::config::Precision::F32 => {
                type $s = num_complex::Complex32;
                $body
            }
        }
    };
}
pub(crate) use with_storage;

/// A complex field element: f64 or f32.
pub trait Storage: Copy + Send + Sync + Default + 'static {
    /// Bytes per stored value.
    const BYTES: usize;
    fn load(self) -> C64;
    fn store(v: C64) -> Self;
}

impl Storage for C64 {
    const BYTES: usize = 16;
    #[inline(always)]
    fn load(self) -> C64 {
        self
    }
    #[inline(always)]
    fn store(v: C64) -> Self {
        v
    }
}

impl Storage for C32 {
    const BYTES: usize = 8;
    #[inline(always)]
    fn load(self) -> C64 {
        C64::new(self.re as f64, self.im as f64)
    }
    #[inline(always)]
    fn store(v: C64) -> Self {
        C32::new(v.re as f32, v.im as f32)
    }
}

/// Σ f(a, b) over all voxels in f64, parallel over z-slices but summed in a
/// fixed order, so the result is bit-identical for any thread count.
pub fn sum_slices<A: Sync, B: Sync>(
    a: ArrayView3<A>,
    f: impl Fn(&A, &B) -> f64 + Sync,
    b: ArrayView3<B>,
) -> f64 {
    let parts: Vec<f64> = a
        .outer_iter()
        .into_par_iter()
        .zip(b.outer_iter().into_par_iter())
        .map(|(sa, sb)| sa.iter().zip(sb.iter()).map(|(x, y)| f(x, y)).sum())
        .collect();
    parts.iter().sum()
}

/// ⟨a, b⟩ = Σ conj(a) b in f64, summed per z-slice in parallel and then in a
/// fixed order (thread-count independent).
pub fn dot<S: Storage>(a: &Array3<S>, b: &Array3<S>) -> C64 {
    let parts: Vec<C64> = a
        .outer_iter()
        .into_par_iter()
        .zip(b.outer_iter().into_par_iter())
        .map(|(sa, sb)| {
            sa.iter()
                .zip(sb.iter())
                .map(|(x, y)| x.load().conj() * y.load())
                .sum()
        })
        .collect();
    parts.iter().sum()
}

/// ‖a‖² in f64 (thread-count independent).
pub fn norm_sqr<S: Storage>(a: &Array3<S>) -> f64 {
    sum_slices(a.view(), |x: &S, _: &S| x.load().norm_sqr(), a.view())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn f32_round_trip_is_one_rounding() {
        let v = C64::new(0.1, -1.0 / 3.0);
        let back = C32::store(v).load();
        assert!((back - v).norm() / v.norm() < 6e-8);
        assert!((back - v).norm() > 0.0, "f32 must actually round");
        assert_eq!(C64::store(v).load(), v);
    }

    #[test]
    fn reductions_run_in_f64() {
        // 1e8 + 1 rounds back to 1e8 in f32; the sums must not.
        let mut a = Array3::from_elem((4, 8, 8), C32::new(1.0, 0.0));
        for k in 0..4 {
            a[[k, 0, 0]] = C32::new(1e4, 0.0);
        }
        assert_eq!(norm_sqr(&a), 4e8 + 252.0);
        assert_eq!(dot(&a, &a), C64::new(4e8 + 252.0, 0.0));
    }
}
