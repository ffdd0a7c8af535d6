//! ∂τ/∂q and ∂τ/∂v of inverse dynamics τ = RNEA(q, v, a) in one forward and one backward sweep
//! over the bodies, in world axes (the structure of Carpentier & Mansard, RSS 2018, "Analytical
//! derivatives of rigid body dynamics algorithms"; the derivation in our words and in lagrange's
//! tangent conventions is docs/physics.md, "Derivatives of the dynamics").
//!
//! Every spatial quantity is in world axes about its tree's origin (the root body's origin, a point
//! held fixed for the instant: CRBA's reference, which keeps digits far from the world origin).
//! Each dof k has its world column S_k, attached either to its joint's child body or, for the
//! translations of free and planar joints (fixed in the parent's axes), to the parent. With w_j
//! and ā_j the velocity and acceleration of joint j's base (the parent plus the joint's
//! parent-attached columns), per dof
//!
//!   Ψ_k = w_j × S_k,   Φ_k = ā_j × S_k + w_j × Ψ_k,   A_k = u_k × S_k + Ψ_k
//!
//! (u_k the velocity of the body S_k is attached to), and per body the inertia I, its rate
//! İ = v ×* I − I v× and momentum h = I v, summed over subtrees (I꜀, İ꜀, h꜀, and the force F).
//! With B꜀ x = İ꜀ x + x ×* h꜀, a dof m and a dof k on the path from the root to m:
//!
//!   ∂τ_k/∂v_m = S_k · (I꜀ A_m + B꜀ S_m),             ∂τ_m/∂v_k = A_k · I꜀ S_m + S_k · B꜀ᵀ S_m,
//!   ∂τ_k/∂q_m = S_k · (S_m ×* F + I꜀ Φ_m + B꜀ Ψ_m),   ∂τ_m/∂q_k = Φ_k · I꜀ S_m + Ψ_k · B꜀ᵀ S_m,
//!
//! with the subtree sums of m's body, plus (S_m × S_k) · F for two dofs of one joint when S_k is
//! attached to the child. O(nv · depth) pairs of a few 6-vector dot products, no per-dof pass.

use crate::kinematics::update_joint;
use crate::model::{JointKind, Model};
use crate::spatial::{Force, Mat3, Motion, RigidInertia, Transform, Vec3};
use crate::Data;
use nalgebra::DMatrix;

/// Buffers of the sweep, allocated once per model.
pub(crate) struct RneaSweep {
    /// Pose of each body in its tree's frame (world axes, the tree's root origin).
    x_tree: Vec<Transform>,
    v: Vec<Motion>,
    a: Vec<Motion>,
    /// Subtree sums, leaves to root: inertia, its rate İ, momentum h and net force.
    i_c: Vec<RigidInertia>,
    idot_c: Vec<RigidInertia>,
    h_c: Vec<Force>,
    f_c: Vec<Force>,
    /// Per dof: world column S, A, Φ, Ψ (module doc) and whether S is attached to the child.
    s: Vec<Motion>,
    a_col: Vec<Motion>,
    phi: Vec<Motion>,
    psi: Vec<Motion>,
    child_attached: Vec<bool>,
}

impl RneaSweep {
    /// Buffers sized for `model`.
    pub fn new(model: &Model) -> Self {
        let (nb, nv) = (model.nbody(), model.nv);
        Self {
            x_tree: vec![Transform::identity(); nb],
            v: vec![Motion::zero(); nb],
            a: vec![Motion::zero(); nb],
            i_c: vec![RigidInertia::zero(); nb],
            idot_c: vec![RigidInertia::zero(); nb],
            h_c: vec![Force::zero(); nb],
            f_c: vec![Force::zero(); nb],
            s: vec![Motion::zero(); nv],
            a_col: vec![Motion::zero(); nv],
            phi: vec![Motion::zero(); nv],
            psi: vec![Motion::zero(); nv],
            child_attached: vec![true; nv],
        }
    }

    /// Bodies the buffers were made for.
    pub fn nbody(&self) -> usize {
        self.x_tree.len()
    }

    /// τ = RNEA(q, v, qacc) into `data.tau` (armature included), ∂τ/∂q (tangent columns) and
    /// ∂τ/∂v into `out` (in that order); updates `data`'s joint transforms and subspaces at q.
    pub fn compute(
        &mut self,
        model: &Model,
        data: &mut Data,
        q: &[f64],
        v: &[f64],
        qacc: &[f64],
        out: (&mut DMatrix<f64>, &mut DMatrix<f64>),
    ) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2 (checked just above), all `compute_avx2` requires.
            unsafe { self.compute_avx2(model, data, q, v, qacc, out) };
            return;
        }
        self.compute_kernel(model, data, q, v, qacc, out);
    }

    /// [`compute_kernel`](Self::compute_kernel) compiled for AVX2 (same operations, same bits).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn compute_avx2(
        &mut self,
        model: &Model,
        data: &mut Data,
        q: &[f64],
        v: &[f64],
        qacc: &[f64],
        out: (&mut DMatrix<f64>, &mut DMatrix<f64>),
    ) {
        self.compute_kernel(model, data, q, v, qacc, out);
    }

    #[inline(always)]
    fn compute_kernel(
        &mut self,
        model: &Model,
        data: &mut Data,
        q: &[f64],
        v: &[f64],
        qacc: &[f64],
        out: (&mut DMatrix<f64>, &mut DMatrix<f64>),
    ) {
        let nb = model.nbody();
        let gravity = Motion::new(Vec3::zeros(), -model.gravity);
        data.poses_stamp.keep_if(q);
        // Forward: poses, velocities, accelerations, per-body terms and per-dof columns.
        for b in 1..nb {
            update_joint(model, data, b, q);
            let p = model.bodies[b].parent;
            let x_pb = &data.x_parent_body[b];
            let (x, v_p, a_p) = if p == 0 {
                (Transform::new(x_pb.rot, Vec3::zeros()), Motion::zero(), gravity)
            } else {
                (self.x_tree[p] * *x_pb, self.v[p], self.a[p])
            };
            let j = model.joint_of(b);
            let (da, nv_j) = (j.dof_adr, j.kind.nv());
            let splits = matches!(j.kind, JointKind::Free | JointKind::Planar { .. });
            // The joint's velocity split by attachment, and the base's velocity and acceleration.
            let (mut vj_parent, mut vj_child) = (Motion::zero(), Motion::zero());
            let mut s_qacc = Motion::zero();
            for k in da..da + nv_j {
                let s_k = x.act_motion(&data.s_body[k]);
                let attached_to_child = !(splits && data.s_body[k].ang == Vec3::zeros());
                self.s[k] = s_k;
                self.child_attached[k] = attached_to_child;
                if attached_to_child {
                    vj_child += s_k * v[k];
                } else {
                    vj_parent += s_k * v[k];
                }
                s_qacc += s_k * qacc[k];
            }
            let w = v_p + vj_parent;
            let v_b = w + vj_child;
            // ā = a_p + Σ_parent-attached (S q̈ + v_p × S q̇); a_b adds the child columns.
            let mut a_base = a_p + v_p.cross_motion(&vj_parent);
            for k in da..da + nv_j {
                if !self.child_attached[k] {
                    a_base += self.s[k] * qacc[k];
                }
            }
            let a_b =
                a_p + s_qacc + v_p.cross_motion(&(vj_parent + vj_child)) + vj_parent.cross_motion(&vj_child);
            for k in da..da + nv_j {
                let s_k = self.s[k];
                let psi = w.cross_motion(&s_k);
                let u = if self.child_attached[k] { v_b } else { v_p };
                self.psi[k] = psi;
                self.phi[k] = a_base.cross_motion(&s_k) + w.cross_motion(&psi);
                self.a_col[k] = u.cross_motion(&s_k) + psi;
            }
            let inertia = model.bodies[b].inertia.transformed(&x);
            let h = inertia.mul_motion(&v_b);
            self.f_c[b] = inertia.mul_motion(&a_b) + v_b.cross_force(&h);
            self.idot_c[b] = inertia_rate(&inertia, &v_b);
            self.i_c[b] = inertia;
            self.h_c[b] = h;
            self.x_tree[b] = x;
            self.v[b] = v_b;
            self.a[b] = a_b;
        }
        let nv = model.nv;
        let (dtau_dq, dtau_dv) = out;
        dtau_dq.fill(0.0);
        dtau_dv.fill(0.0);
        let (dq, dv) = (dtau_dq.as_mut_slice(), dtau_dv.as_mut_slice());
        // Backward: subtree sums, then the rows and columns of each joint's dofs.
        for b in (1..nb).rev() {
            let j = model.joint_of(b);
            let (da, nv_j) = (j.dof_adr, j.kind.nv());
            let (i_c, idot_c, h_c, f_c) = (&self.i_c[b], &self.idot_c[b], self.h_c[b], self.f_c[b]);
            let mut df_dv = [Force::zero(); 6];
            let mut df_dq = [Force::zero(); 6];
            let mut p_col = [Force::zero(); 6];
            let mut q_col = [Force::zero(); 6];
            for (i, m) in (da..da + nv_j).enumerate() {
                let s_m = &self.s[m];
                let b_s = idot_c.mul_motion(s_m);
                let s_x_h = s_m.cross_force(&h_c);
                p_col[i] = i_c.mul_motion(s_m);
                q_col[i] = b_s - s_x_h;
                df_dv[i] = i_c.mul_motion(&self.a_col[m]) + b_s + s_x_h;
                let psi = &self.psi[m];
                df_dq[i] = s_m.cross_force(&f_c)
                    + i_c.mul_motion(&self.phi[m])
                    + idot_c.mul_motion(psi)
                    + psi.cross_force(&h_c);
                data.tau[m] = s_m.dot(&f_c) + model.dof_armature[m] * qacc[m];
            }
            // The joint's own block.
            for (i, m) in (da..da + nv_j).enumerate() {
                for k in da..da + nv_j {
                    let s_k = &self.s[k];
                    dv[k + m * nv] = s_k.dot(&df_dv[i]);
                    let mut x = s_k.dot(&df_dq[i]);
                    if self.child_attached[k] {
                        x += self.s[m].cross_motion(s_k).dot(&f_c);
                    }
                    dq[k + m * nv] = x;
                }
            }
            // The ancestors' rows of this joint's columns, and this joint's rows of theirs.
            let mut k = if nv_j > 0 { model.dof_parent[da] } else { usize::MAX };
            while k != usize::MAX {
                let (s_k, a_k, phi_k, psi_k) = (&self.s[k], &self.a_col[k], &self.phi[k], &self.psi[k]);
                for (i, m) in (da..da + nv_j).enumerate() {
                    dv[k + m * nv] = s_k.dot(&df_dv[i]);
                    dq[k + m * nv] = s_k.dot(&df_dq[i]);
                    dv[m + k * nv] = a_k.dot(&p_col[i]) + s_k.dot(&q_col[i]);
                    dq[m + k * nv] = phi_k.dot(&p_col[i]) + psi_k.dot(&q_col[i]);
                }
                k = model.dof_parent[k];
            }
            let p = model.bodies[b].parent;
            if p != 0 {
                let (i_b, idot_b) = (self.i_c[b], self.idot_c[b]);
                self.i_c[p] += &i_b;
                self.idot_c[p] += &idot_b;
                self.h_c[p] += h_c;
                self.f_c[p] += f_c;
            }
        }
    }
}

/// İ = v ×* I − I v× of a rigid-body inertia moving with velocity v (same frame): again of the
/// form [[İ_o, [ḣ]×], [−[ḣ]×, 0]], stored as a massless [`RigidInertia`] with first moment
/// ḣ = ω × h + m v_lin and rotational part İ_o = [ω]× I_o − I_o [ω]× − (h v_linᵀ + v_lin hᵀ) + 2 (v_lin · h) 1.
fn inertia_rate(i: &RigidInertia, v: &Motion) -> RigidInertia {
    let (w, vl, h) = (&v.ang, &v.lin, &i.h);
    // [ω]× I_o − I_o [ω]× = W + Wᵀ with W = [ω]× I_o ([ω]× antisymmetric, I_o symmetric).
    let wi = crate::spatial::skew(w) * i.i_origin;
    let mut i_dot: Mat3 = wi + wi.transpose();
    let hv = h * vl.transpose();
    i_dot -= hv + hv.transpose();
    let d = 2.0 * vl.dot(h);
    i_dot[(0, 0)] += d;
    i_dot[(1, 1)] += d;
    i_dot[(2, 2)] += d;
    RigidInertia { mass: 0.0, h: w.cross(h) + vl * i.mass, i_origin: i_dot }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The AVX2 build of the sweep gives the same bits as the portable one (no fused
    /// multiply–add, no reordering).
    #[test]
    #[cfg(target_arch = "x86_64")]
    #[ignore = "compares the CPU-specific (AVX2) build of the sweep with the portable one; needs such a CPU: cargo test --release -p lagrange --lib -- --ignored (as .ci/run does)"]
    fn avx2_sweep_is_bit_for_bit() {
        if !std::arch::is_x86_feature_detected!("avx2") {
            eprintln!("skipped: this CPU has no AVX2, the AVX2 sweep is never used here");
            return;
        }
        for (file, model, q) in crate::kernel_test_states::robots() {
            let mut data = Data::new(&model);
            let mut sweep = RneaSweep::new(&model);
            let nv = model.nv;
            let v: Vec<f64> = (0..nv).map(|k| 0.5 * (k as f64).cos()).collect();
            let a: Vec<f64> = (0..nv).map(|k| 0.3 - 0.1 * k as f64).collect();
            let (mut dq0, mut dv0) = (DMatrix::zeros(nv, nv), DMatrix::zeros(nv, nv));
            let (mut dq1, mut dv1) = (DMatrix::zeros(nv, nv), DMatrix::zeros(nv, nv));
            sweep.compute_kernel(&model, &mut data, &q, &v, &a, (&mut dq0, &mut dv0));
            // SAFETY: AVX2 is present (checked above).
            unsafe { sweep.compute_avx2(&model, &mut data, &q, &v, &a, (&mut dq1, &mut dv1)) };
            assert_eq!(dq0.as_slice(), dq1.as_slice(), "{file}");
            assert_eq!(dv0.as_slice(), dv1.as_slice(), "{file}");
        }
    }
}
