//! MuJoCo's primal solvers of the soft problem (MuJoCo documentation, "Computation → Solver"):
//! minimize ½ (a − a₀)ᵀ M (a − a₀) + s(J a − aref) over the acceleration a, with s the piecewise
//! quadratic constraint cost of [`Rows`]. The problem is convex (strictly, since M ≻ 0), so its
//! minimizer — and with it every row's force −∂s/∂jar — is unique; any convergent method gives the
//! same answer to its tolerance.
//!
//! - **Newton**: the search direction −H⁻¹ g with H = M + Jᵀ (∂²s) J (D on quadratic rows, the
//!   cone's block on elliptic contacts in their middle zone), factored by a Cholesky that skips
//!   H's structural zeros (`sparse_cholesky.rs`);
//! - **CG**: Polak–Ribière conjugate gradients preconditioned by M⁻¹ (the LᵀDL factor of M);
//!
//! both with an exact line search along the direction: Newton's method on the convex,
//! piecewise-smooth one-dimensional cost, safeguarded by bisection of a sign-change bracket.
//! Termination as MuJoCo's: the scaled improvement of the cost or the scaled gradient norm below
//! `tolerance`, the scale being 1 / (meaninertia · max(1, nv)).

use super::cost::Rows;
use super::hessian::{Assembler, Target};
use super::tree_mass::TreeMass;
use crate::constraint::dense::{cholesky, cholesky_rank_one, cholesky_solve};
#[cfg(target_arch = "x86_64")]
use crate::constraint::nonzero_list::NonzeroList;
use crate::dynamics::solve_with_factor_unchecked;
use crate::model::{Data, EfcState, Model};
use nalgebra::{DMatrix, DVector};

/// Which primal method.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Primal {
    /// Newton's method with the cost's Hessian (MuJoCo's `mjSOL_NEWTON`).
    Newton,
    /// Polak–Ribière conjugate gradient, M⁻¹-preconditioned (MuJoCo's `mjSOL_CG`).
    Cg,
}

/// Iteration limits and tolerances (MJCF `<option>`).
#[derive(Clone, Copy, Debug)]
pub struct Settings {
    /// The most iterations (`iterations`).
    pub iterations: u32,
    /// Scaled improvement or gradient norm below which the solve stops (`tolerance`).
    pub tolerance: f64,
    /// The most line-search iterations per iteration (`ls_iterations`).
    pub ls_iterations: u32,
    /// Line-search tolerance (`ls_tolerance`).
    pub ls_tolerance: f64,
    /// Start from the previous step's accelerations when they cost less than the unconstrained
    /// ones (`<flag warmstart>`).
    pub warmstart: bool,
    /// 1 / (meaninertia · max(1, nv)).
    pub scale: f64,
}

/// The nonzero columns of each row of J (rows enter the solve through their ancestor dofs only):
/// row i's columns are `index[start[i]..start[i + 1]]`.
pub(super) struct Sparsity<'a> {
    pub start: &'a [usize],
    pub index: &'a [usize],
    /// J's value at each of `index`'s entries (row i's are `value[start[i]..start[i + 1]]`).
    pub value: &'a [f64],
}

impl Sparsity<'_> {
    /// Row i's nonzero columns and J's values there.
    pub fn row_values(&self, i: usize) -> (&[usize], &[f64]) {
        let (s, e) = (self.start[i], self.start[i + 1]);
        (&self.index[s..e], &self.value[s..e])
    }

    /// Row i's nonzero columns.
    pub fn columns(&self, i: usize) -> &[usize] {
        &self.index[self.start[i]..self.start[i + 1]]
    }
}

/// r ← J x (rows 0..nefc): from J's dense storage `dense` when given (small problems: column by
/// column, products that vectorize, each row's sum still in ascending column order), else row by
/// row over the record of J's nonzeros.
pub(super) fn mul_j(
    s: &Sparsity,
    dense: Option<&DMatrix<f64>>,
    nefc: usize,
    x: &DVector<f64>,
    r: &mut DVector<f64>,
) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2 (checked just above), all `mul_j_avx2` requires.
        unsafe { mul_j_avx2(s, dense, nefc, x, r) };
        return;
    }
    mul_j_kernel(s, dense, nefc, x, r);
}

/// [`mul_j`] compiled for AVX2: the same products and sums in the same order (no fused
/// multiply–adds), four entries per instruction, so the same bits. From J's dense storage
/// ([`mul_j_dense_avx2`]) when there are at least four rows.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn mul_j_avx2(
    s: &Sparsity,
    dense: Option<&DMatrix<f64>>,
    nefc: usize,
    x: &DVector<f64>,
    r: &mut DVector<f64>,
) {
    if let Some(j) = dense {
        if nefc >= 4
            && x.len() <= MUL_J_COLUMNS
            && nefc <= j.nrows()
            && x.len() <= j.ncols()
            && nefc <= r.len()
        {
            // SAFETY: the sizes were checked just above; the CPU has AVX2 (this function's
            // contract).
            unsafe { mul_j_dense_avx2(j, x.as_slice(), &mut r.as_mut_slice()[..nefc]) };
            return;
        }
    }
    mul_j_kernel(s, dense, nefc, x, r);
}

/// The most columns (dofs) [`mul_j_dense_avx2`] takes (its list of the nonzero entries of x
/// lives on the stack); the dense Newton path has at most `DENSE_NV_CHAIN`.
#[cfg(target_arch = "x86_64")]
const MUL_J_COLUMNS: usize = 256;

/// r ← J x from J's dense storage (column-major, nefc ≥ 4 rows used): each row's sum over the
/// columns k with x_k ≠ 0 in ascending order, r_i = ((0 + J_ik₀ x_k₀) + J_ik₁ x_k₁) + …, as
/// [`mul_j_kernel`] forms it (the same bits), by [`columns_times_avx2`] over the listed nonzero
/// entries of x.
///
/// # Safety
/// The CPU has AVX2; `4 ≤ r.len() ≤ j.nrows()`, `x.len() ≤ j.ncols()` and
/// `x.len() ≤ MUL_J_COLUMNS`.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn mul_j_dense_avx2(j: &DMatrix<f64>, x: &[f64], r: &mut [f64]) {
    let stride = j.nrows();
    // The nonzero x_k: their column offsets in J and their values.
    let mut nonzero = NonzeroList::<MUL_J_COLUMNS>::new();
    nonzero.list(x.len(), |k| (k * stride, x[k]));
    let offs = nonzero.offsets();
    // SAFETY: the caller's contract: every listed column k < x.len() ≤ J's columns holds
    // r.len() ≤ stride rows; the CPU has AVX2.
    unsafe { columns_times_avx2::<false>(j.as_slice().as_ptr(), nonzero.values(), |c| offs[c], r) };
}

/// r ← Σ_c A[:, c] · v_c over the columns c = 0 .. vals.len() − 1 of a column-major matrix at
/// `a` (column c's first entry at offset `offset(c)`, its factor `vals[c]`), summed in column
/// order, eight rows at a time held in two registers across all columns (instead of r loaded and
/// stored once per column). Rows left over at the end (fewer than four) are formed again by a
/// last block of four ending at the last row (the same values stored twice). `FIRST_AS_IS`: the
/// sum starts with the first column's product as it is (nalgebra's `mul_to`; needs a column),
/// else at zero, then each product added (`mul_j_kernel`'s sums): the two differ only in the sign
/// of a zero sum. No fused multiply–adds: the bits of the scalar forms.
///
/// # Safety
/// The CPU has AVX2; `r.len() ≥ 4`; every column has `r.len()` valid entries from its offset;
/// with `FIRST_AS_IS` `vals` is not empty.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn columns_times_avx2<const FIRST_AS_IS: bool>(
    a: *const f64,
    vals: &[f64],
    offset: impl Fn(usize) -> usize,
    r: &mut [f64],
) {
    use std::arch::x86_64::{
        _mm256_add_pd, _mm256_loadu_pd, _mm256_mul_pd, _mm256_set1_pd, _mm256_setzero_pd, _mm256_storeu_pd,
    };
    let n = r.len();
    let rp = r.as_mut_ptr();
    let first = usize::from(FIRST_AS_IS);
    // SAFETY: every block of rows b..b + 4 has b + 4 ≤ n, inside each column (the caller's
    // contract) and inside r; the CPU has AVX2.
    unsafe {
        let start = |b: usize| {
            if FIRST_AS_IS {
                _mm256_mul_pd(_mm256_loadu_pd(a.add(offset(0) + b)), _mm256_set1_pd(vals[0]))
            } else {
                _mm256_setzero_pd()
            }
        };
        let mut i = 0;
        while i + 8 <= n {
            let (mut r0, mut r1) = (start(i), start(i + 4));
            for (c, &v) in (first..).zip(&vals[first..]) {
                let o = offset(c);
                let (v, col) = (_mm256_set1_pd(v), a.add(o + i));
                r0 = _mm256_add_pd(r0, _mm256_mul_pd(_mm256_loadu_pd(col), v));
                r1 = _mm256_add_pd(r1, _mm256_mul_pd(_mm256_loadu_pd(col.add(4)), v));
            }
            _mm256_storeu_pd(rp.add(i), r0);
            _mm256_storeu_pd(rp.add(i + 4), r1);
            i += 8;
        }
        while i < n {
            let b = i.min(n - 4);
            let mut r0 = start(b);
            for (c, &v) in (first..).zip(&vals[first..]) {
                let o = offset(c);
                r0 = _mm256_add_pd(r0, _mm256_mul_pd(_mm256_loadu_pd(a.add(o + b)), _mm256_set1_pd(v)));
            }
            _mm256_storeu_pd(rp.add(b), r0);
            i = b + 4;
        }
    }
}

#[inline(always)]
fn mul_j_kernel(
    s: &Sparsity,
    dense: Option<&DMatrix<f64>>,
    nefc: usize,
    x: &DVector<f64>,
    r: &mut DVector<f64>,
) {
    let x = x.as_slice();
    let r = &mut r.as_mut_slice()[..nefc];
    if let Some(j) = dense {
        let (stride, j) = (j.nrows(), j.as_slice());
        r.fill(0.0);
        for (k, &x_k) in x.iter().enumerate() {
            if x_k != 0.0 {
                for (r_i, &j_ik) in r.iter_mut().zip(&j[k * stride..k * stride + nefc]) {
                    *r_i += j_ik * x_k;
                }
            }
        }
        return;
    }
    for (i, r_i) in r.iter_mut().enumerate() {
        let (cols, vals) = s.row_values(i);
        *r_i = cols.iter().zip(vals).map(|(&k, &j_ik)| j_ik * x[k]).sum();
    }
}

/// out ← Jᵀ f (rows 0..nefc): from J's dense storage `dense` when given (one dot product per
/// column, in four partial sums), else over the record of J's nonzeros, row after row.
pub(super) fn mul_jt(
    s: &Sparsity,
    dense: Option<&DMatrix<f64>>,
    nefc: usize,
    f: &DVector<f64>,
    out: &mut [f64],
) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2 (checked just above), all `mul_jt_avx2` requires.
        unsafe { mul_jt_avx2(s, dense, nefc, f, out) };
        return;
    }
    mul_jt_kernel(s, dense, nefc, f, out);
}

/// [`mul_jt`] compiled for AVX2: the four partial sums of [`dot`] are one vector register's
/// lanes, the same sums in the same order, so the same bits.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn mul_jt_avx2(
    s: &Sparsity,
    dense: Option<&DMatrix<f64>>,
    nefc: usize,
    f: &DVector<f64>,
    out: &mut [f64],
) {
    if let Some(j) = dense {
        if nefc <= j.nrows() && out.len() <= j.ncols() && nefc <= f.len() {
            // SAFETY: the sizes were checked just above; the CPU has AVX2 (this function's
            // contract).
            unsafe { mul_jt_dense_avx2(j, &f.as_slice()[..nefc], out) };
            return;
        }
    }
    mul_jt_kernel(s, dense, nefc, f, out);
}

/// out_k ← (Jᵀ f)_k from J's dense storage, each the [`dot`] of J's column k (rows 0..f.len())
/// with f: four partial sums in one register, combined as (s₀ + s₂) + (s₁ + s₃), then the
/// remainder in order — the same bits as [`mul_jt_kernel`], with the column read through
/// pointers (no slice set-up per column).
///
/// # Safety
/// The CPU has AVX2; `f.len() ≤ j.nrows()` and `out.len() ≤ j.ncols()`.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn mul_jt_dense_avx2(j: &DMatrix<f64>, f: &[f64], out: &mut [f64]) {
    use std::arch::x86_64::{
        _mm256_add_pd, _mm256_loadu_pd, _mm256_mul_pd, _mm256_setzero_pd, _mm256_storeu_pd,
    };
    let (stride, jp, fp) = (j.nrows(), j.as_slice().as_ptr(), f.as_ptr());
    let n = f.len();
    let whole = n / 4 * 4;
    for (k, o) in out.iter_mut().enumerate() {
        // SAFETY: column k < out.len() ≤ J's columns, rows below n ≤ stride: inside J's storage;
        // f has n entries; the CPU has AVX2 (this function's contract).
        unsafe {
            let col = jp.add(k * stride);
            let mut acc = _mm256_setzero_pd();
            let mut i = 0;
            while i < whole {
                acc = _mm256_add_pd(
                    acc,
                    _mm256_mul_pd(_mm256_loadu_pd(col.add(i)), _mm256_loadu_pd(fp.add(i))),
                );
                i += 4;
            }
            let mut s = [0.0; 4];
            _mm256_storeu_pd(s.as_mut_ptr(), acc);
            let mut t = (s[0] + s[2]) + (s[1] + s[3]);
            while i < n {
                t += *col.add(i) * *fp.add(i);
                i += 1;
            }
            *o = t;
        }
    }
}

#[inline(always)]
fn mul_jt_kernel(s: &Sparsity, dense: Option<&DMatrix<f64>>, nefc: usize, f: &DVector<f64>, out: &mut [f64]) {
    let f = &f.as_slice()[..nefc];
    if let Some(j) = dense {
        let (stride, j) = (j.nrows(), j.as_slice());
        for (k, o) in out.iter_mut().enumerate() {
            *o = dot(&j[k * stride..k * stride + nefc], f);
        }
        return;
    }
    out.fill(0.0);
    for (i, &f_i) in f.iter().enumerate() {
        if f_i != 0.0 {
            let (cols, vals) = s.row_values(i);
            for (&k, &j_ik) in cols.iter().zip(vals) {
                out[k] += f_i * j_ik;
            }
        }
    }
}

/// Σ a_i b_i in four partial sums (the lanes of a vector register), then the remainder.
#[inline(always)]
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let mut s = [0.0; 4];
    let (a4, b4) = (a.chunks_exact(4), b.chunks_exact(4));
    let (ra, rb) = (a4.remainder(), b4.remainder());
    for (x, y) in a4.zip(b4) {
        for l in 0..4 {
            s[l] += x[l] * y[l];
        }
    }
    let mut t = (s[0] + s[2]) + (s[1] + s[3]);
    for (x, y) in ra.iter().zip(rb) {
        t += x * y;
    }
    t
}

/// r ← M x: a dense product for the dense Newton path (`dense`), else reading only M's
/// nonzeros from their compact copy `tm` (gathered from `m`): the diagonal and each dof's
/// ancestor chain (`Model::dof_parent`; M[l][k] ≠ 0 only when l is an ancestor of k or k of l).
pub(super) fn mul_m(
    dense: bool,
    dof_parent: &[usize],
    m: &DMatrix<f64>,
    tm: &TreeMass,
    x: &DVector<f64>,
    r: &mut DVector<f64>,
) {
    let nv = x.len();
    if dense {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2 (checked just above), all `dense_mul_avx2` requires.
            unsafe { dense_mul_avx2(m, x, r) };
            return;
        }
        m.mul_to(x, r);
        return;
    }
    tm.mul_on(dof_parent, 0..nv, x.as_slice(), r.as_mut_slice());
}

/// r ← M x as nalgebra's product forms it (`mul_to`: a column at a time, r_i = ((M_i0 x_0 +
/// M_i1 x_1) + M_i2 x_2) + …, the first column's product taken as it is, no fused multiply–add),
/// the same bits, by [`columns_times_avx2`] over all of M's columns. Below four rows: nalgebra's
/// product itself.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn dense_mul_avx2(m: &DMatrix<f64>, x: &DVector<f64>, r: &mut DVector<f64>) {
    let n = r.len();
    if n < 4 || m.nrows() != n || m.ncols() != x.len() || x.is_empty() {
        m.mul_to(x, r);
        return;
    }
    // SAFETY: M is n × x.len() (checked), column-major: each column's n entries from k · n; at
    // least one column (checked); the CPU has AVX2 (this function's contract).
    unsafe { columns_times_avx2::<true>(m.as_slice().as_ptr(), x.as_slice(), |c| c * n, r.as_mut_slice()) };
}

/// r ← M x on the dofs `dofs` (whole trees, each tree's dofs ascending; M couples a dof only to
/// its tree), reading M's nonzeros only: the diagonal and each dof's ancestor chain. The other
/// entries of r are left as they are. (The solves read the compact copy instead,
/// `TreeMass::mul_on`, the same products in the same order.)
#[cfg(test)]
pub(super) fn mul_m_on(
    dof_parent: &[usize],
    m: &DMatrix<f64>,
    dofs: impl IntoIterator<Item = usize> + Clone,
    x: &[f64],
    r: &mut [f64],
) {
    // (M column-major: entry (l, k) at k · nv + l.)
    let (nv, m) = (m.nrows(), m.as_slice());
    for k in dofs.clone() {
        r[k] = m[k * nv + k] * x[k];
    }
    for k in dofs {
        let mut l = dof_parent[k];
        while l != crate::model::NO_DOF {
            let m_lk = m[k * nv + l];
            r[l] += m_lk * x[k];
            r[k] += m_lk * x[l];
            l = dof_parent[l];
        }
    }
}

/// Up to this many dofs the Newton Hessian is assembled and factored dense (and M x is a dense
/// product): below it the sparse bookkeeping costs more than the zeros it skips.
const DENSE_NV: usize = 40;

/// Up to this many dofs the Hessian is also dense when the mass matrix is at least half
/// nonzero (long chains: H and its factor are then dense whatever the rows, and the island
/// path's sparse factorization only adds indirection — a 30-link chain's solve 2.7× cheaper).
const DENSE_NV_CHAIN: usize = 200;

/// Whether `model`'s soft Newton solves take the dense path (one dense Hessian and Cholesky
/// factor for all rows) rather than the islands' sparse one (`island.rs`): nv ≤ [`DENSE_NV`],
/// or nv ≤ `DENSE_NV_CHAIN` with M's lower triangle (each dof and its ancestors) at least half
/// of nv (nv + 1) / 2 entries. Fixed by the model's trees; `Data::new` records it in `SoftWork`.
pub(crate) fn dense_newton(model: &Model) -> bool {
    let nv = model.nv;
    if nv <= DENSE_NV {
        return true;
    }
    if nv > DENSE_NV_CHAIN {
        return false;
    }
    let lower: usize = (0..nv)
        .map(|k| {
            let (mut n, mut d) = (1, k);
            while model.dof_parent[d] != crate::model::NO_DOF {
                d = model.dof_parent[d];
                n += 1;
            }
            n
        })
        .sum();
    2 * lower >= nv * (nv + 1) / 2
}

/// Solves the soft problem from the rows of `data` (with `efc_aref`, `efc_r`, `efc_d` set) and
/// `qfrc_smooth`, `qacc_smooth`, the mass matrix and its factor: writes `qacc`, `efc_force`,
/// `efc_state`, `qfrc_constraint`, `solver_niter`, `solver_improvement`, `solver_gradient`,
/// `efc_converged`, and counts a solve that stopped at the iteration limit in `efc_unconverged`.
pub(crate) fn solve_primal(model: &Model, data: &mut Data, method: Primal, s: Settings) {
    let nv = model.nv;
    let nefc = data.nefc;
    if !data.soft.j_recorded {
        // J was written by another writer since the soft position stage: its nonzeros again.
        let Data { efc_j, soft, .. } = &mut *data;
        super::jacobian::record(
            efc_j,
            nefc,
            &mut soft.nz_start,
            &mut soft.nz_index,
            &mut soft.nz_value,
            &mut soft.nz_scratch,
        );
    }
    let Data {
        efc_j,
        efc_type,
        efc_id,
        efc_d,
        efc_r,
        efc_frictionloss,
        efc_aref,
        efc_force,
        efc_state,
        contacts,
        contact_mu,
        soft,
        mass_matrix,
        mass_factor,
        qacc,
        qacc_smooth,
        qacc_warmstart,
        qfrc_smooth,
        qfrc_constraint,
        ne,
        nf,
        ..
    } = data;
    let (nz_start, nz_index) = (std::mem::take(&mut soft.nz_start), std::mem::take(&mut soft.nz_index));
    let nz_value = std::mem::take(&mut soft.nz_value);
    // M's nonzeros, once, where the products read them (`tree_mass.rs`).
    let mut tree_m = std::mem::take(&mut soft.tree_m);
    let dense = soft.dense;
    if !dense {
        tree_m.gather(mass_matrix, &model.dof_parent);
    }
    let nz = Sparsity { start: &nz_start, index: &nz_index, value: &nz_value };
    // The dense path (`dense_newton`): J's products from its dense storage (`mul_j`, `mul_jt`).
    let j_dense = dense.then_some(&*efc_j);
    let rows = Rows {
        ne: *ne,
        nf: *nf,
        nefc,
        kind: efc_type,
        id: efc_id,
        d: efc_d,
        r: efc_r,
        floss: efc_frictionloss,
        contacts,
        mu: contact_mu,
    };
    // The Gauss term ½ (x − a₀)ᵀ (M x − qfrc_smooth) at x, from M x.
    let gauss = |x: &DVector<f64>, ma: &DVector<f64>| -> f64 {
        let (x, a0) = (&x.as_slice()[..nv], &qacc_smooth.as_slice()[..nv]);
        let (ma, f0) = (&ma.as_slice()[..nv], &qfrc_smooth.as_slice()[..nv]);
        x.iter()
            .zip(a0)
            .zip(ma.iter().zip(f0))
            .map(|((&x, &a0), (&ma, &f0))| 0.5 * (x - a0) * (ma - f0))
            .sum()
    };
    // The total cost at x (fills ma, jar, force, state).
    let total = |x: &DVector<f64>,
                 ma: &mut DVector<f64>,
                 jar: &mut DVector<f64>,
                 force: &mut DVector<f64>,
                 state: &mut [_]| {
        mul_m(dense, &model.dof_parent, mass_matrix, &tree_m, x, ma);
        mul_j(&nz, j_dense, nefc, x, jar);
        for (j, &r) in jar.as_mut_slice()[..nefc].iter_mut().zip(&efc_aref.as_slice()[..nefc]) {
            *j -= r;
        }
        gauss(x, ma) + rows.update(jar, force, state)
    };
    // Start: the warm start (the previous solution) if it costs less than qacc_smooth.
    // At qacc_smooth the Gauss term is zero and M a = qfrc_smooth (qacc_smooth = M⁻¹
    // qfrc_smooth): only J a − aref is formed (MuJoCo's cost(qacc_smooth) from efc_b likewise).
    qacc.copy_from(qacc_smooth);
    soft.ma.copy_from(qfrc_smooth);
    mul_j(&nz, j_dense, nefc, qacc, &mut soft.jar);
    for (j, &r) in soft.jar.as_mut_slice()[..nefc].iter_mut().zip(&efc_aref.as_slice()[..nefc]) {
        *j -= r;
    }
    let mut cost = rows.update(&soft.jar, efc_force, efc_state);
    if s.warmstart {
        let c = total(qacc_warmstart, &mut soft.mdir, &mut soft.jv, &mut soft.jar_trial, efc_state);
        if c < cost {
            // The warm start's M a, jar, forces and states (in the scratch buffers) become the
            // current ones: what evaluating the cost again at it would write.
            qacc.copy_from(qacc_warmstart);
            std::mem::swap(&mut soft.ma, &mut soft.mdir);
            std::mem::swap(&mut soft.jar, &mut soft.jv);
            std::mem::swap(efc_force, &mut soft.jar_trial);
            cost = c;
        } else {
            // Back to qacc_smooth's states (the trial wrote its own): its M a and jar are kept.
            rows.update(&soft.jar, efc_force, efc_state);
        }
    }
    let mut improvement = f64::INFINITY;
    let mut gradient = 0.0;
    let mut iter = 0;
    let mut have_dir = false;
    // Whether `soft.dense_factor` holds the factor of the Hessian at `soft.factor_state`.
    let mut factor_valid = false;
    let mut stalled = false;
    let island_path = method == Primal::Newton && !dense;
    let mut converged_islands = false;
    if island_path {
        // Large problems: island by island (`island.rs`).
        let problem = super::island::Problem {
            model,
            rows: &rows,
            nz: &nz,
            m: &tree_m,
            a0: qacc_smooth,
            f0: qfrc_smooth,
            settings: s,
        };
        let out = super::island::newton(&problem, soft, mass_factor, qacc, efc_force, efc_state);
        iter = out.iterations;
        improvement = out.improvement;
        gradient = out.gradient;
        converged_islands = out.converged;
    }
    // Small problems, and CG: every row together.
    if !island_path {
        loop {
            // g = M a − qfrc_smooth − Jᵀ f (Jᵀ f in qfrc_constraint: at the last iteration,
            // the forces' own).
            mul_jt(&nz, j_dense, nefc, efc_force, qfrc_constraint.as_mut_slice());
            for (((g, &ma), &f0), &jtf) in soft
                .grad
                .as_mut_slice()
                .iter_mut()
                .zip(soft.ma.as_slice())
                .zip(qfrc_smooth.as_slice())
                .zip(qfrc_constraint.as_slice())
            {
                *g = ma - f0 - jtf;
            }
            gradient = s.scale * soft.grad.norm();
            if gradient < s.tolerance || improvement < s.tolerance || iter >= s.iterations {
                break;
            }
            iter += 1;
            match method {
                Primal::Newton => {
                    // (Large problems take the island path above.)
                    // Small: H = M + Jᵀ (∂²s) J by dense Cholesky: the previous iteration's
                    // factor updated row by row where the states changed (MuJoCo's
                    // `HessianIncremental`), else formed and factored afresh (its lower
                    // triangle, all the dense Cholesky reads).
                    let updated = factor_valid
                        && update_factor(
                            &nz,
                            efc_d.as_slice(),
                            &efc_state[..nefc],
                            &mut soft.factor_state[..nefc],
                            &mut soft.dense_factor,
                            &mut soft.rank_one,
                        );
                    factor_valid = updated || {
                        // M's lower triangle (all the assembly adds to and the Cholesky reads).
                        for (h, m) in soft
                            .hessian
                            .as_mut_slice()
                            .chunks_exact_mut(nv)
                            .zip(mass_matrix.as_slice().chunks_exact(nv))
                            .enumerate()
                            .map(|(q, (h, m))| (&mut h[q..], &m[q..]))
                        {
                            h.copy_from_slice(m);
                        }
                        let mut rows_h =
                            Assembler::new(Target::Dense(&mut soft.hessian), &nz, &mut soft.hessian_column);
                        rows.hessian(&soft.jar, efc_state, |i, dim, block| rows_h.add(i, dim, block));
                        rows_h.finish();
                        let ok = cholesky(&soft.hessian, nv, &mut soft.dense_factor, 0.0);
                        soft.factor_state[..nefc].copy_from_slice(&efc_state[..nefc]);
                        ok
                    };
                    soft.dir.copy_from(&soft.grad);
                    if factor_valid {
                        cholesky_solve(&soft.dense_factor, nv, soft.dir.as_mut_slice());
                    } else {
                        solve_with_factor_unchecked(model, mass_factor, soft.dir.as_mut_slice());
                    }
                    soft.dir.neg_mut();
                }
                Primal::Cg => {
                    soft.mgrad.copy_from(&soft.grad);
                    solve_with_factor_unchecked(model, mass_factor, soft.mgrad.as_mut_slice());
                    let beta = if have_dir {
                        let den = soft.grad_prev.dot(&soft.mgrad_prev);
                        let num: f64 =
                            (0..nv).map(|k| soft.grad[k] * (soft.mgrad[k] - soft.mgrad_prev[k])).sum();
                        if den > 0.0 {
                            (num / den).max(0.0)
                        } else {
                            0.0
                        }
                    } else {
                        0.0
                    };
                    for k in 0..nv {
                        soft.dir[k] = -soft.mgrad[k] + beta * soft.dir[k];
                    }
                    soft.grad_prev.copy_from(&soft.grad);
                    soft.mgrad_prev.copy_from(&soft.mgrad);
                    have_dir = true;
                }
            }
            mul_j(&nz, j_dense, nefc, &soft.dir, &mut soft.jv);
            mul_m(dense, &model.dof_parent, mass_matrix, &tree_m, &soft.dir, &mut soft.mdir);
            // (Over slices: nalgebra's matrix iterators cost several instructions per entry.)
            let g0: f64 = (soft.ma.as_slice().iter().zip(qfrc_smooth.as_slice()).zip(soft.dir.as_slice()))
                .map(|((&ma, &f0), &d)| (ma - f0) * d)
                .sum();
            let dmd = soft.dir.dot(&soft.mdir);
            let alpha = line_search(&rows, &soft.jar, &soft.jv, &mut soft.jar_trial, g0, dmd, s);
            if alpha == 0.0 {
                // No descent along the direction (the minimum to round-off).
                stalled = true;
                break;
            }
            // The move: a, M a and J a − aref along the direction (MuJoCo's mj_solPrimal updates
            // them the same way instead of forming the products again).
            qacc.axpy(alpha, &soft.dir, 1.0);
            soft.ma.axpy(alpha, &soft.mdir, 1.0);
            for (j, &v) in soft.jar.as_mut_slice()[..nefc].iter_mut().zip(&soft.jv.as_slice()[..nefc]) {
                *j += alpha * v;
            }
            let new_cost = gauss(qacc, &soft.ma) + rows.update(&soft.jar, efc_force, efc_state);
            improvement = s.scale * (cost - new_cost);
            cost = new_cost;
        }
    }
    // qfrc_constraint = Jᵀ f (the loop above left it at the final forces).
    if island_path {
        mul_jt(&nz, j_dense, nefc, efc_force, qfrc_constraint.as_mut_slice());
    }
    data.soft.nz_start = nz_start;
    data.soft.nz_index = nz_index;
    data.soft.nz_value = nz_value;
    data.soft.tree_m = tree_m;
    data.solver_niter = iter;
    data.solver_improvement = if improvement.is_finite() { improvement } else { 0.0 };
    data.solver_gradient = gradient;
    // MuJoCo's criterion: converged when the scaled gradient or improvement fell below the
    // tolerance (or the line search found no descent: the minimum to round-off); else the solve
    // stopped at its iteration limit, counted with its scaled gradient as the residual.
    let converged = if island_path {
        converged_islands
    } else {
        stalled || gradient < s.tolerance || improvement < s.tolerance
    };
    data.efc_converged = converged;
    if !converged {
        data.efc_unconverged += 1;
        data.efc_unconverged_residual = data.efc_unconverged_residual.max(gradient);
    }
}

/// Brings the dense Cholesky factor `l` of the Newton Hessian H = M + Σ D_i J_iᵀ J_i (the sum over
/// the rows in their quadratic state) from the row states it was formed for (`factored`) to
/// `state`: one rank-one update by √D_i J_i for each row that entered its quadratic state and one
/// downdate for each row that left it, O(nv²) each instead of assembling and factoring H afresh
/// (MuJoCo's `HessianIncremental`, engine_solver.c). `factored` becomes `state`. `x` is nv-long
/// scratch. Returns false (the caller factors H afresh) when a row is on an elliptic cone's
/// surface in either (its Hessian block is not a rank-one term of the row), when more rows
/// changed than [`refactor_is_cheaper`] allows, or when a downdate fails.
fn update_factor(
    nz: &Sparsity,
    d: &[f64],
    state: &[EfcState],
    factored: &mut [EfcState],
    l: &mut DMatrix<f64>,
    x: &mut [f64],
) -> bool {
    let nv = x.len();
    let mut changed = 0;
    for (s, f) in state.iter().zip(factored.iter()) {
        match term_change(*f, *s) {
            TermChange::Block => return false,
            TermChange::Same => {}
            TermChange::Enters | TermChange::Leaves => changed += 1,
        }
    }
    if refactor_is_cheaper(changed, nv) {
        return false;
    }
    for (i, (s, f)) in state.iter().zip(factored.iter_mut()).enumerate() {
        let change = term_change(*f, *s);
        *f = *s;
        if change == TermChange::Same {
            continue;
        }
        x.fill(0.0);
        let (cols, vals) = nz.row_values(i);
        let w = d[i].sqrt();
        for (&k, &j_ik) in cols.iter().zip(vals) {
            x[k] = w * j_ik;
        }
        if !cholesky_rank_one(l, nv, x, if change == TermChange::Enters { 1.0 } else { -1.0 }) {
            return false;
        }
    }
    true
}

/// Whether a Newton factor over `nv` dofs is brought to `changed` rows' new states faster by
/// forming and factoring the Hessian afresh than by one rank-one update or downdate per row:
/// when more than one row in eight dofs changed. A rank-one update is O(nv²) work but a chain of
/// nv dependent steps (a square root and a division each, from one column's x to the next's),
/// so on robot-sized factors its latency dominates: the humanoid (nv = 27) steps 4 % faster with
/// at most 3 updates per factor than with up to nv (its 24-row landings); go1 (nv = 18) gains
/// 1–2 %. MuJoCo's `HessianIncremental` always updates.
fn refactor_is_cheaper(changed: usize, nv: usize) -> bool {
    changed * 8 > nv
}

/// How a row's term of the Newton Hessian changed from one state to the next.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum TermChange {
    /// The same term (both quadratic, or neither with a term).
    Same,
    /// The row entered its quadratic state: + D_i J_iᵀ J_i, a rank-one update.
    Enters,
    /// The row left it: a rank-one downdate.
    Leaves,
    /// On an elliptic cone's surface in either state: a dense block, not a rank-one term.
    Block,
}

/// The change of a row's Hessian term from state `was` to `is` (see [`TermChange`]): what the
/// dense and the islands' factor updates both go by.
pub(super) fn term_change(was: EfcState, is: EfcState) -> TermChange {
    if was == EfcState::Cone || is == EfcState::Cone {
        return TermChange::Block;
    }
    match (was == EfcState::Quadratic, is == EfcState::Quadratic) {
        (false, true) => TermChange::Enters,
        (true, false) => TermChange::Leaves,
        _ => TermChange::Same,
    }
}

/// The step α ≥ 0 minimizing the cost along the direction: g0 + α dmd + ds/dα = 0 with ds/dα
/// from [`Rows::directional`] at jar + α jv (`trial` is scratch). Returns 0 if the direction does
/// not descend.
fn line_search(
    rows: &Rows,
    jar: &DVector<f64>,
    jv: &DVector<f64>,
    trial: &mut DVector<f64>,
    g0: f64,
    dmd: f64,
    s: Settings,
) -> f64 {
    let n = rows.nefc;
    let deriv = |alpha: f64| {
        for ((t, &j), &v) in trial.as_mut_slice()[..n].iter_mut().zip(jar.as_slice()).zip(jv.as_slice()) {
            *t = j + alpha * v;
        }
        let (d1, d2) = rows.directional(trial, jv);
        (g0 + alpha * dmd + d1, dmd + d2)
    };
    line_search_with(deriv, s)
}

/// The line search's iteration on the cost's slope and curvature along the direction at step α
/// (`deriv(α)`): Newton steps safeguarded by a sign-change bracket (secant, then bisection).
/// Returns 0 if the direction does not descend.
pub(super) fn line_search_with(mut deriv: impl FnMut(f64) -> (f64, f64), s: Settings) -> f64 {
    let (f0, h0) = deriv(0.0);
    if f0 >= 0.0 || !f0.is_finite() {
        return 0.0;
    }
    let tol = s.ls_tolerance * f0.abs();
    let (mut lo, mut f_lo) = (0.0, f0);
    let (mut hi, mut f_hi) = (f64::INFINITY, f64::NAN);
    let mut alpha = if h0 > 0.0 { -f0 / h0 } else { 1.0 };
    for _ in 0..s.ls_iterations.max(1) {
        let (f, h) = deriv(alpha);
        if f.abs() <= tol {
            return alpha;
        }
        if f < 0.0 {
            lo = alpha;
            f_lo = f;
        } else {
            hi = alpha;
            f_hi = f;
        }
        let newton = if h > 0.0 { alpha - f / h } else { f64::NAN };
        alpha = if newton > lo && newton < hi {
            newton
        } else if hi.is_finite() {
            let secant = lo - f_lo * (hi - lo) / (f_hi - f_lo);
            if secant > lo && secant < hi {
                secant
            } else {
                0.5 * (lo + hi)
            }
        } else {
            2.0 * alpha.max(lo)
        };
        if hi.is_finite() && hi - lo <= 1e-15 * hi {
            break;
        }
    }
    if lo > 0.0 {
        lo
    } else if hi.is_finite() {
        // Every trial overshot: the smallest tried step still lowers the cost of a convex
        // function whose slope at 0 is negative only if the minimum lies beyond; keep hi/2 steps.
        0.5 * hi
    } else {
        alpha
    }
}

#[cfg(test)]
mod tests {
    use super::dense_newton;
    use crate::model::Model;

    /// An MJCF world of `chains` chains of `links` bodies each, every link a ball joint (the
    /// first of each chain free).
    fn chains(chains: usize, links: usize) -> Model {
        let mut xml = String::from("<mujoco><worldbody>");
        for c in 0..chains {
            xml += &format!("<body pos='{c} 0 1'><freejoint/><geom size='.05'/>");
            for _ in 1..links {
                xml += "<body pos='.1 0 0'><joint type='ball'/><geom size='.05'/>";
            }
            xml += &"</body>".repeat(links);
        }
        xml += "</worldbody></mujoco>";
        Model::from_str(&xml).expect("the test model compiles")
    }

    /// The AVX2 product M x gives nalgebra's bits (which the portable path and the golden
    /// trajectories use), for sizes on both sides of its blocks of eight and four rows, with
    /// signed zeros and mixed magnitudes in x.
    #[test]
    #[cfg(target_arch = "x86_64")]
    #[ignore = "compares the CPU-specific (AVX2) build of the product with nalgebra's; needs such a CPU: cargo test --release -p lagrange --lib -- --ignored (as .ci/run does)"]
    fn dense_mul_avx2_is_nalgebras_product_bit_for_bit() {
        use nalgebra::{DMatrix, DVector};
        if !std::arch::is_x86_feature_detected!("avx2") {
            eprintln!("skipped: this CPU has no AVX2, the AVX2 product is never used here");
            return;
        }
        for n in [1, 3, 4, 5, 7, 8, 9, 12, 15, 16, 27, 40] {
            let m = DMatrix::from_fn(n, n, |i, k| {
                ((i * 31 + k * 17) as f64 * 0.37).sin() * 10f64.powi((i % 5) as i32 - 2)
            });
            let x = DVector::from_fn(n, |k, _| match k % 6 {
                0 => -0.0,
                1 => 0.0,
                _ => ((k * 13) as f64).cos() * 1e3f64.powi((k % 3) as i32 - 1),
            });
            let mut expected = DVector::zeros(n);
            m.mul_to(&x, &mut expected);
            let mut r = DVector::from_element(n, f64::NAN);
            // SAFETY: the CPU has AVX2 (checked above).
            unsafe { super::dense_mul_avx2(&m, &x, &mut r) };
            for i in 0..n {
                assert_eq!(r[i].to_bits(), expected[i].to_bits(), "n {n}, row {i}");
            }
        }
    }

    /// The AVX2 product J x from J's dense storage gives the portable sums' bits (each row from
    /// zero over the columns with x_k ≠ 0), for row counts on both sides of its blocks, a stride
    /// above the row count, and zeros of both signs in x.
    #[test]
    #[cfg(target_arch = "x86_64")]
    #[ignore = "compares the CPU-specific (AVX2) build of the product with the portable one; needs such a CPU: cargo test --release -p lagrange --lib -- --ignored (as .ci/run does)"]
    fn dense_j_product_avx2_is_the_portable_sums_bit_for_bit() {
        use nalgebra::{DMatrix, DVector};
        if !std::arch::is_x86_feature_detected!("avx2") {
            eprintln!("skipped: this CPU has no AVX2, the AVX2 product is never used here");
            return;
        }
        let nv = 27;
        for nefc in [4, 5, 7, 8, 9, 12, 15, 16, 37] {
            let j = DMatrix::from_fn(nefc + 3, nv, |i, k| {
                if (i + k) % 4 == 0 {
                    0.0
                } else {
                    ((i * 29 + k * 11) as f64 * 0.53).cos() * 10f64.powi((k % 5) as i32 - 2)
                }
            });
            let x = DVector::from_fn(nv, |k, _| match k % 5 {
                0 => -0.0,
                1 => 0.0,
                _ => ((k * 7) as f64).sin() * 1e3f64.powi((k % 3) as i32 - 1),
            });
            let mut expected = DVector::from_element(nefc, f64::NAN);
            let none = super::Sparsity { start: &[], index: &[], value: &[] };
            super::mul_j_kernel(&none, Some(&j), nefc, &x, &mut expected);
            let mut r = vec![f64::NAN; nefc];
            // SAFETY: the CPU has AVX2 (checked above); 4 ≤ nefc ≤ J's rows, nv ≤ its columns
            // and ≤ MUL_J_COLUMNS.
            unsafe { super::mul_j_dense_avx2(&j, x.as_slice(), &mut r) };
            for i in 0..nefc {
                assert_eq!(r[i].to_bits(), expected[i].to_bits(), "nefc {nefc}, row {i}");
            }
        }
    }

    #[test]
    fn dense_path_for_small_models_and_long_chains_only() {
        // nv 12: small.
        assert!(dense_newton(&chains(2, 3)));
        // One chain of 30 links, nv 93: M is dense.
        assert!(dense_newton(&chains(1, 30)));
        // Ten free bodies, nv 60: M block-diagonal, the islands' path.
        assert!(!dense_newton(&chains(10, 1)));
        // Two chains of 15, nv 96: M's two dense blocks just over half of it.
        assert!(dense_newton(&chains(2, 15)));
        // Three chains of 12, nv 117: a third of it.
        assert!(!dense_newton(&chains(3, 12)));
        // A chain of 70 links, nv 213: beyond the dense path's size.
        assert!(!dense_newton(&chains(1, 70)));
    }
}
