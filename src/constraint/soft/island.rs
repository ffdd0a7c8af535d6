//! Constraint islands of the soft Newton solve (MuJoCo 4.0's engine_island.c, `mj_island`, and
//! `mj_solNewton_island`, engine_solver.c): the groups of dofs that the mass matrix (a dof
//! couples to its tree) and the rows (a row couples the dofs of its nonzero columns) join. The
//! soft problem separates over islands — its cost is the sum of theirs — so each island's
//! minimizer is found on its own: its own Newton iterations, line search and termination
//! test, scaled by its own inertia (MuJoCo's island scale 1 / Σ M_kk over its dofs). A pile
//! that has come to rest stops iterating while a tumbling one goes on; the work of a solve is
//! the sum of the islands' work instead of the largest island's iteration count times the
//! whole problem.
//!
//! [`Islands::discover`] finds them (union–find over dofs from the trees and the rows'
//! recorded columns); [`newton`] runs the iterations on every island still iterating at once:
//! the gradient, the Hessian's rows, its factor (`SparseCholesky::factor_rows`), the solve,
//! J d and M d only on those islands' dofs and rows, one exact line search per island over its
//! own rows — an iteration costs what its islands hold, not what the model holds (MuJoCo's
//! island solves work on island-local copies to the same end). Dofs of trees no row touches
//! keep `qacc_smooth` (MuJoCo does the same).

use super::cost::Rows;
use super::hessian::{Assembler, Target};
use super::primal::{line_search_with, term_change, Settings, Sparsity, TermChange};
use super::sparse_cholesky::{SparseCholesky, RANK};
use super::tree_mass::TreeMass;
use super::work::SoftWork;
use crate::dynamics::solve_with_factor_unchecked;
use crate::model::{EfcState, Model, NO_DOF};
use nalgebra::DVector;

const NONE: usize = usize::MAX;

/// The islands of one solve and each island's iteration state.
#[derive(Clone, Debug, Default)]
pub(crate) struct Islands {
    /// Number of islands.
    pub n: usize,
    /// Each dof's island (`NONE`: no row touches its tree) and each row's (`NONE`: a row with
    /// no nonzero column).
    pub dof: Vec<usize>,
    pub row: Vec<usize>,
    /// Island i's dofs are `dofs[dof_start[i]..dof_start[i + 1]]`, its rows
    /// `rows[row_start[i]..row_start[i + 1]]` (both ascending).
    pub dof_start: Vec<usize>,
    pub dofs: Vec<usize>,
    pub row_start: Vec<usize>,
    pub rows: Vec<usize>,
    /// Each dof's tree (its root dof), union–find parents over trees (by their root dofs), and
    /// each root's island while numbering.
    tree: Vec<usize>,
    parent: Vec<usize>,
    root_island: Vec<usize>,
    /// Per island: scale (1 / Σ M_kk), cost, last improvement and gradient, iterations, and
    /// whether it still iterates; the step and the line search's slope and curvature terms.
    scale: Vec<f64>,
    cost: Vec<f64>,
    improvement: Vec<f64>,
    gradient: Vec<f64>,
    iterations: Vec<u32>,
    active: Vec<bool>,
    converged: Vec<bool>,
    alpha: Vec<f64>,
    g0: Vec<f64>,
    dmd: Vec<f64>,
    /// The dofs (island after island, each ascending) of the islands still iterating, and of
    /// those among them whose factor is formed anew, while an iteration runs.
    active_dofs: Vec<usize>,
    fresh_dofs: Vec<usize>,
    /// Per island: whether the factor's rows hold its factor (at the rows' `factor_state`), and
    /// whether this iteration forms it anew.
    factored: Vec<bool>,
    fresh: Vec<bool>,
    /// Per row: its state when its island's factor was last formed or updated.
    factor_state: Vec<EfcState>,
}

impl Islands {
    /// Buffers for nv dofs and nefc rows (they grow with larger problems only).
    pub fn with_capacity(nv: usize, nefc: usize) -> Self {
        fn per<T>(n: usize) -> Vec<T> {
            Vec::with_capacity(n + 1)
        }
        Self {
            n: 0,
            dof: per(nv),
            row: per(nefc),
            dof_start: per(nv),
            dofs: per(nv),
            row_start: per(nv),
            rows: per(nefc),
            tree: per(nv),
            parent: per(nv),
            root_island: per(nv),
            scale: per(nv),
            cost: per(nv),
            improvement: per(nv),
            gradient: per(nv),
            iterations: per(nv),
            active: per(nv),
            converged: per(nv),
            alpha: per(nv),
            g0: per(nv),
            dmd: per(nv),
            active_dofs: per(nv),
            fresh_dofs: per(nv),
            factored: per(nv),
            fresh: per(nv),
            factor_state: per(nefc),
        }
    }

    /// Island i's dofs, ascending.
    fn dofs_of(&self, i: usize) -> &[usize] {
        &self.dofs[self.dof_start[i]..self.dof_start[i + 1]]
    }

    /// Island i's rows, ascending.
    fn rows_of(&self, i: usize) -> &[usize] {
        &self.rows[self.row_start[i]..self.row_start[i + 1]]
    }

    fn find(&mut self, mut x: usize) -> usize {
        while self.parent[x] != x {
            self.parent[x] = self.parent[self.parent[x]];
            x = self.parent[x];
        }
        x
    }

    fn union(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            // The smaller root becomes the parent: deterministic, whatever the row order.
            let (lo, hi) = if ra < rb { (ra, rb) } else { (rb, ra) };
            self.parent[hi] = lo;
        }
    }

    /// The islands of the `nefc` rows of `nz` over `nv` dofs with tree parents `dof_parent`,
    /// numbered in the order of their first row; the scale of each from M's diagonal (`m`).
    pub(super) fn discover(
        &mut self,
        nv: usize,
        dof_parent: &[usize],
        nefc: usize,
        nz: &Sparsity,
        m: &TreeMass,
    ) {
        // Each dof's tree (its root dof: parents come first), then one union per pair of trees
        // a row joins (a row's columns run tree by tree).
        self.tree.clear();
        for k in 0..nv {
            let t = if dof_parent[k] == NO_DOF { k } else { self.tree[dof_parent[k]] };
            self.tree.push(t);
        }
        self.parent.clear();
        self.parent.extend(0..nv);
        let mut previous: &[usize] = &[];
        for i in 0..nefc {
            let cols = nz.columns(i);
            // A contact's rows share their columns: its first row joins them.
            if cols == previous {
                continue;
            }
            previous = cols;
            if let Some((&first, rest)) = cols.split_first() {
                let (t0, mut last) = (self.tree[first], self.tree[first]);
                for &c in rest {
                    let t = self.tree[c];
                    if t != last {
                        self.union(t0, t);
                        last = t;
                    }
                }
            }
        }
        self.root_island.clear();
        self.root_island.resize(nv, NONE);
        self.row.clear();
        self.n = 0;
        for i in 0..nefc {
            let island = match nz.columns(i).first() {
                Some(&c) => {
                    let r = self.find(self.tree[c]);
                    if self.root_island[r] == NONE {
                        self.root_island[r] = self.n;
                        self.n += 1;
                    }
                    self.root_island[r]
                }
                None => NONE,
            };
            self.row.push(island);
        }
        self.dof.clear();
        for k in 0..nv {
            let r = self.find(self.tree[k]);
            self.dof.push(self.root_island[r]);
        }
        let n = self.n;
        counting_lists(n, &self.dof, &mut self.dof_start, &mut self.dofs);
        counting_lists(n, &self.row, &mut self.row_start, &mut self.rows);
        self.scale.clear();
        for i in 0..n {
            let inertia: f64 =
                self.dofs[self.dof_start[i]..self.dof_start[i + 1]].iter().map(|&k| m.diag(k)).sum();
            self.scale.push(1.0 / inertia);
        }
        for v in [
            &mut self.cost,
            &mut self.improvement,
            &mut self.gradient,
            &mut self.alpha,
            &mut self.g0,
            &mut self.dmd,
        ] {
            v.clear();
            v.resize(n, 0.0);
        }
        self.improvement.fill(f64::INFINITY);
        self.iterations.clear();
        self.iterations.resize(n, 0);
        self.active.clear();
        self.active.resize(n, true);
        self.converged.clear();
        self.converged.resize(n, false);
        self.factored.clear();
        self.factored.resize(n, false);
        self.fresh.clear();
        self.fresh.resize(n, false);
        self.factor_state.clear();
        self.factor_state.resize(nefc, EfcState::Satisfied);
    }
}

/// Island lists from each item's island (`NONE`: in none): items of island i in
/// `items[start[i]..start[i + 1]]`, ascending.
fn counting_lists(n: usize, of: &[usize], start: &mut Vec<usize>, items: &mut Vec<usize>) {
    start.clear();
    start.resize(n + 1, 0);
    for &i in of {
        if i != NONE {
            start[i + 1] += 1;
        }
    }
    for i in 0..n {
        start[i + 1] += start[i];
    }
    items.clear();
    items.resize(start[n], 0);
    // start[i] is island i's next free slot while filling, then shifted back.
    for (k, &i) in of.iter().enumerate() {
        if i != NONE {
            items[start[i]] = k;
            start[i] += 1;
        }
    }
    for i in (1..=n).rev() {
        start[i] = start[i - 1];
    }
    start[0] = 0;
}

/// The problem of one solve, read-only.
pub(super) struct Problem<'a> {
    pub model: &'a Model,
    pub rows: &'a Rows<'a>,
    pub nz: &'a Sparsity<'a>,
    /// M (its nonzeros, `tree_mass.rs`), `qacc_smooth`, `qfrc_smooth`.
    pub m: &'a TreeMass,
    pub a0: &'a DVector<f64>,
    pub f0: &'a DVector<f64>,
    pub settings: Settings,
}

/// What the solve ended with: the most iterations of an island, the largest last scaled
/// improvement and gradient of an island, and whether every island converged.
pub(super) struct Outcome {
    pub iterations: u32,
    pub improvement: f64,
    pub gradient: f64,
    pub converged: bool,
}

/// Newton's method island by island (see the module doc) from `qacc` (with `soft.ma` = M qacc,
/// `soft.jar` = J qacc − aref, and `force`, `state` at it); leaves the solution in `qacc` and
/// the forces and states at it. Each iteration's work is that of the islands still iterating:
/// their dofs, rows and factor rows (the other islands' values stay as their last iteration
/// left them, and nothing reads them).
pub(super) fn newton(
    p: &Problem,
    soft: &mut SoftWork,
    mass_factor: &nalgebra::DMatrix<f64>,
    qacc: &mut DVector<f64>,
    force: &mut DVector<f64>,
    state: &mut [EfcState],
) -> Outcome {
    let (model, rows, nz, s) = (p.model, p.rows, p.nz, p.settings);
    let (nv, nefc) = (model.nv, rows.nefc);
    let isl = &mut soft.islands;
    isl.discover(nv, &model.dof_parent, nefc, nz, p.m);
    let n = isl.n;
    // Trees without rows: the unconstrained acceleration (M a = qfrc_smooth there).
    for k in 0..nv {
        if isl.dof[k] == NONE {
            qacc[k] = p.a0[k];
            soft.ma[k] = p.f0[k];
        }
    }
    // Island i's cost (Gauss term over its dofs, then its rows' terms, each in ascending order)
    // at the current point, with its rows' forces and states.
    let island_cost = |isl: &Islands,
                       i: usize,
                       qacc: &DVector<f64>,
                       ma: &DVector<f64>,
                       jar: &DVector<f64>,
                       force: &mut DVector<f64>,
                       state: &mut [EfcState]|
     -> f64 {
        let mut c = 0.0;
        let (x, a0, ma, f0) = (qacc.as_slice(), p.a0.as_slice(), ma.as_slice(), p.f0.as_slice());
        for &k in isl.dofs_of(i) {
            c += 0.5 * (x[k] - a0[k]) * (ma[k] - f0[k]);
        }
        rows.update_rows(jar, force, state, isl.rows_of(i), |_, t| c += t);
        c
    };
    let mut cost = std::mem::take(&mut isl.cost);
    for (i, c) in cost.iter_mut().enumerate().take(n) {
        *c = island_cost(isl, i, qacc, &soft.ma, &soft.jar, force, state);
    }
    let mut iterations = 0;
    let mut analyzed = false;
    loop {
        // g = M a − qfrc_smooth − Jᵀ f on each iterating island, and its scaled norm.
        let grad = soft.grad.as_mut_slice();
        let (ma, f0, forces) = (soft.ma.as_slice(), p.f0.as_slice(), force.as_slice());
        let mut any = false;
        for i in 0..n {
            if !isl.active[i] {
                continue;
            }
            let dofs = isl.dofs_of(i);
            for &k in dofs {
                grad[k] = ma[k] - f0[k];
            }
            for &r in isl.rows_of(i) {
                let f = forces[r];
                if f != 0.0 {
                    let (cols, vals) = nz.row_values(r);
                    for (&k, &j_rk) in cols.iter().zip(vals) {
                        grad[k] -= j_rk * f;
                    }
                }
            }
            let g2: f64 = dofs.iter().map(|&k| grad[k] * grad[k]).sum();
            isl.gradient[i] = isl.scale[i] * g2.sqrt();
            if isl.gradient[i] < s.tolerance || isl.improvement[i] < s.tolerance {
                isl.active[i] = false;
                isl.converged[i] = true;
            } else if isl.iterations[i] >= s.iterations {
                isl.active[i] = false;
            } else {
                isl.iterations[i] += 1;
                iterations = iterations.max(isl.iterations[i]);
                any = true;
            }
        }
        if !any {
            break;
        }
        // Each iterating island's factor brought to its rows' current states: rank-one
        // updates for the rows that entered or left the quadratic state since it was formed
        // (MuJoCo's `HessianIncremental`), or a new one — the first iteration, a cone's block
        // (not a rank-one term), a failed downdate.
        isl.active_dofs.clear();
        isl.fresh_dofs.clear();
        for i in 0..n {
            isl.fresh[i] = false;
            if !isl.active[i] {
                continue;
            }
            let (d0, d1) = (isl.dof_start[i], isl.dof_start[i + 1]);
            isl.active_dofs.extend_from_slice(&isl.dofs[d0..d1]);
            if isl.factored[i] {
                // Rows that changed, batched while they share their columns (a contact's rows:
                // one walk of the factor for them all, `rank_update`), applied in row order.
                let mut batch = ([0usize; RANK], 0);
                let update = |factor: &mut SparseCholesky, batch: &[usize]| {
                    let (mut vals, mut scale, mut add) = ([&[][..]; RANK], [0.0; RANK], [false; RANK]);
                    for (v, &r) in batch.iter().enumerate() {
                        vals[v] = nz.row_values(r).1;
                        scale[v] = rows.d[r].sqrt();
                        add[v] = state[r] == EfcState::Quadratic;
                    }
                    let k = batch.len();
                    factor.rank_update(nz.columns(batch[0]), &vals[..k], &scale[..k], &add[..k])
                };
                let mut ok = true;
                for &r in &isl.rows[isl.row_start[i]..isl.row_start[i + 1]] {
                    let change = term_change(isl.factor_state[r], state[r]);
                    if change == TermChange::Block {
                        ok = false;
                        break;
                    }
                    if change != TermChange::Same {
                        isl.factor_state[r] = state[r];
                        let (b, len) = &mut batch;
                        if *len == RANK || (*len > 0 && nz.columns(b[0]) != nz.columns(r)) {
                            ok = update(&mut soft.factor, &b[..*len]);
                            *len = 0;
                            if !ok {
                                break;
                            }
                        }
                        b[*len] = r;
                        *len += 1;
                    }
                }
                if ok && batch.1 > 0 {
                    ok = update(&mut soft.factor, &batch.0[..batch.1]);
                }
                if !ok {
                    isl.factored[i] = false;
                }
            }
            if !isl.factored[i] {
                isl.fresh[i] = true;
                isl.fresh_dofs.extend_from_slice(&isl.dofs[d0..d1]);
            }
        }
        if !analyzed {
            soft.active_rows.clear();
            for i in 0..nefc {
                let same_contact = i > 0
                    && rows.kind[i].is_contact()
                    && rows.kind[i] == rows.kind[i - 1]
                    && rows.id[i] == rows.id[i - 1];
                match soft.active_rows.last_mut() {
                    Some(g) if same_contact => g.1 = i,
                    _ => soft.active_rows.push((i, i)),
                }
            }
            soft.factor.analyze(nv, &model.dof_parent, &soft.active_rows, nz.start, nz.index);
            analyzed = true;
        }
        // A new factor: H = M + Jᵀ (∂²s) J on those islands' dofs, factored.
        let mut factored = true;
        if !isl.fresh_dofs.is_empty() {
            soft.factor.set_rows_to_m(&isl.fresh_dofs, p.m, &model.dof_parent);
            {
                let mut rows_h =
                    Assembler::new(Target::Sparse(soft.factor.h_mut()), nz, &mut soft.hessian_column);
                let (row_island, fresh) = (&isl.row, &isl.fresh);
                rows.hessian(&soft.jar, state, |i, dim, block| {
                    if row_island[i] != NONE && fresh[row_island[i]] {
                        rows_h.add(i, dim, block);
                    }
                });
                rows_h.finish();
            }
            factored = soft.factor.factor_rows(&isl.fresh_dofs, &isl.dof);
            for i in 0..n {
                if isl.fresh[i] {
                    isl.factored[i] = factored;
                    for &r in &isl.rows[isl.row_start[i]..isl.row_start[i + 1]] {
                        isl.factor_state[r] = state[r];
                    }
                }
            }
        }
        let dir = soft.dir.as_mut_slice();
        let grad = soft.grad.as_slice();
        for &k in &isl.active_dofs {
            dir[k] = grad[k];
        }
        if factored {
            soft.factor.solve_rows(dir, &isl.active_dofs);
        } else {
            // (M⁻¹ is block diagonal by tree: the other trees' entries are not read.)
            solve_with_factor_unchecked(model, mass_factor, dir);
        }
        for &k in &isl.active_dofs {
            dir[k] = -dir[k];
        }
        // J d and M d on the iterating islands' rows and dofs.
        let (jv, mdir) = (soft.jv.as_mut_slice(), soft.mdir.as_mut_slice());
        for i in (0..n).filter(|&i| isl.active[i]) {
            for &r in isl.rows_of(i) {
                let (cols, vals) = nz.row_values(r);
                jv[r] = cols.iter().zip(vals).map(|(&k, &j_rk)| j_rk * dir[k]).sum();
            }
        }
        p.m.mul_on(&model.dof_parent, isl.active_dofs.iter().copied(), dir, mdir);
        // One exact line search per iterating island, over its dofs and rows.
        for i in 0..n {
            isl.alpha[i] = 0.0;
            if !isl.active[i] {
                continue;
            }
            let (mut g0, mut dmd) = (0.0, 0.0);
            {
                let (ma, f0, dir, mdir) =
                    (soft.ma.as_slice(), p.f0.as_slice(), soft.dir.as_slice(), soft.mdir.as_slice());
                for &k in isl.dofs_of(i) {
                    g0 += (ma[k] - f0[k]) * dir[k];
                    dmd += dir[k] * mdir[k];
                }
            }
            let list = &isl.rows[isl.row_start[i]..isl.row_start[i + 1]];
            let (jar, jv, trial) = (&soft.jar, &soft.jv, &mut soft.jar_trial);
            let alpha = line_search_with(
                |alpha| {
                    {
                        let (t, jar, jv) = (trial.as_mut_slice(), jar.as_slice(), jv.as_slice());
                        for &r in list {
                            t[r] = jar[r] + alpha * jv[r];
                        }
                    }
                    let (d1, d2) = rows.directional_rows(trial, jv, list);
                    (g0 + alpha * dmd + d1, dmd + d2)
                },
                s,
            );
            if alpha == 0.0 {
                // No descent along the direction (the island's minimum to round-off).
                isl.active[i] = false;
                isl.converged[i] = true;
                continue;
            }
            isl.alpha[i] = alpha;
            // The move, and the island's new cost.
            {
                let (x, ma) = (qacc.as_mut_slice(), soft.ma.as_mut_slice());
                let (dir, mdir) = (soft.dir.as_slice(), soft.mdir.as_slice());
                for &k in isl.dofs_of(i) {
                    x[k] += alpha * dir[k];
                    ma[k] += alpha * mdir[k];
                }
                let (jar, jv) = (soft.jar.as_mut_slice(), soft.jv.as_slice());
                for &r in list {
                    jar[r] += alpha * jv[r];
                }
            }
            let new_cost = island_cost(isl, i, qacc, &soft.ma, &soft.jar, force, state);
            isl.improvement[i] = isl.scale[i] * (cost[i] - new_cost);
            cost[i] = new_cost;
        }
    }
    let outcome = Outcome {
        iterations,
        improvement: (0..n).map(|i| isl.improvement[i]).filter(|x| x.is_finite()).fold(0.0, f64::max),
        gradient: (0..n).map(|i| isl.gradient[i]).fold(0.0, f64::max),
        converged: isl.converged[..n].iter().all(|&c| c),
    };
    isl.cost = cost;
    outcome
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn islands_join_trees_through_rows() {
        // Trees {0, 1}, {2, 3}, {4}, {5}: row 0 couples 1 and 3, row 1 has no column, row 2
        // touches 5 only; dof 4 is in no island.
        let nv = 6;
        let dof_parent = [NO_DOF, 0, NO_DOF, 2, NO_DOF, NO_DOF];
        let (start, index, value) = ([0, 2, 2, 3], [1, 3, 5], [1.0, -1.0, 2.0]);
        let nz = Sparsity { start: &start, index: &index, value: &value };
        let dense = nalgebra::DMatrix::from_diagonal(&DVector::from_vec(vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0]));
        let mut m = TreeMass::new(&dof_parent);
        m.gather(&dense, &dof_parent);
        let mut isl = Islands::with_capacity(nv, 3);
        isl.discover(nv, &dof_parent, 3, &nz, &m);
        assert_eq!(isl.n, 2);
        assert_eq!(isl.dof, [0, 0, 0, 0, NONE, 1]);
        assert_eq!(isl.row, [0, NONE, 1]);
        assert_eq!(&isl.dofs[isl.dof_start[0]..isl.dof_start[1]], &[0, 1, 2, 3]);
        assert_eq!(&isl.rows[isl.row_start[1]..isl.row_start[2]], &[2]);
        // MuJoCo's island scale: 1 / Σ M_kk over the island's dofs.
        assert_eq!(isl.scale, [0.1, 1.0 / 6.0]);
    }
}
