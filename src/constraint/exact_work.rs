//! The exact (rigid) solver's workspace: the Delassus matrix J M⁻¹ Jᵀ of the rows, its factor
//! or eigenvectors, the active set of the unilateral solve, the Gauss–Seidel scratch of the
//! Coulomb solve and its warm start (`docs/architecture.md`, "Constraint solvers"). It lives in
//! [`Data`](crate::Data), private to the solver: the outputs users read (`efc_force`, `efc_rank`,
//! `efc_converged`, …) are `Data`'s own fields.

use crate::model::EfcType;
use nalgebra::{DMatrix, DVector};

/// Buffers of [`solve_exact`](super::solve_exact), the Coulomb solve and the velocity projection,
/// sized for the row capacity of [`Data`](crate::Data) (grown with it by `Data::reserve_rows`).
#[derive(Clone, Debug)]
pub(crate) struct ExactWork {
    /// The Delassus matrix J M⁻¹ Jᵀ, nefc × nefc, and its factor or eigenvectors.
    pub delassus: DMatrix<f64>,
    pub factor: DMatrix<f64>,
    /// Right-hand side and eigenvalue scratch of the dense solve, length nefc.
    pub rhs: DVector<f64>,
    pub eig: DVector<f64>,
    /// The unilateral solve's active set, its Delassus block and right-hand side.
    pub active: Vec<usize>,
    /// Per row, whether it is in `active` (the Coulomb solve's polish).
    pub in_active: Vec<bool>,
    pub sub: DMatrix<f64>,
    pub sub_rhs: DVector<f64>,
    /// Rows whose Delassus diagonal A_ii is at most this are round-off (their force would move
    /// nothing: J_i M⁻¹ J_iᵀ ≈ 0) and get no force: 1e-12 of the largest diagonal, set by the
    /// frictional solve.
    pub a_floor: f64,
    /// Warm start of the iterative solve: the forces of the previous acceleration-level solve and
    /// the (type, id) of each of its rows; reused when the rows are the same.
    pub warm: DVector<f64>,
    pub warm_rows: Vec<(EfcType, usize)>,
    /// Whether the last acceleration-level Coulomb solve ended with an exact solve of its active
    /// set (a polish that held): the next solve of the same rows tries that set first.
    pub warm_exact: bool,
    /// The factorization work (multiply-adds) of that polish, and what the sweeps of the last
    /// warm-started solve that swept cost (sweeps × (n² + n·nv) and their polishes; 0 after a
    /// cold start): the polish is tried first while it is the cheaper.
    pub warm_polish_work: f64,
    pub warm_sweep_work: f64,
    /// λ at the start of a Gauss–Seidel sweep.
    pub lambda_prev: DVector<f64>,
    /// The iterate whose sweep changed the motion least so far: what an unconverged solve
    /// returns (a pile's sweeps can swing far from it before the iteration limit).
    pub best: DVector<f64>,
    /// Per row, during the velocity projection: a limit or contact row that carried a compressive
    /// force in the last acceleration-level solve. Its velocity is held at 0 (the row stays
    /// closed) rather than allowed to grow: a small separating J v left by the integrator's error
    /// is drift, not a lift-off.
    pub pressing: Vec<bool>,
    /// Per row, the Coulomb solve's polish: a contact (at its normal row) whose friction is on
    /// its cone, slipping or starting to.
    pub slipping: Vec<bool>,
    /// Per friction row of a slipping contact, during the polish: its force per unit of the
    /// cone's radius, −μ_k² u_k / ‖μ ∘ u‖ (u the slip), the direction the polish substitutes.
    pub slip_dir: DVector<f64>,
    /// Per contact (at its normal row), the shift ν of its last cone solve's secular equation
    /// (the Newton start of the next sweep's).
    pub nu: DVector<f64>,
    /// The polish's Newton unknowns (its active rows, then the friction rows of its slipping
    /// contacts), per unknown the normal row of its contact (`usize::MAX` for an active row), and
    /// per row its place among the unknowns (`usize::MAX` when fixed).
    pub newton_rows: Vec<usize>,
    pub newton_normal: Vec<usize>,
    pub newton_pos: Vec<usize>,
    /// The polish's LU solves, block by block over the constraint islands.
    pub lu: super::block_lu::BlockLu,
    /// The ADMM solve's per-row buffers ([`super::admm`]).
    pub admm: super::admm::AdmmWork,
    /// Jᵀ, nv × nefc (columns 0..nefc used): each row of J contiguous (J_i · x, Jᵀ λ).
    pub jt: DMatrix<f64>,
    /// L⁻ᵀJᵀ of the block of rows whose Delassus products are being formed (`super::exact`,
    /// `gram_block`): per dof of the block's trees, its entries over the block's rows contiguous
    /// (at most nv · nefc entries).
    pub ljt: Vec<f64>,
    /// Per dof of that block, the block's rows [first, last + 1) outside which its row of
    /// L⁻ᵀJᵀ is zero.
    pub dof_rows: Vec<(usize, usize)>,
    /// The rows in order of the first dof of their span (the Delassus pattern's pairing when
    /// some row touches more than two trees), or 0..nefc (that case's single block of rows).
    pub order: Vec<usize>,
    /// Per row, the dofs [lo, hi) of the kinematic trees it touches (`dynamics::tree_span`):
    /// M⁻¹ J_iᵀ is zero outside them, and A_ij = 0 when two rows' spans are disjoint.
    pub spans: Vec<(usize, usize)>,
    /// Per row, the dofs [first, last + 1) from its first nonzero of J to its last (empty for a
    /// zero row): J_i is zero outside them.
    pub support: Vec<(usize, usize)>,
    /// The nonzero pattern of the Delassus matrix (`super::delassus_pattern`), column by column
    /// in compressed form: column j's rows that may be nonzero (their spans meet j's) are
    /// `pattern_rows[pattern_ptr[j]..pattern_ptr[j + 1]]`, ascending. Valid for `pattern_n` rows
    /// (0 when none was built: the columns are then read whole); `pattern_full` when every pair
    /// meets (one robot), where the columns are read whole too.
    pub pattern_ptr: Vec<usize>,
    pub pattern_rows: Vec<usize>,
    pub pattern_n: usize,
    pub pattern_full: bool,
    /// Per row, the dof ranges of the (at most two) kinematic trees its J row touches (the second
    /// empty when it touches one), when every row touches at most two (`delassus_by_trees`).
    pub trees: Vec<[(usize, usize); 2]>,
    /// Whether `trees` holds the current rows' trees (false when some row touches more than two:
    /// their spans are read instead).
    pub trees_valid: bool,
    /// The rows touching each tree, in compressed form keyed by the tree's first dof: tree
    /// rooted at dof t has rows `tree_rows[tree_ptr[t]..tree_ptr[t + 1]]`, ascending (nv + 1
    /// offsets; at most two entries per row).
    pub tree_ptr: Vec<usize>,
    pub tree_rows: Vec<usize>,
    /// Per row, during a velocity-level Coulomb solve: its force in the last acceleration-level
    /// solve (`Data::efc_previous_force`, looked up once per solve rather than per sweep).
    pub previous: DVector<f64>,
    /// The active set (a hash of its free rows and slipping contacts) of the last polish tried in
    /// the current Coulomb solve: a retry on the same set is skipped.
    pub polish_set: u64,
    /// The multiply-adds of the current Coulomb solve's polishes so far (their factorizations):
    /// a retry is allowed while they stay below the sweeps'.
    pub polish_work: f64,
    /// The Gauss–Seidel sweep's motion change M⁻¹Jᵀ Δλ (entries 0..nv) and correction M⁻¹Jᵀ λ
    /// (nv..2nv).
    pub motion: DVector<f64>,
    /// M⁻¹Jᵀ μ of a solve's multipliers μ, nv (`super::exact`, `add_minv_jt_mu`).
    pub minv_jt_mu: DVector<f64>,
    /// M⁻¹Jᵀ, nv × nefc (column i over row i's trees, `tree_ranges`; not written elsewhere),
    /// formed only when the Gauss–Seidel sweeps' solves with M would cost more
    /// (`super::exact::form_minv_jt`), and whether it holds the current rows'.
    pub minv_jt: DMatrix<f64>,
    pub minv_jt_ready: bool,
    /// Estimated work (instructions) of forming `minv_jt` for the current rows, and of one
    /// solve with M's factor: a sweep's motion costs two such solves, or two passes over
    /// `minv_jt` once formed.
    pub minv_jt_work: f64,
    pub solve_work: f64,
}

impl ExactWork {
    /// The dofs of row i's kinematic trees, as two ranges (the second may be empty), or its
    /// span when the trees are not known: M⁻¹J_iᵀ is zero outside them.
    pub fn tree_ranges(&self, i: usize) -> [(usize, usize); 2] {
        if self.trees_valid {
            self.trees[i]
        } else {
            [self.spans[i], (0, 0)]
        }
    }

    /// The dofs of row i's nonzeros, as two ranges (the second may be empty): its trees
    /// (`trees`) cut to its first and last nonzero (`support`), or that support alone when the
    /// trees are not known. J_i is zero outside them. Needs the Delassus products
    /// (`super::exact`) at the current rows.
    pub fn row_ranges(&self, i: usize) -> [(usize, usize); 2] {
        let (first, end) = self.support[i];
        if !self.trees_valid {
            return [(first, end), (0, 0)];
        }
        self.trees[i].map(|(lo, hi)| {
            let (lo, hi) = (lo.max(first), hi.min(end));
            if lo < hi {
                (lo, hi)
            } else {
                (0, 0)
            }
        })
    }
}

impl ExactWork {
    /// The workspace for `nefc` rows of a model with `nv` dofs.
    pub fn new(nv: usize, nefc: usize) -> Self {
        Self {
            delassus: DMatrix::zeros(nefc, nefc),
            factor: DMatrix::zeros(nefc, nefc),
            rhs: DVector::zeros(nefc),
            eig: DVector::zeros(nefc),
            active: Vec::with_capacity(nefc),
            in_active: vec![false; nefc],
            sub: DMatrix::zeros(nefc, nefc),
            sub_rhs: DVector::zeros(nefc),
            a_floor: 0.0,
            warm: DVector::zeros(nefc),
            warm_rows: Vec::with_capacity(nefc),
            warm_exact: false,
            warm_polish_work: 0.0,
            warm_sweep_work: 0.0,
            lambda_prev: DVector::zeros(nefc),
            best: DVector::zeros(nefc),
            pressing: vec![false; nefc],
            slipping: vec![false; nefc],
            slip_dir: DVector::zeros(nefc),
            nu: DVector::zeros(nefc),
            newton_rows: Vec::with_capacity(nefc),
            newton_normal: Vec::with_capacity(nefc),
            newton_pos: vec![usize::MAX; nefc],
            lu: Default::default(),
            admm: Default::default(),
            jt: DMatrix::zeros(nv, nefc),
            ljt: vec![0.0; nv * nefc],
            dof_rows: vec![(0, 0); nv],
            order: vec![0; nefc],
            spans: vec![(0, 0); nefc],
            support: vec![(0, 0); nefc],
            pattern_ptr: Vec::with_capacity(nefc + 1),
            pattern_rows: Vec::with_capacity(nefc * nefc),
            pattern_n: 0,
            pattern_full: false,
            trees: vec![[(0, 0); 2]; nefc],
            trees_valid: false,
            tree_ptr: vec![0; nv + 1],
            tree_rows: vec![0; 2 * nefc],
            previous: DVector::zeros(nefc),
            polish_set: 0,
            polish_work: 0.0,
            motion: DVector::zeros(2 * nv),
            minv_jt_mu: DVector::zeros(nv),
            minv_jt: DMatrix::zeros(nv, nefc),
            minv_jt_ready: false,
            minv_jt_work: 0.0,
            solve_work: 0.0,
        }
    }

    /// The dense matrices (Jᵀ, L⁻ᵀJᵀ and M⁻¹Jᵀ, the Delassus matrix and its factors, the block LU's scratch)
    /// for `nefc` rows, if smaller, and the Delassus pattern's room: only the exact mode needs them
    /// (nefc² numbers each).
    pub fn grow_matrices(&mut self, nv: usize, nefc: usize) {
        if self.motion.len() != 2 * nv {
            self.motion = DVector::zeros(2 * nv);
            self.minv_jt_mu = DVector::zeros(nv);
        }
        if self.dof_rows.len() != nv {
            self.dof_rows = vec![(0, 0); nv];
            self.tree_ptr = vec![0; nv + 1];
        }
        if self.delassus.nrows() >= nefc && self.jt.nrows() == nv {
            return;
        }
        self.jt = DMatrix::zeros(nv, nefc);
        self.minv_jt = DMatrix::zeros(nv, nefc);
        self.minv_jt_ready = false;
        self.ljt = vec![0.0; nv * nefc];
        self.order = vec![0; nefc];
        self.tree_rows = vec![0; 2 * nefc];
        // The pattern's room for every pair, so that it never grows inside a step (its size is
        // the rows' meeting pairs: at most the Delassus matrix's entries).
        self.pattern_ptr = Vec::with_capacity(nefc + 1);
        self.pattern_rows = Vec::with_capacity(nefc * nefc);
        self.pattern_n = 0;
        for m in [&mut self.delassus, &mut self.factor, &mut self.sub] {
            *m = DMatrix::zeros(nefc, nefc);
        }
        self.lu.grow(nefc);
    }

    /// The per-row vectors for `nefc` rows.
    pub fn grow_vectors(&mut self, nefc: usize) {
        for v in [
            &mut self.rhs,
            &mut self.eig,
            &mut self.sub_rhs,
            &mut self.lambda_prev,
            &mut self.best,
            &mut self.previous,
            &mut self.slip_dir,
            &mut self.nu,
        ] {
            *v = DVector::zeros(nefc);
        }
        self.warm.resize_vertically_mut(nefc, 0.0);
        self.pressing.resize(nefc, false);
        self.slipping.resize(nefc, false);
        self.newton_pos.resize(nefc, usize::MAX);
        self.newton_rows.reserve(nefc.saturating_sub(self.newton_rows.len()));
        self.newton_normal.reserve(nefc.saturating_sub(self.newton_normal.len()));
        self.in_active.resize(nefc, false);
        self.spans.resize(nefc, (0, 0));
        self.support.resize(nefc, (0, 0));
        self.trees.resize(nefc, [(0, 0); 2]);
        self.admm.grow(nefc);
        self.active.reserve(nefc.saturating_sub(self.active.len()));
        self.warm_rows.reserve(nefc.saturating_sub(self.warm_rows.len()));
    }
}

#[cfg(test)]
mod tests {
    use super::ExactWork;

    /// The per-row vectors every mode grows carry no nefc² buffer: a soft scene's rows never pay
    /// for the exact mode's dense matrices (the block LU's scratch included); those grow with
    /// `grow_matrices` only.
    #[test]
    fn per_row_vectors_allocate_no_matrix() {
        let mut work = ExactWork::new(12, 0);
        work.grow_vectors(2000);
        assert_eq!(work.rhs.len(), 2000);
        assert_eq!(work.delassus.len(), 0);
        assert_eq!(work.lu.capacity(), 0);
        work.grow_matrices(12, 300);
        assert_eq!(work.delassus.nrows(), 300);
        assert!(work.lu.capacity() >= 300);
    }
}
