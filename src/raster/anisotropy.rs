//! The anisotropic permittivity of voxels that a grain surface cuts
//! (METHOD §3, "Surface voxels in Maxwell's equations").
//!
//! A voxel cut by a grain surface holds two media side by side. Volume
//! averaging gives it the arithmetic mean `ε_t = Σ f_i ε_i` for every field
//! direction, which is right for the field's components along the surface
//! (E_t is continuous, so the mean of D_t is `ε_t E_t`) but wrong for the
//! component along the normal, where D_n is continuous and E_n jumps: there
//! the mean of E is `D_n Σ f_i/ε_i`, the harmonic mean `ε_n`. The voxel's
//! permittivity is therefore the uniaxial tensor
//!
//! `ε = ε_t I + (ε_n − ε_t) n̂ n̂ᵀ`
//!
//! with n̂ the surface normal in the voxel (Farjadpour et al. 2006; Kottke,
//! Farjadpour & Johnson 2008). With it the grid error of a smooth
//! interface falls at second order in the cell instead of first.
//!
//! [`SurfaceNormals`] keeps, per z-slice, the normal of every voxel a grain
//! surface cuts (made once by the rasteriser, like the volume fractions);
//! [`Anisotropy`] is the per-wavelength result, the correction
//! `δ n̂ n̂ᵀ` with `δ = ε_n − ε_t` of each such voxel, which the Maxwell
//! operator adds to the scalar permittivity grid. It stores a list of
//! uniaxial terms `δ â âᵀ`, sorted by voxel, several allowed per voxel, so
//! that other tensor parts (a crystal's axis) take the same form.
//!
//! A uniaxial crystal grain (ordinary `ε_o`, extraordinary `ε_e`, optic axis
//! ĉ) is the tensor `ε_o I + (ε_e − ε_o) ĉĉᵀ`. Where the grid holds its
//! orientation average `ε̄ = (2ε_o + ε_e)/3` at share `f`, the voxel's scalar
//! part moves by `f (ε_o − ε̄)` and it gains the term `f (ε_e − ε_o) ĉĉᵀ`;
//! a cut voxel's surface term takes the crystal's `ε_o` in its means.
//!
//! Where the harmonic mean is not used: a voxel with a constituent whose
//! `Re ε ≤ 0` (a metal; the harmonic mean can pass through a pole there), a
//! voxel whose grain share rounds to 0 or 1, and the surface of an explicit
//! structure (no normals): those keep the arithmetic mean, isotropic.

use num_complex::Complex64;

/// Grain shares within this of 0 or 1 make a voxel uncut.
pub const CUT_SHARE: f64 = 1e-9;

/// A crystal grain's share of one voxel of a slice, with its axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GrainShare {
    /// `ix + nx · iy` within the slice.
    pub index: u32,
    /// The grain's species.
    pub species: u32,
    /// The grain's volume fraction of the voxel.
    pub share: f64,
    /// The crystal's optic (c) axis, a unit vector.
    pub axis: [f64; 3],
}

/// The grain surface's unit normal in one voxel of a slice.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Normal {
    /// `ix + nx · iy` within the slice.
    pub index: u32,
    /// Unit vector (x, y, z).
    pub n: [f64; 3],
}

/// The normals of the cut voxels, per z-slice, sorted by index.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SurfaceNormals {
    pub slices: Vec<Vec<Normal>>,
}

impl SurfaceNormals {
    /// Sum the weighted normals that one slice's particles pushed (any
    /// order, repeats allowed) per voxel, normalise them and sort by index;
    /// voxels whose sum vanishes are dropped.
    pub fn merge_slice(mut raw: Vec<Normal>) -> Vec<Normal> {
        raw.sort_by_key(|n| n.index);
        let mut out: Vec<Normal> = Vec::with_capacity(raw.len());
        for r in raw {
            match out.last_mut() {
                Some(last) if last.index == r.index => {
                    for a in 0..3 {
                        last.n[a] += r.n[a];
                    }
                }
                _ => out.push(r),
            }
        }
        out.retain_mut(|v| {
            let len = (v.n[0] * v.n[0] + v.n[1] * v.n[1] + v.n[2] * v.n[2]).sqrt();
            if len > 0.0 && len.is_finite() {
                v.n = [v.n[0] / len, v.n[1] / len, v.n[2] / len];
                true
            } else {
                false
            }
        });
        out
    }
}

/// One uniaxial part `δ â âᵀ` of a voxel's permittivity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Term {
    /// `ix + nx · iy` within the slice.
    pub index: u32,
    /// Unit axis (x, y, z).
    pub axis: [f64; 3],
    pub delta: Complex64,
}

/// The tensor part of a permittivity grid: voxel `v` of slice `iz` has
/// `ε_v I + Σ δ â âᵀ` over its terms, which are `terms[offsets[iz] ..
/// offsets[iz + 1]]`, sorted by index.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Anisotropy {
    /// Slice shape `(ny, nx)`.
    pub plane: (usize, usize),
    pub offsets: Vec<usize>,
    pub terms: Vec<Term>,
}

impl Anisotropy {
    /// No terms, for `nz` slices of `(ny, nx)`.
    pub fn empty(nz: usize, plane: (usize, usize)) -> Anisotropy {
        Anisotropy {
            plane,
            offsets: vec![0; nz + 1],
            terms: Vec::new(),
        }
    }

    pub fn nz(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    /// The terms of slice `iz`.
    pub fn slice(&self, iz: usize) -> &[Term] {
        &self.terms[self.offsets[iz]..self.offsets[iz + 1]]
    }

    pub fn is_empty(&self) -> bool {
        self.terms.is_empty()
    }

    /// The terms of slice `iz` grouped by voxel (one slice of terms per
    /// voxel that has any).
    pub fn voxel_terms(&self, iz: usize) -> impl Iterator<Item = &[Term]> {
        self.slice(iz).chunk_by(|a, b| a.index == b.index)
    }

    /// Clear, keeping the allocation, for `nz` slices.
    pub fn clear(&mut self, nz: usize, plane: (usize, usize)) {
        self.plane = plane;
        self.offsets.clear();
        self.offsets.resize(nz + 1, 0);
        self.terms.clear();
    }

    /// The same tensor field with z reversed (slice `iz` becomes
    /// `nz − 1 − iz` and every axis's z component changes sign), for a
    /// layer lit from below.
    pub fn flipped(&self) -> Anisotropy {
        let nz = self.nz();
        let mut out = Anisotropy::empty(nz, self.plane);
        for iz in (0..nz).rev() {
            out.terms.extend(self.slice(iz).iter().map(|t| Term {
                axis: [t.axis[0], t.axis[1], -t.axis[2]],
                ..*t
            }));
            out.offsets[nz - iz] = out.terms.len();
        }
        out
    }

    /// Every δ divided by `s` (a grid scaled to an embedding medium).
    pub fn scale(&mut self, s: Complex64) {
        for t in &mut self.terms {
            t.delta /= s;
        }
    }
}

/// The normal-direction permittivity of a cut voxel: the harmonic mean
/// `1 / Σ f_i/ε_i` of the background (share `1 − F`) and the species
/// (shares `f_s`), or `None` where it is not used (a constituent with
/// `Re ε ≤ 0` present, or the voxel is not cut).
pub fn harmonic_mean(
    eps_bg: Complex64,
    shares: impl Iterator<Item = (f64, Complex64)>,
) -> Option<Complex64> {
    let mut total = 0.0;
    let mut inv = Complex64::new(0.0, 0.0);
    let mut kinds = 0;
    for (f, e) in shares {
        if f <= 0.0 {
            continue;
        }
        if e.re <= 0.0 {
            return None;
        }
        total += f;
        inv += f / e;
        kinds += 1;
    }
    let rest = 1.0 - total;
    if rest > CUT_SHARE {
        if eps_bg.re <= 0.0 {
            return None;
        }
        inv += rest / eps_bg;
        kinds += 1;
    }
    if kinds < 2 || total < CUT_SHARE {
        return None;
    }
    Some(1.0 / inv)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn harmonic_mean_of_two_media() {
        let (a, b) = (Complex64::new(2.25, 0.0), Complex64::new(7.0, 0.5));
        let h = harmonic_mean(a, [(0.3, b)].into_iter()).unwrap();
        let want = 1.0 / (0.7 / a + 0.3 / b);
        assert!((h - want).norm() < 1e-14);
        // Passive constituents give a passive mean, below the arithmetic one.
        assert!(h.im >= 0.0 && h.re < (0.7 * a + 0.3 * b).re);
        // Not cut, or a metal present: no harmonic mean.
        assert!(harmonic_mean(a, [(1.0, b)].into_iter()).is_none());
        assert!(harmonic_mean(a, [(0.0, b)].into_iter()).is_none());
        let metal = Complex64::new(-40.0, 10.0);
        assert!(harmonic_mean(a, [(0.5, metal)].into_iter()).is_none());
        // Two species filling the voxel between them are cut.
        let two = harmonic_mean(a, [(0.5, b), (0.5, a)].into_iter()).unwrap();
        assert!((two - 1.0 / (0.5 / b + 0.5 / a)).norm() < 1e-14);
    }

    #[test]
    fn normals_merge_per_voxel() {
        let raw = vec![
            Normal {
                index: 5,
                n: [0.0, 0.0, 2.0],
            },
            Normal {
                index: 1,
                n: [3.0, 0.0, 0.0],
            },
            Normal {
                index: 5,
                n: [0.0, 2.0, 0.0],
            },
            Normal {
                index: 7,
                n: [0.0, 0.0, 0.0],
            },
        ];
        let m = SurfaceNormals::merge_slice(raw);
        assert_eq!(m.len(), 2);
        assert_eq!(m[0].index, 1);
        assert_eq!(m[0].n, [1.0, 0.0, 0.0]);
        let s = 0.5f64.sqrt();
        assert!((m[1].n[1] - s).abs() < 1e-15 && (m[1].n[2] - s).abs() < 1e-15);
    }

    #[test]
    fn flip_reverses_slices_and_z() {
        let mut a = Anisotropy::empty(2, (1, 2));
        a.terms.push(Term {
            index: 1,
            axis: [0.0, 0.6, 0.8],
            delta: Complex64::new(-1.0, 0.1),
        });
        a.offsets = vec![0, 1, 1];
        let f = a.flipped();
        assert!(f.slice(0).is_empty());
        assert_eq!(f.slice(1)[0].axis, [0.0, 0.6, -0.8]);
        assert_eq!(f.flipped(), a);
    }
}
