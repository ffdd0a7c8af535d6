//! The exact (rigid) constraint solver: the KKT system of Lagrangian mechanics with multipliers
//! (docs/physics.md §1.6, eq. 20: M q̈ + c − τ = Jᵀλ together with the acceleration form of the constraints,
//! J q̈ + J̇v = 0), solved by the range-space method with the tree-sparse LᵀDL factor of M
//! (RBDA §6.3): Y = M⁻¹Jᵀ, the Delassus matrix A = J Y, then A λ = −(J q̈_smooth + J̇v) and
//! q̈ = q̈_smooth + Y λ. Redundant rows give the minimum-norm multipliers ([`solve_psd`]).
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
use crate::dynamics::{crba_unchecked, factorize_mass_matrix, tree_span};
use crate::error::{check, InputError};
use crate::kinematics::body_poses;
use crate::model::{integrate_configuration_unchecked, Data, EfcType, Model, NO_DOF};

/// Y = M⁻¹Jᵀ into `efc_minv_jt` (each row's column over its span only: zero outside it, and not
/// written there) and A = J M⁻¹ Jᵀ into `efc_delassus` for the current rows (needs
/// the factor of M in `mass_factor`). Each row touches the dofs of at most two kinematic trees,
/// and M is block-diagonal over trees: Y_i is solved over its row's trees only and A_ij is
/// J_i · Y_j over the dofs both rows' trees share (zero when there are none) — the dense
/// products' arithmetic, in the same order, without their exact-zero terms.
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
                minv_jt: efc_minv_jt,
                delassus: efc_delassus,
                jt,
                spans,
                yt,
                yt_acc,
                yt_run,
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
                ..
            },
        ..
    } = data;
    // Jᵀ, read down J's columns (contiguous in its storage), and each row's span.
    let jt = &mut jt.as_mut_slice()[..nv * n];
    let yt = &mut yt[..n * nv];
    for k in 0..nv {
        let col = &efc_j.as_slice()[k * efc_j.nrows()..k * efc_j.nrows() + n];
        yt[k * n..(k + 1) * n].copy_from_slice(col);
        for (i, &jik) in col.iter().enumerate() {
            jt[k + i * nv] = jik;
        }
    }
    for i in 0..n {
        let row = &jt[i * nv..(i + 1) * nv];
        spans[i] = match (row.iter().position(|&x| x != 0.0), row.iter().rposition(|&x| x != 0.0)) {
            (Some(first), Some(last)) => tree_span(model, first, last),
            _ => (0, 0),
        };
    }
    // Per dof, the rows that may touch it (its tree's: the spans are whole trees).
    dof_rows.fill((n, 0));
    for (i, &(lo, hi)) in spans[..n].iter().enumerate() {
        for r in &mut dof_rows[lo..hi] {
            *r = (r.0.min(i), r.1.max(i + 1));
        }
    }
    // Y = M⁻¹Jᵀ for all rows at once, on its transpose.
    solve_rows(model, mass_factor.as_slice(), yt, n, dof_rows, &mut yt_acc[..n], &mut yt_run[..n]);
    // Each row's column of M⁻¹Jᵀ over its span (zero outside it, where no reader looks).
    let y = &mut efc_minv_jt.as_mut_slice()[..nv * n];
    for (i, &(lo, hi)) in spans[..n].iter().enumerate() {
        for (k, x) in (lo..hi).zip(&mut y[i * nv + lo..i * nv + hi]) {
            *x = yt[k * n + i];
        }
    }
    // A_ij = J_i · Y_j over the dofs of both rows' trees, ascending (outside them a term of the
    // dense sum is an exact zero), for i ≤ j, mirrored to A_ji; zero when the trees are disjoint.
    let stride = efc_delassus.nrows();
    let a = efc_delassus.as_mut_slice();
    let width = spans[..n].iter().map(|&(lo, hi)| hi - lo).max().unwrap_or(0);
    // Each row's trees: when none touches more than two (contacts, a connect between two
    // bodies), the products and the pattern go tree by tree.
    *trees_valid = row_trees(model, &jt[..nv * n], &spans[..n], &mut trees[..n]);
    if *trees_valid {
        tree_lists(&trees[..n], tree_ptr, tree_rows);
        delassus_by_trees(a, stride, nv, jt, y, &trees[..n], tree_ptr, tree_rows, pattern_ptr, pattern_rows);
        *pattern_n = n;
        *pattern_full = pattern_rows.len() == n * n;
        return;
    }
    let sorted = 2 * width < nv;
    if sorted {
        delassus_meeting_pairs(a, stride, n, nv, jt, y, spans, &mut order[..n], width);
    } else {
        delassus_all_pairs(a, stride, n, nv, jt, y, spans);
    }
    delassus_pattern(&spans[..n], sorted.then_some(&order[..n]), width, pattern_ptr, pattern_rows);
    *pattern_n = n;
    *pattern_full = pattern_rows.len() == n * n;
}

/// Per row, the dof ranges of the kinematic trees its J row (in `jt`, rows of nv) touches, the
/// tree of its first nonzero and that of its last (`[first, (0, 0)]` when they are one tree;
/// both empty for a zero row). False when some row touches a third tree between them (a tendon
/// or an equality over several trees): the caller then pairs rows by their spans.
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

/// The Delassus matrix A_ij = J_i · Y_j and its nonzero pattern for rows that each touch at
/// most two trees (`trees`, listed per tree in `tree_ptr`/`tree_rows`): rows i and j meet when
/// they share a tree, and A_ij is the sum over the shared trees' dofs, ascending — the dense sum's
/// terms without its exact zeros (elsewhere J_i or Y_j is zero), in its order. The pattern of
/// column j is the union of its trees' rows (ascending); every other entry is zero. Work: the
/// pattern's size times a tree's dofs, where the span pairing pays n² pairs once a row's trees
/// lie far apart (a pile: a contact between the first and the last body spans every dof).
#[allow(clippy::too_many_arguments)]
fn delassus_by_trees(
    a: &mut [f64],
    stride: usize,
    nv: usize,
    jt: &[f64],
    y: &[f64],
    trees: &[[(usize, usize); 2]],
    tree_ptr: &[usize],
    tree_rows: &[usize],
    pattern_ptr: &mut Vec<usize>,
    pattern_rows: &mut Vec<usize>,
) {
    let n = trees.len();
    for j in 0..n {
        a[j * stride..j * stride + n].fill(0.0);
    }
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
    for j in 0..n {
        let [tj0, tj1] = trees[j];
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
            if i > j {
                continue;
            }
            let y_j = &y[j * nv..(j + 1) * nv];
            let j_i = &jt[i * nv..(i + 1) * nv];
            let mut sum: f64 = std::iter::empty::<f64>().sum();
            for t in trees[i] {
                if t.0 < t.1 && (t == tj0 || t == tj1) {
                    for k in t.0..t.1 {
                        sum += j_i[k] * y_j[k];
                    }
                }
            }
            a[i + j * stride] = sum;
            a[j + i * stride] = sum;
        }
        pattern_ptr.push(pattern_rows.len());
    }
}

/// The nonzero pattern of the Delassus matrix of the rows with tree spans `spans`: per column j,
/// ascending, the rows i whose span meets j's (A_ij is zero otherwise), in compressed columns
/// (`ptr` n + 1 offsets into `rows`). With `order` (the rows sorted by their span's first dof,
/// `width` the widest span) only the rows that can meet j are visited, as in
/// [`delassus_meeting_pairs`]; without it every pair is checked. The gather–scatter work of a
/// Gauss–Seidel sweep on the pattern is its size, the Delassus matrix's nonzeros, rather than n²
/// (a pile: each contact meets only the contacts of its two bodies). `rows` grows only when a
/// pattern is larger than any before it.
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

/// A_ij = J_i · Y_j (over both rows' spans) for every pair i ≤ j, column by column (contiguous
/// writes), and the lower triangle by symmetry: when most rows' trees meet (one robot, a pair of
/// boxes).
fn delassus_all_pairs(
    a: &mut [f64],
    stride: usize,
    n: usize,
    nv: usize,
    jt: &[f64],
    y: &[f64],
    spans: &[(usize, usize)],
) {
    for j in 0..n {
        let (lo_j, hi_j) = spans[j];
        let y_j = &y[j * nv..(j + 1) * nv];
        for i in 0..=j {
            let (lo_i, hi_i) = spans[i];
            let (lo, hi) = (lo_i.max(lo_j), hi_i.min(hi_j));
            a[i + j * stride] = if lo >= hi {
                0.0
            } else {
                jt[i * nv + lo..i * nv + hi].iter().zip(&y_j[lo..hi]).map(|(x, y)| x * y).sum()
            };
        }
    }
    // The lower triangle in 8 × 8 tiles (each tile's reads and writes stay in a few cache lines
    // of the capacity-strided matrix).
    const TILE: usize = 8;
    for ib in (0..n).step_by(TILE) {
        for jb in (ib..n).step_by(TILE) {
            for i in ib..(ib + TILE).min(n) {
                for j in jb.max(i + 1)..(jb + TILE).min(n) {
                    a[j + i * stride] = a[i + j * stride];
                }
            }
        }
    }
}

/// [`delassus_all_pairs`] visiting only the pairs whose spans meet, for rows on many separate
/// trees (a stack, a bin: each row touches one or two of them): the rest is zero. The rows in
/// order of their span's first dof (`order`); row i can meet row j only if
/// lo_j − `width` < lo_i < hi_j (`width` the widest span).
#[allow(clippy::too_many_arguments)]
fn delassus_meeting_pairs(
    a: &mut [f64],
    stride: usize,
    n: usize,
    nv: usize,
    jt: &[f64],
    y: &[f64],
    spans: &[(usize, usize)],
    order: &mut [usize],
    width: usize,
) {
    // Insertion sort, stable: the rows come mostly in order already (a contact's rows together,
    // contacts by body).
    for k in 0..n {
        let lo = spans[k].0;
        let mut p = k;
        while p > 0 && spans[order[p - 1]].0 > lo {
            order[p] = order[p - 1];
            p -= 1;
        }
        order[p] = k;
    }
    for j in 0..n {
        a[j * stride..j * stride + n].fill(0.0);
    }
    for j in 0..n {
        let (lo_j, hi_j) = spans[j];
        if lo_j >= hi_j {
            continue;
        }
        let y_j = &y[j * nv..(j + 1) * nv];
        let start = order.partition_point(|&i| spans[i].0 + width <= lo_j);
        for &i in &order[start..] {
            let (lo_i, hi_i) = spans[i];
            if lo_i >= hi_j {
                break;
            }
            let (lo, hi) = (lo_i.max(lo_j), hi_i.min(hi_j));
            if i > j || lo >= hi {
                continue;
            }
            let v: f64 = jt[i * nv + lo..i * nv + hi].iter().zip(&y_j[lo..hi]).map(|(x, y)| x * y).sum();
            a[i + j * stride] = v;
            a[j + i * stride] = v;
        }
    }
}

/// Solves M X = B for the n right-hand sides of `yt` (Bᵀ on entry, Xᵀ on return: n × nv,
/// column-major, one dof's column of n entries contiguous) with the tree-sparse factor of M: each
/// step of the solve updates a whole column, across every right-hand side. Per right-hand side
/// the operations, and their order, are those of `dynamics::crba::solve_with_factor_span_unchecked`
/// (Lᵀ z = b from the leaves up, D w = z, L x = w from the root down with each run of the
/// ancestor chain summed apart), so the same bits: dofs outside a row's trees hold zeros and
/// stay zero, and each dof's step runs over `rows[dof]` only, the rows that may touch its tree.
/// `acc` and `run` (n each) are scratch.
fn solve_rows(
    model: &Model,
    factor: &[f64],
    yt: &mut [f64],
    n: usize,
    rows: &[(usize, usize)],
    acc: &mut [f64],
    run: &mut [f64],
) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2 (checked just above), all `solve_rows_avx2` requires.
        unsafe { solve_rows_avx2(model, factor, yt, n, rows, acc, run) };
        return;
    }
    solve_rows_kernel(model, factor, yt, n, rows, acc, run);
}

/// [`solve_rows_kernel`] compiled for AVX2: the same operations in the same order (no fused
/// multiply–adds), four right-hand sides per instruction, so the same bits.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn solve_rows_avx2(
    model: &Model,
    factor: &[f64],
    yt: &mut [f64],
    n: usize,
    rows: &[(usize, usize)],
    acc: &mut [f64],
    run: &mut [f64],
) {
    solve_rows_kernel(model, factor, yt, n, rows, acc, run);
}

#[inline(always)]
fn solve_rows_kernel(
    model: &Model,
    h: &[f64],
    yt: &mut [f64],
    n: usize,
    rows: &[(usize, usize)],
    acc: &mut [f64],
    run: &mut [f64],
) {
    let nv = model.nv;
    let lambda = &model.dof_parent[..nv];
    // The empty sum, as `Iterator::sum` starts it.
    let zero: f64 = std::iter::empty::<f64>().sum();
    // Lᵀ z = b: x[j] −= L[i][j] x[i] over the ancestor chain of each dof, from the leaves up
    // (rows [r0, r1) only: the others are zero on the dof's tree and stay so).
    for i in (0..nv).rev() {
        let (r0, r1) = rows[i];
        if lambda[i] == NO_DOF || r0 >= r1 {
            continue;
        }
        let col_l = &h[i * nv..(i + 1) * nv];
        let (before, rest) = yt.split_at_mut(i * n);
        let x_i = &rest[r0..r1];
        let mut e = lambda[i];
        while e != NO_DOF {
            let s = model.dof_run_start[e];
            for j in s..=e {
                let l = col_l[j];
                for (a, b) in before[j * n + r0..j * n + r1].iter_mut().zip(x_i) {
                    *a -= l * b;
                }
            }
            e = lambda[s];
        }
    }
    // D w = z.
    for i in 0..nv {
        let (r0, r1) = rows[i];
        let d = h[i + i * nv];
        for a in &mut yt[i * n + r0.min(r1)..i * n + r1] {
            *a /= d;
        }
    }
    // L x = w: x[i] −= Σ over the runs of its ancestor chain (each run summed, then added).
    for i in 0..nv {
        let (r0, r1) = rows[i];
        if lambda[i] == NO_DOF || r0 >= r1 {
            continue;
        }
        let col_l = &h[i * nv..(i + 1) * nv];
        let (before, rest) = yt.split_at_mut(i * n);
        let (acc, run) = (&mut acc[r0..r1], &mut run[r0..r1]);
        acc.fill(0.0);
        let mut e = lambda[i];
        while e != NO_DOF {
            let s = model.dof_run_start[e];
            run.fill(zero);
            for j in s..=e {
                let l = col_l[j];
                for (r, x) in run.iter_mut().zip(&before[j * n + r0..j * n + r1]) {
                    *r += x * l;
                }
            }
            for (a, r) in acc.iter_mut().zip(run.iter()) {
                *a += r;
            }
            e = lambda[s];
        }
        for (x, a) in rest[r0..r1].iter_mut().zip(acc.iter()) {
            *x -= a;
        }
    }
}

/// J_i · x for row `i` of the current rows, over its trees' dofs ([`row_ranges`]; J_i is zero
/// outside them): the dense sum's terms in its order, without its exact zeros. Needs the rows'
/// Jᵀ and trees of [`delassus`] at the current J.
fn row_dot(data: &Data, nv: usize, i: usize, x: &[f64]) -> f64 {
    let row = &data.exact.jt.as_slice()[i * nv..(i + 1) * nv];
    let mut sum: f64 = std::iter::empty::<f64>().sum();
    for (lo, hi) in row_ranges(data, i) {
        for (j, x) in row[lo..hi].iter().zip(&x[lo..hi]) {
            sum += j * x;
        }
    }
    sum
}

/// The dofs of row i's trees, ascending, as two ranges (`exact.trees`; the second may be
/// empty), or its span and an empty range when the trees are not known: J_i and M⁻¹J_iᵀ are
/// zero outside them. Needs [`delassus`] at the current rows.
fn row_ranges(data: &Data, i: usize) -> [(usize, usize); 2] {
    if data.exact.trees_valid {
        data.exact.trees[i]
    } else {
        [data.exact.spans[i], (0, 0)]
    }
}

/// x += s · M⁻¹Jᵀ μ with μ the first nefc entries of `efc_rhs` (the result of a Delassus solve),
/// each row's column over its trees' dofs ([`row_ranges`]; zero outside them).
fn add_minv_jt_mu(data: &Data, nv: usize, s: f64, x: &mut [f64]) {
    let y = data.exact.minv_jt.as_slice();
    for i in 0..data.nefc {
        let mu = s * data.exact.rhs[i];
        for (lo, hi) in row_ranges(data, i) {
            for (x, y) in x[lo..hi].iter_mut().zip(&y[i * nv + lo..i * nv + hi]) {
                *x += y * mu;
            }
        }
    }
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
    add_minv_jt_mu(data, nv, 1.0, qacc.as_mut_slice());
    data.qacc = qacc;
    data.qfrc_constraint.fill(0.0);
    data.exact.warm_rows.clear();
    for i in 0..n {
        let lambda = data.exact.rhs[i];
        data.efc_force[i] = lambda;
        data.exact.warm[i] = lambda;
        data.exact.warm_rows.push((data.efc_type[i], data.efc_id[i]));
        for (lo, hi) in row_ranges(data, i) {
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
        add_minv_jt_mu(data, model.nv, -1.0, dq.as_mut_slice());
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
    add_minv_jt_mu(data, nv, 1.0, v);
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

    /// The tree-restricted Delassus products equal the dense J M⁻¹ Jᵀ (each entry the same sum
    /// without its exact zeros), and the nonzero pattern holds every nonzero, on a scene with several trees: two stacked boxes, a hinged
    /// pendulum touching the floor, a free capsule.
    #[test]
    fn delassus_equals_the_dense_products() {
        // All pairs visited (the trees' spans cover most dofs).
        check_delassus(
            "<mujoco><worldbody><geom type='plane' size='0 0 1'/>\
             <body pos='0 0 0.049'><freejoint/><geom type='box' size='0.05 0.05 0.05'/></body>\
             <body pos='0 0 0.148'><freejoint/><geom type='box' size='0.05 0.05 0.05'/></body>\
             <body pos='0.5 0 0.3'><joint type='hinge' axis='0 1 0'/><geom type='capsule' fromto='0 0 0 0 0 -0.31' size='0.02'/>\
             <body pos='0 0 -0.3'><joint type='hinge' axis='1 0 0'/><geom size='0.03'/></body></body>\
             <body pos='1 0 0.019' euler='0 90 0'><freejoint/><geom type='capsule' size='0.02 0.1'/></body>\
             </worldbody></mujoco>",
        );
        // Only the meeting pairs visited: two stacks of two boxes and three lone boxes, in an
        // order whose rows do not come sorted by tree (a stack's upper box first).
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
    }

    /// [`delassus`] of the scene `xml` in exact mode against the dense products.
    fn check_delassus(xml: &str) {
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
        for i in 0..n {
            for c in 0..n {
                let dense: f64 = (0..nv).map(|k| j[(i, k)] * y[(k, c)]).sum();
                let (r, s) = (i.min(c), i.max(c));
                let dense_upper: f64 = (0..nv).map(|k| j[(r, k)] * y[(k, s)]).sum();
                assert_eq!(data.exact.delassus[(i, c)], dense_upper, "({i}, {c})");
                // Every nonzero lies in the pattern (the Gauss–Seidel gathers read only it).
                let w = &data.exact;
                assert_eq!(w.pattern_n, n);
                let column = &w.pattern_rows[w.pattern_ptr[c]..w.pattern_ptr[c + 1]];
                assert!(dense_upper == 0.0 || column.contains(&i), "({i}, {c}) outside the pattern");
                assert!((dense - dense_upper).abs() <= 1e-12 * (1.0 + dense.abs()));
                let (lo, hi) = data.exact.spans[c];
                if (lo..hi).contains(&(i % nv)) {
                    assert_eq!(data.exact.minv_jt[(i % nv, c)], y[(i % nv, c)]);
                } else {
                    assert_eq!(y[(i % nv, c)], 0.0);
                }
            }
        }
    }
}
