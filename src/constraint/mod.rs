//! The constraint layer (docs/architecture.md, "Layers"): which rows a model has ([`ConstraintModel`]), their
//! Jacobian `J`, residual `φ`, `J v` and `J̇ v` in [`Data`](crate::Data) (`efc_*` buffers), and the
//! exact (rigid) solver: the KKT system `M q̈ + c − τ = Jᵀλ`, `J q̈ + J̇v = 0` (docs/physics.md §1.6,
//! eq. 19–22: λ are Lagrange multipliers, `Jᵀλ` the generalized forces of constraint), plus the
//! drift correction of the steppers (projection onto φ = 0 and J v = 0).
//!
//! Row kinds (MuJoCo's order): equality constraints (connect, weld, joint coupling, fixed-tendon
//! coupling) and URDF mimic couplings; dof friction loss (bounded rows); limits of hinge, slide
//! and ball joints; contacts from the collision layer (normal + elliptic Coulomb cone). Unilateral
//! rows obey Signorini's complementarity at the acceleration level and inelastic impacts at the
//! velocity level; rows with dry friction are solved by `solve_coulomb`, the others exactly by an
//! active-set method. The soft (MuJoCo-compatible) mode ([`soft`]) writes the same buffers with
//! MuJoCo's rows, regularization and solvers.

mod active_set;
mod admm;
mod block_lu;
mod contact;
pub mod contact_force;
mod contact_problem;
mod coulomb;
mod coulomb_polish;
mod dense;
mod energy_guard;
mod exact;
mod exact_work;
mod friction_loss;
mod limits;
#[cfg(target_arch = "x86_64")]
pub(crate) mod nonzero_list;
mod row_lifecycle;
mod rows;
pub mod soft;
mod solver;
mod velocity_check;

pub use admm::{ExactContactSolver, ADMM_TOLERANCE};
pub use contact::CONTACT_ACTIVE_DISTANCE;
pub use contact_problem::{BlockLaw, ContactProblem, ProblemBlock, ProblemResidual, ProblemSolution};
pub use coulomb::{Level, SolverSettings, SEPARATING_VELOCITY, SLIP_VELOCITY};
pub(crate) use dense::{cholesky, cholesky_solve};
pub(crate) use exact::{project_positions, project_velocities_unchecked, solve_exact};
pub use exact::{project_velocities, row_violation};
pub(crate) use exact_work::ExactWork;
pub use friction_loss::FrictionRow;
pub use limits::{ball_angle_axis, LimitKind, LimitRow, LIMIT_ACTIVE_DISTANCE};
pub(crate) use row_lifecycle::RowLifecycle;
pub use rows::{ConstraintModel, RowGeometry, ScalarCoord};
pub use solver::{ConstraintSolver, DriftCorrection, ExactSolver, SoftSolver};

/// Which constraint model `forward` solves.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ConstraintMode {
    /// Rigid constraints: the KKT solution (Lagrange multipliers).
    #[default]
    Exact,
    /// MuJoCo's soft convex model (solref/solimp, [`soft`]).
    Soft,
}

impl ConstraintMode {
    /// `exact` or `soft`, as `info` and `eval` print it.
    pub fn name(self) -> &'static str {
        match self {
            ConstraintMode::Exact => "exact",
            ConstraintMode::Soft => "soft",
        }
    }
}

/// Relative size (to the largest diagonal entry) below which a pivot of J M⁻¹ Jᵀ's pivoted
/// Cholesky factor counts as zero (a redundant row).
pub const RANK_TOLERANCE: f64 = 1e-10;
