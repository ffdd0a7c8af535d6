//! Dense symmetric positive semi-definite solve for the Delassus system `A λ = b`
//! (A = J M⁻¹ Jᵀ, small: one row per constraint equation). Cholesky when A is positive definite;
//! when a pivot vanishes (redundant rows, e.g. a planar loop closed by a 3-row connect) the
//! minimum-norm solution `A⁺ b` from a rank-revealing (pivoted) Cholesky factor and the QR
//! factorization of that factor (Higham, *Accuracy and Stability of Numerical Algorithms*, §10.3;
//! Golub & Van Loan, *Matrix Computations*, 4th ed., §5.5). Works in caller-provided buffers: no
//! allocation.

#[cfg(target_arch = "x86_64")]
use super::nonzero_list::NonzeroList;
use super::RANK_TOLERANCE;
use nalgebra::{DMatrix, DVector};

/// Solves `A x = b` for the symmetric PSD `a` (its top-left n × n block, n = `b.len()`), in place:
/// `b` holds x on return. `work` (at least n × n) and `vec` (at least n) are scratch; `a` (at
/// least n × 2) is overwritten when the fallback runs. Returns the numerical rank of A: n for a
/// regular system, less when the minimum-norm solution (zero multipliers along the null space of
/// A) was taken: the pivots of a pivoted Cholesky factor above `RANK_TOLERANCE` times A's largest
/// diagonal entry.
pub(crate) fn solve_psd(
    a: &mut DMatrix<f64>,
    b: &mut [f64],
    work: &mut DMatrix<f64>,
    vec: &mut DVector<f64>,
) -> usize {
    match psd_rank_tolerance(a, b) {
        Some(tol) => solve_psd_tol(a, b, work, vec, tol),
        None => 0,
    }
}

/// The rank tolerance of the PSD system `A x = b` (A the top-left n × n block of `a`, n =
/// `b.len()`): `RANK_TOLERANCE` times A's largest diagonal entry; None (and `b` zeroed: the
/// solution is x = 0, rank 0) when there are no unknowns or that entry is zero or not finite.
pub(crate) fn psd_rank_tolerance(a: &DMatrix<f64>, b: &mut [f64]) -> Option<f64> {
    let n = b.len();
    let scale = (0..n).map(|i| a[(i, i)].abs()).fold(0.0, f64::max);
    if n == 0 || scale == 0.0 || !scale.is_finite() {
        b.fill(0.0);
        return None;
    }
    Some(scale * RANK_TOLERANCE)
}

/// [`solve_psd`] with the rank tolerance `tol` given (the pivots of the pivoted Cholesky factor
/// above it count): for a block of a larger system, judged by the whole system's tolerance
/// ([`super::block_lu::BlockLu::solve_psd`]).
pub(crate) fn solve_psd_tol(
    a: &mut DMatrix<f64>,
    b: &mut [f64],
    work: &mut DMatrix<f64>,
    vec: &mut DVector<f64>,
    tol: f64,
) -> usize {
    let n = b.len();
    if cholesky(a, n, work, tol) {
        cholesky_solve(work, n, b);
        return n;
    }
    min_norm_solve(a, n, b, work, vec, tol)
}

/// Solves the general (non-symmetric) `A x = b` for the top-left n × n block of `a`, n =
/// `b.len()`, by LU factorization with complete pivoting (Golub & Van Loan, *Matrix
/// Computations*, 4th ed., §3.4.8), in place: `a` holds the factors and `b` the solution on
/// return; `piv` (at least 2n) is scratch. A rank-deficient system (redundant rows) gets a basic
/// solution: the unknowns beyond the numerical rank (pivots at most `RANK_TOLERANCE` times the
/// largest entry) are zero. False, with `b` unspecified, when the system is inconsistent (its
/// eliminated right-hand side beyond the rank is above 1e-9 of b's largest entry plus `floor`,
/// the size of the round-off b itself carries: a Newton residual near convergence is that
/// round-off) or not finite. The solver solves its systems block by block
/// ([`super::block_lu::BlockLu`], the same result); this whole-matrix form is the reference its
/// tests compare with.
#[cfg(test)]
pub(crate) fn lu_solve(a: &mut DMatrix<f64>, b: &mut [f64], piv: &mut [usize], floor: f64) -> bool {
    let n = b.len();
    let stride = a.nrows();
    let m = a.as_mut_slice();
    let scale = largest_entry(m, stride, n);
    if !(scale > 0.0 && scale.is_finite()) {
        return false;
    }
    let b_scale = b.iter().fold(0.0f64, |acc, x| acc.max(x.abs()));
    lu_kernel_dispatch(m, stride, b, piv, LuBounds { tol: scale * RANK_TOLERANCE, b_scale, floor })
        && (n == 0 || b.iter().all(|x| x.is_finite()))
}

/// The thresholds of the LU solve with complete pivoting for a system (the whole system's, also
/// when it is solved block by block).
#[derive(Clone, Copy, Debug)]
pub(crate) struct LuBounds {
    /// Pivots at most this are zero: `RANK_TOLERANCE` times the matrix's largest entry.
    pub tol: f64,
    /// The right-hand side's largest entry.
    pub b_scale: f64,
    /// The round-off floor of the consistency test.
    pub floor: f64,
}

/// The largest |entry| of the top-left n × n block of `m` (column-major, `stride`).
pub(crate) fn largest_entry(m: &[f64], stride: usize, n: usize) -> f64 {
    let mut scale = 0.0f64;
    for j in 0..n {
        for x in &m[j * stride..j * stride + n] {
            scale = scale.max(x.abs());
        }
    }
    scale
}

/// [`lu_kernel`], compiled for AVX2 where the CPU has it.
pub(crate) fn lu_kernel_dispatch(
    m: &mut [f64],
    stride: usize,
    b: &mut [f64],
    piv: &mut [usize],
    bounds: LuBounds,
) -> bool {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2 (checked just above), all `lu_kernel_avx2` requires.
        return unsafe { lu_kernel_avx2(m, stride, b, piv, bounds) };
    }
    lu_kernel(m, stride, b, piv, bounds)
}

/// [`lu_kernel`] compiled for AVX2: the same operations in the same order (no fused
/// multiply–adds), four entries of a column per instruction, so the same bits.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn lu_kernel_avx2(
    m: &mut [f64],
    stride: usize,
    b: &mut [f64],
    piv: &mut [usize],
    bounds: LuBounds,
) -> bool {
    lu_kernel(m, stride, b, piv, bounds)
}

/// The elimination and back substitution of the LU solve with complete pivoting (`lu_solve`) on
/// the top-left n × n block of `m` (column-major, `stride`), n = `b.len()`, with the given
/// thresholds; true when the system is consistent (the caller checks finiteness).
#[inline(always)]
fn lu_kernel(m: &mut [f64], stride: usize, b: &mut [f64], piv: &mut [usize], bounds: LuBounds) -> bool {
    let n = b.len();
    let (_rows, cols) = piv[..2 * n].split_at_mut(n);
    let LuBounds { tol, b_scale, floor } = bounds;
    let mut rank = n;
    for k in 0..n {
        let (mut p, mut q, mut best) = (k, k, 0.0f64);
        for j in k..n {
            for (i, x) in m[j * stride + k..j * stride + n].iter().enumerate() {
                if x.abs() > best {
                    (p, q, best) = (k + i, j, x.abs());
                }
            }
        }
        if best <= tol {
            rank = k;
            break;
        }
        cols[k] = q;
        if p != k {
            for j in 0..n {
                m.swap(p + j * stride, k + j * stride);
            }
            b.swap(p, k);
        }
        if q != k {
            for i in 0..n {
                m.swap(i + q * stride, i + k * stride);
            }
        }
        let pivot = m[k + k * stride];
        for x in &mut m[k * stride + k + 1..k * stride + n] {
            *x /= pivot;
        }
        let (head, tail) = m.split_at_mut((k + 1) * stride);
        let col_k = &head[k * stride + k + 1..k * stride + n];
        for j in 0..n - k - 1 {
            let col_j = &mut tail[j * stride..j * stride + n];
            let akj = col_j[k];
            if akj != 0.0 {
                for (x, l) in col_j[k + 1..n].iter_mut().zip(col_k) {
                    *x -= l * akj;
                }
            }
        }
        let bk = b[k];
        for (x, l) in b[k + 1..n].iter_mut().zip(col_k) {
            *x -= l * bk;
        }
    }
    // Consistency of the equations beyond the rank.
    if b[rank..].iter().any(|x| x.abs() > 1e-9 * b_scale + floor) {
        return false;
    }
    b[rank..].fill(0.0);
    for k in (0..rank).rev() {
        b[k] /= m[k + k * stride];
        let bk = b[k];
        for (x, u) in b[..k].iter_mut().zip(&m[k * stride..k * stride + k]) {
            *x -= u * bk;
        }
    }
    // Undo the column permutation (the unknowns were swapped as the columns were).
    for k in (0..rank).rev() {
        b.swap(k, cols[k]);
    }
    true
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

/// Columns up to this many entries take [`cholesky_avx2`]'s blocked form (its list of the
/// earlier columns that reach row j lives on the stack); longer ones the column-by-column kernel.
#[cfg(target_arch = "x86_64")]
const BLOCKED_N: usize = 256;

/// [`cholesky_kernel`]'s arithmetic, blocked for AVX2: per entry the same operations in the same
/// order (a_ij, then one product and one difference for each earlier column k with l_jk ≠ 0, k
/// ascending, no fused multiply–adds; then the division by the pivot), so the same bits. Column
/// j is formed four rows at a time (eight when it can) with the running differences held in
/// registers across all earlier columns, instead of updating the whole column in memory once per
/// earlier column: for the Newton Hessian of a 27-dof humanoid the set-up of the many short
/// column updates cost more than their arithmetic. The earlier columns with l_jk ≠ 0 are listed
/// once per column. Each block is divided by the pivot's root in registers, before its one store
/// (a division pass over the stored column would read each group of four across two stores, which
/// the store buffer cannot forward: a stall per group). Rows left over at the end of a column
/// (fewer than four) are formed again by the last block of four, which ends at row n − 1 (the
/// same values stored twice); in the last three columns that block starts above the diagonal and
/// stores only its lanes from row j on (the upper triangle of `l` is left as it was).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn cholesky_avx2(a: &DMatrix<f64>, n: usize, l: &mut DMatrix<f64>, tol: f64) -> bool {
    use std::arch::x86_64::{
        _mm256_blend_pd, _mm256_blendv_pd, _mm256_castsi256_pd, _mm256_cmpeq_epi64, _mm256_cmpgt_epi64,
        _mm256_cvtsd_f64, _mm256_div_pd, _mm256_loadu_pd, _mm256_maskstore_pd, _mm256_mul_pd,
        _mm256_set1_epi64x, _mm256_set1_pd, _mm256_setr_epi64x, _mm256_setzero_pd, _mm256_storeu_pd,
        _mm256_sub_pd,
    };
    if n > BLOCKED_N {
        return cholesky_kernel(a, n, l, tol);
    }
    let stride = l.nrows();
    let a_stride = a.nrows();
    assert!(n <= stride && n <= a_stride && n <= a.ncols() && n <= l.ncols());
    let (a_s, ls) = (a.as_slice(), l.as_mut_slice());
    // The earlier columns reaching row j: their offsets in `ls` and their entries l_jk.
    let mut earlier = NonzeroList::<BLOCKED_N>::new();
    let ap = a_s.as_ptr();
    for j in 0..n {
        let lr = ls.as_ptr();
        // SAFETY: k < j < n ≤ `l`'s column count and j < n ≤ stride, so k · stride + j is inside
        // `ls`.
        earlier.list(j, |k| (k * stride, unsafe { *lr.add(k * stride + j) }));
        let (offs, vals) = (earlier.offsets(), earlier.values());
        let (a_col, l_col) = (j * a_stride, j * stride);
        if n < 4 {
            for i in j..n {
                let mut x = a_s[a_col + i];
                for (&o, &v) in offs.iter().zip(vals) {
                    x -= ls[o + i] * v;
                }
                ls[l_col + i] = x;
            }
            let d = ls[l_col + j];
            if d <= tol {
                return false;
            }
            let d = d.sqrt();
            ls[l_col + j] = d;
            for x in &mut ls[l_col + j + 1..l_col + n] {
                *x /= d;
            }
        } else {
            // The pivot l_jj is in the first block formed (lane j − b of the block at row b);
            // every block is divided by √l_jj in registers before it is stored (the pivot's lane
            // replaced by √l_jj), so that no entry is stored twice and nothing is read back
            // across two stores, which the store buffer cannot forward.
            let mut dv = _mm256_setzero_pd();
            let mut first = true;
            // SAFETY: every block of four rows starts at a row b with b + 4 ≤ n ≤ both strides (the assert above), so the loads from column j of A and
            // from the earlier columns of L (offsets k · stride, k < j ≤ n − 1 < both column
            // counts) and the stores into column j of L stay inside both matrices' storage; the
            // earlier columns are only read while column j is written; a block that starts above
            // row j (the last columns, fewer than four rows) stores only its lanes from row j on;
            // the CPU has AVX2 (this function's contract).
            unsafe {
                let lp = ls.as_mut_ptr();
                let mut i = j;
                while i + 8 <= n {
                    let mut x0 = _mm256_loadu_pd(ap.add(a_col + i));
                    let mut x1 = _mm256_loadu_pd(ap.add(a_col + i + 4));
                    for (&o, &v) in offs.iter().zip(vals) {
                        let v = _mm256_set1_pd(v);
                        x0 = _mm256_sub_pd(x0, _mm256_mul_pd(_mm256_loadu_pd(lp.add(o + i)), v));
                        x1 = _mm256_sub_pd(x1, _mm256_mul_pd(_mm256_loadu_pd(lp.add(o + i + 4)), v));
                    }
                    if first {
                        // i = j: the pivot is lane 0.
                        let Some(d) = pivot_root(_mm256_cvtsd_f64(x0), tol) else {
                            return column_failed(a_s, ls, offs, vals, a_col, l_col, j, n);
                        };
                        dv = _mm256_set1_pd(d);
                        x0 = _mm256_blend_pd::<1>(_mm256_div_pd(x0, dv), dv);
                        first = false;
                    } else {
                        x0 = _mm256_div_pd(x0, dv);
                    }
                    _mm256_storeu_pd(lp.add(l_col + i), x0);
                    _mm256_storeu_pd(lp.add(l_col + i + 4), _mm256_div_pd(x1, dv));
                    i += 8;
                }
                while i < n {
                    // The last block ends at row n − 1 (it may repeat rows already formed, or
                    // start above row j: those lanes are not stored).
                    let b = i.min(n - 4);
                    let mut x0 = _mm256_loadu_pd(ap.add(a_col + b));
                    for (&o, &v) in offs.iter().zip(vals) {
                        x0 = _mm256_sub_pd(
                            x0,
                            _mm256_mul_pd(_mm256_loadu_pd(lp.add(o + b)), _mm256_set1_pd(v)),
                        );
                    }
                    if first {
                        // The pivot is lane j − b (0 when b = j, up to 3 in the last columns).
                        let mut lanes = [0.0; 4];
                        _mm256_storeu_pd(lanes.as_mut_ptr(), x0);
                        let Some(d) = pivot_root(lanes[j - b], tol) else {
                            return column_failed(a_s, ls, offs, vals, a_col, l_col, j, n);
                        };
                        dv = _mm256_set1_pd(d);
                        let at_pivot = _mm256_cmpeq_epi64(
                            _mm256_setr_epi64x(0, 1, 2, 3),
                            _mm256_set1_epi64x((j - b) as i64),
                        );
                        x0 = _mm256_blendv_pd(_mm256_div_pd(x0, dv), dv, _mm256_castsi256_pd(at_pivot));
                        first = false;
                    } else {
                        x0 = _mm256_div_pd(x0, dv);
                    }
                    if b >= j {
                        _mm256_storeu_pd(lp.add(l_col + b), x0);
                    } else {
                        // Lanes b + l ≥ j, i.e. l > j − b − 1.
                        let above = _mm256_set1_epi64x((j - b) as i64 - 1);
                        let mask = _mm256_cmpgt_epi64(_mm256_setr_epi64x(0, 1, 2, 3), above);
                        _mm256_maskstore_pd(lp.add(l_col + b), mask, x0);
                    }
                    i = b + 4;
                }
            }
        }
    }
    true
}

/// √p for a pivot p above `tol` (NaN passes, as in [`cholesky_kernel`]'s test), else None.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn pivot_root(p: f64, tol: f64) -> Option<f64> {
    if p <= tol {
        None
    } else {
        Some(p.sqrt())
    }
}

/// [`cholesky_avx2`]'s column j when its pivot is not above the tolerance: the column's entries
/// from row j on stored undivided, as [`cholesky_kernel`] leaves them (the same products and
/// differences in the same order, one entry at a time), and false.
#[cfg(target_arch = "x86_64")]
#[allow(clippy::too_many_arguments)]
#[cold]
fn column_failed(
    a_s: &[f64],
    ls: &mut [f64],
    offs: &[usize],
    vals: &[f64],
    a_col: usize,
    l_col: usize,
    j: usize,
    n: usize,
) -> bool {
    for i in j..n {
        let mut x = a_s[a_col + i];
        for (&o, &v) in offs.iter().zip(vals) {
            x -= ls[o + i] * v;
        }
        ls[l_col + i] = x;
    }
    false
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

/// Updates the lower Cholesky factor `l` of A (top-left n × n) in place to the factor of
/// A + sign · x xᵀ (`sign` +1: a rank-one update; −1: a downdate), by the rotations of the
/// classical algorithm (Golub & Van Loan, *Matrix Computations*, 4th ed., §6.5.4; Gill, Golub,
/// Murray & Saunders 1974): O(n²) instead of the O(n³) of factoring again. `x` (n long) is
/// overwritten. Entries of x that are zero before their column is reached are skipped (they
/// rotate nothing). Returns false, leaving `l` unusable, when a downdate leaves a pivot not
/// positive (A − x xᵀ not positive definite to working precision) or a value is not finite.
pub(crate) fn cholesky_rank_one(l: &mut DMatrix<f64>, n: usize, x: &mut [f64], sign: f64) -> bool {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2 (checked just above), all `cholesky_rank_one_avx2` requires.
        return unsafe { cholesky_rank_one_avx2(l, n, x, sign) };
    }
    cholesky_rank_one_kernel(l, n, x, sign)
}

/// [`cholesky_rank_one`] compiled for AVX2: the rotation of each entry pair is independent of
/// the others', four at a time, the same operations in the same order (no fused
/// multiply–adds), so the same bits.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn cholesky_rank_one_avx2(l: &mut DMatrix<f64>, n: usize, x: &mut [f64], sign: f64) -> bool {
    cholesky_rank_one_kernel(l, n, x, sign)
}

#[inline(always)]
fn cholesky_rank_one_kernel(l: &mut DMatrix<f64>, n: usize, x: &mut [f64], sign: f64) -> bool {
    let stride = l.nrows();
    let ls = l.as_mut_slice();
    let x = &mut x[..n];
    for k in 0..n {
        let xk = x[k];
        if xk == 0.0 {
            continue;
        }
        let col = &mut ls[k * stride + k..k * stride + n];
        let lkk = col[0];
        let r2 = lkk * lkk + sign * xk * xk;
        // A pivot that cancels to round-off: the downdated matrix is singular at working
        // precision; the caller factors it afresh instead.
        if !r2.is_finite() || r2 <= 1e-12 * lkk * lkk {
            return false;
        }
        let r = r2.sqrt();
        let (c, s) = (r / lkk, xk / lkk);
        // 1/c = lkk/r, formed beside c: one division per column instead of one per entry
        // (MuJoCo's `mju_cholUpdate` scales by 1/c likewise), off the chain from one column's
        // x to the next's.
        let c_inv = lkk / r;
        col[0] = r;
        let (_, tail) = x.split_at_mut(k + 1);
        for (lik, xi) in col[1..].iter_mut().zip(tail.iter_mut()) {
            *lik = (*lik + sign * s * *xi) * c_inv;
            *xi = c * *xi - s * *lik;
        }
    }
    true
}

/// Solves L Lᵀ x = b in place with the factor of [`cholesky`] (forward substitution column by
/// column, per entry in the same order as the row form; back substitution by rows of Lᵀ, which
/// are L's columns, each row's sum from its last entry to its first; each unknown scaled by its
/// pivot's reciprocal). The solve is a chain of n dependent unknowns each way: the sum order and
/// the reciprocals keep the chain to a product and a difference per unknown (a 27-dof humanoid
/// steps about 2 % faster than with a division and a row's whole sum on it).
pub(crate) fn cholesky_solve(l: &DMatrix<f64>, n: usize, b: &mut [f64]) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2 (checked just above), all `cholesky_solve_avx2` requires.
        unsafe { cholesky_solve_avx2(l, n, b) };
        return;
    }
    cholesky_solve_kernel(l, n, b);
}

/// [`cholesky_solve`] compiled for AVX2: the same operations in the same order (the forward
/// substitution's column updates four entries at a time; the back substitution's sums stay
/// sequential), so the same bits.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn cholesky_solve_avx2(l: &DMatrix<f64>, n: usize, b: &mut [f64]) {
    cholesky_solve_kernel(l, n, b);
}

#[inline(always)]
fn cholesky_solve_kernel(l: &DMatrix<f64>, n: usize, b: &mut [f64]) {
    let stride = l.nrows();
    let ls = l.as_slice();
    let b = &mut b[..n];
    for k in 0..n {
        let col_k = &ls[k * stride + k..k * stride + n];
        let (head, tail) = b[k..].split_at_mut(1);
        // The pivot's reciprocal does not wait for b: formed ahead, it leaves a product (not a
        // division) on the chain from one entry to the next.
        head[0] *= 1.0 / col_k[0];
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
        // From the last row up: the term of x[i + 1], found just before, comes last, so the
        // running difference over the others (known earlier) is formed while x[i + 1] is.
        for (&y, &x) in col_i[1..].iter().zip(tail.iter()).rev() {
            s -= y * x;
        }
        head[0] = s * (1.0 / col_i[0]);
    }
}

/// The minimum-norm solution x = A⁺ b of a singular PSD system, in `b`, and A's numerical rank:
/// [`deletion_min_norm`] when `a` has room for its scratch (n columns), else [`pivoted_min_norm`].
fn min_norm_solve(
    a: &mut DMatrix<f64>,
    n: usize,
    b: &mut [f64],
    l: &mut DMatrix<f64>,
    perm: &mut DVector<f64>,
    tol: f64,
) -> usize {
    if a.ncols() >= n && a.nrows() >= n && l.ncols() >= n && perm.len() >= n {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2 (checked just above), all `deletion_min_norm_avx2` requires.
            return unsafe { deletion_min_norm_avx2(a, n, b, l, perm, tol) };
        }
        return deletion_min_norm::<false>(a, n, b, l, perm, tol);
    }
    pivoted_min_norm(a, n, b, l, perm, tol)
}

/// [`deletion_min_norm`] compiled for AVX2 (the column updates four entries per instruction; the
/// same operations in the same order, so the same bits).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn deletion_min_norm_avx2(
    a: &mut DMatrix<f64>,
    n: usize,
    b: &mut [f64],
    l: &mut DMatrix<f64>,
    perm: &mut DVector<f64>,
    tol: f64,
) -> usize {
    deletion_min_norm::<true>(a, n, b, l, perm, tol)
}

/// Σ xᵢ yᵢ in four interleaved partial sums (lanes i mod 4, added as (s₀ + s₁) + (s₂ + s₃), then
/// the tail in order): a fixed order, so the same bits on every run; [`dot4_avx2`] with `AVX`.
#[inline(always)]
fn dot4<const AVX: bool>(x: &[f64], y: &[f64]) -> f64 {
    #[cfg(target_arch = "x86_64")]
    if AVX {
        // SAFETY: `AVX` is true only in `deletion_min_norm_avx2`, which runs on CPUs with AVX2.
        return unsafe { dot4_avx2(x, y) };
    }
    let mut s = [0.0; 4];
    let (xc, yc) = (x.chunks_exact(4), y.chunks_exact(4));
    let (xr, yr) = (xc.remainder(), yc.remainder());
    for (p, q) in xc.zip(yc) {
        for k in 0..4 {
            s[k] += p[k] * q[k];
        }
    }
    let mut t = (s[0] + s[1]) + (s[2] + s[3]);
    for (p, q) in xr.iter().zip(yr) {
        t += p * q;
    }
    t
}

/// [`dot4`] with AVX2 intrinsics: the four partial sums in one register (a multiply and an add per
/// chunk, no fused multiply–add), so the same bits.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn dot4_avx2(x: &[f64], y: &[f64]) -> f64 {
    use std::arch::x86_64::{
        _mm256_add_pd, _mm256_loadu_pd, _mm256_mul_pd, _mm256_setzero_pd, _mm256_storeu_pd,
    };
    let len = x.len().min(y.len());
    let chunks = len / 4;
    let mut acc = _mm256_setzero_pd();
    for c in 0..chunks {
        // SAFETY: 4c + 3 < len, within both slices.
        let (p, q) =
            unsafe { (_mm256_loadu_pd(x.as_ptr().add(4 * c)), _mm256_loadu_pd(y.as_ptr().add(4 * c))) };
        acc = _mm256_add_pd(acc, _mm256_mul_pd(p, q));
    }
    let mut s = [0.0; 4];
    // SAFETY: `s` holds four f64.
    unsafe { _mm256_storeu_pd(s.as_mut_ptr(), acc) };
    let mut t = (s[0] + s[1]) + (s[2] + s[3]);
    for i in 4 * chunks..len {
        t += x[i] * y[i];
    }
    t
}

/// The minimum-norm solution x = A⁺ b of a singular PSD system (in `b`) from a Cholesky factor in
/// the rows' own order with the dependent rows deleted, and A's numerical rank r. O(n b² + (n − r)
/// r² + r³) for a factor of bandwidth b (a stack's or chain's contacts in order couple only their
/// neighbours): the pivoted factor and QR of [`pivoted_min_norm`] are O(n² r) whatever the
/// structure (a 20-box stack's 250 redundant rows: most of its step).
///
/// 1. Left-looking Cholesky in the given order; a row whose pivot is not above `tol` is dependent
///    on the earlier ones (for a PSD matrix its Schur complement row then vanishes with the
///    pivot): its column is zeroed. The independent rows I (r of them) and dependent rows D give
///    A = L̃ L̃ᵀ with L̃ = L[:, I] = [L₁; L₂] (rows I, rows D), L₁ lower triangular (Golub & Van
///    Loan, *Matrix Computations*, 4th ed., §4.2.8 on semidefinite Cholesky).
/// 2. A = U A₁₁ Uᵀ with U = [I; S] (rows I, rows D), S = L₂ L₁⁻¹ (each dependent row as a
///    combination of the independent ones) and A₁₁ = L₁ L₁ᵀ. U has full column rank, so
///    A⁺ = U H⁻¹ A₁₁⁻¹ H⁻¹ Uᵀ with H = UᵀU = I + SᵀS (with U = QR: Q R⁻ᵀ A₁₁⁻¹ R⁻¹ Qᵀ).
///    H's eigenvalues are at least 1: its Cholesky is well conditioned; A₁₁'s condition is that
///    of A's nonzero part, as a regular solve.
///
/// The rank decision is per row, in order, rather than on the largest remaining pivot; for rows
/// that are exactly redundant (a box's four corners against one face) both find the same rank,
/// and the solution is the same A⁺ b up to round-off. Scratch: `l` holds L; `a` (n × n, its
/// stride at least n) holds H (rows 0..r) over S (rows r..n) in its first r columns and two
/// vectors in column r; `perm` holds each column's extent, then I followed by D (indices as the
/// bits of its f64 entries).
#[inline(always)]
fn deletion_min_norm<const AVX: bool>(
    a: &mut DMatrix<f64>,
    n: usize,
    b: &mut [f64],
    l: &mut DMatrix<f64>,
    perm: &mut DVector<f64>,
    tol: f64,
) -> usize {
    let (ls, sa) = (l.nrows(), a.nrows());
    let lm = l.as_mut_slice();
    // 1. The factor, dependent columns zeroed.
    {
        let am = a.as_slice();
        let mut kmin = 0;
        for j in 0..n {
            let (done, rest) = lm.split_at_mut(j * ls);
            let col_j = &mut rest[j..n];
            col_j.copy_from_slice(&am[j * sa + j..j * sa + n]);
            // The earlier columns reaching row j: from the first whose nonzeros (up to `perm[k]`,
            // one past its last, as bits) go beyond row j − 1, which only moves down with j.
            while kmin < j && (perm[kmin].to_bits() as usize) <= j {
                kmin += 1;
            }
            for k in kmin..j {
                let end = perm[k].to_bits() as usize;
                if end <= j {
                    continue;
                }
                let col_k = &done[k * ls + j..k * ls + end];
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
                col_j.fill(0.0);
                perm[j] = f64::from_bits(j as u64);
            } else {
                let d = d.sqrt();
                col_j[0] = d;
                for x in &mut col_j[1..] {
                    *x /= d;
                }
                perm[j] = f64::from_bits((j + 1 + col_j.iter().rposition(|&x| x != 0.0).unwrap_or(0)) as u64);
            }
        }
    }
    let mut r = 0;
    for j in 0..n {
        if lm[j * ls + j] != 0.0 {
            perm[r] = f64::from_bits(j as u64);
            r += 1;
        }
    }
    if r == 0 {
        b[..n].fill(0.0);
        return 0;
    }
    if r == n {
        cholesky_solve(l, n, b);
        return n;
    }
    {
        let mut m = r;
        for j in 0..n {
            if lm[j * ls + j] == 0.0 {
                perm[m] = f64::from_bits(j as u64);
                m += 1;
            }
        }
    }
    let m = n - r;
    let idx = |p: usize| perm[p].to_bits() as usize;
    let am = a.as_mut_slice();
    // L[i, j] (zero above the diagonal: `l`'s upper triangle is not written).
    let lij = |i: usize, j: usize| if i >= j { lm[j * ls + i] } else { 0.0 };
    // 2. S (m × r) in rows r..n of a's columns 0..r, right to left: S L₁ = L₂.
    for c in (0..r).rev() {
        let ic = idx(c);
        let (head, tail) = am.split_at_mut((c + 1) * sa);
        let s_c = &mut head[c * sa + r..c * sa + n];
        for (e, x) in s_c.iter_mut().enumerate() {
            *x = lij(idx(r + e), ic);
        }
        for k in c + 1..r {
            let lkc = lm[ic * ls + idx(k)];
            if lkc == 0.0 {
                continue;
            }
            // Column k from its first nonzero row (kept in its row 0, below).
            let lo = tail[(k - c - 1) * sa].to_bits() as usize;
            let s_k = &tail[(k - c - 1) * sa + r + lo..(k - c - 1) * sa + n];
            for (x, &y) in s_c[lo..].iter_mut().zip(s_k) {
                *x -= y * lkc;
            }
        }
        let d = lm[ic * ls + ic];
        for x in s_c.iter_mut() {
            *x /= d;
        }
        // Column c's first nonzero row, in its row 0 as bits (above H's diagonal for c ≥ 1, which
        // nothing below reads): the products with it start there.
        if c > 0 {
            let lo = s_c.iter().position(|&x| x != 0.0).unwrap_or(m);
            head[c * sa] = f64::from_bits(lo as u64);
        }
    }
    // H = I + SᵀS, lower triangle, in rows 0..r; each product over the rows where both columns
    // can be nonzero (S's columns start at their first nonzero: a dependent row combines nearby
    // independent ones).
    for q in 0..r {
        let lo_q = if q == 0 {
            am[r..n].iter().position(|&x| x != 0.0).unwrap_or(m)
        } else {
            am[q * sa].to_bits() as usize
        };
        for p in q..r {
            let lo_p = if p == 0 { lo_q } else { am[p * sa].to_bits() as usize };
            let lo = r + lo_p.max(lo_q);
            let h = dot4::<AVX>(&am[p * sa + lo..p * sa + n], &am[q * sa + lo..q * sa + n]);
            am[q * sa + p] = h + if p == q { 1.0 } else { 0.0 };
        }
    }
    // H's Cholesky factor in place (left-looking; pivots at least 1 in exact arithmetic).
    for j in 0..r {
        let (done, rest) = am.split_at_mut(j * sa);
        let col_j = &mut rest[j..r];
        for k in 0..j {
            let col_k = &done[k * sa + j..k * sa + r];
            let hjk = col_k[0];
            if hjk == 0.0 {
                continue;
            }
            for (x, &y) in col_j.iter_mut().zip(col_k) {
                *x -= y * hjk;
            }
        }
        let d = col_j[0].sqrt();
        col_j[0] = d;
        for x in &mut col_j[1..] {
            *x /= d;
        }
    }
    // 3. Column r of a: b_D in rows 0..m, then g (r entries) in rows m..n.
    let (hs, t) = am.split_at_mut(r * sa);
    let t = &mut t[..n];
    let (bd, g) = t.split_at_mut(m);
    for e in 0..m {
        bd[e] = b[idx(r + e)];
    }
    // g = Uᵀ b = b_I + Sᵀ b_D.
    for c in 0..r {
        g[c] = b[idx(c)] + dot4::<AVX>(&hs[c * sa + r..c * sa + n], bd);
    }
    let h_solve = |g: &mut [f64]| {
        for c in 0..r {
            let col = &hs[c * sa + c..c * sa + r];
            g[c] /= col[0];
            let gc = g[c];
            for (x, &y) in g[c + 1..r].iter_mut().zip(&col[1..]) {
                *x -= y * gc;
            }
        }
        for c in (0..r).rev() {
            let col = &hs[c * sa + c..c * sa + r];
            let s = g[c] - dot4::<AVX>(&col[1..], &g[c + 1..r]);
            g[c] = s / col[0];
        }
    };
    h_solve(g);
    // A₁₁⁻¹ = L₁⁻ᵀ L₁⁻¹ (L₁[k, c] = L[I_k, I_c]).
    for c in 0..r {
        let ic = idx(c);
        g[c] /= lm[ic * ls + ic];
        let gc = g[c];
        if gc != 0.0 {
            for k in c + 1..r {
                g[k] -= lm[ic * ls + idx(k)] * gc;
            }
        }
    }
    for c in (0..r).rev() {
        let ic = idx(c);
        let mut s = g[c];
        for k in c + 1..r {
            s -= lm[ic * ls + idx(k)] * g[k];
        }
        g[c] = s / lm[ic * ls + ic];
    }
    h_solve(g);
    // x = U g: x_I = g, x_D = S g.
    bd.fill(0.0);
    for c in 0..r {
        let gc = g[c];
        for (x, &y) in bd.iter_mut().zip(&hs[c * sa + r..c * sa + n]) {
            *x += y * gc;
        }
    }
    for c in 0..r {
        b[idx(c)] = g[c];
    }
    for e in 0..m {
        b[idx(r + e)] = bd[e];
    }
    r
}

/// The minimum-norm solution x = A⁺ b of a singular PSD system, in `b`, and A's numerical rank,
/// by a pivoted factor and QR (the form [`deletion_min_norm`] replaced; kept for a matrix
/// buffer too small for that one's scratch, and as its tests' reference).
///
/// 1. Cholesky with symmetric pivoting (Higham, *Accuracy and Stability of Numerical
///    Algorithms*, 2nd ed., §10.3): P A Pᵀ = L Lᵀ with L n × r lower trapezoidal, stopping when
///    the largest remaining pivot is not above `tol` (r is the rank).
/// 2. Householder QR of L = Q R (Q n × r orthonormal columns, R r × r upper triangular).
/// 3. With c = P b: ŷ = Q R⁻ᵀ R⁻¹ Qᵀ c is the minimum-norm solution of L Lᵀ ŷ = c (it lies in
///    range(L) = range(P A Pᵀ)), and x = Pᵀ ŷ, whose norm is ŷ's.
///
/// R's condition number is the square root of the nonzero part of A's, so step 3 is as accurate
/// as a regular Cholesky solve. Cost O(n² r) (a Jacobi eigendecomposition took tens of sweeps of
/// O(n³)). Scratch: `l` (n × n) holds L, then Q's reflectors and R; `a` is overwritten (P b and
/// the reflectors' coefficients); `perm` holds P.
fn pivoted_min_norm(
    a: &mut DMatrix<f64>,
    n: usize,
    b: &mut [f64],
    l: &mut DMatrix<f64>,
    perm: &mut DVector<f64>,
    tol: f64,
) -> usize {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2 (checked just above), all `min_norm_solve_avx2` requires.
        return unsafe { min_norm_solve_avx2(a, n, b, l, perm, tol) };
    }
    min_norm_kernel(a, n, b, l, perm, tol)
}

/// [`min_norm_kernel`] compiled for AVX2: the same operations in the same order (no fused
/// multiply–adds, sums in their order), the updates four entries per instruction, so the same
/// bits.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn min_norm_solve_avx2(
    a: &mut DMatrix<f64>,
    n: usize,
    b: &mut [f64],
    l: &mut DMatrix<f64>,
    perm: &mut DVector<f64>,
    tol: f64,
) -> usize {
    min_norm_kernel(a, n, b, l, perm, tol)
}

#[inline(always)]
fn min_norm_kernel(
    a: &mut DMatrix<f64>,
    n: usize,
    b: &mut [f64],
    l: &mut DMatrix<f64>,
    perm: &mut DVector<f64>,
    tol: f64,
) -> usize {
    let (ls, a_stride) = (l.nrows(), a.nrows());
    let lm = l.as_mut_slice();
    // 1. Pivoted Cholesky on the lower triangle (LAPACK's dpstf2 order): a symmetric swap of k
    // and p exchanges rows k and p of the finished columns, the two diagonal entries, column k
    // below p with column p, and column k between k and p with row p. Every entry gets the same
    // updates, in the same order, as on the full symmetric matrix.
    {
        let am = a.as_slice();
        for j in 0..n {
            lm[j * ls + j..j * ls + n].copy_from_slice(&am[j * a_stride + j..j * a_stride + n]);
            perm[j] = j as f64;
        }
    }
    let mut rank = n;
    for k in 0..n {
        let p = (k..n).fold(k, |best, j| if lm[j + j * ls] > lm[best + best * ls] { j } else { best });
        if lm[p + p * ls] <= tol {
            rank = k;
            break;
        }
        if p != k {
            for c in 0..k {
                lm.swap(k + c * ls, p + c * ls);
            }
            lm.swap(k + k * ls, p + p * ls);
            for i in k + 1..p {
                lm.swap(i + k * ls, p + i * ls);
            }
            for i in p + 1..n {
                lm.swap(i + k * ls, i + p * ls);
            }
            perm.swap_rows(k, p);
        }
        let (head, tail) = lm.split_at_mut((k + 1) * ls);
        let col_k = &mut head[k * ls + k..k * ls + n];
        let d = col_k[0].sqrt();
        col_k[0] = d;
        for x in &mut col_k[1..] {
            *x /= d;
        }
        let col_k = &col_k[1..];
        for j in k + 1..n {
            let ljk = col_k[j - k - 1];
            let col_j = &mut tail[(j - k - 1) * ls + j..(j - k - 1) * ls + n];
            for (x, &y) in col_j.iter_mut().zip(&col_k[j - k - 1..]) {
                *x -= y * ljk;
            }
        }
    }
    let r = rank;
    if r == 0 {
        b[..n].fill(0.0);
        return 0;
    }
    // L's strict upper part of its first r columns is zero.
    for j in 0..r {
        lm[j * ls..j * ls + j].fill(0.0);
    }
    // 2. Householder QR of L's first r columns, in place (LAPACK's dlarfg convention: v₀ = 1
    // implicit, the rest below the diagonal, τ in a's column 0, R on and above the diagonal).
    let (taus, rest) = a.as_mut_slice().split_at_mut(a_stride);
    for j in 0..r {
        let (head, tail) = lm.split_at_mut((j + 1) * ls);
        let col_j = &mut head[j * ls + j..j * ls + n];
        let x0 = col_j[0];
        let norm: f64 = col_j[1..].iter().map(|x| x * x).sum::<f64>().sqrt();
        if norm == 0.0 {
            taus[j] = 0.0;
            continue;
        }
        let beta = -x0.signum() * x0.hypot(norm);
        let tau = (beta - x0) / beta;
        let scale = 1.0 / (x0 - beta);
        for x in &mut col_j[1..] {
            *x *= scale;
        }
        col_j[0] = beta;
        taus[j] = tau;
        let v = &col_j[1..];
        for c in j + 1..r {
            let col_c = &mut tail[(c - j - 1) * ls + j..(c - j - 1) * ls + n];
            let s = col_c[0] + v.iter().zip(&col_c[1..]).map(|(x, y)| x * y).sum::<f64>();
            col_c[0] -= tau * s;
            for (x, &y) in col_c[1..].iter_mut().zip(v) {
                *x -= tau * s * y;
            }
        }
    }
    // 3. c = P b in a's column 1; Qᵀ c; R⁻¹, then R⁻ᵀ on its first r entries; Q back.
    let c = &mut rest[..n];
    for i in 0..n {
        c[i] = b[perm[i] as usize];
    }
    let reflect = |c: &mut [f64], j: usize| {
        let tau = taus[j];
        let v = &lm[j * ls + j + 1..j * ls + n];
        let s = c[j] + v.iter().zip(&c[j + 1..n]).map(|(x, y)| x * y).sum::<f64>();
        c[j] -= tau * s;
        for (x, &y) in c[j + 1..n].iter_mut().zip(v) {
            *x -= tau * s * y;
        }
    };
    for j in 0..r {
        reflect(c, j);
    }
    for i in (0..r).rev() {
        let s = c[i] - (i + 1..r).map(|k| lm[i + k * ls] * c[k]).sum::<f64>();
        c[i] = s / lm[i + i * ls];
    }
    for i in 0..r {
        let col_i = &lm[i * ls..i * ls + i];
        let s = c[i] - col_i.iter().zip(&c[..i]).map(|(x, y)| x * y).sum::<f64>();
        c[i] = s / lm[i + i * ls];
    }
    c[r..n].fill(0.0);
    for j in (0..r).rev() {
        reflect(c, j);
    }
    for i in 0..n {
        b[perm[i] as usize] = c[i];
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

    /// A deterministic stream of numbers in [−½, ½) (a 64-bit linear congruential generator).
    fn uniform(mut seed: u64) -> impl FnMut() -> f64 {
        move || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        }
    }

    /// Rank-one updates and downdates of a factor against factoring A ± x xᵀ afresh, with a
    /// sparse x (leading zeros, as a constraint row's Jacobian on a chain of dofs), and the
    /// downdate that removes a direction A needs refused.
    #[test]
    fn rank_one_update_and_downdate_match_a_fresh_factor() {
        let mut rand = uniform(11);
        for n in [1, 4, 9, 27] {
            let b = DMatrix::from_fn(n, n, |_, _| rand());
            let a = &b * b.transpose() + DMatrix::identity(n, n);
            let x = DVector::from_fn(n, |i, _| if i < n / 3 { 0.0 } else { rand() });
            for sign in [1.0, -1.0] {
                let a_new = &a + sign * &x * x.transpose();
                let mut l = DMatrix::zeros(n, n);
                assert!(cholesky(&a, n, &mut l, 0.0));
                let mut xs = x.as_slice().to_vec();
                // The downdate of a + x xᵀ by x is A: update first, then check both ways.
                if sign < 0.0 {
                    let a_up = &a + &x * x.transpose();
                    assert!(cholesky(&a_up, n, &mut l, 0.0));
                    xs.copy_from_slice(x.as_slice());
                    assert!(cholesky_rank_one(&mut l, n, &mut xs, -1.0));
                    let got = &l * l.transpose();
                    let err = (&got - &a).abs().max();
                    assert!(err < 1e-12 * (1.0 + a.abs().max()), "n {n} downdate: {err:e}");
                    continue;
                }
                assert!(cholesky_rank_one(&mut l, n, &mut xs, sign));
                let mut fresh = DMatrix::zeros(n, n);
                assert!(cholesky(&a_new, n, &mut fresh, 0.0));
                let err = (l.lower_triangle() - fresh.lower_triangle()).abs().max();
                assert!(err < 1e-12 * (1.0 + fresh.abs().max()), "n {n} update: {err:e}");
            }
        }
        // Removing more than A holds: A = 1 + x xᵀ downdated by 2x is not positive definite.
        let x = DVector::from_vec(vec![0.0, 1.0, 2.0]);
        let a = DMatrix::identity(3, 3) + &x * x.transpose();
        let mut l = DMatrix::zeros(3, 3);
        assert!(cholesky(&a, 3, &mut l, 0.0));
        let mut xs = vec![0.0, 2.0, 4.0];
        assert!(!cholesky_rank_one(&mut l, 3, &mut xs, -1.0));
    }

    /// The blocked AVX2 factorization against the column-by-column kernel, to the bit: sizes
    /// around the block widths, matrices with structural zeros (the skipped columns), a strided
    /// factor buffer whose upper triangle is left alone, and the refusal of a matrix that is not
    /// positive definite.
    #[test]
    fn blocked_cholesky_matches_the_kernel_to_the_bit() {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            let mut rand = uniform(5);
            for n in [1, 2, 3, 4, 5, 7, 8, 9, 12, 13, 27, 40] {
                for zeros in [false, true] {
                    let b = DMatrix::from_fn(n, n, |i, k| {
                        if zeros && (i + 2 * k) % 3 == 0 && i != k {
                            0.0
                        } else {
                            rand()
                        }
                    });
                    let mut a = &b * b.transpose() + DMatrix::identity(n, n);
                    if zeros {
                        // Decoupled halves: zero blocks in A and its factor.
                        for i in 0..n / 2 {
                            for k in n / 2..n {
                                a[(i, k)] = 0.0;
                                a[(k, i)] = 0.0;
                            }
                        }
                    }
                    // A strided buffer whose upper triangle must keep what it held.
                    let (mut want, mut got) =
                        (DMatrix::from_element(n + 3, n, 7.0), DMatrix::from_element(n + 3, n, 7.0));
                    assert!(cholesky_kernel(&a, n, &mut want, 0.0));
                    // SAFETY: the CPU has AVX2 (checked above).
                    assert!(unsafe { cholesky_avx2(&a, n, &mut got, 0.0) });
                    for k in 0..n {
                        for i in k..n {
                            assert_eq!(want[(i, k)].to_bits(), got[(i, k)].to_bits(), "n {n} ({i}, {k})");
                        }
                        for i in 0..k {
                            assert_eq!(got[(i, k)], 7.0, "n {n} upper ({i}, {k})");
                        }
                    }
                }
            }
            let a = DMatrix::from_row_slice(
                5,
                5,
                &[
                    1.0, 2.0, 0.0, 0.0, 0.0, 2.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0,
                    1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0,
                ],
            );
            let (mut l, mut want) = (DMatrix::zeros(5, 5), DMatrix::zeros(5, 5));
            // SAFETY: as above.
            assert!(!unsafe { cholesky_avx2(&a, 5, &mut l, 0.0) });
            assert!(!cholesky_kernel(&a, 5, &mut want, 0.0));
            // The failed column (1, pivot 1 − 2² < 0) is left undivided by both, the same bits.
            for k in 0..2 {
                for i in k..5 {
                    assert_eq!(l[(i, k)].to_bits(), want[(i, k)].to_bits(), "failed factor ({i}, {k})");
                }
            }
        }
    }

    /// The deletion form against the pivoted factor and QR (both called directly) on a chain's
    /// pattern: groups of rows, each coupling two neighbouring "bodies" of six dofs, half of
    /// each group's rows combinations of its others (a box's redundant corners); consistent and
    /// inconsistent right-hand sides. The same rank, the same A⁺ b to round-off.
    #[test]
    fn deletion_min_norm_matches_the_pivoted_form() {
        let mut rand = uniform(3);
        for bodies in [2usize, 5, 12] {
            let nv = 6 * bodies;
            let mut rows: Vec<DVector<f64>> = Vec::new();
            for g in 0..bodies - 1 {
                let base: Vec<DVector<f64>> = (0..6)
                    .map(|_| {
                        DVector::from_fn(nv, |i, _| if i / 6 == g || i / 6 == g + 1 { rand() } else { 0.0 })
                    })
                    .collect();
                let mut group = base.clone();
                for _ in 0..6 {
                    let mut x = DVector::zeros(nv);
                    for v in &base {
                        x += v * rand();
                    }
                    group.push(x);
                }
                // Interleaved: dependent rows between independent ones, as a patch's corners.
                group.swap(3, 7);
                rows.extend(group);
            }
            let n = rows.len();
            let j = DMatrix::from_fn(n, nv, |i, k| rows[i][k]);
            let a0 = &j * j.transpose();
            for consistent in [true, false] {
                let z = DVector::from_fn(n, |_, _| rand());
                let rhs = if consistent { &a0 * &z } else { z.clone() };
                let tol = RANK_TOLERANCE * (0..n).map(|i| a0[(i, i)]).fold(0.0, f64::max);
                let (mut a1, mut a2) = (a0.clone(), a0.clone());
                let (mut l1, mut l2) = (DMatrix::zeros(n, n), DMatrix::zeros(n, n));
                let (mut p1, mut p2) = (DVector::zeros(n), DVector::zeros(n));
                let (mut x1, mut x2) = (rhs.as_slice().to_vec(), rhs.as_slice().to_vec());
                let r1 = deletion_min_norm::<false>(&mut a1, n, &mut x1, &mut l1, &mut p1, tol);
                let r2 = pivoted_min_norm(&mut a2, n, &mut x2, &mut l2, &mut p2, tol);
                assert_eq!(r1, r2, "bodies {bodies}");
                assert_eq!(r1, 6 * (bodies - 1), "bodies {bodies}");
                let scale = x2.iter().fold(1.0f64, |m, x| m.max(x.abs()));
                let err = x1.iter().zip(&x2).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
                assert!(err < 1e-9 * scale, "bodies {bodies} consistent {consistent}: {err:e}");
                #[cfg(target_arch = "x86_64")]
                if std::arch::is_x86_feature_detected!("avx2") {
                    let (mut a3, mut l3, mut p3) = (a0.clone(), DMatrix::zeros(n, n), DVector::zeros(n));
                    let mut x3 = rhs.as_slice().to_vec();
                    // SAFETY: the CPU has AVX2 (checked above).
                    let r3 = unsafe { deletion_min_norm_avx2(&mut a3, n, &mut x3, &mut l3, &mut p3, tol) };
                    assert_eq!(r3, r1);
                    for (a, b) in x3.iter().zip(&x1) {
                        assert_eq!(a.to_bits(), b.to_bits(), "AVX2 and scalar forms differ");
                    }
                }
            }
        }
    }

    /// A = B Bᵀ with B n × r (rank r < n), b = A z: the solution is A⁺ b, the component of z in
    /// range(A), checked against the projection onto range(B) by normal equations in f64.
    #[test]
    fn minimum_norm_solution_of_rank_deficient_systems() {
        let mut rand = uniform(7);
        for (n, r) in [(2, 1), (5, 3), (12, 6), (30, 17), (40, 39)] {
            let bm = DMatrix::from_fn(n, r, |_, _| rand());
            let z = DVector::from_fn(n, |_, _| rand());
            let a0 = &bm * bm.transpose();
            let rhs = &a0 * &z;
            // The expected x: the projection of z onto range(B).
            let gram = bm.transpose() * &bm;
            let coef = gram.clone().cholesky().unwrap().solve(&(bm.transpose() * &z));
            let expected = &bm * coef;
            let mut a = a0.clone();
            let (mut w, mut v) = (DMatrix::zeros(n, n), DVector::zeros(n));
            let mut x = rhs.as_slice().to_vec();
            assert_eq!(solve_psd(&mut a, &mut x, &mut w, &mut v), r, "n {n} r {r}");
            let err = x.iter().zip(expected.iter()).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
            assert!(err < 1e-10 * expected.amax().max(1.0), "n {n} r {r}: {err:e}");
        }
    }
}
