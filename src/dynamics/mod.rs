//! Rigid-body dynamics (docs/architecture.md, "Layers"): inverse dynamics (RNEA), the joint-space inertia
//! matrix (CRBA) and its tree-sparse factorization, forward dynamics (ABA), energy, centre of mass
//! and momentum, MuJoCo's per-body accelerations and wrenches after a solve (`rne_post`), and the
//! forward-mode velocity derivative of the bias forces along each dof (`rnea_velocity`), which the
//! implicit stepper uses; MuJoCo's fluid forces (`fluid`).
//! Every function writes into [`Data`](crate::Data) and allocates nothing.

mod aba;
mod crba;
mod energy;
pub mod fluid;
pub mod gravcomp;
pub(crate) mod rne_post;
mod rnea;
mod rnea_velocity;

pub use aba::aba;
pub(crate) use aba::aba_unchecked;
pub use crba::{crba, crba_upper, factorize_mass_matrix, solve_mass_matrix, solve_with_factor};
pub(crate) use crba::{
    crba_unchecked, factorize_mass_matrix_damped, solve_transposed_with_factor_unchecked,
    solve_with_factor_span_unchecked, solve_with_factor_unchecked, tree_span,
};
pub(crate) use energy::kinetic_energy_unchecked;
pub use energy::{center_of_mass, kinetic_energy, potential_energy, spatial_momentum};
pub(crate) use rne_post::RnePost;
pub use rne_post::{
    body_acceleration, external_wrench, interaction_wrench, object_acceleration, rne_post_constraint,
};
pub(crate) use rnea::bias_forces_unchecked;
pub use rnea::{bias_forces, gravity_forces, rnea};
pub(crate) use rnea_velocity::BiasDerivative;
