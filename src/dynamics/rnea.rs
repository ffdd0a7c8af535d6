//! Recursive Newton–Euler inverse dynamics (RBDA §5.3, Table 5.1).

use crate::error::{check, InputError};
use crate::kinematics::{joint_velocity, update_joint};
use crate::model::{Data, JointKind, Model};
use crate::spatial::{Force, Motion, Vec3};
use nalgebra::DVector;

/// Inverse dynamics τ = M(q) q̈ + c(q, v) into `data.tau` (and returned). Gravity enters as a
/// fictitious upward acceleration of the world (RBDA §5.3); armature adds `armature · q̈`.
///
/// # Errors
/// [`InputError::Length`] when q is not nq long, v or qacc not nv long, or `data` was made for
/// another model.
///
/// ```
/// use lagrange::prelude::*;
/// let model = Model::from_file("models/ur5/ur5.urdf")?;
/// let mut data = Data::new(&model);
/// let (q, v, qacc) = (vec![0.1; 6], vec![0.0; 6], vec![0.0; 6]);
/// let tau = lagrange::dynamics::rnea(&model, &mut data, &q, &v, &qacc)?;
/// assert!(tau[1].abs() > 1.0); // the shoulder holds the arm against gravity
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn rnea<'d>(
    model: &Model,
    data: &'d mut Data,
    q: &[f64],
    v: &[f64],
    qacc: &[f64],
) -> Result<&'d DVector<f64>, InputError> {
    check::data("rnea", model, data)?;
    check::q("rnea", model, q)?;
    check::v("rnea", "v", model, v)?;
    check::v("rnea", "qacc", model, qacc)?;
    Ok(rnea_unchecked(model, data, q, v, qacc))
}

/// [`rnea`] without the argument checks.
pub(crate) fn rnea_unchecked<'d>(
    model: &Model,
    data: &'d mut Data,
    q: &[f64],
    v: &[f64],
    qacc: &[f64],
) -> &'d DVector<f64> {
    rnea_dispatch::<true>(model, data, q, v, qacc);
    &data.tau
}

/// [`rnea_kernel`] compiled for AVX2 where the CPU has it; `ACC`: with the accelerations `qacc`
/// (without, `qacc` is not read: the bias forces).
#[inline(always)]
fn rnea_dispatch<const ACC: bool>(model: &Model, data: &mut Data, q: &[f64], v: &[f64], qacc: &[f64]) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2 (checked just above), all `rnea_avx2` requires.
        unsafe { rnea_avx2::<ACC>(model, data, q, v, qacc) };
        return;
    }
    rnea_kernel::<ACC>(model, data, q, v, qacc);
}

/// [`rnea_kernel`] compiled for AVX2, as ABA's: no fused multiply–add (Rust fuses none unasked),
/// so the bits of the baseline build.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn rnea_avx2<const ACC: bool>(model: &Model, data: &mut Data, q: &[f64], v: &[f64], qacc: &[f64]) {
    rnea_kernel::<ACC>(model, data, q, v, qacc);
}

/// The two passes. Without `ACC` (q̈ = 0, the bias forces) the terms of q̈ are left out (`S q̈`
/// in a body's acceleration, `armature · q̈` in τ): adding their zeros changes no bit but the
/// sign of a zero sum. A body without inertia (a massless link between two hinges of one MuJoCo
/// body) needs no force of its own: I a + v ×* I v is zero (up to the signs of zeros), so its
/// net force is its children's alone.
#[inline(always)]
fn rnea_kernel<const ACC: bool>(model: &Model, data: &mut Data, q: &[f64], v: &[f64], qacc: &[f64]) {
    // The joint transforms and subspaces of an earlier pass at this q (the position stage's, the
    // same bits) are not formed again (`Data::poses_stamp`).
    let posed = data.poses_stamp.matches(q);
    if !posed {
        data.poses_stamp.clear();
    }
    data.v_body[0] = Motion::zero();
    data.a_body[0] = Motion::new(Vec3::zeros(), -model.gravity);
    // Pass 1, root to leaves: body velocities, accelerations and the net force each needs.
    for b in 1..model.nbody() {
        if !posed {
            update_joint(model, data, b, q);
        }
        let p = model.bodies[b].parent;
        let x = data.x_parent_body[b];
        let j = model.joint_of(b);
        let (v_body, a_body) = if matches!(j.kind, JointKind::Revolute { .. }) {
            // A hinge's column is (axis, 0) (`update_joint`): the joint's velocity (axis q̇, 0)
            // and acceleration have no linear part, and the products with those zeros are left
            // out (the same bits up to the signs of zeros).
            let k = j.dof_adr;
            let axis = data.s_body[k].ang;
            let w = axis * v[k];
            let mut v_body = x.inv_act_motion(&data.v_body[p]);
            v_body.ang += w;
            let mut a_body = x.inv_act_motion(&data.a_body[p]);
            if ACC {
                a_body.ang += axis * qacc[k];
            }
            // v × (w, 0) = (ω × w, v_lin × w).
            a_body.ang += v_body.ang.cross(&w);
            a_body.lin += v_body.lin.cross(&w);
            (v_body, a_body)
        } else {
            let v_joint = joint_velocity(model, data, b, v);
            let mut a_joint = j.kind.bias_motion(&v_joint);
            if ACC {
                for k in j.dof_adr..j.dof_adr + j.kind.nv() {
                    a_joint += data.s_body[k] * qacc[k];
                }
            }
            let v_body = x.inv_act_motion(&data.v_body[p]) + v_joint;
            (v_body, x.inv_act_motion(&data.a_body[p]) + a_joint + v_body.cross_motion(&v_joint))
        };
        let inertia = &model.bodies[b].inertia;
        // f = I a + v ×* I v (RBDA eq. 5.9).
        data.f_body[b] = if inertia.is_zero() {
            Force::zero()
        } else {
            inertia.mul_motion(&a_body) + v_body.cross_force(&inertia.mul_motion(&v_body))
        };
        data.v_body[b] = v_body;
        data.a_body[b] = a_body;
    }
    data.velocity_stamp.set(q, v);
    // Pass 2, leaves to root: project forces on the joint axes, pass the rest to the parent.
    for b in (1..model.nbody()).rev() {
        let j = model.joint_of(b);
        if !ACC && matches!(j.kind, JointKind::Revolute { .. }) {
            // S = (axis, 0): S · f = axis · f_ang (the same bits up to the sign of a zero).
            data.tau[j.dof_adr] = data.s_body[j.dof_adr].ang.dot(&data.f_body[b].ang);
        } else {
            for k in j.dof_adr..j.dof_adr + j.kind.nv() {
                data.tau[k] = if ACC {
                    data.s_body[k].dot(&data.f_body[b]) + model.dof_armature[k] * qacc[k]
                } else {
                    data.s_body[k].dot(&data.f_body[b])
                };
            }
        }
        let p = model.bodies[b].parent;
        if p != 0 {
            let f_parent = data.x_parent_body[b].act_force(&data.f_body[b]);
            data.f_body[p] += f_parent;
        }
    }
}

/// Bias forces c(q, v) = RNEA(q, v, 0): Coriolis, centrifugal and gravity (MuJoCo's
/// `qfrc_bias`), into `data.tau`.
///
/// # Errors
/// As [`rnea`].
pub fn bias_forces<'d>(
    model: &Model,
    data: &'d mut Data,
    q: &[f64],
    v: &[f64],
) -> Result<&'d DVector<f64>, InputError> {
    check::data("bias_forces", model, data)?;
    check::q("bias_forces", model, q)?;
    check::v("bias_forces", "v", model, v)?;
    Ok(bias_forces_unchecked(model, data, q, v))
}

/// [`bias_forces`] without the argument checks.
pub(crate) fn bias_forces_unchecked<'d>(
    model: &Model,
    data: &'d mut Data,
    q: &[f64],
    v: &[f64],
) -> &'d DVector<f64> {
    rnea_dispatch::<false>(model, data, q, v, &[]);
    &data.tau
}

/// Generalized gravity g(q) = RNEA(q, 0, 0), into `data.tau`.
///
/// # Errors
/// As [`rnea`].
pub fn gravity_forces<'d>(
    model: &Model,
    data: &'d mut Data,
    q: &[f64],
) -> Result<&'d DVector<f64>, InputError> {
    check::data("gravity_forces", model, data)?;
    check::q("gravity_forces", model, q)?;
    data.scratch_v.fill(0.0);
    let zeros = std::mem::take(&mut data.scratch_v);
    rnea_unchecked(model, data, q, zeros.as_slice(), zeros.as_slice());
    data.scratch_v = zeros;
    Ok(&data.tau)
}
