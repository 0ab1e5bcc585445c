//! Complex arithmetic on `W` lanes at once (split real and imaginary
//! parts), written so LLVM vectorises it, a dispatcher that runs a kernel
//! compiled for the widest vector unit the CPU has, and the copy of one
//! spectral row into contiguous lanes and back ([`RowCells`]) that the
//! row sweeps of [`operator`](super::operator) and [`shift`](super::shift)
//! share. Each lane does exactly the operations of `num_complex` (no fused
//! multiply-add), so every code path gives the same bits.

use ndarray::ArrayViewMut2;
use num_complex::Complex64 as C64;
use std::ops::{Add, Mul, Sub};

/// How many cells ahead the row copy prefetches a spectral row.
const AHEAD: usize = 3;

/// Lanes per operation: one AVX-512 register of real parts and one of
/// imaginary parts.
pub const W: usize = 8;

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cx {
    pub re: [f64; W],
    pub im: [f64; W],
}

impl Cx {
    pub const ZERO: Cx = Cx {
        re: [0.0; W],
        im: [0.0; W],
    };

    /// Every lane `c`.
    #[inline(always)]
    pub fn splat(c: C64) -> Cx {
        Cx {
            re: [c.re; W],
            im: [c.im; W],
        }
    }

    #[inline(always)]
    pub fn lane(&self, k: usize) -> C64 {
        C64::new(self.re[k], self.im[k])
    }

    #[inline(always)]
    pub fn set(&mut self, k: usize, c: C64) {
        self.re[k] = c.re;
        self.im[k] = c.im;
    }

    /// Lanes from `src` (at most `W` values; the rest zero).
    #[inline(always)]
    pub fn load(src: &[C64]) -> Cx {
        let mut x = Cx::ZERO;
        // A full block as an array, so the copy compiles to vector shuffles.
        if let Ok(src) = <&[C64; W]>::try_from(src) {
            for (k, c) in src.iter().enumerate() {
                x.re[k] = c.re;
                x.im[k] = c.im;
            }
        } else {
            for (k, c) in src.iter().enumerate() {
                x.re[k] = c.re;
                x.im[k] = c.im;
            }
        }
        x
    }

    /// The first `dst.len()` (at most `W`) lanes into `dst`.
    #[inline(always)]
    pub fn store(&self, dst: &mut [C64]) {
        if let Ok(dst) = <&mut [C64; W]>::try_from(&mut *dst) {
            for (k, c) in dst.iter_mut().enumerate() {
                *c = C64::new(self.re[k], self.im[k]);
            }
        } else {
            for (k, c) in dst.iter_mut().enumerate() {
                *c = C64::new(self.re[k], self.im[k]);
            }
        }
    }
}

impl Add for Cx {
    type Output = Cx;
    #[inline(always)]
    fn add(self, o: Cx) -> Cx {
        let mut r = Cx::ZERO;
        for k in 0..W {
            r.re[k] = self.re[k] + o.re[k];
            r.im[k] = self.im[k] + o.im[k];
        }
        r
    }
}

impl Sub for Cx {
    type Output = Cx;
    #[inline(always)]
    fn sub(self, o: Cx) -> Cx {
        let mut r = Cx::ZERO;
        for k in 0..W {
            r.re[k] = self.re[k] - o.re[k];
            r.im[k] = self.im[k] - o.im[k];
        }
        r
    }
}

impl Mul for Cx {
    type Output = Cx;
    /// As `num_complex`: `(ac − bd, ad + bc)`.
    #[inline(always)]
    fn mul(self, o: Cx) -> Cx {
        let mut r = Cx::ZERO;
        for k in 0..W {
            r.re[k] = self.re[k] * o.re[k] - self.im[k] * o.im[k];
            r.im[k] = self.re[k] * o.im[k] + self.im[k] * o.re[k];
        }
        r
    }
}

/// Ask the cache for `data` ahead of its use. The sweeps read a
/// spectral row's cells a power of two apart, one page each, where the
/// hardware prefetchers do not reach.
#[inline(always)]
fn prefetch(data: &[C64]) {
    #[cfg(target_arch = "x86_64")]
    for line in data.chunks(4) {
        // SAFETY: a prefetch hint never faults and changes no state the
        // program can observe; the address lies inside `data`.
        unsafe {
            use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
            _mm_prefetch::<_MM_HINT_T0>(line.as_ptr().cast());
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = data;
}

/// `fn name(args) -> R` that runs `body(args)` compiled for AVX-512 or
/// AVX2 where the CPU has them: `body` is `#[inline(always)]`, so it is
/// compiled into each `#[target_feature]` variant with its wider
/// registers (a closure handed to [`dispatch`] is inlined only when LLVM
/// finds it small enough). Each variant does the same operations as the
/// portable one, so the bits do not depend on the CPU.
macro_rules! widest {
    ($(#[$doc:meta])* $vis:vis fn $name:ident($($arg:ident: $ty:ty),* $(,)?) -> $ret:ty = $body:path;) => {
        $(#[$doc])*
        $vis fn $name($($arg: $ty),*) -> $ret {
            #[cfg(target_arch = "x86_64")]
            {
                #[target_feature(enable = "avx512f")]
                fn avx512($($arg: $ty),*) -> $ret {
                    $body($($arg),*)
                }
                #[target_feature(enable = "avx2")]
                fn avx2($($arg: $ty),*) -> $ret {
                    $body($($arg),*)
                }
                match $crate::solver::simd::unit() {
                    // SAFETY: `unit` found AVX-512F on this CPU.
                    $crate::solver::simd::Unit::Avx512 => return unsafe { avx512($($arg),*) },
                    // SAFETY: `unit` found AVX2 on this CPU.
                    $crate::solver::simd::Unit::Avx2 => return unsafe { avx2($($arg),*) },
                    $crate::solver::simd::Unit::Portable => {}
                }
            }
            $body($($arg),*)
        }
    };
}
pub(crate) use widest;

/// Run `f`, compiled for AVX-512 or AVX2 where the CPU has them (the
/// kernels are `#[inline(always)]`, so they are compiled into these
/// wrappers with the wider registers).
#[inline(always)]
pub fn dispatch<R>(f: impl FnOnce() -> R) -> R {
    #[cfg(target_arch = "x86_64")]
    match unit() {
        // SAFETY: `unit` found AVX-512F on this CPU.
        Unit::Avx512 => return unsafe { avx512(f) },
        // SAFETY: `unit` found AVX2 on this CPU.
        Unit::Avx2 => return unsafe { avx2(f) },
        Unit::Portable => {}
    }
    f()
}

/// The vector units the kernels are compiled for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Unit {
    Avx512,
    Avx2,
    Portable,
}

/// The widest of them this CPU has (what [`dispatch`] and [`widest!`] run
/// on).
#[inline(always)]
pub fn unit() -> Unit {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx512f") {
            return Unit::Avx512;
        }
        if std::arch::is_x86_feature_detected!("avx2") {
            return Unit::Avx2;
        }
    }
    Unit::Portable
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
fn avx512<R>(f: impl FnOnce() -> R) -> R {
    f()
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn avx2<R>(f: impl FnOnce() -> R) -> R {
    f()
}

/// A spectral row's cells in contiguous scratch, layout (block of `W`
/// harmonics, cell): the row's cells lie a power of two apart in the
/// spectrum, so a sweep reads them once into here (prefetching a few cells
/// ahead, where the hardware prefetchers do not reach) and writes its result
/// back at the end.
pub struct RowCells {
    cells: Vec<Cx>,
}

impl RowCells {
    /// Room for rows of `n` cells and `ny` harmonics.
    pub fn new(n: usize, ny: usize) -> Self {
        RowCells {
            cells: vec![Cx::ZERO; n * ny.div_ceil(W)],
        }
    }

    /// Copy `row` ((n, ny), cell index outermost) in, block `b` of each cell
    /// as `load(b, lanes)`; returns the `n` cells of each block, block by block.
    #[inline(always)]
    pub fn gather(
        &mut self,
        row: &ArrayViewMut2<C64>,
        load: impl Fn(usize, Cx) -> Cx,
    ) -> std::slice::ChunksExactMut<'_, Cx> {
        let (n, ny) = row.dim();
        let nb = ny.div_ceil(W);
        let cells = &mut self.cells[..nb * n];
        for j in 0..n {
            if j + AHEAD < n {
                prefetch(
                    row.row(j + AHEAD)
                        .as_slice()
                        .expect("contiguous spectral row"),
                );
            }
            let r = row.row(j);
            let r = r.as_slice().expect("contiguous spectral row");
            for b in 0..nb {
                cells[b * n + j] = load(b, Cx::load(&r[b * W..ny.min((b + 1) * W)]));
            }
        }
        cells.chunks_exact_mut(n)
    }

    /// Write the cells back into `row` (the inverse of [`Self::gather`]).
    #[inline(always)]
    pub fn scatter(&self, row: &mut ArrayViewMut2<C64>) {
        let (n, ny) = row.dim();
        let nb = ny.div_ceil(W);
        for j in 0..n {
            let mut r = row.row_mut(j);
            let r = r.as_slice_mut().expect("contiguous spectral row");
            for b in 0..nb {
                self.cells[b * n + j].store(&mut r[b * W..ny.min((b + 1) * W)]);
            }
        }
    }
}
