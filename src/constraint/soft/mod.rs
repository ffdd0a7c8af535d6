//! The soft, MuJoCo-compatible constraint mode (docs/architecture.md, "Layers"; MuJoCo documentation,
//! "Computation → Constraint model", "Soft constraints" and "Solver", for MuJoCo 4.0): every row
//! is a spring–damper-like soft constraint whose reference acceleration aref and regularizer R
//! come from the element's `solref` and `solimp` ([`impedance`]), and the constrained
//! acceleration minimizes a convex cost ([`cost`]) by Newton, CG ([`primal`]) or projected
//! Gauss–Seidel on the dual ([`pgs`]), as `<option solver>` says.
//!
//! The rows ([`rows`]) follow MuJoCo's activation rules (margins, both limit sides, pyramidal or
//! elliptic cones) and are written into the same `efc_*` buffers as the exact mode's, with
//! MuJoCo's buffer names for the soft quantities (`efc_R`, `efc_D`, `efc_aref`, `efc_KBIP`,
//! `efc_diagA`, `efc_state` as `efc_r`, `efc_d`, `efc_aref`, `efc_kbip`, `efc_diag_a`,
//! `efc_state`). Nothing is projected after a step: drift is what the soft model allows.

mod contact_columns;
pub mod cost;
mod hessian;
pub mod impedance;
mod island;
mod jacobian;
pub mod noslip;
pub mod pgs;
pub mod primal;
pub mod rows;
mod sparse_cholesky;
mod tree_mass;
pub mod weights;
mod work;

pub(crate) use primal::solve_primal;
pub use primal::{Primal, Settings};
pub(crate) use rows::{soft_active, soft_positions, soft_velocities};
pub use weights::InverseWeights;
pub(crate) use work::SoftWork;

use crate::model::options::Solver;
use crate::model::{Data, Model};

/// The solver settings of `model`'s `<option>`.
pub fn settings(model: &Model, weights: &InverseWeights) -> Settings {
    let o = &model.options;
    Settings {
        iterations: o.iterations,
        tolerance: o.tolerance,
        ls_iterations: o.ls_iterations,
        ls_tolerance: o.ls_tolerance,
        warmstart: o.flags.warmstart,
        scale: 1.0 / (weights.meaninertia * (model.nv.max(1) as f64)),
    }
}

/// The soft solve of the rows in `data` (from `soft_positions` and `soft_velocities`):
/// impedance, regularizer and reference acceleration, then the model's solver. Writes `qacc`,
/// `efc_force`, `qfrc_constraint` and the solver statistics; keeps `qacc` as the next warm start.
pub(crate) fn solve_soft(model: &Model, weights: &InverseWeights, data: &mut Data) {
    impedance::make_impedance(model, weights, data);
    let s = settings(model, weights);
    match model.options.solver {
        Solver::Newton => solve_primal(model, data, Primal::Newton, s),
        Solver::Cg => solve_primal(model, data, Primal::Cg, s),
        Solver::Pgs => pgs::solve_pgs(model, data, s),
    }
    if model.options.noslip_iterations > 0 {
        noslip::solve_noslip(model, data, s.scale);
    }
    data.qacc_warmstart.copy_from(&data.qacc);
}
