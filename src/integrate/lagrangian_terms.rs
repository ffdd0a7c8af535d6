//! The terms of the Lagrangian L(q, ξ) = ½ ξᵀ M(q) ξ − V(q) that a variational integrator needs,
//! in one recursive O(n) pass over the tree (the recursive evaluation of Lee, Liu, Park &
//! Srinivasa, *A Linear-Time Variational Integrator for Multibody Systems*, WAFR 2016, §4, in
//! RBDA's body-coordinate spatial algebra):
//!
//! - the generalized momentum M(q) ξ = Sᵀ Σ_subtree I V (armature added);
//! - ∂T/∂q at fixed ξ, *right-trivialized*: the derivative along q ⊕ ε e_k, the perturbation the
//!   configuration update [`integrate_configuration`](crate::model::integrate_configuration)
//!   makes. Moving dof k of joint c by ε (the joint transform right-multiplied by exp(ε S_k), which
//!   holds for every joint type) changes body c's velocity by
//!   δV_c = −S_k × (V_c − v_J) + δv_J, with δv_J = [0; −S_k,ang × v_J,lin] for free and planar
//!   joints (their translation columns turn with the body) and 0 otherwise; every descendant's
//!   velocity changes by the same motion carried to it. So ∂T/∂q_k = H_c · δV_c with H_c the
//!   subtree momentum in c's coordinates;
//! - the generalized gravity g(q) = ∂V/∂q = RNEA(q, 0, 0) (the world accelerating upwards),
//!   which needs of each subtree only its mass m and first moment c (= m × centre of mass) in the
//!   joint's body frame: the subtree's gravity wrench there is (c × a, m a) with a the body-frame
//!   upward acceleration, and c carries to the parent as R c + m p (RBDA eq. 2.66's first-moment
//!   part), 3-vectors where the spatial recursion moves 6-vectors and inertias.
//!
//! ξ is a velocity in the model's v layout (body-frame angular velocity for ball and free joints,
//! parent-frame linear velocity for free joints).

use crate::error::{check, InputError};
use crate::kinematics::update_joint;
use crate::model::{Data, JointKind, Model};
use crate::spatial::{Force, Motion, Transform, Vec3};
use nalgebra::DVector;

/// Buffers of the pass and its three results.
pub struct LagrangianTerms {
    /// Joint transforms and motion subspaces at the q of the last `compute`.
    x_parent_body: Vec<Transform>,
    s_body: Vec<Motion>,
    v_joint: Vec<Motion>,
    v_body: Vec<Motion>,
    /// The world's upward acceleration −g in each body's frame.
    a_gravity: Vec<Vec3>,
    momentum: Vec<Force>,
    /// Subtree masses and first moments (body frame).
    subtree_mass: Vec<f64>,
    subtree_moment: Vec<Vec3>,
    /// M(q) ξ.
    pub momentum_gen: DVector<f64>,
    /// ∂T/∂q (q, ξ), right-trivialized.
    pub dkinetic_dq: DVector<f64>,
    /// g(q) = ∂V/∂q (gravity only), right-trivialized.
    pub gravity_gen: DVector<f64>,
}

impl LagrangianTerms {
    /// Buffers sized for `model`, the terms zero.
    pub fn new(model: &Model) -> Self {
        let nb = model.nbody();
        Self {
            x_parent_body: vec![Transform::identity(); nb],
            s_body: vec![Motion::zero(); model.nv],
            v_joint: vec![Motion::zero(); nb],
            v_body: vec![Motion::zero(); nb],
            a_gravity: vec![Vec3::zeros(); nb],
            momentum: vec![Force::zero(); nb],
            subtree_mass: vec![0.0; nb],
            subtree_moment: vec![Vec3::zeros(); nb],
            momentum_gen: DVector::zeros(model.nv),
            dkinetic_dq: DVector::zeros(model.nv),
            gravity_gen: DVector::zeros(model.nv),
        }
    }

    /// Evaluates the three terms at (q, ξ); updates the joint transforms and subspaces of `data`
    /// and keeps a copy for [`recompute_velocity_terms`](Self::recompute_velocity_terms).
    ///
    /// # Errors
    /// [`InputError::Length`] when q is not nq long, ξ not nv long, or `data` was made for another
    /// model.
    pub fn compute(
        &mut self,
        model: &Model,
        data: &mut Data,
        q: &[f64],
        xi: &[f64],
    ) -> Result<(), InputError> {
        check::data("LagrangianTerms::compute", model, data)?;
        check::q("LagrangianTerms::compute", model, q)?;
        check::v("LagrangianTerms::compute", "xi", model, xi)?;
        self.compute_unchecked(model, data, q, xi);
        Ok(())
    }

    /// [`compute`](Self::compute) without the argument checks.
    pub(crate) fn compute_unchecked(&mut self, model: &Model, data: &mut Data, q: &[f64], xi: &[f64]) {
        data.poses_stamp.keep_if(q);
        for b in 1..model.nbody() {
            update_joint(model, data, b, q);
            self.x_parent_body[b] = data.x_parent_body[b];
            let j = model.joint_of(b);
            for k in j.dof_adr..j.dof_adr + j.kind.nv() {
                self.s_body[k] = data.s_body[k];
            }
        }
        self.pass(model, xi, true);
    }

    /// M(q) ξ and ∂T/∂q for a new ξ at the q of the last [`compute`](Self::compute) (its joint
    /// transforms reused; g(q) unchanged).
    ///
    /// # Errors
    /// [`InputError::Length`] when ξ is not nv long.
    pub fn recompute_velocity_terms(&mut self, model: &Model, xi: &[f64]) -> Result<(), InputError> {
        check::v("LagrangianTerms::recompute_velocity_terms", "xi", model, xi)?;
        self.pass(model, xi, false);
        Ok(())
    }

    pub(crate) fn pass(&mut self, model: &Model, xi: &[f64], with_gravity: bool) {
        let nb = model.nbody();
        self.v_body[0] = Motion::zero();
        self.a_gravity[0] = -model.gravity;
        for b in 1..nb {
            let p = model.bodies[b].parent;
            let x = &self.x_parent_body[b];
            let j = model.joint_of(b);
            let mut v_j = Motion::zero();
            for k in j.dof_adr..j.dof_adr + j.kind.nv() {
                v_j += self.s_body[k] * xi[k];
            }
            let v_b = x.inv_act_motion(&self.v_body[p]) + v_j;
            let inertia = &model.bodies[b].inertia;
            self.momentum[b] = inertia.mul_motion(&v_b);
            if with_gravity {
                self.a_gravity[b] = x.rot.tr_mul(&self.a_gravity[p]);
                self.subtree_mass[b] = inertia.mass;
                self.subtree_moment[b] = inertia.h;
            }
            self.v_joint[b] = v_j;
            self.v_body[b] = v_b;
        }
        for b in (1..nb).rev() {
            let j = model.joint_of(b);
            let turning = matches!(j.kind, JointKind::Free | JointKind::Planar { .. });
            let h_c = self.momentum[b];
            let v_j = self.v_joint[b];
            let w = self.v_body[b] - v_j;
            for k in j.dof_adr..j.dof_adr + j.kind.nv() {
                let s = &self.s_body[k];
                self.momentum_gen[k] = s.dot(&h_c) + model.dof_armature[k] * xi[k];
                let mut dv = -s.cross_motion(&w);
                if turning {
                    dv.lin -= s.ang.cross(&v_j.lin);
                }
                self.dkinetic_dq[k] = dv.dot(&h_c);
            }
            if with_gravity {
                let a = self.a_gravity[b];
                let g_c = Force { ang: self.subtree_moment[b].cross(&a), lin: a * self.subtree_mass[b] };
                for k in j.dof_adr..j.dof_adr + j.kind.nv() {
                    self.gravity_gen[k] = self.s_body[k].dot(&g_c);
                }
            }
            let p = model.bodies[b].parent;
            if p != 0 {
                let x = &self.x_parent_body[b];
                self.momentum[p] += x.act_force(&h_c);
                if with_gravity {
                    let (m, c) = (self.subtree_mass[b], self.subtree_moment[b]);
                    self.subtree_moment[p] += x.rot * c + x.pos * m;
                    self.subtree_mass[p] += m;
                }
            }
        }
    }
}
