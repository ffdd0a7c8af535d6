//! Dense symmetric positive semi-definite solve for the Delassus system `A λ = b`
//! (A = J M⁻¹ Jᵀ, small: one row per constraint equation). Cholesky when A is positive definite;
//! when a pivot vanishes (redundant rows, e.g. a planar loop closed by a 3-row connect) the
//! minimum-norm solution `A⁺ b` from a cyclic Jacobi eigendecomposition (Golub & Van Loan,
//! *Matrix Computations*, 4th ed., §8.5). Works in caller-provided buffers: no allocation.

use super::RANK_TOLERANCE;
use nalgebra::{DMatrix, DVector};

/// Solves `A x = b` for the symmetric PSD `a` (its top-left n × n block, n = `b.len()`), in place:
/// `b` holds x on return. `work` (at least n × n) and `vec` (at least n) are scratch; `a` is
/// overwritten when the fallback runs. Returns the numerical rank of A: n for a regular system,
/// less when the minimum-norm solution (zero multipliers along the null space of A) was taken.
pub(crate) fn solve_psd(
    a: &mut DMatrix<f64>,
    b: &mut [f64],
    work: &mut DMatrix<f64>,
    vec: &mut DVector<f64>,
) -> usize {
    let n = b.len();
    if n == 0 {
        return 0;
    }
    let scale = (0..n).map(|i| a[(i, i)].abs()).fold(0.0, f64::max);
    if scale == 0.0 || !scale.is_finite() {
        b.fill(0.0);
        return 0;
    }
    if cholesky(a, n, work, scale * RANK_TOLERANCE) {
        cholesky_solve(work, n, b);
        return n;
    }
    min_norm_solve(a, n, b, work, vec)
}

/// Lower Cholesky factor of A into `l`; false if a pivot is not above `tol`. Only A's lower
/// triangle is read.
///
/// Column by column (left-looking), each column's entries updated by the earlier columns in
/// ascending order — per entry the same operations in the same order as the textbook row form
/// `l_ij = (a_ij − Σ_k l_ik l_jk) / l_jj`, so the factor is the same to the bit, but every inner
/// loop runs down a column (contiguous in nalgebra's column-major storage), and columns whose
/// entry in row j is zero are skipped (they subtract exact zeros).
pub(crate) fn cholesky(a: &DMatrix<f64>, n: usize, l: &mut DMatrix<f64>, tol: f64) -> bool {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2 (checked just above), all `cholesky_avx2` requires.
        return unsafe { cholesky_avx2(a, n, l, tol) };
    }
    cholesky_kernel(a, n, l, tol)
}

/// [`cholesky_kernel`] compiled for AVX2: the same operations in the same order (no fused
/// multiply–adds), four entries of a column per instruction, so the same bits.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn cholesky_avx2(a: &DMatrix<f64>, n: usize, l: &mut DMatrix<f64>, tol: f64) -> bool {
    cholesky_kernel(a, n, l, tol)
}

#[inline(always)]
fn cholesky_kernel(a: &DMatrix<f64>, n: usize, l: &mut DMatrix<f64>, tol: f64) -> bool {
    let stride = l.nrows();
    let a_stride = a.nrows();
    let (a_s, ls) = (a.as_slice(), l.as_mut_slice());
    for j in 0..n {
        let cj = j * stride;
        // The earlier columns (read) and column j (written) as disjoint slices, so that the
        // inner loops run without bounds checks or aliasing and vectorize (a separate multiply
        // and subtract per entry, as the scalar form: the same bits).
        let (done, rest) = ls.split_at_mut(cj);
        let col_j = &mut rest[j..n];
        col_j.copy_from_slice(&a_s[j * a_stride + j..j * a_stride + n]);
        for k in 0..j {
            let col_k = &done[k * stride + j..k * stride + n];
            let ljk = col_k[0];
            if ljk == 0.0 {
                continue;
            }
            for (x, &y) in col_j.iter_mut().zip(col_k) {
                *x -= y * ljk;
            }
        }
        let d = col_j[0];
        if d <= tol {
            return false;
        }
        let d = d.sqrt();
        col_j[0] = d;
        for x in &mut col_j[1..] {
            *x /= d;
        }
    }
    true
}

/// Solves L Lᵀ x = b in place with the factor of [`cholesky`] (forward substitution column by
/// column, per entry in the same order as the row form; back substitution by rows of Lᵀ, which
/// are L's columns).
pub(crate) fn cholesky_solve(l: &DMatrix<f64>, n: usize, b: &mut [f64]) {
    let stride = l.nrows();
    let ls = l.as_slice();
    let b = &mut b[..n];
    for k in 0..n {
        let col_k = &ls[k * stride + k..k * stride + n];
        let (head, tail) = b[k..].split_at_mut(1);
        head[0] /= col_k[0];
        let bk = head[0];
        if bk != 0.0 {
            for (x, &y) in tail.iter_mut().zip(&col_k[1..]) {
                *x -= y * bk;
            }
        }
    }
    for i in (0..n).rev() {
        let col_i = &ls[i * stride + i..i * stride + n];
        let (head, tail) = b[i..].split_at_mut(1);
        let mut s = head[0];
        for (&y, &x) in col_i[1..].iter().zip(tail.iter()) {
            s -= y * x;
        }
        head[0] = s / col_i[0];
    }
}

/// x = V diag(1/σ) Vᵀ b over the eigenvalues σ above the tolerance (A's eigenvectors V by cyclic
/// Jacobi rotations; `a` becomes diagonal).
fn min_norm_solve(
    a: &mut DMatrix<f64>,
    n: usize,
    b: &mut [f64],
    v: &mut DMatrix<f64>,
    vtb: &mut DVector<f64>,
) -> usize {
    for i in 0..n {
        for j in 0..n {
            v[(i, j)] = if i == j { 1.0 } else { 0.0 };
        }
    }
    let norm: f64 =
        (0..n).flat_map(|i| (0..n).map(move |j| (i, j))).map(|(i, j)| a[(i, j)].powi(2)).sum::<f64>().sqrt();
    for _sweep in 0..60 {
        let off: f64 = (0..n)
            .flat_map(|i| (0..n).map(move |j| (i, j)))
            .filter(|(i, j)| i != j)
            .map(|(i, j)| a[(i, j)].powi(2))
            .sum::<f64>()
            .sqrt();
        if off <= 1e-15 * norm {
            break;
        }
        for p in 0..n {
            for q in p + 1..n {
                let apq = a[(p, q)];
                if apq.abs() <= f64::MIN_POSITIVE {
                    continue;
                }
                let theta = (a[(q, q)] - a[(p, p)]) / (2.0 * apq);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                // A ← Gᵀ A G on columns then rows p, q; V ← V G.
                for k in 0..n {
                    let (akp, akq) = (a[(k, p)], a[(k, q)]);
                    a[(k, p)] = c * akp - s * akq;
                    a[(k, q)] = s * akp + c * akq;
                }
                for k in 0..n {
                    let (apk, aqk) = (a[(p, k)], a[(q, k)]);
                    a[(p, k)] = c * apk - s * aqk;
                    a[(q, k)] = s * apk + c * aqk;
                }
                for k in 0..n {
                    let (vkp, vkq) = (v[(k, p)], v[(k, q)]);
                    v[(k, p)] = c * vkp - s * vkq;
                    v[(k, q)] = s * vkp + c * vkq;
                }
            }
        }
    }
    let sigma_max = (0..n).map(|i| a[(i, i)]).fold(0.0, f64::max);
    let mut rank = 0;
    for j in 0..n {
        let sigma = a[(j, j)];
        let dot: f64 = (0..n).map(|i| v[(i, j)] * b[i]).sum();
        vtb[j] = if sigma > RANK_TOLERANCE * sigma_max {
            rank += 1;
            dot / sigma
        } else {
            0.0
        };
    }
    for (i, bi) in b.iter_mut().enumerate() {
        *bi = (0..n).map(|j| v[(i, j)] * vtb[j]).sum();
    }
    rank
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn regular_and_redundant_systems() {
        // Regular: A = [[4, 1], [1, 3]], b = [1, 2] → x = [1/11, 7/11].
        let mut a = DMatrix::from_row_slice(2, 2, &[4.0, 1.0, 1.0, 3.0]);
        let (mut w, mut v) = (DMatrix::zeros(2, 2), DVector::zeros(2));
        let mut b = [1.0, 2.0];
        assert_eq!(solve_psd(&mut a, &mut b, &mut w, &mut v), 2);
        assert!((b[0] - 1.0 / 11.0).abs() < 1e-15 && (b[1] - 7.0 / 11.0).abs() < 1e-15);
        // Redundant: two identical rows, A = [[1, 1], [1, 1]], b = [2, 2]: the minimum-norm
        // solution splits the force evenly, [1, 1].
        let mut a = DMatrix::from_row_slice(2, 2, &[1.0, 1.0, 1.0, 1.0]);
        let mut b = [2.0, 2.0];
        assert_eq!(solve_psd(&mut a, &mut b, &mut w, &mut v), 1);
        assert!((b[0] - 1.0).abs() < 1e-14 && (b[1] - 1.0).abs() < 1e-14, "{b:?}");
    }
}
