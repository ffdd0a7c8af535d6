//! The rows' part of the Newton Hessian, Jᵀ (∂²s) J, added to the lower triangle of H = M + …
//! (MuJoCo documentation, "Computation → Solver", Newton; MuJoCo's `MakeHessian` and
//! `HessianCone`, engine_solver.c, which form Jᵀ D J and add the cones' blocks).
//!
//! The rows come one block at a time from [`Rows::hessian`](super::cost::Rows::hessian): a
//! weight D on a quadratic row, or a dense block on an elliptic contact's rows. Rows of one contact
//! share their nonzero columns (`rows.rs`, `contact_rows`, records a contact's rows over the union of
//! their nonzeros), so they are summed as a group: each entry's sum over the group's rows is
//! one dot product of two contiguous vectors (the group's values laid out transposed in scratch)
//! added to H once — instead of one scattered read–modify–write of H per row and entry. Consecutive scalar rows with the same columns (a
//! pyramidal contact's edges in their quadratic state) form one group; an elliptic contact's
//! block multiplies its rows first (W = B G, G the rows' values), then Gᵀ W is summed the same
//! way. Rows whose columns differ (J recorded by the full scan, which drops exact zeros) are
//! added pair by pair.

use super::primal::Sparsity;
use super::sparse_cholesky::SparseH;
use nalgebra::DMatrix;

/// The most scalar rows summed as one group (a pyramidal contact of condim 6 has 10; a box
/// on a plane, four contacts on the same dofs, 16).
const GROUP: usize = 16;
/// The most rows of a block (an elliptic contact of condim 6).
const BLOCK: usize = 6;

/// The length of the assembler's scratch for `nv` dofs (a group's transposed values and
/// coefficients, at most `GROUP` rows on at most nv columns each).
pub(super) const fn scratch_len(nv: usize) -> usize {
    2 * GROUP.div_ceil(4) * 4 * (nv + 3)
}

/// Where the rows' terms are added: a dense nv × nv H (the dense Newton path, `primal.rs`), or
/// H's values on the analyzed pattern of its sparse factor (the islands' path: no nv² storage,
/// each row of H contiguous; `sparse_cholesky.rs`). Both receive the same sums in the same
/// order, entry by entry.
pub(super) enum Target<'a> {
    Dense(&'a mut DMatrix<f64>),
    Sparse(SparseH<'a>),
}

/// Adds the rows' Hessian blocks to H's lower triangle (see the module doc). Scalar rows are
/// held in a pending group until a row with other columns (or a block) arrives; [`finish`]
/// adds the last group.
///
/// [`finish`]: Assembler::finish
pub(super) struct Assembler<'a> {
    h: Target<'a>,
    nz: &'a Sparsity<'a>,
    /// Scratch for a group's values (laid out transposed, or padded), [`scratch_len`] long.
    column: &'a mut [f64],
    /// The pending group: its rows and their weights.
    rows: [usize; GROUP],
    weights: [f64; GROUP],
    len: usize,
}

impl<'a> Assembler<'a> {
    /// An assembler adding to `h` (over nv dofs) the rows of `nz`; `column` is scratch of
    /// [`scratch_len`]`(nv)`.
    pub fn new(h: Target<'a>, nz: &'a Sparsity<'a>, column: &'a mut [f64]) -> Self {
        Self { h, nz, column, rows: [0; GROUP], weights: [0.0; GROUP], len: 0 }
    }

    /// Adds block `block` (dim × dim, symmetric) on rows i..i + dim: Jᵀ B J over those rows.
    pub fn add(&mut self, i: usize, dim: usize, block: &[[f64; 6]; 6]) {
        if dim == 1 {
            if self.len == GROUP || (self.len > 0 && self.nz.columns(self.rows[0]) != self.nz.columns(i)) {
                self.flush();
            }
            self.rows[self.len] = i;
            self.weights[self.len] = block[0][0];
            self.len += 1;
            return;
        }
        self.flush();
        let cols = self.nz.columns(i);
        if (i + 1..i + dim).all(|r| self.nz.columns(r) == cols) {
            self.add_block(i, dim, block);
        } else {
            for a in i..i + dim {
                for b in i..i + dim {
                    self.add_pair(a, b, block[a - i][b - i]);
                }
            }
        }
    }

    /// Adds the pending group.
    pub fn finish(mut self) {
        self.flush();
    }

    /// The pending scalar rows (same columns): H[p][q] += Σ_r w_r G_r[p] G_r[q], p ≥ q.
    fn flush(&mut self) {
        let k = self.len;
        if k == 0 {
            return;
        }
        self.len = 0;
        let cols = self.nz.columns(self.rows[0]);
        let mut g: [&[f64]; GROUP] = [&[]; GROUP];
        for (g, &row) in g.iter_mut().zip(&self.rows[..k]) {
            *g = self.nz.row_values(row).1;
        }
        let weights = self.weights;
        if let Target::Dense(h) = &mut self.h {
            if k == 1 && cols.len() == 1 {
                // One row on one dof (a joint limit): H[p][p] += (w g) g, as below.
                let (p, g) = (cols[0], g[0][0]);
                h[(p, p)] += weights[0] * g * g;
                return;
            }
            if k > 8 {
                let nv = h.nrows();
                add_weighted_rows(h.as_mut_slice(), nv, cols, &g[..k], &weights[..k], self.column);
                return;
            }
        }
        let coefficients = |g_q: &[f64], c: &mut [f64]| {
            for ((c, &w), &g) in c.iter_mut().zip(&weights[..k]).zip(g_q) {
                *c = w * g;
            }
        };
        match &mut self.h {
            Target::Dense(h) => add_columns(h, cols, &g[..k], self.column, coefficients),
            Target::Sparse(h) => add_columns_sparse(h, cols, &g[..k], self.column, coefficients),
        }
    }

    /// Rows i..i + dim with the same columns and a dense block B: with G the rows' values,
    /// H[p][q] += Σ_a G_a[p] (B G)_a[q], p ≥ q.
    fn add_block(&mut self, i: usize, dim: usize, block: &[[f64; 6]; 6]) {
        // The block's size a compile-time constant: its products unrolled whatever the
        // surrounding code's inlining.
        match dim {
            1 => self.add_block_of::<1>(i, block),
            2 => self.add_block_of::<2>(i, block),
            3 => self.add_block_of::<3>(i, block),
            4 => self.add_block_of::<4>(i, block),
            5 => self.add_block_of::<5>(i, block),
            _ => self.add_block_of::<BLOCK>(i, block),
        }
    }

    /// [`Self::add_block`] of a `D` × `D` block: each column's coefficients B g_q summed over
    /// b = 0 … D − 1 in order.
    fn add_block_of<const D: usize>(&mut self, i: usize, block: &[[f64; 6]; 6]) {
        let cols = self.nz.columns(i);
        let mut g: [&[f64]; D] = [&[]; D];
        for (a, g) in g.iter_mut().enumerate() {
            *g = self.nz.row_values(i + a).1;
        }
        let coefficients = |g_q: &[f64], c: &mut [f64]| {
            for (c, row) in c.iter_mut().zip(block) {
                let mut s = 0.0;
                for (&b_ab, &g_b) in row[..D].iter().zip(&g_q[..D]) {
                    s += b_ab * g_b;
                }
                *c = s;
            }
        };
        match &mut self.h {
            Target::Dense(h) => add_columns(h, cols, &g, self.column, coefficients),
            Target::Sparse(h) => add_columns_sparse(h, cols, &g, self.column, coefficients),
        }
    }

    /// H[p][q] += w J[a][p] J[b][q] over the nonzero columns p ≥ q of rows a and b.
    fn add_pair(&mut self, a: usize, b: usize, w: f64) {
        let ((row_a, j_a), (row_b, j_b)) = (self.nz.row_values(a), self.nz.row_values(b));
        let h = match &mut self.h {
            Target::Dense(h) => h,
            Target::Sparse(h) => {
                for (&q, &j_bq) in row_b.iter().zip(j_b) {
                    let c = w * j_bq;
                    for (&p, &j_ap) in row_a.iter().zip(j_a) {
                        if p >= q {
                            if let Some(entry) = h.entry(p, q) {
                                *entry += j_ap * c;
                            }
                        }
                    }
                }
                return;
            }
        };
        let nv = h.nrows();
        let h = h.as_mut_slice();
        for (&q, &j_bq) in row_b.iter().zip(j_b) {
            let column = &mut h[q * nv..(q + 1) * nv];
            let c = w * j_bq;
            for (&p, &j_ap) in row_a.iter().zip(j_a) {
                if p >= q {
                    column[p] += j_ap * c;
                }
            }
        }
    }
}

/// H[p][q] += Σ_r c_r(q) G_r[p] over columns q of `cols` and p ≥ q (rows `g`, all on `cols`;
/// `coefficients(g_q, c)` writes c_r(q) from the rows' values g_q = (G_0[q], …) at column
/// position q). Up to eight rows, each entry's sum is formed in registers from the rows' values,
/// four rows at a time (an elliptic contact of condim 6 is two such passes); more rows by
/// [`add_columns_wide_kernel`] (scalar rows: [`add_weighted_rows`]), four entries of a column at a time, each entry's sum over the rows the
/// dot product [`dot4`] of the rows' values transposed and the coefficients. Either way it is
/// added to H once.
#[inline(always)]
fn add_columns(
    h: &mut DMatrix<f64>,
    cols: &[usize],
    g: &[&[f64]],
    scratch: &mut [f64],
    mut coefficients: impl FnMut(&[f64], &mut [f64]),
) {
    let (n, k) = (cols.len(), g.len());
    let nv = h.nrows();
    let h = h.as_mut_slice();
    if k <= 8 {
        // Up to eight rows: each entry's sum over (up to) four rows at a time in a register,
        // straight from the rows' values.
        let (mut g_q, mut c) = ([0.0; 8], [0.0; 8]);
        for q in 0..n {
            for (x, g) in g_q.iter_mut().zip(g) {
                *x = g[q];
            }
            coefficients(&g_q[..k], &mut c[..k]);
            let column = &mut h[cols[q] * nv..(cols[q] + 1) * nv];
            let rows = &cols[q..];
            for (g, c) in g.chunks(4).zip(c[..k].chunks(4)) {
                match g.len() {
                    1 => {
                        for (&p, &g0) in rows.iter().zip(&g[0][q..n]) {
                            column[p] += c[0] * g0;
                        }
                    }
                    2 => {
                        for ((&p, &g0), &g1) in rows.iter().zip(&g[0][q..n]).zip(&g[1][q..n]) {
                            column[p] += c[0] * g0 + c[1] * g1;
                        }
                    }
                    3 => {
                        for (((&p, &g0), &g1), &g2) in
                            rows.iter().zip(&g[0][q..n]).zip(&g[1][q..n]).zip(&g[2][q..n])
                        {
                            column[p] += c[0] * g0 + c[1] * g1 + c[2] * g2;
                        }
                    }
                    _ => {
                        for ((((&p, &g0), &g1), &g2), &g3) in
                            rows.iter().zip(&g[0][q..n]).zip(&g[1][q..n]).zip(&g[2][q..n]).zip(&g[3][q..n])
                        {
                            column[p] += c[0] * g0 + c[1] * g1 + c[2] * g2 + c[3] * g3;
                        }
                    }
                }
            }
        }
        return;
    }
    add_columns_wide_kernel(h, nv, cols, g, scratch, &mut coefficients);
}

/// H[p][q] += Σ_r w_r G_r[p] G_r[q] (p ≥ q, over `cols`) for more than eight scalar rows `g`
/// with weights `w` into the dense H (column-major, `nv` rows): the sums [`add_columns`] forms
/// for them — each entry's sum over the rows in four partial sums (the rows r ≡ l mod 4 in
/// partial sum l, in order, each term G_r[p] · (w_r G_r[q])), combined as (s₀ + s₂) + (s₁ + s₃)
/// and added to H once: the dot product [`dot4`] of the rows' values transposed and the
/// coefficients, the same bits. With AVX2, four entries of a column at a time: the rows' values
/// are copied once into `scratch`, each followed by three zeros (four consecutive columns of a
/// row are one load), beside them the coefficients w_r G_r; entries whose four columns are
/// consecutive dofs are added to H as one vector.
fn add_weighted_rows(h: &mut [f64], nv: usize, cols: &[usize], g: &[&[f64]], w: &[f64], scratch: &mut [f64]) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2 (checked just above), all `add_weighted_rows_avx2` requires.
        unsafe { add_weighted_rows_avx2(h, nv, cols, g, w, scratch) };
        return;
    }
    let mut coefficients = |g_q: &[f64], c: &mut [f64]| {
        for ((c, &w), &g) in c.iter_mut().zip(w).zip(g_q) {
            *c = w * g;
        }
    };
    add_columns_wide_kernel(h, nv, cols, g, scratch, &mut coefficients);
}

/// [`add_weighted_rows`] for AVX2 (see there): the same products and sums in the same order, no
/// fused multiply–adds, so the same bits.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn add_weighted_rows_avx2(
    h: &mut [f64],
    nv: usize,
    cols: &[usize],
    g: &[&[f64]],
    w: &[f64],
    scratch: &mut [f64],
) {
    use std::arch::x86_64::{
        _mm256_add_pd, _mm256_broadcast_sd, _mm256_loadu_pd, _mm256_mul_pd, _mm256_setzero_pd,
        _mm256_storeu_pd,
    };
    let (n, k) = (cols.len(), g.len().min(GROUP).min(w.len()));
    let n4 = n + 3;
    let (rows, rest) = scratch.split_at_mut(k * n4);
    let coef = &mut rest[..k * n4];
    for (((row, c), g), &w) in rows.chunks_exact_mut(n4).zip(coef.chunks_exact_mut(n4)).zip(g).zip(w) {
        row[..n].copy_from_slice(&g[..n]);
        row[n..].fill(0.0);
        for (c, &g) in c.iter_mut().zip(&g[..n]) {
            *c = w * g;
        }
    }
    let (base, coef) = (rows.as_ptr(), coef.as_ptr());
    let whole = k / 4 * 4;
    for (q, &col_q) in cols.iter().enumerate() {
        let column = &mut h[col_q * nv..(col_q + 1) * nv];
        let mut t = q;
        while t < n {
            let mut v = [0.0; 4];
            // SAFETY: row r's four values from position t < n end at r · n4 + t + 4 ≤ (r + 1) · n4,
            // inside `rows` (k rows of n4), and its coefficient at column position q < n is inside
            // `coef` (k rows of n4); the CPU has AVX2 (this function's contract).
            unsafe {
                let (mut s0, mut s1, mut s2, mut s3) =
                    (_mm256_setzero_pd(), _mm256_setzero_pd(), _mm256_setzero_pd(), _mm256_setzero_pd());
                let (mut p, mut c) = (base.add(t), coef.add(q));
                let term = |p: *const f64, c: *const f64| {
                    _mm256_mul_pd(_mm256_loadu_pd(p), _mm256_broadcast_sd(&*c))
                };
                let mut r = 0;
                while r < whole {
                    s0 = _mm256_add_pd(s0, term(p, c));
                    s1 = _mm256_add_pd(s1, term(p.add(n4), c.add(n4)));
                    s2 = _mm256_add_pd(s2, term(p.add(2 * n4), c.add(2 * n4)));
                    s3 = _mm256_add_pd(s3, term(p.add(3 * n4), c.add(3 * n4)));
                    p = p.add(4 * n4);
                    c = c.add(4 * n4);
                    r += 4;
                }
                let left = k - whole;
                if left > 0 {
                    s0 = _mm256_add_pd(s0, term(p, c));
                }
                if left > 1 {
                    s1 = _mm256_add_pd(s1, term(p.add(n4), c.add(n4)));
                }
                if left > 2 {
                    s2 = _mm256_add_pd(s2, term(p.add(2 * n4), c.add(2 * n4)));
                }
                _mm256_storeu_pd(v.as_mut_ptr(), _mm256_add_pd(_mm256_add_pd(s0, s2), _mm256_add_pd(s1, s3)));
            }
            add_four(column, cols, t, &v);
            t += 4;
        }
    }
}

/// `column[cols[t + i]] += v[i]` for the (up to) four column positions t … t + 3 below
/// `cols.len()`: one slice update when they are four consecutive dofs (a free joint's block).
#[inline(always)]
fn add_four(column: &mut [f64], cols: &[usize], t: usize, v: &[f64; 4]) {
    let (n, p0) = (cols.len(), cols[t]);
    if t + 4 <= n && cols[t + 3] == p0 + 3 {
        for (x, &v) in column[p0..p0 + 4].iter_mut().zip(v) {
            *x += v;
        }
    } else {
        for (&p, &v) in cols[t..n.min(t + 4)].iter().zip(v) {
            column[p] += v;
        }
    }
}

/// [`add_columns`]'s sums for more than eight rows without AVX2, four entries of a column at a
/// time lane by lane (see [`add_weighted_rows`]), the coefficients from `coefficients`.
#[inline(always)]
fn add_columns_wide_kernel(
    h: &mut [f64],
    nv: usize,
    cols: &[usize],
    g: &[&[f64]],
    scratch: &mut [f64],
    coefficients: &mut impl FnMut(&[f64], &mut [f64]),
) {
    let (n, k) = (cols.len(), g.len().min(GROUP));
    // Each row's values and three zeros: a block of four from any column position t < n.
    let n4 = n + 3;
    let rows = &mut scratch[..k * n4];
    for (row, g) in rows.chunks_exact_mut(n4).zip(g) {
        row[..n].copy_from_slice(&g[..n]);
        row[n..].fill(0.0);
    }
    let rows = &*rows;
    let (mut g_q, mut c) = ([0.0; GROUP], [0.0; GROUP]);
    // Four consecutive values of row r from column position t < n on.
    let at = |r: usize, t: usize| -> [f64; 4] {
        let x = &rows[r * n4 + t..r * n4 + t + 4];
        [x[0], x[1], x[2], x[3]]
    };
    let whole = k / 4 * 4;
    for (q, &col_q) in cols.iter().enumerate() {
        for (x, row) in g_q.iter_mut().zip(rows.chunks_exact(n4)) {
            *x = row[q];
        }
        coefficients(&g_q[..k], &mut c[..k]);
        let column = &mut h[col_q * nv..(col_q + 1) * nv];
        let mut t = q;
        while t < n {
            let mut s = [[0.0f64; 4]; 4];
            let mut r = 0;
            while r < whole {
                for (l, s_l) in s.iter_mut().enumerate() {
                    let (g_p, c_r) = (at(r + l, t), c[r + l]);
                    for lane in 0..4 {
                        s_l[lane] += g_p[lane] * c_r;
                    }
                }
                r += 4;
            }
            for (l, s_l) in s.iter_mut().enumerate().take(k - whole) {
                let (g_p, c_r) = (at(r + l, t), c[r + l]);
                for lane in 0..4 {
                    s_l[lane] += g_p[lane] * c_r;
                }
            }
            let mut v = [0.0; 4];
            for (lane, v) in v.iter_mut().enumerate() {
                *v = (s[0][lane] + s[2][lane]) + (s[1][lane] + s[3][lane]);
            }
            add_four(column, cols, t, &v);
            t += 4;
        }
    }
}

/// For more than eight rows (`add_columns_sparse`): the rows' values transposed,
/// per column q its k values padded with zeros to kp (a multiple of 4), and each column's
/// coefficients beside them, both in `scratch`; (Gᵀ, C, kp). (Out of line: large groups are
/// rare, and the callers' common paths stay compact.)
#[inline(never)]
fn transposed_with_coefficients<'a>(
    scratch: &'a mut [f64],
    g: &[&[f64]],
    n: usize,
    coefficients: &mut impl FnMut(&[f64], &mut [f64]),
) -> (&'a [f64], &'a [f64], usize) {
    let k = g.len();
    let kp = k.div_ceil(4) * 4;
    let (gt, rest) = scratch.split_at_mut(n * kp);
    let c = &mut rest[..n * kp];
    // Row by row (each row's values read contiguously), then the padding.
    for (r, g) in g.iter().enumerate() {
        for (gt_p, &v) in gt.chunks_exact_mut(kp).zip(&g[..n]) {
            gt_p[r] = v;
        }
    }
    if k < kp {
        for gt_p in gt.chunks_exact_mut(kp) {
            gt_p[k..].fill(0.0);
        }
    }
    for (g_q, c_q) in gt.chunks_exact(kp).zip(c.chunks_exact_mut(kp)) {
        coefficients(&g_q[..k], &mut c_q[..k]);
        c_q[k..].fill(0.0);
    }
    (gt, c, kp)
}

/// [`add_columns`] into H's values on the sparse factor's pattern: the same sum for each entry
/// (p, q), p ≥ q, added once, in the same order over the rows. The coefficients of every
/// column are formed first (in `scratch`), then H is walked row by row (each row's pattern
/// ascending, as the group's columns are: one merge per row).
// (Kept out of line: the dense path's assembly, inlined into its callers, stays as compact as
// it was without it.)
#[inline(never)]
fn add_columns_sparse(
    h: &mut SparseH,
    cols: &[usize],
    g: &[&[f64]],
    scratch: &mut [f64],
    mut coefficients: impl FnMut(&[f64], &mut [f64]),
) {
    let (n, k) = (cols.len(), g.len());
    if k <= 8 {
        // Each column's coefficients c(q) at c[8q..8q + k] (from the rows' values there, as
        // `add_columns` forms them), then each entry's sum over (up to) four rows at a time.
        let c = &mut scratch[..8 * n];
        let mut g_q = [0.0; 8];
        for (q, c_q) in c.chunks_exact_mut(8).enumerate() {
            for (x, g) in g_q.iter_mut().zip(g) {
                *x = g[q];
            }
            coefficients(&g_q[..k], &mut c_q[..k]);
        }
        // (The group's size a compile-time constant: the sums unrolled.)
        match k {
            1 => add_rows_sparse::<1>(h, cols, g, c),
            2 => add_rows_sparse::<2>(h, cols, g, c),
            3 => add_rows_sparse::<3>(h, cols, g, c),
            4 => add_rows_sparse::<4>(h, cols, g, c),
            5 => add_rows_sparse::<5>(h, cols, g, c),
            6 => add_rows_sparse::<6>(h, cols, g, c),
            7 => add_rows_sparse::<7>(h, cols, g, c),
            _ => add_rows_sparse::<8>(h, cols, g, c),
        }
        return;
    }
    let (gt, c, kp) = transposed_with_coefficients(scratch, g, n, &mut coefficients);
    for (t, &p) in cols.iter().enumerate() {
        let gt_p = &gt[t * kp..(t + 1) * kp];
        let (row, vals) = h.row_mut(p);
        let mut u = 0;
        for (s, &q) in cols[..t].iter().enumerate() {
            u = find_from(row, u, q);
            if u < row.len() {
                vals[u] += dot4(gt_p, &c[s * kp..(s + 1) * kp]);
            }
        }
        h.diag[p] += dot4(gt_p, &c[t * kp..(t + 1) * kp]);
    }
}

/// The k ≤ 8 rows' sums of [`add_columns_sparse`] with `K` rows: entry (p, q) gets
/// Σ_r c_r(q) G_r[p] four rows at a time (one addition per four), as `add_columns` forms it.
#[inline(always)]
fn add_rows_sparse<const K: usize>(h: &mut SparseH, cols: &[usize], g: &[&[f64]], c: &[f64]) {
    // The sum of the rows lo..hi (at most four) in order, left to right.
    #[inline(always)]
    fn chunk<const K: usize>(c: &[f64], g_p: &[f64; 8], lo: usize) -> f64 {
        let hi = (lo + 4).min(K);
        let mut v = c[lo] * g_p[lo];
        for r in lo + 1..hi {
            v += c[r] * g_p[r];
        }
        v
    }
    for (t, &p) in cols.iter().enumerate() {
        // The rows' values at p, once per row of H.
        let mut g_p = [0.0; 8];
        for (x, g) in g_p.iter_mut().zip(g) {
            *x = g[t];
        }
        let (row, vals) = h.row_mut(p);
        let mut u = 0;
        for (s, &q) in cols[..t].iter().enumerate() {
            u = find_from(row, u, q);
            if u < row.len() {
                let c_s = &c[8 * s..8 * s + 8];
                vals[u] += chunk::<K>(c_s, &g_p, 0);
                if K > 4 {
                    vals[u] += chunk::<K>(c_s, &g_p, 4);
                }
            }
        }
        let c_t = &c[8 * t..8 * t + 8];
        h.diag[p] += chunk::<K>(c_t, &g_p, 0);
        if K > 4 {
            h.diag[p] += chunk::<K>(c_t, &g_p, 4);
        }
    }
}

/// The position of `q` in the ascending `row` from position `u` on (`row.len()` if absent,
/// which a pattern that covers the rows' pairs never has).
#[inline(always)]
fn find_from(row: &[usize], mut u: usize, q: usize) -> usize {
    while u < row.len() && row[u] < q {
        u += 1;
    }
    debug_assert!(u < row.len() && row[u] == q, "a row pair outside H's pattern");
    if u < row.len() && row[u] == q {
        u
    } else {
        row.len()
    }
}

impl SparseH<'_> {
    /// The stored entry (p, q), p ≥ q, of H's lower triangle (None outside the pattern).
    fn entry(&mut self, p: usize, q: usize) -> Option<&mut f64> {
        if p == q {
            return Some(&mut self.diag[p]);
        }
        let (a, b) = (self.start[p], self.start[p + 1]);
        let u = self.cols[a..b].binary_search(&q).ok()?;
        Some(&mut self.vals[a + u])
    }

    /// Row p's strictly lower columns (ascending) and its values there.
    #[inline(always)]
    fn row_mut(&mut self, p: usize) -> (&[usize], &mut [f64]) {
        let (a, b) = (self.start[p], self.start[p + 1]);
        (&self.cols[a..b], &mut self.vals[a..b])
    }
}

/// Σ a_i b_i of two equally long vectors whose length is a multiple of four: four partial
/// sums (the lanes of a vector register) combined at the end.
#[inline]
fn dot4(a: &[f64], b: &[f64]) -> f64 {
    let mut s = [0.0; 4];
    for (x, y) in a.chunks_exact(4).zip(b.chunks_exact(4)) {
        let (x, y): (&[f64; 4], &[f64; 4]) =
            (x.try_into().unwrap_or(&[0.0; 4]), y.try_into().unwrap_or(&[0.0; 4]));
        for l in 0..4 {
            s[l] += x[l] * y[l];
        }
    }
    (s[0] + s[2]) + (s[1] + s[3])
}

#[cfg(test)]
mod tests {
    use super::super::sparse_cholesky::SparseCholesky;
    use super::*;

    /// Jᵀ B J (lower triangle) by the definition.
    fn reference(j: &DMatrix<f64>, blocks: &[(usize, usize, [[f64; 6]; 6])], nv: usize) -> DMatrix<f64> {
        let mut h = DMatrix::zeros(nv, nv);
        for &(i, dim, b) in blocks {
            for a in 0..dim {
                for c in 0..dim {
                    for p in 0..nv {
                        for q in 0..=p {
                            h[(p, q)] += j[(i + a, p)] * b[a][c] * j[(i + c, q)];
                        }
                    }
                }
            }
        }
        h
    }

    #[test]
    fn grouped_rows_and_blocks_sum_to_jt_b_j() {
        // Rows 0..2: one group on columns {1, 3, 4}; row 2 alone on {0, 4}; rows 3..6 a block
        // on {0, 2, 3} (row 4 has an exact zero there, kept); rows 6..8 a block whose rows have
        // different columns (pair by pair); rows 8..14 a group of six on {0, 1, 3, 4} (two
        // passes of the register path), rows 14..26 a group of twelve on {0, 2, 4} and rows
        // 26..35 a group of nine on {0, …, 4} (the wide path; its columns scattered, then
        // consecutive).
        let nv = 5;
        let mut cols: Vec<&[usize]> =
            vec![&[1, 3, 4], &[1, 3, 4], &[0, 4], &[0, 2, 3], &[0, 2, 3], &[0, 2, 3], &[2], &[1, 2]];
        cols.extend([&[0usize, 1, 3, 4][..]; 6]);
        cols.extend([&[0usize, 2, 4][..]; 12]);
        cols.extend([&[0usize, 1, 2, 3, 4][..]; 9]);
        let mut j = DMatrix::zeros(cols.len(), nv);
        let (mut start, mut index, mut value) = (vec![0], vec![], vec![]);
        for (i, c) in cols.iter().enumerate() {
            for (t, &k) in c.iter().enumerate() {
                let v = if i == 4 && k == 2 { 0.0 } else { 0.3 + 0.7 * ((i * 5 + t * 3) % 7) as f64 - 1.1 };
                j[(i, k)] = v;
                index.push(k);
                value.push(v);
            }
            start.push(index.len());
        }
        let nz = Sparsity { start: &start, index: &index, value: &value };
        let mut b3 = [[0.0; 6]; 6];
        for (a, row) in b3.iter_mut().enumerate().take(3) {
            for (c, x) in row.iter_mut().enumerate().take(3) {
                *x = if a == c { 2.0 + a as f64 } else { 0.25 };
            }
        }
        let mut b2 = [[0.0; 6]; 6];
        b2[0] = [1.5, -0.5, 0.0, 0.0, 0.0, 0.0];
        b2[1] = [-0.5, 0.75, 0.0, 0.0, 0.0, 0.0];
        let scalar = |w: f64| {
            let mut b = [[0.0; 6]; 6];
            b[0][0] = w;
            b
        };
        let mut blocks =
            vec![(0, 1, scalar(2.0)), (1, 1, scalar(0.5)), (2, 1, scalar(3.0)), (3, 3, b3), (6, 2, b2)];
        blocks.extend((8..35).map(|i| (i, 1, scalar(0.2 + 0.1 * i as f64))));
        let mut h = DMatrix::zeros(nv, nv);
        let mut column = vec![0.0; scratch_len(nv)];
        let mut asm = Assembler::new(Target::Dense(&mut h), &nz, &mut column);
        for &(i, dim, b) in &blocks {
            asm.add(i, dim, &b);
        }
        asm.finish();
        // The same into H's values on a sparse factor's (full) pattern: the same bits.
        let full = DMatrix::from_fn(nv, nv, |p, q| if p == q { nv as f64 } else { 1.0 });
        let mut factor = SparseCholesky::default();
        assert!(factor.factor(&full, nv, 0.0));
        factor.load(&DMatrix::zeros(nv, nv));
        let mut asm = Assembler::new(Target::Sparse(factor.h_mut()), &nz, &mut column);
        for &(i, dim, b) in &blocks {
            asm.add(i, dim, &b);
        }
        asm.finish();
        let mut sparse = factor.h_mut();
        for p in 0..nv {
            for q in 0..=p {
                assert_eq!(sparse.entry(p, q).map(|x| *x), Some(h[(p, q)]), "H[{p}][{q}]");
            }
        }
        let want = reference(&j, &blocks, nv);
        for p in 0..nv {
            for q in 0..nv {
                let w = if q <= p { want[(p, q)] } else { 0.0 };
                assert!(
                    (h[(p, q)] - w).abs() <= 1e-14 * (1.0 + w.abs()),
                    "H[{p}][{q}] = {} against {w}",
                    h[(p, q)]
                );
            }
        }
    }
}
