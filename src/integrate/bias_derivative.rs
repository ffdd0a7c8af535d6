//! ∂c/∂v, the velocity derivative of the bias forces c(q, v) = RNEA(q, v, 0) (MuJoCo's
//! `qfrc_bias`; the quantity of its `mjd_rne_vel`), by differentiating the recursive Newton–Euler
//! recursion (RBDA §5.3, Table 5.1) in the direction of each degree of freedom — forward-mode
//! differentiation of the recursion, exact to rounding, not finite differences. With q fixed the
//! joint transforms and motion subspaces S are constant, and for a direction δv:
//!
//!   δv_J = S δv,   δV_b = X δV_parent + δv_J,
//!   δA_b = X δA_parent + δc_J + δV_b × v_J + V_b × δv_J,
//!   δf_b = I δA_b + δV_b ×* I V_b + V_b ×* I δV_b,   δτ = Sᵀ Σ_subtree δf,
//!
//! where c_J = [0; v_J,lin × v_J,ang] is the velocity-product term of free and planar joints
//! (bilinear in v_J) and gravity, constant, drops out. Column k of the nv × nv result is δτ for
//! δv = e_k: O(nv · nbody) in all.

use crate::kinematics::{joint_velocity, update_joint};
use crate::model::{JointKind, Model};
use crate::spatial::{Force, Motion};
use crate::Data;
use nalgebra::DMatrix;

/// Buffers of the derivative pass, allocated once per model.
pub struct BiasDerivative {
    v_body: Vec<Motion>,
    v_joint: Vec<Motion>,
    dv_body: Vec<Motion>,
    da_body: Vec<Motion>,
    df_body: Vec<Force>,
    /// ∂c/∂v (nv × nv), column k the derivative along dof k.
    pub dbias_dv: DMatrix<f64>,
}

impl BiasDerivative {
    pub fn new(model: &Model) -> Self {
        let nb = model.nbody();
        Self {
            v_body: vec![Motion::zero(); nb],
            v_joint: vec![Motion::zero(); nb],
            dv_body: vec![Motion::zero(); nb],
            da_body: vec![Motion::zero(); nb],
            df_body: vec![Force::zero(); nb],
            dbias_dv: DMatrix::zeros(model.nv, model.nv),
        }
    }

    /// Fills [`dbias_dv`](Self::dbias_dv) at (q, v); updates the joint transforms and motion
    /// subspaces of `data` at q.
    pub fn compute(&mut self, model: &Model, data: &mut Data, q: &[f64], v: &[f64]) {
        let nb = model.nbody();
        self.v_body[0] = Motion::zero();
        for b in 1..nb {
            update_joint(model, data, b, q);
            let p = model.bodies[b].parent;
            self.v_joint[b] = joint_velocity(model, data, b, v);
            self.v_body[b] = data.x_parent_body[b].inv_act_motion(&self.v_body[p]) + self.v_joint[b];
        }
        for k in 0..model.nv {
            let c = model.dof_body[k];
            self.dv_body[0] = Motion::zero();
            self.da_body[0] = Motion::zero();
            for b in 1..nb {
                let p = model.bodies[b].parent;
                if b < c || (b > c && self.dv_body[p] == Motion::zero() && self.da_body[p] == Motion::zero())
                {
                    // Not in the subtree of dof k's body: no change.
                    self.dv_body[b] = Motion::zero();
                    self.da_body[b] = Motion::zero();
                    self.df_body[b] = Force::zero();
                    continue;
                }
                let x = &data.x_parent_body[b];
                let dv_joint = if b == c { data.s_body[k] } else { Motion::zero() };
                let (v_j, v_b) = (self.v_joint[b], self.v_body[b]);
                let dc_joint = match model.joint_of(b).kind {
                    JointKind::Free | JointKind::Planar { .. } => Motion::new(
                        Default::default(),
                        dv_joint.lin.cross(&v_j.ang) + v_j.lin.cross(&dv_joint.ang),
                    ),
                    _ => Motion::zero(),
                };
                let dv_b = x.inv_act_motion(&self.dv_body[p]) + dv_joint;
                let da_b = x.inv_act_motion(&self.da_body[p])
                    + dc_joint
                    + dv_b.cross_motion(&v_j)
                    + v_b.cross_motion(&dv_joint);
                let inertia = &model.bodies[b].inertia;
                self.df_body[b] = inertia.mul_motion(&da_b)
                    + dv_b.cross_force(&inertia.mul_motion(&v_b))
                    + v_b.cross_force(&inertia.mul_motion(&dv_b));
                self.dv_body[b] = dv_b;
                self.da_body[b] = da_b;
            }
            for b in (1..nb).rev() {
                let j = model.joint_of(b);
                for i in j.dof_adr..j.dof_adr + j.kind.nv() {
                    self.dbias_dv[(i, k)] = data.s_body[i].dot(&self.df_body[b]);
                }
                let p = model.bodies[b].parent;
                if p != 0 {
                    let f = data.x_parent_body[b].act_force(&self.df_body[b]);
                    self.df_body[p] += f;
                }
            }
        }
    }
}
