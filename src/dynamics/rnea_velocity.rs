//! ∂c/∂v, the velocity derivative of the bias forces c(q, v) = RNEA(q, v, 0) (MuJoCo's
//! `qfrc_bias`; the quantity of its `mjd_rne_vel`) — also ∂τ/∂v of RNEA(q, v, a), which the
//! acceleration does not enter — by differentiating the recursive Newton–Euler
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
pub(crate) struct BiasDerivative {
    v_body: Vec<Motion>,
    v_joint: Vec<Motion>,
    /// I V of each body (its momentum), the same for every direction.
    momentum: Vec<Force>,
    dv_body: Vec<Motion>,
    da_body: Vec<Motion>,
    df_body: Vec<Force>,
    /// Whether each body is in the subtree of the body of the current direction's dof.
    in_subtree: Vec<bool>,
    /// ∂c/∂v (nv × nv), column k the derivative along dof k.
    pub dbias_dv: DMatrix<f64>,
}

impl BiasDerivative {
    /// Buffers sized for `model`, the derivative zero.
    pub fn new(model: &Model) -> Self {
        let nb = model.nbody();
        Self {
            v_body: vec![Motion::zero(); nb],
            v_joint: vec![Motion::zero(); nb],
            momentum: vec![Force::zero(); nb],
            dv_body: vec![Motion::zero(); nb],
            da_body: vec![Motion::zero(); nb],
            df_body: vec![Force::zero(); nb],
            in_subtree: vec![false; nb],
            dbias_dv: DMatrix::zeros(model.nv, model.nv),
        }
    }

    /// Fills [`dbias_dv`](Self::dbias_dv) at (q, v); updates the joint transforms and motion
    /// subspaces of `data` at q.
    ///
    /// Along dof k of body c only c's subtree moves (δV, δA and δf are zero elsewhere): the
    /// forward pass and the force sums run over that subtree, and the subtree's force at c is then
    /// carried up c's ancestor chain alone (the other bodies add zeros, which are skipped).
    pub fn compute(&mut self, model: &Model, data: &mut Data, q: &[f64], v: &[f64]) {
        let nb = model.nbody();
        data.poses_stamp.keep_if(q);
        self.v_body[0] = Motion::zero();
        for b in 1..nb {
            update_joint(model, data, b, q);
            let p = model.bodies[b].parent;
            self.v_joint[b] = joint_velocity(model, data, b, v);
            self.v_body[b] = data.x_parent_body[b].inv_act_motion(&self.v_body[p]) + self.v_joint[b];
            self.momentum[b] = model.bodies[b].inertia.mul_motion(&self.v_body[b]);
        }
        self.columns(model, data);
    }

    /// The nv columns of ∂c/∂v from the prepared `v_joint`, `v_body` and `momentum`.
    fn columns(&mut self, model: &Model, data: &Data) {
        let nb = model.nbody();
        self.dbias_dv.fill(0.0);
        for k in 0..model.nv {
            let c = model.dof_body[k];
            // Bodies are numbered parents first: the subtree of c is c and the later bodies whose
            // parent is in it.
            for b in c..nb {
                let p = model.bodies[b].parent;
                self.in_subtree[b] = b == c || (p >= c && self.in_subtree[p]);
                if !self.in_subtree[b] {
                    continue;
                }
                let x = &data.x_parent_body[b];
                let (v_j, v_b) = (self.v_joint[b], self.v_body[b]);
                let (dv_b, da_b) = if b == c {
                    // The parent does not move along dof k.
                    let dv_joint = data.s_body[k];
                    let dc_joint = match model.joint_of(b).kind {
                        JointKind::Free | JointKind::Planar { .. } => Motion::new(
                            Default::default(),
                            dv_joint.lin.cross(&v_j.ang) + v_j.lin.cross(&dv_joint.ang),
                        ),
                        _ => Motion::zero(),
                    };
                    (dv_joint, dc_joint + dv_joint.cross_motion(&v_j) + v_b.cross_motion(&dv_joint))
                } else {
                    let dv_b = x.inv_act_motion(&self.dv_body[p]);
                    (dv_b, x.inv_act_motion(&self.da_body[p]) + dv_b.cross_motion(&v_j))
                };
                let inertia = &model.bodies[b].inertia;
                self.df_body[b] = inertia.mul_motion(&da_b)
                    + dv_b.cross_force(&self.momentum[b])
                    + v_b.cross_force(&inertia.mul_motion(&dv_b));
                self.dv_body[b] = dv_b;
                self.da_body[b] = da_b;
            }
            // The subtree's forces, leaves first, each body's into its parent's (c's included).
            for b in (c + 1..nb).rev() {
                if self.in_subtree[b] {
                    let j = model.joint_of(b);
                    for i in j.dof_adr..j.dof_adr + j.kind.nv() {
                        self.dbias_dv[(i, k)] = data.s_body[i].dot(&self.df_body[b]);
                    }
                    let p = model.bodies[b].parent;
                    let f = data.x_parent_body[b].act_force(&self.df_body[b]);
                    self.df_body[p] += f;
                }
            }
            // c and its ancestors: the one force carried up the chain.
            let mut f = self.df_body[c];
            let mut b = c;
            loop {
                let j = model.joint_of(b);
                for i in j.dof_adr..j.dof_adr + j.kind.nv() {
                    self.dbias_dv[(i, k)] = data.s_body[i].dot(&f);
                }
                let p = model.bodies[b].parent;
                if p == 0 {
                    break;
                }
                f = data.x_parent_body[b].act_force(&f);
                b = p;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::rnea;

    /// ∂c/∂v against central differences of RNEA(q, v, 0) on the panda and the floating solo12
    /// (free-joint velocity-product terms included).
    #[test]
    fn matches_central_differences_of_rnea() {
        for (file, model, q) in crate::kernel_test_states::robots() {
            let mut data = Data::new(&model);
            let v: Vec<f64> = (0..model.nv).map(|k| 1.3 * (0.7 * k as f64).sin() + 0.2).collect();
            let mut d = BiasDerivative::new(&model);
            d.compute(&model, &mut data, &q, &v);
            let zero = vec![0.0; model.nv];
            let eps = 1e-6;
            let mut worst: f64 = 0.0;
            let scale = d.dbias_dv.amax().max(1.0);
            for k in 0..model.nv {
                let (mut vp, mut vm) = (v.clone(), v.clone());
                vp[k] += eps;
                vm[k] -= eps;
                let cp = rnea(&model, &mut data, &q, &vp, &zero).unwrap().clone();
                let cm = rnea(&model, &mut data, &q, &vm, &zero).unwrap().clone();
                for i in 0..model.nv {
                    let fd = (cp[i] - cm[i]) / (2.0 * eps);
                    worst = worst.max((fd - d.dbias_dv[(i, k)]).abs() / scale);
                }
            }
            // c is quadratic in v: central differences are exact up to rounding (~ε/eps).
            assert!(worst < 1e-8, "{file}: worst relative difference {worst:e}");
        }
    }
}
