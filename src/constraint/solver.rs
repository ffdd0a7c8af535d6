//! One interface to the two constraint solvers (`docs/architecture.md`, "Constraint solvers"):
//! the **exact** (rigid) solver — Lagrange multipliers of the KKT system, Signorini and Coulomb
//! by an active-set method or Gauss–Seidel, drift projected after each step — and the **soft**
//! (MuJoCo-compatible) solver — MuJoCo's convex model with its regularizer, reference
//! acceleration and Newton/CG/PGS, nothing projected. `forward` asks the model's
//! [`ConstraintSolver`] which rows exist and runs its stages; the steppers ask it to correct
//! drift. Each solver keeps its scratch in its own private workspace of `Data`
//! ([`ExactWork`](super::ExactWork), [`SoftWork`](super::soft::SoftWork)) and writes the same
//! named outputs (`efc_*`, `qfrc_constraint`, `qacc`).

use super::soft::{self, InverseWeights};
use super::{
    project_positions, project_velocities_unchecked, row_violation, solve_exact, ConstraintMode,
    ConstraintModel, SolverSettings,
};
use crate::integrate::State;
use crate::model::{Data, Model};

/// How the exact mode keeps a constrained state on its manifold (drift correction belongs to
/// the stepper, not to `forward`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DriftCorrection {
    /// After each step, project q onto φ(q) = 0 and v onto J v = 0.
    pub projection: bool,
    /// Tolerance on max |φ| of the position projection.
    pub tolerance: f64,
    /// Baumgarte gains [α, β] of J q̈ + J̇v + α J v + β φ = 0 in the acceleration solve
    /// (None: the pure KKT system).
    pub baumgarte: Option<[f64; 2]>,
}

impl Default for DriftCorrection {
    fn default() -> Self {
        Self { projection: true, tolerance: 1e-12, baumgarte: None }
    }
}

/// The exact solver's settings.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ExactSolver {
    /// The drift correction after each step.
    pub drift: DriftCorrection,
    /// Iteration limit and tolerance of the iterative solve of rows with dry friction.
    pub settings: SolverSettings,
}

/// The soft solver's fixed data: the inverse weights at `qpos0` its regularizer is built from
/// (None when the model has no constraint rows). Its settings are the model's `<option>`
/// (`solver`, `iterations`, `tolerance`, …).
#[derive(Clone, Debug, Default)]
pub struct SoftSolver {
    /// The inverse weights at `qpos0` (`None` without constraint rows).
    pub weights: Option<InverseWeights>,
}

/// The model's constraint solver (part of [`Plan`](crate::forward::Plan)).
#[derive(Clone, Debug)]
pub enum ConstraintSolver {
    /// Rigid constraints ([`ConstraintMode::Exact`](super::ConstraintMode::Exact)).
    Exact(ExactSolver),
    /// MuJoCo's soft model ([`ConstraintMode::Soft`](super::ConstraintMode::Soft)).
    Soft(SoftSolver),
}

impl Default for ConstraintSolver {
    fn default() -> Self {
        ConstraintSolver::Exact(ExactSolver::default())
    }
}

impl ConstraintSolver {
    /// The solver of `mode` for `model` with the rows `rows` (the soft mode's inverse weights are
    /// computed here, at `qpos0`, when there are rows).
    pub fn new(mode: ConstraintMode, model: &Model, rows: &ConstraintModel) -> Self {
        match mode {
            ConstraintMode::Exact => ConstraintSolver::Exact(ExactSolver::default()),
            ConstraintMode::Soft => ConstraintSolver::Soft(SoftSolver {
                weights: (!rows.is_empty()).then(|| InverseWeights::new(model)),
            }),
        }
    }

    /// Which mode this is.
    pub fn mode(&self) -> ConstraintMode {
        match self {
            ConstraintSolver::Exact(_) => ConstraintMode::Exact,
            ConstraintSolver::Soft(_) => ConstraintMode::Soft,
        }
    }

    /// The soft mode's inverse weights (None in exact mode, or without constraint rows).
    pub fn soft_weights(&self) -> Option<&InverseWeights> {
        match self {
            ConstraintSolver::Soft(s) => s.weights.as_ref(),
            ConstraintSolver::Exact(_) => None,
        }
    }

    /// The exact solver's settings (None in soft mode).
    pub fn exact(&self) -> Option<&ExactSolver> {
        match self {
            ConstraintSolver::Exact(e) => Some(e),
            ConstraintSolver::Soft(_) => None,
        }
    }

    /// The exact solver's settings, to change them (None in soft mode).
    pub fn exact_mut(&mut self) -> Option<&mut ExactSolver> {
        match self {
            ConstraintSolver::Exact(e) => Some(e),
            ConstraintSolver::Soft(_) => None,
        }
    }

    /// The collision pass and the rows' activity at `q`: whether a row exists, so that `forward`
    /// takes the M path (CRBA, the rows, the solve) instead of ABA. Soft: MuJoCo's margins and
    /// activation rules. Exact: an equality, a joint at a limit or a touching contact.
    pub(crate) fn rows_exist(
        &self,
        rows: &ConstraintModel,
        model: &Model,
        data: &mut Data,
        q: &[f64],
    ) -> bool {
        match self {
            ConstraintSolver::Soft(SoftSolver { weights: Some(_) }) => {
                soft::soft_active(rows, model, data, q)
            }
            _ => {
                let active = !rows.is_empty() && rows.any_active(data, q);
                rows.collide_unchecked(model, data, q) || active
            }
        }
    }

    /// The rows' Jacobians and residuals at `q` (the position stage; M factored).
    pub(crate) fn positions(&self, rows: &ConstraintModel, model: &Model, data: &mut Data, q: &[f64]) {
        match self {
            ConstraintSolver::Soft(SoftSolver { weights: Some(_) }) => {
                soft::soft_positions(rows, model, data, q, model.options.cone)
            }
            _ => rows.positions_unchecked(model, data, q, true),
        }
    }

    /// The rows' velocities J v (and J̇ v in exact mode) at (q, v) (the velocity stage).
    pub(crate) fn velocities(
        &self,
        rows: &ConstraintModel,
        model: &Model,
        data: &mut Data,
        q: &[f64],
        v: &[f64],
    ) {
        match self {
            ConstraintSolver::Soft(SoftSolver { weights: Some(_) }) => {
                soft::soft_velocities(rows, model, data, v)
            }
            _ => rows.velocities(model, data, q, v),
        }
    }

    /// The constraint stage: `efc_force`, `qfrc_constraint` and `qacc` from `qacc_smooth`.
    pub(crate) fn solve(&self, model: &Model, data: &mut Data) {
        match self {
            ConstraintSolver::Soft(SoftSolver { weights: Some(w) }) => soft::solve_soft(model, w, data),
            ConstraintSolver::Exact(e) => solve_exact(model, data, e.drift.baumgarte, e.settings),
            // A soft model without rows never takes the M path.
            ConstraintSolver::Soft(SoftSolver { weights: None }) => {}
        }
    }

    /// After a step `h`: in exact mode, q projected onto φ(q) = 0 (Gauss–Newton on the manifold)
    /// and v onto J v = 0 (M-orthogonally; impacts inelastic, dry friction as impulses over the
    /// step), if the drift correction says so; in soft mode nothing (as in MuJoCo). Returns
    /// (iterations, [max |φ|, max |J v|]) after the correction (soft: the last solve's
    /// iterations and its rows' violation); no work without constraint rows.
    pub(crate) fn correct_drift(
        &self,
        rows: &ConstraintModel,
        model: &Model,
        data: &mut Data,
        state: &mut State,
        h: f64,
    ) -> (u32, [f64; 2]) {
        if rows.is_empty() {
            data.thaw_rows();
            return (0, [0.0, 0.0]);
        }
        let e = match self {
            ConstraintSolver::Exact(e) => e,
            ConstraintSolver::Soft(_) => {
                data.thaw_rows();
                return (data.solver_niter, row_violation(data));
            }
        };
        // Rows still pressing after the step's last stage stay closed through the projection (a
        // sustained contact drifted open by the integrator's error is closed again, not released).
        data.freeze_rows(true);
        let DriftCorrection { projection, tolerance, .. } = e.drift;
        let out = if projection {
            let (iterations, phi) =
                project_positions(model, rows, data, state.q.as_mut_slice(), tolerance, 50);
            // The velocity projection takes every row at the projected q, friction included
            // (impulses in the Coulomb cone).
            rows.positions_unchecked(model, data, state.q.as_slice(), true);
            // Nothing to project when the step's velocity obeys every row's law already (each
            // row's speed within the position tolerance per second: a row moves by far less
            // than the tolerance over a step).
            let jv =
                if super::velocity_check::already_projected(data, model.nv, state.v.as_slice(), tolerance) {
                    row_violation(data)[1]
                } else {
                    project_velocities_unchecked(model, data, state.v.as_mut_slice(), h, e.settings)
                };
            (iterations, [phi, jv])
        } else {
            rows.evaluate_unchecked(model, data, state.q.as_slice(), state.v.as_slice());
            (0, row_violation(data))
        };
        data.thaw_rows();
        out
    }
}
