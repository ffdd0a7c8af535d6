//! ∂τ/∂q, the configuration derivative of inverse dynamics τ = RNEA(q, v, a), by forward-mode
//! differentiation of the recursive Newton–Euler recursion (RBDA §5.3, Table 5.1) along each
//! tangent direction of q — exact to rounding, not finite differences; the derivation is in
//! docs/physics.md, "Derivatives of the dynamics".
//!
//! The tangent direction of dof k (MuJoCo's `mj_integratePos` layout: a free joint's translation
//! in its parent's axes, rotations in the body's axes, hinges, slides and planar coordinates
//! additive) displaces body c = `dof_body[k]` by the small spatial motion S_k (its motion-subspace
//! column, body coordinates) and carries c's subtree rigidly. In local coordinates only three
//! things move: the parent-to-c transform, δX m = −S_k × (X m) (and δ(Xᵀ* f) = Xᵀ*(S_k ×* f));
//! the subspace columns of c's joint that are fixed in the parent (the translations of free and
//! planar joints), δS_i = −S_k × S_i; and with them c's joint velocity and velocity-product term.
//! The forward pass runs over c's subtree, the force sums over the subtree and then up c's
//! ancestor chain, as for [`BiasDerivative`](super::BiasDerivative): O(nv · nbody) in all.

use crate::kinematics::joint_velocity;
use crate::model::{JointKind, Model};
use crate::spatial::{Force, Motion};
use crate::Data;
use nalgebra::DMatrix;

/// Buffers of the configuration-derivative pass, allocated once per model.
pub(crate) struct ConfigurationDerivative {
    v_joint: Vec<Motion>,
    momentum: Vec<Force>,
    dv_body: Vec<Motion>,
    da_body: Vec<Motion>,
    df_body: Vec<Force>,
    in_subtree: Vec<bool>,
}

impl ConfigurationDerivative {
    /// Buffers sized for `model`.
    pub fn new(model: &Model) -> Self {
        let nb = model.nbody();
        Self {
            v_joint: vec![Motion::zero(); nb],
            momentum: vec![Force::zero(); nb],
            dv_body: vec![Motion::zero(); nb],
            da_body: vec![Motion::zero(); nb],
            df_body: vec![Force::zero(); nb],
            in_subtree: vec![false; nb],
        }
    }

    /// ∂τ/∂q into `out` (nv × nv, column k along dof k's tangent direction). `data` must hold
    /// RNEA's result at (q, v, qacc): joint transforms and subspaces, `v_body`, `a_body` and the
    /// subtree-summed `f_body` (what [`rnea_unchecked`](crate::dynamics) leaves there).
    pub fn compute(&mut self, model: &Model, data: &Data, v: &[f64], qacc: &[f64], out: &mut DMatrix<f64>) {
        let nb = model.nbody();
        for b in 1..nb {
            self.v_joint[b] = joint_velocity(model, data, b, v);
            self.momentum[b] = model.bodies[b].inertia.mul_motion(&data.v_body[b]);
        }
        out.fill(0.0);
        for k in 0..model.nv {
            let c = model.dof_body[k];
            let s_k = data.s_body[k];
            let j = model.joint_of(c);
            let (da, nv_j) = (j.dof_adr, j.kind.nv());
            // Joints whose translation columns are fixed in the parent turn them with the body.
            let turns = matches!(j.kind, JointKind::Free | JointKind::Planar { .. });
            let ds = |i: usize| -> Motion {
                let s_i = data.s_body[i];
                if turns && s_i.ang == crate::spatial::Vec3::zeros() {
                    -s_k.cross_motion(&s_i)
                } else {
                    Motion::zero()
                }
            };
            for b in c..nb {
                let p = model.bodies[b].parent;
                self.in_subtree[b] = b == c || (p >= c && self.in_subtree[p]);
                if !self.in_subtree[b] {
                    continue;
                }
                let x = &data.x_parent_body[b];
                let (v_j, v_b) = (self.v_joint[b], data.v_body[b]);
                let (dv_b, da_b) = if b == c {
                    let (mut dv_joint, mut da_joint) = (Motion::zero(), Motion::zero());
                    for i in da..da + nv_j {
                        let d = ds(i);
                        dv_joint += d * v[i];
                        da_joint += d * qacc[i];
                    }
                    let dc_joint = if turns {
                        Motion::new(
                            Default::default(),
                            dv_joint.lin.cross(&v_j.ang) + v_j.lin.cross(&dv_joint.ang),
                        )
                    } else {
                        Motion::zero()
                    };
                    let xv_parent = v_b - v_j;
                    let xa_parent = x.inv_act_motion(&data.a_body[p]);
                    let dv_b = dv_joint - s_k.cross_motion(&xv_parent);
                    let da_b = da_joint + dc_joint - s_k.cross_motion(&xa_parent)
                        + dv_b.cross_motion(&v_j)
                        + v_b.cross_motion(&dv_joint);
                    (dv_b, da_b)
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
            for b in (c + 1..nb).rev() {
                if self.in_subtree[b] {
                    let jb = model.joint_of(b);
                    for i in jb.dof_adr..jb.dof_adr + jb.kind.nv() {
                        out[(i, k)] = data.s_body[i].dot(&self.df_body[b]);
                    }
                    let p = model.bodies[b].parent;
                    let f = data.x_parent_body[b].act_force(&self.df_body[b]);
                    self.df_body[p] += f;
                }
            }
            // c: its own turned columns meet the nominal subtree force; the force handed to the
            // parent goes through the moved transform.
            let f_c = data.f_body[c];
            let df_c = self.df_body[c];
            for i in da..da + nv_j {
                out[(i, k)] = data.s_body[i].dot(&df_c) + ds(i).dot(&f_c);
            }
            let p = model.bodies[c].parent;
            if p == 0 {
                continue;
            }
            let mut f = data.x_parent_body[c].act_force(&(df_c + s_k.cross_force(&f_c)));
            let mut b = p;
            loop {
                let jb = model.joint_of(b);
                for i in jb.dof_adr..jb.dof_adr + jb.kind.nv() {
                    out[(i, k)] = data.s_body[i].dot(&f);
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
