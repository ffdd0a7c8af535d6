//! Derivatives of the dynamics for control and learning (docs/derivatives.md, the
//! derivation in docs/physics.md, "Derivatives of the dynamics"): analytic ∂τ/∂q and ∂τ/∂v of
//! inverse dynamics ([`rnea_derivatives`]), analytic ∂q̈/∂q, ∂q̈/∂v and ∂q̈/∂τ of forward dynamics
//! ([`aba_derivatives`], and [`smooth_derivatives`] with passive and actuator forces), all into a
//! preallocated [`DerivativesWork`]; and the transition Jacobians of a whole step, constraints
//! included, by finite differences as MuJoCo's `mjd_transitionFD` or with analytic velocity and
//! control columns through the soft solve's optimality conditions ([`transition_jacobians`]).
//!
//! Conventions: q columns are in each joint's tangent space as MuJoCo's `mj_integratePos` moves
//! along it (a free joint's translation in its parent's axes, its rotation and a ball's in the
//! body's axes); velocities, accelerations and forces in lagrange's own (MuJoCo's) coordinates.

mod forward_dynamics;
mod rnea;
mod rnea_sweep;
mod transition;
mod transition_analytic;
mod work;

pub use forward_dynamics::{aba_derivatives, smooth_derivatives};
pub use rnea::rnea_derivatives;
pub use transition::{transition_jacobians, TransitionMethod, TransitionOptions, TransitionWork};
pub use work::DerivativesWork;
