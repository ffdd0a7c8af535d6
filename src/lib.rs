//! # lagrange
//!
//! A multibody dynamics engine: URDF (and soon MJCF) models become kinematic trees in generalized
//! coordinates; the recursive algorithms of Featherstone's *Rigid Body Dynamics Algorithms* (RBDA)
//! give forward kinematics, Jacobians, inverse dynamics (RNEA), the mass matrix (CRBA) with its
//! tree-sparse factorization, and forward dynamics (ABA); time steppers integrate them.
//!
//! State vectors use MuJoCo's qpos/qvel layout; see `DESIGN.md` and the README.

// The kernels index several parallel per-dof arrays (S, v, q̈, τ) with one dof index; iterator
// zips over four slices would hide the RBDA table they transcribe.
#![allow(clippy::needless_range_loop)]

pub mod batch;
pub mod collision;
pub mod constraint;
pub mod dynamics;
pub mod error;
pub mod forward;
pub mod frames;
pub mod integrate;
pub mod io;
#[cfg(test)]
mod kernel_test_states;
pub mod kinematics;
pub mod mass;
pub mod model;
pub mod prelude;
pub mod sim;
pub mod spatial;

pub use model::{Data, Model};
