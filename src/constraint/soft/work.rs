//! The soft solvers' workspace (Newton, CG and PGS of [`super`]): the cost's per-row and
//! per-dof scratch, the Hessian and its Cholesky factor, and the dual matrix of PGS. It lives in
//! [`Data`](crate::Data), private to the solvers; their outputs (`efc_force`, `efc_state`,
//! `qacc`, `solver_niter`, …) are `Data`'s own fields.

use crate::model::{EfcState, Model};
use nalgebra::{DMatrix, DVector};

/// Scratch of the soft solvers (`crate::constraint::soft`).
#[derive(Clone, Debug)]
pub(crate) struct SoftWork {
    /// J a − aref per row, and J d along a search direction d.
    pub jar: DVector<f64>,
    pub jv: DVector<f64>,
    /// J a − aref at a trial point of the line search.
    pub jar_trial: DVector<f64>,
    /// The cost's gradient, its preconditioned form, the search direction, M a, M d, and the
    /// previous gradient and direction (CG) — length nv.
    pub grad: DVector<f64>,
    pub mgrad: DVector<f64>,
    pub dir: DVector<f64>,
    pub ma: DVector<f64>,
    pub mdir: DVector<f64>,
    pub grad_prev: DVector<f64>,
    pub mgrad_prev: DVector<f64>,
    /// The dense path's Hessian M + Jᵀ D J (+ cone blocks), nv × nv (empty on the islands' path,
    /// whose Hessian lives on its factor's pattern), and the islands' sparse Cholesky factor.
    pub hessian: DMatrix<f64>,
    pub factor: super::sparse_cholesky::SparseCholesky,
    /// Whether the model's Newton solves take the dense path (`primal::dense_newton`).
    pub dense: bool,
    /// The dense Cholesky factor of the dense path's Hessians (nv × nv; empty on the islands'
    /// path).
    pub dense_factor: DMatrix<f64>,
    /// The row states `dense_factor` was formed for (the Newton iterations after the first
    /// update it row by row as states change; `primal.rs`), and the scaled row of one update (nv).
    pub factor_state: Vec<EfcState>,
    pub rank_one: Vec<f64>,
    /// The row groups (first, last) that can have a Hessian block (each row, a contact's rows
    /// together): the cliques of the Newton Hessian's pattern.
    pub active_rows: Vec<(usize, usize)>,
    /// The nonzero columns of each row of J: row i's are `nz_index[nz_start[i]..nz_start[i + 1]]`.
    pub nz_start: Vec<usize>,
    pub nz_index: Vec<usize>,
    /// J's values at those entries, in the same order.
    pub nz_value: Vec<f64>,
    /// Whether `nz_start`/`nz_index`/`nz_value` list J's nonzeros as the soft position stage
    /// wrote them (rows 0..nz_start.len() − 1; every row after them zero): true from the start
    /// (`efc_j` is allocated zero, the record empty: the first position stage clears nothing),
    /// false whenever another writer (the exact rows) wrote `efc_j` since.
    pub j_recorded: bool,
    /// The nonzero columns of one contact's rows while they are recorded (nv).
    pub columns: Vec<usize>,
    /// Their values in the contact's frame rows (`contact::contact_jacobian_columns`; nv).
    pub column_values: Vec<[f64; 6]>,
    /// Their values in a pyramidal contact's edge rows (nv).
    pub edge_values: Vec<[f64; 10]>,
    /// A condim-3 pyramidal contact's four edges per column (`rows.rs`, `pyramidal3`).
    pub edge4: Vec<[f64; 4]>,
    /// Each dof's world axes at its body's origin, shared by the contacts of a position stage.
    pub dof_axes: super::contact_columns::DofAxes,
    /// The contacts' rows as recorded, (first row, rows): each contact's rows share their columns.
    pub contact_blocks: Vec<(usize, usize)>,
    /// A vector's entries on one block's columns (nv; the velocity stage's J v).
    pub gathered: Vec<f64>,
    /// (row, column) of J's nonzeros in column order, while `nz_start`/`nz_index` are built.
    pub nz_scratch: Vec<(usize, usize)>,
    /// Scratch of a row group's Hessian term while H is assembled (`hessian::scratch_len`).
    pub hessian_column: Vec<f64>,
    /// M's nonzeros, compact, gathered once per solve on the islands' path (`tree_mass.rs`).
    pub tree_m: super::tree_mass::TreeMass,
    /// The constraint islands of the sparse Newton solve (`island.rs`).
    pub islands: super::island::Islands,
    /// The dual (PGS) matrix J M⁻¹ Jᵀ + R, its right-hand side, and M⁻¹ Jᵀ (nv × nefc).
    pub ar: DMatrix<f64>,
    pub minv_jt: DMatrix<f64>,
}

impl SoftWork {
    /// The workspace for `model` and `nefc` rows.
    pub fn new(model: &Model, nefc: usize) -> Self {
        let nv = model.nv;
        let dense = super::primal::dense_newton(model);
        Self {
            jar: DVector::zeros(nefc),
            jv: DVector::zeros(nefc),
            jar_trial: DVector::zeros(nefc),
            grad: DVector::zeros(nv),
            mgrad: DVector::zeros(nv),
            dir: DVector::zeros(nv),
            ma: DVector::zeros(nv),
            mdir: DVector::zeros(nv),
            grad_prev: DVector::zeros(nv),
            mgrad_prev: DVector::zeros(nv),
            hessian: if dense { DMatrix::zeros(nv, nv) } else { DMatrix::zeros(0, 0) },
            factor: super::sparse_cholesky::SparseCholesky::with_capacity(nv),
            dense,
            dense_factor: if dense { DMatrix::zeros(nv, nv) } else { DMatrix::zeros(0, 0) },
            factor_state: vec![EfcState::Satisfied; nefc],
            rank_one: vec![0.0; nv],
            active_rows: Vec::with_capacity(nefc),
            nz_start: {
                let mut start = Vec::with_capacity(nefc + 1);
                start.push(0);
                start
            },
            nz_index: Vec::with_capacity(nefc * nv),
            nz_value: Vec::with_capacity(nefc * nv),
            j_recorded: true,
            columns: Vec::with_capacity(nv),
            column_values: Vec::with_capacity(nv),
            edge_values: vec![[0.0; 10]; nv],
            edge4: vec![[0.0; 4]; nv],
            dof_axes: super::contact_columns::DofAxes::new(nv),
            contact_blocks: Vec::with_capacity(nefc),
            gathered: vec![0.0; nv],
            nz_scratch: Vec::new(),
            hessian_column: vec![0.0; super::hessian::scratch_len(nv)],
            tree_m: super::tree_mass::TreeMass::new(&model.dof_parent[..nv]),
            islands: super::island::Islands::with_capacity(nv, nefc),
            ar: DMatrix::zeros(0, 0),
            minv_jt: DMatrix::zeros(0, 0),
        }
    }
}
