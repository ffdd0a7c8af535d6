//! The mutable workspace of the algorithms, allocated once per model.

use super::Model;
use crate::spatial::{ArticulatedInertia, Force, Motion, RigidInertia, Transform};
use nalgebra::{DMatrix, DVector, Matrix6};

/// Buffers every algorithm writes into. `Data::new(&model)` allocates them all; afterwards the
/// algorithms allocate nothing. Per-body arrays are indexed by body (0 = world), per-dof arrays by
/// degree of freedom.
#[derive(Clone, Debug)]
pub struct Data {
    /// Pose of each body frame in its parent body frame (joint placement · joint transform).
    pub x_parent_body: Vec<Transform>,
    /// Pose of each body frame in the world.
    pub x_world_body: Vec<Transform>,
    /// Pose of each named frame in the world (filled by `forward_kinematics`).
    pub x_world_frame: Vec<Transform>,
    /// Motion subspace column of each degree of freedom, in its body's coordinates.
    pub s_body: Vec<Motion>,
    /// Motion subspace column of each degree of freedom in world coordinates (CRBA).
    pub s_world: Vec<Motion>,
    /// Spatial velocity of each body, body coordinates.
    pub v_body: Vec<Motion>,
    /// Spatial acceleration of each body (including the gravity offset in RNEA/ABA), body coords.
    pub a_body: Vec<Motion>,
    /// Velocity-product acceleration `c_J + v × v_J` of each body (ABA), body coordinates.
    pub c_body: Vec<Motion>,
    /// Net spatial force on each body (RNEA) or articulated bias force (ABA), body coordinates.
    pub f_body: Vec<Force>,
    /// Composite rigid-body inertia of each subtree (CRBA), world coordinates.
    pub i_composite: Vec<RigidInertia>,
    /// Articulated-body inertia of each body (ABA), body coordinates.
    pub i_articulated: Vec<ArticulatedInertia>,
    /// `U = Iᴬ S` per degree of freedom (ABA).
    pub u_dof: Vec<Force>,
    /// `u = τ − Sᵀ pᴬ` per degree of freedom (ABA).
    pub u_tau: DVector<f64>,
    /// `D⁻¹ = (Sᵀ U)⁻¹` of each body's joint, top-left nv×nv block (ABA).
    pub d_inv: Vec<Matrix6<f64>>,
    /// Joint-space inertia matrix M(q) (CRBA), armature included.
    pub mass_matrix: DMatrix<f64>,
    /// Tree-sparse LᵀDL factor of M (RBDA §6.3): unit L strictly below the diagonal, D on it.
    pub mass_factor: DMatrix<f64>,
    /// Generalized forces from RNEA.
    pub tau: DVector<f64>,
    /// Generalized accelerations from ABA or a solve with M.
    pub qacc: DVector<f64>,
    /// Scratch vector of length nv.
    pub scratch_v: DVector<f64>,
}

impl Data {
    /// Allocates every buffer for `model`.
    pub fn new(model: &Model) -> Self {
        let nb = model.nbody();
        let nv = model.nv;
        Self {
            x_parent_body: vec![Transform::identity(); nb],
            x_world_body: vec![Transform::identity(); nb],
            x_world_frame: vec![Transform::identity(); model.frames.len()],
            s_body: vec![Motion::zero(); nv],
            s_world: vec![Motion::zero(); nv],
            v_body: vec![Motion::zero(); nb],
            a_body: vec![Motion::zero(); nb],
            c_body: vec![Motion::zero(); nb],
            f_body: vec![Force::zero(); nb],
            i_composite: vec![RigidInertia::zero(); nb],
            i_articulated: vec![ArticulatedInertia::default(); nb],
            u_dof: vec![Force::zero(); nv],
            u_tau: DVector::zeros(nv),
            d_inv: vec![Matrix6::zeros(); nb],
            mass_matrix: DMatrix::zeros(nv, nv),
            mass_factor: DMatrix::zeros(nv, nv),
            tau: DVector::zeros(nv),
            qacc: DVector::zeros(nv),
            scratch_v: DVector::zeros(nv),
        }
    }
}
