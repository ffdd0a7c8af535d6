//! # lagrange
//!
//! A multibody dynamics engine: URDF and MJCF models become kinematic trees in generalized
//! coordinates; the recursive algorithms of Featherstone's *Rigid Body Dynamics Algorithms* give
//! forward kinematics, Jacobians, inverse dynamics (RNEA), the mass matrix (CRBA) with its
//! tree-sparse factorization and forward dynamics (ABA); constraint forces (loops, couplings,
//! limits, frictional contact, in an exact or a MuJoCo-compatible soft mode), actuators and six
//! integrators make a simulation, checked against MuJoCo and Pinocchio.
//!
//! A [`Model`] is everything fixed once a file is compiled; a [`Data`] is one simulation: its
//! state (`time`, `qpos`, `qvel`, `act`), its inputs (`ctrl`, `qfrc_applied`) and every output,
//! with MuJoCo's names. The calls take `(&Model, &mut Data)`:
//!
//! ```
//! use lagrange::prelude::*;
//! let model = Model::from_file("models/mjcf/unitree_go1/scene.xml")?;
//! let mut data = Data::new(&model);
//! reset_keyframe(&model, &mut data, "home")?;
//! for _ in 0..100 {
//!     step(&model, &mut data)?;
//! }
//! forward(&model, &mut data);
//! let feet: f64 = contacts(&model, &data).map(|c| c.force[0]).sum();
//! assert!(feet > 100.0); // the floor carries the robot (12.7 kg)
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! State vectors use MuJoCo's qpos/qvel layout; `docs/architecture.md` describes the layers, the
//! pipeline and the solvers, `docs/physics.md` the closed forms the tests check.

#![warn(missing_docs)]
// The kernels index several parallel per-dof arrays (S, v, q̈, τ) with one dof index; iterator
// zips over four slices would hide the RBDA table they transcribe.
#![allow(clippy::needless_range_loop)]

pub mod batch;
pub mod collision;
pub mod constraint;
pub mod derivatives;
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
pub mod sensor;
pub mod sim;
pub mod spatial;
pub mod tendon;

pub use model::{Data, Model};
