//! The exact (rigid) constraint solver: the KKT system of Lagrangian mechanics with multipliers
//! (docs/physics.md §1.6, eq. 20: M q̈ + c − τ = Jᵀλ together with the acceleration form of the constraints,
//! J q̈ + J̇v = 0), solved by the range-space method with the tree-sparse LᵀDL factor of M
//! (RBDA §6.3): the Delassus matrix A = J M⁻¹ Jᵀ = (L⁻ᵀJᵀ)ᵀ D⁻¹ (L⁻ᵀJᵀ) (RBDA §6.5: L⁻ᵀ keeps
//! the sparsity of Jᵀ — a row's column of L⁻ᵀJᵀ is zero outside its bodies' ancestor dofs), then
//! A λ = −(J q̈_smooth + J̇v) and q̈ = q̈_smooth + M⁻¹Jᵀλ. Redundant rows give the minimum-norm
//! multipliers ([`solve_psd`]).
//!
//! Drift correction for steppers: [`project_positions`] (Gauss–Newton onto φ(q) = 0 along
//! M⁻¹Jᵀ, on the configuration manifold) and [`project_velocities`] (the M-orthogonal projection
//! of v onto J v = 0).

use super::active_set::{solve_delassus, solve_mixed};
use super::admm::{solve_admm, ExactContactSolver};
use super::coulomb::{has_friction, solve_coulomb, Level, SolverSettings, SEPARATING_VELOCITY};
use super::energy_guard::limit_energy;
use super::ConstraintModel;
use super::ExactWork;
use crate::collision::{collide, EXACT_REACH};
use crate::dynamics::{crba_unchecked, factorize_mass_matrix, solve_with_factor_unchecked, tree_span};
use crate::error::{check, InputError};
use crate::kinematics::body_poses;
use crate::model::{integrate_configuration_unchecked, Data, EfcType, Model, NO_DOF};

/// The Delassus matrix A = J M⁻¹ Jᵀ of the current rows into `exact.delassus` (needs the factor
/// of M in `mass_factor`), with Jᵀ (`exact.jt`), each row's support, spans and trees, and A's
/// nonzero pattern. M = LᵀDL is block-diagonal over kinematic trees, so A is a sum over trees:
/// for each tree, the rows touching it ([`tree_lists`]) form a block whose products
/// [`gram_block`] adds — X = L⁻ᵀJᵀ over the tree's dofs, then A += Xᵀ D⁻¹ X — and rows whose
/// trees are disjoint have A_ij = 0. When some row touches more than two trees (a tendon over
/// several), all rows form one block over all dofs.
fn delassus(model: &Model, data: &mut Data) {
    let n = data.nefc;
    let nv = model.nv;
    // The dense matrices for the whole row capacity (grown once, when a problem is larger than
    // any before it).
    let cap = data.efc_capacity();
    data.exact.grow_matrices(nv, cap);
    let Data {
        efc_j,
        mass_factor,
        exact:
            ExactWork {
                delassus: efc_delassus,
                jt,
                ljt,
                spans,
                support,
                order,
                dof_rows,
                pattern_ptr,
                pattern_rows,
                pattern_n,
                pattern_full,
                trees,
                trees_valid,
                tree_ptr,
                tree_rows,
                minv_jt_ready,
                minv_jt_work,
                solve_work,
                ..
            },
        ..
    } = data;
    // Jᵀ, read down J's columns (contiguous in its storage), and each row's support and span.
    let j_stride = efc_j.nrows();
    let j_cols = efc_j.as_slice();
    let jt = &mut jt.as_mut_slice()[..nv * n];
    for k in 0..nv {
        for (i, &jik) in j_cols[k * j_stride..k * j_stride + n].iter().enumerate() {
            jt[k + i * nv] = jik;
        }
    }
    for i in 0..n {
        let row = &jt[i * nv..(i + 1) * nv];
        (support[i], spans[i]) =
            match (row.iter().position(|&x| x != 0.0), row.iter().rposition(|&x| x != 0.0)) {
                (Some(first), Some(last)) => ((first, last + 1), tree_span(model, first, last)),
                _ => ((0, 0), (0, 0)),
            };
    }
    let stride = efc_delassus.nrows();
    let a = efc_delassus.as_mut_slice();
    for j in 0..n {
        a[j * stride..j * stride + n].fill(0.0);
    }
    let h = mass_factor.as_slice();
    // Each row's trees: when none touches more than two (contacts, a connect between two
    // bodies), the products and the pattern go tree by tree.
    *trees_valid = row_trees(model, &jt[..nv * n], &spans[..n], &mut trees[..n]);
    *pattern_n = n;
    *minv_jt_ready = false;
    // What forming M⁻¹Jᵀ would cost and what one solve with M costs (`sweep_motion`'s choice).
    *solve_work = SOLVE_PAIR_WORK * ancestor_pairs(model, (0, nv)) as f64 + SOLVE_DOF_WORK * nv as f64;
    *minv_jt_work = 0.0;
    let mut block = |rows: &[usize], dofs: (usize, usize), a: &mut [f64]| {
        let pairs = ancestor_pairs(model, dofs) as f64;
        *minv_jt_work += MINV_JT_WORK * rows.len() as f64 * (2.0 * pairs + (dofs.1 - dofs.0) as f64);
        let block = Block { model, h, j_cols, j_stride, rows, dofs };
        block.add_gram(ljt, dof_rows, a, stride);
    };
    if *trees_valid {
        tree_lists(&trees[..n], tree_ptr, tree_rows);
        for_each_tree_block(model, tree_ptr, tree_rows, |rows, dofs| block(rows, dofs, a));
        *pattern_full = (0..nv).any(|t| tree_ptr[t + 1] - tree_ptr[t] == n);
        if *pattern_full {
            pattern_ptr.clear();
            pattern_rows.clear();
        } else {
            pattern_by_trees(&trees[..n], tree_ptr, tree_rows, pattern_ptr, pattern_rows);
        }
        return;
    }
    for (i, o) in order[..n].iter_mut().enumerate() {
        *o = i;
    }
    if n > 0 {
        block(&order[..n], (0, nv), a);
    }
    let width = spans[..n].iter().map(|&(lo, hi)| hi - lo).max().unwrap_or(0);
    let sorted = 2 * width < nv;
    if sorted {
        sort_by_span_start(&spans[..n], &mut order[..n]);
    }
    delassus_pattern(&spans[..n], sorted.then_some(&order[..n]), width, pattern_ptr, pattern_rows);
    *pattern_full = pattern_rows.len() == n * n;
}

/// Calls `block(rows, dofs)` for each kinematic tree that some row touches, in dof order: the
/// tree's dofs [root, end) and its rows (`tree_lists`' compressed lists `tree_ptr`, `tree_rows`,
/// indexed by the tree's root dof).
fn for_each_tree_block(
    model: &Model,
    tree_ptr: &[usize],
    tree_rows: &[usize],
    mut block: impl FnMut(&[usize], (usize, usize)),
) {
    let mut root = 0;
    while root < model.nv {
        let end = tree_span(model, root, root).1;
        let rows = &tree_rows[tree_ptr[root]..tree_ptr[root + 1]];
        if !rows.is_empty() {
            block(rows, (root, end));
        }
        root = end;
    }
}

/// Work estimates (instructions, measured with callgrind on chain_30 and bin_10) of a solve with
/// M's factor (`dynamics::solve_with_factor_span_unchecked`: per ancestor pair of dofs, and per
/// dof), and of forming M⁻¹Jᵀ per row and multiply-add ([`Block::minv_jt`], vectorized across
/// rows).
const SOLVE_PAIR_WORK: f64 = 8.0;
const SOLVE_DOF_WORK: f64 = 100.0;
const MINV_JT_WORK: f64 = 1.5;

/// The pairs (dof, ancestor dof) among the dofs [lo, hi): the multiply-adds of each half of a
/// solve with M's tree-sparse factor.
fn ancestor_pairs(model: &Model, (lo, hi): (usize, usize)) -> usize {
    let mut pairs = 0;
    for k in lo..hi {
        let mut e = model.dof_parent[k];
        while e != NO_DOF {
            let s = model.dof_run_start[e];
            pairs += e + 1 - s;
            e = model.dof_parent[s];
        }
    }
    pairs
}

/// M⁻¹Jᵀ of the current rows into `exact.minv_jt` (each row's column over its trees, or its
/// span when the trees are not known; not written elsewhere), block by block as [`delassus`]
/// formed the products (needs its tree lists, at the same rows). Formed only when the
/// Gauss–Seidel sweeps have cost more in solves with M than this costs (`sweep_motion`).
pub(super) fn form_minv_jt(model: &Model, data: &mut Data) {
    let n = data.nefc;
    let nv = model.nv;
    let Data {
        efc_j,
        mass_factor,
        exact:
            ExactWork { minv_jt, minv_jt_ready, ljt, order, dof_rows, trees_valid, tree_ptr, tree_rows, .. },
        ..
    } = data;
    let (j_stride, j_cols, h) = (efc_j.nrows(), efc_j.as_slice(), mass_factor.as_slice());
    let y = minv_jt.as_mut_slice();
    let mut block = |rows: &[usize], dofs: (usize, usize), y: &mut [f64]| {
        Block { model, h, j_cols, j_stride, rows, dofs }.minv_jt(ljt, dof_rows, y);
    };
    if *trees_valid {
        for_each_tree_block(model, tree_ptr, tree_rows, |rows, dofs| block(rows, dofs, y));
    } else if n > 0 {
        for (i, o) in order[..n].iter_mut().enumerate() {
            *o = i;
        }
        block(&order[..n], (0, nv), y);
    }
    *minv_jt_ready = true;
}

/// Per row, the dof ranges of the (at most two) kinematic trees its J row (in `jt`, rows of nv)
/// touches, the tree of its first nonzero and that of its last (`[first, (0, 0)]` when they are
/// one tree; both empty for a zero row). False when some row touches a third tree between them
/// (a tendon or an equality over several trees): the caller then pairs rows by their spans.
fn row_trees(model: &Model, jt: &[f64], spans: &[(usize, usize)], trees: &mut [[(usize, usize); 2]]) -> bool {
    let nv = model.nv;
    for (i, (&(lo, hi), t)) in spans.iter().zip(trees.iter_mut()).enumerate() {
        if lo >= hi {
            *t = [(0, 0); 2];
            continue;
        }
        let first = tree_span(model, lo, lo);
        let last = tree_span(model, hi - 1, hi - 1);
        if first == last {
            *t = [first, (0, 0)];
            continue;
        }
        if jt[i * nv + first.1..i * nv + last.0].iter().any(|&x| x != 0.0) {
            return false;
        }
        *t = [first, last];
    }
    true
}

/// The rows touching each tree (`trees` of [`row_trees`]), in compressed form keyed by the
/// tree's first dof (`ptr`, nv + 1 offsets into `rows`), each tree's rows ascending.
fn tree_lists(trees: &[[(usize, usize); 2]], ptr: &mut [usize], rows: &mut [usize]) {
    ptr.fill(0);
    let touched = |t: &[(usize, usize); 2]| t.map(|r| (r.0 < r.1).then_some(r.0));
    for t in trees {
        for root in touched(t).into_iter().flatten() {
            ptr[root + 1] += 1;
        }
    }
    for k in 1..ptr.len() {
        ptr[k] += ptr[k - 1];
    }
    // Filled with ptr[t] as the cursor (ending at the start of the next tree), then shifted back.
    for (i, t) in trees.iter().enumerate() {
        for root in touched(t).into_iter().flatten() {
            rows[ptr[root]] = i;
            ptr[root] += 1;
        }
    }
    for k in (1..ptr.len()).rev() {
        ptr[k] = ptr[k - 1];
    }
    ptr[0] = 0;
}

/// The nonzero pattern of the Delassus matrix for rows that each touch at most two trees
/// (`trees`, listed per tree in `tree_ptr`/`tree_rows`): rows i and j meet when they share a
/// tree, so the pattern of column j is the union of its trees' rows (ascending); every other
/// entry is zero. Its size is the work of a Gauss–Seidel sweep's gathers (a pile: each contact
/// meets only the contacts of its two bodies).
fn pattern_by_trees(
    trees: &[[(usize, usize); 2]],
    tree_ptr: &[usize],
    tree_rows: &[usize],
    pattern_ptr: &mut Vec<usize>,
    pattern_rows: &mut Vec<usize>,
) {
    pattern_ptr.clear();
    pattern_rows.clear();
    pattern_ptr.push(0);
    let list = |t: (usize, usize)| -> &[usize] {
        if t.0 < t.1 {
            &tree_rows[tree_ptr[t.0]..tree_ptr[t.0 + 1]]
        } else {
            &[]
        }
    };
    for &[tj0, tj1] in trees {
        let (p, q) = (list(tj0), list(tj1));
        // The union of the two ascending lists, ascending, each row once.
        let (mut u, mut v) = (0, 0);
        loop {
            let i = match (p.get(u), q.get(v)) {
                (Some(&x), Some(&z)) => {
                    u += usize::from(x <= z);
                    v += usize::from(z <= x);
                    x.min(z)
                }
                (Some(&x), None) => {
                    u += 1;
                    x
                }
                (None, Some(&z)) => {
                    v += 1;
                    z
                }
                (None, None) => break,
            };
            pattern_rows.push(i);
        }
        pattern_ptr.push(pattern_rows.len());
    }
}

/// The nonzero pattern of the Delassus matrix of the rows with tree spans `spans`: per column j,
/// ascending, the rows i whose span meets j's (A_ij is zero otherwise), in compressed columns
/// (`ptr` n + 1 offsets into `rows`). With `order` (the rows sorted by their span's first dof,
/// [`sort_by_span_start`]; `width` the widest span) only the rows that can meet j are visited —
/// row i can meet row j only if lo_j − `width` < lo_i < hi_j; without it every pair is checked.
/// `rows` grows only when a pattern is larger than any before it.
fn delassus_pattern(
    spans: &[(usize, usize)],
    order: Option<&[usize]>,
    width: usize,
    ptr: &mut Vec<usize>,
    rows: &mut Vec<usize>,
) {
    let n = spans.len();
    ptr.clear();
    rows.clear();
    ptr.push(0);
    let meets = |i: usize, (lo_j, hi_j): (usize, usize)| {
        let (lo_i, hi_i) = spans[i];
        lo_i.max(lo_j) < hi_i.min(hi_j)
    };
    for j in 0..n {
        let (lo_j, hi_j) = spans[j];
        if lo_j < hi_j {
            match order {
                Some(order) => {
                    let start = rows.len();
                    let first = order.partition_point(|&i| spans[i].0 + width <= lo_j);
                    for &i in &order[first..] {
                        if spans[i].0 >= hi_j {
                            break;
                        }
                        if meets(i, spans[j]) {
                            rows.push(i);
                        }
                    }
                    rows[start..].sort_unstable();
                }
                None => rows.extend((0..n).filter(|&i| meets(i, spans[j]))),
            }
        }
        ptr.push(rows.len());
    }
}

/// The rows in order of their span's first dof (`order`: 0..n on entry), by a stable insertion
/// sort: the rows come mostly in order already (a contact's rows together, contacts by body).
fn sort_by_span_start(spans: &[(usize, usize)], order: &mut [usize]) {
    for k in 0..order.len() {
        let lo = spans[k].0;
        let mut p = k;
        while p > 0 && spans[order[p - 1]].0 > lo {
            order[p] = order[p - 1];
            p -= 1;
        }
        order[p] = k;
    }
}

/// One block of rows for the products: the rows `rows` (ascending, m of them) touching the
/// dofs [lo, hi) (whole kinematic trees, outside which their terms are not summed here), with
/// J's columns `j_cols` (stride `j_stride`) and the LᵀDL factor `h` of M (RBDA §6.3: column k
/// holds L[k][j] on k's ancestors j, and D_k).
struct Block<'a> {
    model: &'a Model,
    h: &'a [f64],
    j_cols: &'a [f64],
    j_stride: usize,
    rows: &'a [usize],
    dofs: (usize, usize),
}

impl Block<'_> {
    /// Adds the block's Delassus products to A (`a`, column-major with `stride`):
    /// A += Σ_k x_k x_kᵀ / D_k with X = L⁻ᵀJᵀ ([`Block::half_solve`]), on the lower triangle,
    /// then mirrored to the upper. For a chain whose contacts come in link order a dof's
    /// nonzeros are the rows of the links below it, so the work falls with the dof's depth.
    fn add_gram(&self, ljt: &mut [f64], dof_rows: &mut [(usize, usize)], a: &mut [f64], stride: usize) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2 (checked just above), all `add_gram_avx2` requires.
            unsafe { self.add_gram_avx2(ljt, dof_rows, a, stride) };
            return;
        }
        self.add_gram_kernel(ljt, dof_rows, a, stride);
    }

    /// [`Block::add_gram_kernel`] compiled for AVX2: the same operations in the same order (no
    /// fused multiply–adds), four rows per instruction, so the same bits.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn add_gram_avx2(
        &self,
        ljt: &mut [f64],
        dof_rows: &mut [(usize, usize)],
        a: &mut [f64],
        stride: usize,
    ) {
        self.add_gram_kernel(ljt, dof_rows, a, stride);
    }

    #[inline(always)]
    fn add_gram_kernel(
        &self,
        ljt: &mut [f64],
        dof_rows: &mut [(usize, usize)],
        a: &mut [f64],
        stride: usize,
    ) {
        let (nv, rows, (lo, hi)) = (self.model.nv, self.rows, self.dofs);
        let m = rows.len();
        let x = self.half_solve(ljt, dof_rows);
        let (r0, consecutive) = (rows[0], rows[m - 1] - rows[0] + 1 == m);
        // A += x_k x_kᵀ / D_k on the lower triangle (row ≥ column), column by column.
        for k in lo..hi {
            let (f, l) = dof_rows[k - lo];
            let d = self.h[k + k * nv];
            let xk = &x[(k - lo) * m..(k - lo + 1) * m];
            for c in f..l {
                let s = xk[c] / d;
                if s == 0.0 {
                    continue;
                }
                if consecutive {
                    let base = (r0 + c) * stride + r0;
                    for (v, w) in a[base + c..base + l].iter_mut().zip(&xk[c..l]) {
                        *v += w * s;
                    }
                } else {
                    let base = rows[c] * stride;
                    for (&i, w) in rows[c..l].iter().zip(&xk[c..l]) {
                        a[base + i] += w * s;
                    }
                }
            }
        }
        // The upper triangle (the block's sums so far: another tree's block may add to a pair
        // of rows touching both, and mirrors it again).
        for (c, &j) in rows.iter().enumerate() {
            for &i in &rows[c + 1..] {
                a[j + i * stride] = a[i + j * stride];
            }
        }
    }

    /// Writes the block's part of M⁻¹Jᵀ = L⁻¹ D⁻¹ X into `y` (row i's column at i · nv, over
    /// the block's dofs): X ([`Block::half_solve`]), D⁻¹, then L from the root down over all the
    /// block's rows (the column fills its trees).
    fn minv_jt(&self, ljt: &mut [f64], dof_rows: &mut [(usize, usize)], y: &mut [f64]) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2 (checked just above), all `minv_jt_avx2` requires.
            unsafe { self.minv_jt_avx2(ljt, dof_rows, y) };
            return;
        }
        self.minv_jt_kernel(ljt, dof_rows, y);
    }

    /// [`Block::minv_jt_kernel`] compiled for AVX2: the same operations in the same order, four
    /// rows per instruction, so the same bits.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn minv_jt_avx2(&self, ljt: &mut [f64], dof_rows: &mut [(usize, usize)], y: &mut [f64]) {
        self.minv_jt_kernel(ljt, dof_rows, y);
    }

    #[inline(always)]
    fn minv_jt_kernel(&self, ljt: &mut [f64], dof_rows: &mut [(usize, usize)], y: &mut [f64]) {
        let (model, h, rows, (lo, hi)) = (self.model, self.h, self.rows, self.dofs);
        let nv = model.nv;
        let m = rows.len();
        let x = self.half_solve(ljt, dof_rows);
        for k in lo..hi {
            let d = h[k + k * nv];
            for v in &mut x[(k - lo) * m..(k - lo + 1) * m] {
                *v /= d;
            }
        }
        // L Y = W from the root down: y_k −= L[k][j] y_j over the ancestors j of k.
        for k in lo..hi {
            let col_l = &h[k * nv..(k + 1) * nv];
            let (before, rest) = x.split_at_mut((k - lo) * m);
            let yk = &mut rest[..m];
            let mut e = model.dof_parent[k];
            while e != NO_DOF {
                let s = model.dof_run_start[e];
                for j in s..=e {
                    let c = col_l[j];
                    if c != 0.0 {
                        for (v, w) in yk.iter_mut().zip(&before[(j - lo) * m..(j - lo + 1) * m]) {
                            *v -= c * w;
                        }
                    }
                }
                e = model.dof_parent[s];
            }
        }
        for (r, &i) in rows.iter().enumerate() {
            for k in lo..hi {
                y[i * nv + k] = x[(k - lo) * m + r];
            }
        }
    }

    /// X = L⁻ᵀJᵀ over the block (in `ljt`, per dof the block's rows contiguous; returned),
    /// solved from the leaves up: x_j −= L[k][j] x_k over the ancestors j of k, x_k final once
    /// k's descendants are done. A row's X is zero outside its bodies' ancestor dofs (RBDA
    /// §6.5); per dof k only the rows [first, last + 1) of its nonzeros (`dof_rows`, indices
    /// into the block's rows) are updated.
    #[inline(always)]
    fn half_solve<'x>(&self, ljt: &'x mut [f64], dof_rows: &mut [(usize, usize)]) -> &'x mut [f64] {
        let (model, rows, (lo, hi)) = (self.model, self.rows, self.dofs);
        let nv = model.nv;
        let m = rows.len();
        let x = &mut ljt[..m * (hi - lo)];
        // Rows r0..r0 + m when the block's rows are consecutive (one robot, a chain): J's
        // columns are then copied as runs.
        let r0 = rows[0];
        let consecutive = rows[m - 1] - r0 + 1 == m;
        for k in lo..hi {
            let col = &self.j_cols[k * self.j_stride..(k + 1) * self.j_stride];
            let xk = &mut x[(k - lo) * m..(k - lo + 1) * m];
            if consecutive {
                xk.copy_from_slice(&col[r0..r0 + m]);
            } else {
                for (v, &i) in xk.iter_mut().zip(rows) {
                    *v = col[i];
                }
            }
        }
        for k in (lo..hi).rev() {
            let (before, rest) = x.split_at_mut((k - lo) * m);
            let xk = &rest[..m];
            let (f, l) = match (xk.iter().position(|&v| v != 0.0), xk.iter().rposition(|&v| v != 0.0)) {
                (Some(f), Some(l)) => (f, l + 1),
                _ => (0, 0),
            };
            dof_rows[k - lo] = (f, l);
            if f >= l {
                continue;
            }
            let col_l = &self.h[k * nv..(k + 1) * nv];
            let xk = &xk[f..l];
            let mut e = model.dof_parent[k];
            while e != NO_DOF {
                let s = model.dof_run_start[e];
                for j in s..=e {
                    let c = col_l[j];
                    if c != 0.0 {
                        let xj = &mut before[(j - lo) * m + f..(j - lo) * m + l];
                        for (v, w) in xj.iter_mut().zip(xk) {
                            *v -= c * w;
                        }
                    }
                }
                e = model.dof_parent[s];
            }
        }
        x
    }
}

/// J_i · x for row `i` of the current rows, over its nonzeros ([`ExactWork::row_ranges`]).
/// Needs the rows' Jᵀ and trees of [`delassus`] at the current J.
fn row_dot(data: &Data, nv: usize, i: usize, x: &[f64]) -> f64 {
    let row = &data.exact.jt.as_slice()[i * nv..(i + 1) * nv];
    let mut sum: f64 = std::iter::empty::<f64>().sum();
    for (lo, hi) in data.exact.row_ranges(i) {
        for (j, x) in row[lo..hi].iter().zip(&x[lo..hi]) {
            sum += j * x;
        }
    }
    sum
}

/// x += s · M⁻¹Jᵀ μ with μ the first nefc entries of `exact.rhs` (the result of a Delassus
/// solve): from M⁻¹Jᵀ when a Gauss–Seidel solve formed it ([`form_minv_jt`]; each row's column
/// over its trees), else Jᵀ μ over each row's nonzeros ([`ExactWork::row_ranges`]) and one solve
/// with the factor of M.
fn add_minv_jt_mu(model: &Model, data: &mut Data, s: f64, x: &mut [f64]) {
    let nv = model.nv;
    let Data { mass_factor, exact, nefc, .. } = data;
    if exact.minv_jt_ready {
        let y = exact.minv_jt.as_slice();
        for i in 0..*nefc {
            let mu = s * exact.rhs[i];
            for (lo, hi) in exact.tree_ranges(i) {
                for (x, y) in x[lo..hi].iter_mut().zip(&y[i * nv + lo..i * nv + hi]) {
                    *x += y * mu;
                }
            }
        }
        return;
    }
    let mut f = std::mem::take(&mut exact.minv_jt_mu);
    f.fill(0.0);
    let jt = exact.jt.as_slice();
    for i in 0..*nefc {
        let mu = s * exact.rhs[i];
        if mu == 0.0 {
            continue;
        }
        for (lo, hi) in exact.row_ranges(i) {
            for (f, j) in f.as_mut_slice()[lo..hi].iter_mut().zip(&jt[i * nv + lo..i * nv + hi]) {
                *f += j * mu;
            }
        }
    }
    solve_with_factor_unchecked(model, mass_factor, f.as_mut_slice());
    for (x, f) in x.iter_mut().zip(f.iter()) {
        *x += f;
    }
    exact.minv_jt_mu = f;
}

/// The constraint stage of the exact mode. Needs, at the same state: the factor of M
/// (`mass_factor`), the rows with `efc_pos`, `efc_vel`, `efc_jdotv`, and `qacc_smooth`. Writes
/// `efc_force` (λ), `qfrc_constraint` (Jᵀλ), `qacc` and `efc_rank`. `baumgarte = [α, β]` adds the
/// stabilization J q̈ + J̇v + α J v + β φ = 0 (Baumgarte 1972); `None` solves the pure KKT system.
pub(crate) fn solve_exact(
    model: &Model,
    data: &mut Data,
    baumgarte: Option<[f64; 2]>,
    settings: SolverSettings,
) {
    let n = data.nefc;
    let nv = model.nv;
    delassus(model, data);
    let [alpha, beta] = baumgarte.unwrap_or([0.0, 0.0]);
    for i in 0..n {
        let j_qacc = row_dot(data, nv, i, data.qacc_smooth.as_slice());
        data.exact.rhs[i] = -(j_qacc + data.efc_jdotv[i]) - alpha * data.efc_vel[i] - beta * data.efc_pos[i];
    }
    if has_friction(data) {
        if settings.solver == ExactContactSolver::Admm {
            solve_admm(model, data, settings);
            data.exact.warm_exact = false;
        } else {
            let scale = data.qacc_smooth.amax();
            solve_coulomb(model, data, Level::Acceleration, settings, scale);
        }
        if !data.efc_converged {
            let h = model.options.timestep;
            // J_i v′, the row velocity after a step h of the motion without constraint forces:
            // J_i (v + h q̈_smooth).
            limit_energy(data, h, |d, i| d.efc_vel[i] + h * row_dot(d, nv, i, d.qacc_smooth.as_slice()));
        }
        // No rank to report: the iterative solve gives one of the equivalent force distributions.
        data.exact.active.clear();
    } else {
        // A limit or contact row moving away from its bound (J v > 0) is separating: no force.
        data.efc_iterations =
            solve_mixed(data, |d, i| !d.rows_frozen() && d.efc_vel[i] > SEPARATING_VELOCITY);
        data.efc_residual = 0.0;
        data.efc_converged = true;
    }
    data.qacc.copy_from(&data.qacc_smooth);
    let mut qacc = std::mem::take(&mut data.qacc);
    add_minv_jt_mu(model, data, 1.0, qacc.as_mut_slice());
    data.qacc = qacc;
    data.qfrc_constraint.fill(0.0);
    data.exact.warm_rows.clear();
    for i in 0..n {
        let lambda = data.exact.rhs[i];
        data.efc_force[i] = lambda;
        data.exact.warm[i] = lambda;
        data.exact.warm_rows.push((data.efc_type[i], data.efc_id[i]));
        for (lo, hi) in data.exact.row_ranges(i) {
            let row = &data.exact.jt.as_slice()[i * nv + lo..i * nv + hi];
            for (f, j) in data.qfrc_constraint.as_mut_slice()[lo..hi].iter_mut().zip(row) {
                *f += j * lambda;
            }
        }
    }
}

/// The violation of the current rows: [position, velocity] with, per row kind, |φ| and |J v| for
/// equality rows, the penetration max(0, −φ) and approach speed max(0, −J v) for limits and
/// contact normals; friction rows (dof friction, contact friction) have neither.
pub fn row_violation(data: &Data) -> [f64; 2] {
    let mut out = [0.0f64; 2];
    for i in 0..data.nefc {
        let (phi, jv) = (data.efc_pos[i], data.efc_vel[i]);
        let (p, v) = match data.efc_type[i] {
            EfcType::Equality => (phi.abs(), jv.abs()),
            EfcType::FrictionDof => (0.0, 0.0),
            // A pyramidal contact's rows all carry the contact's distance (soft mode).
            EfcType::ContactPyramidal => ((-phi).max(0.0), 0.0),
            _ if data.efc_type[i].is_unilateral() && data.efc_is_normal_or_limit(i) => {
                ((-phi).max(0.0), (-jv).max(0.0))
            }
            _ => (0.0, 0.0),
        };
        out = [out[0].max(p), out[1].max(v)];
    }
    out
}

/// Moves `q` onto the constraint manifold φ(q) = 0 by Gauss–Newton steps Δ = −M⁻¹Jᵀ A⁺ φ applied
/// on the configuration manifold (`q ← q ⊕ Δ`, free and ball joints included), M taken at the
/// starting q. Stops when max |φ| ≤ `tolerance` or after `max_iterations`; returns (iterations,
/// final max |φ|). Leaves the factor of M at the starting q in `data`, and the rows it corrected
/// frozen ([`Data::add_frozen_rows`]) for the velocity projection; [`Data::thaw_rows`] ends that.
pub(crate) fn project_positions(
    model: &Model,
    constraints: &ConstraintModel,
    data: &mut Data,
    q: &mut [f64],
    tolerance: f64,
    max_iterations: u32,
) -> (u32, f64) {
    crba_unchecked(model, data, q);
    factorize_mass_matrix(model, data);
    let mut iterations = 0;
    loop {
        if iterations > 0 {
            body_poses(model, data, q);
        }
        if constraints.has_collision() {
            collide(model, &constraints.collision, data, EXACT_REACH);
        }
        constraints.positions_unchecked(model, data, q, false);
        if iterations == 0 {
            // The rows corrected stay rows until they land on φ = 0.
            data.add_frozen_rows(false);
        }
        let n = data.nefc;
        let residual = data.efc_pos.rows(0, n).amax();
        if residual <= tolerance || iterations >= max_iterations || !residual.is_finite() {
            return (iterations, residual);
        }
        delassus(model, data);
        for i in 0..n {
            data.exact.rhs[i] = data.efc_pos[i];
        }
        solve_delassus(data);
        let mut dq = std::mem::take(&mut data.scratch_v);
        dq.fill(0.0);
        add_minv_jt_mu(model, data, -1.0, dq.as_mut_slice());
        integrate_configuration_unchecked(model, q, dq.as_slice(), 1.0);
        data.scratch_v = dq;
        iterations += 1;
    }
}

/// Replaces `v` by its M-orthogonal projection onto {J v = 0 on bilateral rows, J v ≥ 0 on
/// unilateral rows} at configuration `q`: v ← v + M⁻¹Jᵀ μ with the impulses μ of the mixed
/// complementarity problem (an inelastic impact on a joint limit: restitution 0). With dry friction
/// the impulses follow Coulomb's law at the velocity level over a step `dt` ([`Level::Velocity`]).
/// Needs the factor of M (e.g. from `project_positions`) and the rows at q (`positions`); returns the largest
/// remaining violation (|J v| bilateral, max(0, −J v) unilateral) and leaves J v in `efc_vel`.
///
/// # Errors
/// [`InputError::Length`] when v is not nv long or `data` was made for another model.
pub fn project_velocities(
    model: &Model,
    data: &mut Data,
    v: &mut [f64],
    dt: f64,
    settings: SolverSettings,
) -> Result<f64, InputError> {
    check::data("project_velocities", model, data)?;
    check::v("project_velocities", "v", model, v)?;
    Ok(project_velocities_unchecked(model, data, v, dt, settings))
}

/// [`project_velocities`] without the argument checks.
pub(crate) fn project_velocities_unchecked(
    model: &Model,
    data: &mut Data,
    v: &mut [f64],
    dt: f64,
    settings: SolverSettings,
) -> f64 {
    let n = data.nefc;
    let nv = model.nv;
    delassus(model, data);
    for i in 0..n {
        data.exact.rhs[i] = -row_dot(data, nv, i, v);
        data.exact.pressing[i] = data.efc_is_normal_or_limit(i) && data.efc_previous_force(i, 0) > 0.0;
    }
    if has_friction(data) {
        let scale = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        solve_coulomb(model, data, Level::Velocity { dt }, settings, scale);
        data.exact.active.clear();
        if !data.efc_converged {
            // The row velocities v gives, J v = −b (b still in efc_force after the solve).
            limit_energy(data, 1.0, |d, i| -d.efc_force[i]);
        }
    } else {
        solve_mixed(data, |_, _| false);
    }
    data.exact.pressing[..n].fill(false);
    add_minv_jt_mu(model, data, 1.0, v);
    // J v of the projected velocity, measured as every row violation is.
    for i in 0..n {
        data.efc_vel[i] = row_dot(data, nv, i, v);
    }
    row_violation(data)[1]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::constraint::ConstraintMode;
    use crate::dynamics::solve_with_factor_unchecked;

    /// The tree-by-tree Delassus products equal the dense J M⁻¹ Jᵀ to round-off, and the nonzero
    /// pattern holds every nonzero, on scenes with several trees: two stacked boxes, a hinged
    /// pendulum touching the floor, a free capsule; stacks whose rows do not come in tree order;
    /// a chain of capsules on the floor (one tree, rows of every depth).
    #[test]
    fn delassus_equals_the_dense_products() {
        check_delassus(
            "<mujoco><worldbody><geom type='plane' size='0 0 1'/>\
             <body pos='0 0 0.049'><freejoint/><geom type='box' size='0.05 0.05 0.05'/></body>\
             <body pos='0 0 0.148'><freejoint/><geom type='box' size='0.05 0.05 0.05'/></body>\
             <body pos='0.5 0 0.3'><joint type='hinge' axis='0 1 0'/><geom type='capsule' fromto='0 0 0 0 0 -0.31' size='0.02'/>\
             <body pos='0 0 -0.3'><joint type='hinge' axis='1 0 0'/><geom size='0.03'/></body></body>\
             <body pos='1 0 0.019' euler='0 90 0'><freejoint/><geom type='capsule' size='0.02 0.1'/></body>\
             </worldbody></mujoco>",
        );
        // Two stacks of two boxes and three lone boxes, in an order whose rows do not come
        // sorted by tree (a stack's upper box first).
        check_delassus(
            "<mujoco><worldbody><geom type='plane' size='0 0 1'/>\
             <body pos='0 0 0.148'><freejoint/><geom type='box' size='0.05 0.05 0.05'/></body>\
             <body pos='0.3 0 0.049'><freejoint/><geom type='box' size='0.05 0.05 0.05'/></body>\
             <body pos='0 0 0.049'><freejoint/><geom type='box' size='0.05 0.05 0.05'/></body>\
             <body pos='0.6 0 0.049'><freejoint/><geom type='box' size='0.05 0.05 0.05'/></body>\
             <body pos='0.9 0 0.148'><freejoint/><geom type='box' size='0.05 0.05 0.05'/></body>\
             <body pos='1.2 0 0.049'><freejoint/><geom type='box' size='0.05 0.05 0.05'/></body>\
             <body pos='0.9 0 0.049'><freejoint/><geom type='box' size='0.05 0.05 0.05'/></body>\
             </worldbody></mujoco>",
        );
        // A chain of eight capsules lying on the floor, a ball joint between each two.
        let mut chain = String::from(
            "<mujoco><worldbody><geom type='plane' size='0 0 1'/><body pos='0 0 0.0199'><freejoint/>",
        );
        for k in 0..8 {
            if k > 0 {
                chain.push_str("<body pos='0.1 0 0'><joint type='ball'/>");
            }
            chain.push_str("<geom type='capsule' fromto='0 0 0 0.1 0 0' size='0.02'/>");
        }
        chain.push_str(&"</body>".repeat(8));
        chain.push_str("</worldbody></mujoco>");
        check_delassus(&chain);
    }

    /// [`delassus`] of the scene `xml` in exact mode against the dense products J (M⁻¹ Jᵀ): equal
    /// to round-off of the entries' size (`ROUND_OFF` of the largest diagonal, the rows' scale),
    /// exactly symmetric, and every nonzero inside the pattern.
    fn check_delassus(xml: &str) {
        const ROUND_OFF: f64 = 1e-12;
        let mut model = crate::Model::from_str(xml).unwrap();
        model.set_constraint_mode(ConstraintMode::Exact);
        let mut data = Data::new(&model);
        crate::forward::forward(&model, &mut data);
        let (n, nv) = (data.nefc, model.nv);
        assert!(n >= 20, "rows {n}");
        delassus(&model, &mut data);
        let j = data.efc_j.rows(0, n).into_owned();
        let mut y = j.transpose();
        for c in 0..n {
            solve_with_factor_unchecked(&model, &data.mass_factor, y.column_mut(c).as_mut_slice());
        }
        let scale = (0..n).map(|i| data.exact.delassus[(i, i)]).fold(0.0, f64::max);
        assert!(scale > 0.0);
        for i in 0..n {
            for c in 0..n {
                let dense: f64 = (0..nv).map(|k| j[(i, k)] * y[(k, c)]).sum();
                let a = data.exact.delassus[(i, c)];
                assert!((a - dense).abs() <= ROUND_OFF * scale, "({i}, {c}): {a} against {dense}");
                assert_eq!(a, data.exact.delassus[(c, i)], "({i}, {c}) symmetric");
                // Every nonzero lies in the pattern (the Gauss–Seidel gathers read only it).
                let w = &data.exact;
                assert_eq!(w.pattern_n, n);
                if !w.pattern_full {
                    let column = &w.pattern_rows[w.pattern_ptr[c]..w.pattern_ptr[c + 1]];
                    assert!(a == 0.0 || column.contains(&i), "({i}, {c}) outside the pattern");
                }
            }
            // M⁻¹Jᵀ formed (the sweeps' second route) is the dense solve's, over the row's trees.
            if i == 0 {
                form_minv_jt(&model, &mut data);
            }
            let w = &data.exact;
            let ymax = y.column(i).amax();
            for (lo, hi) in w.tree_ranges(i) {
                for k in lo..hi {
                    assert!((w.minv_jt[(k, i)] - y[(k, i)]).abs() <= ROUND_OFF * ymax, "M⁻¹Jᵀ ({k}, {i})");
                }
            }
            let outside =
                (0..nv).filter(|&k| !w.tree_ranges(i).iter().any(|&(lo, hi)| (lo..hi).contains(&k)));
            assert!(outside.into_iter().all(|k| y[(k, i)] == 0.0), "M⁻¹J_{i}ᵀ nonzero outside its trees");
            // J_i is zero outside its row ranges, and row_dot is J_i · x.
            let x: Vec<f64> = (0..nv).map(|k| 1.0 + k as f64).collect();
            let dense: f64 = (0..nv).map(|k| j[(i, k)] * x[k]).sum();
            assert!((row_dot(&data, nv, i, &x) - dense).abs() <= ROUND_OFF * (1.0 + dense.abs()));
        }
    }
}
