//! 6-D spatial algebra (Featherstone, *Rigid Body Dynamics Algorithms*, 2008, ch. 2).
//!
//! Spatial vectors are stored as pairs of 3-vectors, angular part first, both expressed in the
//! coordinates of one frame and (for the linear/moment part) about that frame's origin:
//! - [`Motion`]: `ang` = angular velocity ω, `lin` = velocity of the body point at the origin.
//! - [`Force`]: `ang` = moment n about the origin, `lin` = force f.
//!
//! [`Transform`] is a rigid pose `x_a_b` of frame b in frame a (`p_a = rot * p_b + pos`); it moves
//! motion and force vectors between the two coordinate systems (RBDA eq. 2.24–2.27).

pub mod fused;
mod inertia;
mod motion;
mod transform;

pub use inertia::{ArticulatedInertia, RigidInertia};
pub use motion::{Force, Motion};
pub use transform::{quat_to_matrix, skew, Transform};

/// 3-vector of f64.
pub type Vec3 = nalgebra::Vector3<f64>;
/// 3×3 matrix of f64.
pub type Mat3 = nalgebra::Matrix3<f64>;
