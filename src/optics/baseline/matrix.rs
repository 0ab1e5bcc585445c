//! Small dense square matrices for the adding–doubling baseline: the
//! reflection and transmission matrices of a layer over the quadrature's
//! directions in one hemisphere (a few tens of rows), with the products and
//! the linear solve the adding formulas need.

use super::BaselineError;

/// A square matrix, row-major.
#[derive(Debug, Clone, PartialEq)]
pub struct Matrix {
    n: usize,
    data: Vec<f64>,
}

impl Matrix {
    /// The `n × n` zero matrix.
    pub fn zeros(n: usize) -> Matrix {
        Matrix {
            n,
            data: vec![0.0; n * n],
        }
    }

    /// The `n × n` identity.
    pub fn identity(n: usize) -> Matrix {
        Matrix::diagonal(&vec![1.0; n])
    }

    /// The diagonal matrix of `d`.
    pub fn diagonal(d: &[f64]) -> Matrix {
        let mut m = Matrix::zeros(d.len());
        for (i, &v) in d.iter().enumerate() {
            m[(i, i)] = v;
        }
        m
    }

    /// The matrix with entries `f(i, j)`.
    pub fn from_fn(n: usize, f: impl Fn(usize, usize) -> f64) -> Matrix {
        let mut m = Matrix::zeros(n);
        for i in 0..n {
            for j in 0..n {
                m[(i, j)] = f(i, j);
            }
        }
        m
    }

    /// Number of rows (= columns).
    pub fn size(&self) -> usize {
        self.n
    }

    /// `self · other`: each entry `Σ_k a_ik b_kj` summed in the order of
    /// `k`, four rows at a time (each row of `other` read once for four
    /// rows of the product), compiled for the widest vector unit the CPU
    /// has ([`wide`]); every path does the same operations per entry
    /// (no fused multiply-add), so the bits do not depend on the CPU.
    pub fn mul(&self, other: &Matrix) -> Matrix {
        let n = self.n;
        let mut out = Matrix::zeros(n);
        wide::mul(n, &self.data, &other.data, &mut out.data);
        out
    }

    /// `self + other`.
    pub fn add(&self, other: &Matrix) -> Matrix {
        let mut out = self.clone();
        for (a, b) in out.data.iter_mut().zip(&other.data) {
            *a += b;
        }
        out
    }

    /// `I − self`.
    pub fn identity_minus(&self) -> Matrix {
        let mut out = self.clone();
        for v in &mut out.data {
            *v = -*v;
        }
        for i in 0..self.n {
            out.data[i * self.n + i] += 1.0;
        }
        out
    }

    /// Column sums: `Σ_i M_ij` per column `j`.
    pub fn column_sums(&self) -> Vec<f64> {
        (0..self.n)
            .map(|j| (0..self.n).map(|i| self[(i, j)]).sum())
            .collect()
    }

    /// The largest absolute entry of `self − other`.
    pub fn max_difference(&self, other: &Matrix) -> f64 {
        self.data
            .iter()
            .zip(&other.data)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max)
    }

    /// `X` with `self · X = rhs`, by Gaussian elimination with partial
    /// pivoting. A singular but consistent system — a direction no light
    /// can reach, such as one trapped between two totally reflecting
    /// surfaces in a layer that neither scatters nor absorbs, where the row
    /// reads `0 = 0` — has that unknown set to 0; an inconsistent one is an
    /// error.
    pub fn solve(&self, rhs: &Matrix) -> Result<Matrix, BaselineError> {
        wide::solve(self, rhs)
    }

    /// The solve's body, compiled into each of [`wide`]'s variants.
    #[inline(always)]
    fn solve_body(&self, rhs: &Matrix) -> Result<Matrix, BaselineError> {
        let n = self.n;
        let mut a = self.data.clone();
        let mut b = rhs.data.clone();
        let scale = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let rhs_scale = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if !(scale.is_finite() && rhs_scale.is_finite()) {
            return Err(BaselineError::Singular);
        }
        let tiny = 1e-14 * scale;
        // Row echelon form; `pivots[r]` is the column of row r's pivot.
        let mut pivots = Vec::with_capacity(n);
        let mut row = 0;
        for col in 0..n {
            if row == n {
                break;
            }
            let pivot = (row..n)
                .max_by(|&p, &q| a[p * n + col].abs().total_cmp(&a[q * n + col].abs()))
                .unwrap_or(row);
            let p = a[pivot * n + col];
            if p.abs() <= tiny {
                continue; // a free unknown, set to 0
            }
            if pivot != row {
                for k in 0..n {
                    a.swap(pivot * n + k, row * n + k);
                    b.swap(pivot * n + k, row * n + k);
                }
            }
            // The pivot row and each row below as separate slices, so the
            // updates vectorise.
            let (a_top, a_rest) = a.split_at_mut((row + 1) * n);
            let (b_top, b_rest) = b.split_at_mut((row + 1) * n);
            let a_pivot = &a_top[row * n + col..(row + 1) * n];
            let b_pivot = &b_top[row * n..(row + 1) * n];
            for (a_row, b_row) in a_rest.chunks_exact_mut(n).zip(b_rest.chunks_exact_mut(n)) {
                let f = a_row[col] / p;
                if f == 0.0 {
                    continue;
                }
                for (t, v) in a_row[col..].iter_mut().zip(a_pivot) {
                    *t -= f * v;
                }
                for (t, v) in b_row.iter_mut().zip(b_pivot) {
                    *t -= f * v;
                }
            }
            pivots.push(col);
            row += 1;
        }
        // The rows without a pivot must read 0 = 0.
        let tolerance = 1e-12 * rhs_scale;
        if b[row * n..].iter().any(|v| v.abs() > tolerance) {
            return Err(BaselineError::Singular);
        }
        // Back substitution a row of X at a time (contiguous rows).
        let mut x = vec![0.0; n * n];
        for (r, &col) in pivots.iter().enumerate().rev() {
            let p = a[r * n + col];
            let (done, rest) = x.split_at_mut((col + 1) * n);
            let target = &mut done[col * n..];
            target.copy_from_slice(&b[r * n..(r + 1) * n]);
            for (c, xc) in rest.chunks_exact(n).enumerate() {
                let f = a[r * n + col + 1 + c];
                if f == 0.0 {
                    continue;
                }
                for (t, v) in target.iter_mut().zip(xc) {
                    *t -= f * v;
                }
            }
            for t in target.iter_mut() {
                *t /= p;
            }
        }
        Ok(Matrix { n, data: x })
    }
}

/// `out += a · b` for row-major `n × n` slices, four rows of `a` at a time.
#[inline(always)]
fn mul_into(n: usize, a: &[f64], b: &[f64], out: &mut [f64]) {
    let mut blocks = out.chunks_exact_mut(4 * n);
    for (block, rows) in (&mut blocks).zip(a.chunks_exact(4 * n)) {
        let (o0, rest) = block.split_at_mut(n);
        let (o1, rest) = rest.split_at_mut(n);
        let (o2, o3) = rest.split_at_mut(n);
        for k in 0..n {
            let (a0, a1, a2, a3) = (rows[k], rows[n + k], rows[2 * n + k], rows[3 * n + k]);
            if a0 == 0.0 && a1 == 0.0 && a2 == 0.0 && a3 == 0.0 {
                continue;
            }
            let row = &b[k * n..(k + 1) * n];
            for ((((d0, d1), d2), d3), v) in o0
                .iter_mut()
                .zip(o1.iter_mut())
                .zip(o2.iter_mut())
                .zip(o3.iter_mut())
                .zip(row)
            {
                *d0 += a0 * v;
                *d1 += a1 * v;
                *d2 += a2 * v;
                *d3 += a3 * v;
            }
        }
    }
    let done = n - n % 4;
    for i in done..n {
        let dst = &mut out[i * n..(i + 1) * n];
        for k in 0..n {
            let x = a[i * n + k];
            if x == 0.0 {
                continue;
            }
            for (d, v) in dst.iter_mut().zip(&b[k * n..(k + 1) * n]) {
                *d += x * v;
            }
        }
    }
}

/// The product and the solve compiled for the widest vector unit the CPU
/// has.
mod wide {
    use super::{mul_into, BaselineError, Matrix};
    use crate::solver::simd::widest;

    widest! {
        pub fn mul(n: usize, a: &[f64], b: &[f64], out: &mut [f64]) -> () = mul_into;
    }

    widest! {
        pub fn solve(m: &Matrix, rhs: &Matrix) -> Result<Matrix, BaselineError> = Matrix::solve_body;
    }
}

impl std::ops::Index<(usize, usize)> for Matrix {
    type Output = f64;
    fn index(&self, (i, j): (usize, usize)) -> &f64 {
        &self.data[i * self.n + j]
    }
}

impl std::ops::IndexMut<(usize, usize)> for Matrix {
    fn index_mut(&mut self, (i, j): (usize, usize)) -> &mut f64 {
        &mut self.data[i * self.n + j]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mul_matches_the_naive_sum() {
        for n in [1, 3, 4, 7, 33] {
            let a = Matrix::from_fn(n, |i, j| ((i * 7 + j * 3) % 5) as f64 * 0.37 - 0.5);
            let b = Matrix::from_fn(n, |i, j| 1.0 / (1.0 + (i + 2 * j) as f64));
            let c = a.mul(&b);
            for i in 0..n {
                for j in 0..n {
                    let mut s = 0.0;
                    for k in 0..n {
                        s += a[(i, k)] * b[(k, j)];
                    }
                    // The same operations in the same order: equal bits.
                    assert_eq!(c[(i, j)], s, "n {n}, ({i}, {j})");
                }
            }
        }
    }

    #[test]
    fn solve_inverts_a_product() {
        let a = Matrix::from_fn(5, |i, j| {
            1.0 / (1.0 + i as f64 + j as f64) + (i == j) as u8 as f64
        });
        let b = Matrix::from_fn(5, |i, j| (i * 5 + j) as f64 - 3.0);
        let x = a.solve(&a.mul(&b)).unwrap();
        assert!(x.max_difference(&b) < 1e-12);
        assert!(Matrix::zeros(3).solve(&Matrix::identity(3)).is_err());
        // Singular but consistent (a row 0 = 0): that unknown is 0.
        let mut m = Matrix::identity(3);
        m[(1, 1)] = 0.0;
        let mut rhs = Matrix::identity(3);
        rhs[(1, 1)] = 0.0;
        let x = m.solve(&rhs).unwrap();
        assert_eq!(x, rhs);
    }
}
