//! Actuator transmissions (MuJoCo's `mj_transmission`; MuJoCo documentation, "Computation →
//! Actuation model → Transmission" and "XML Reference → actuator → general", attributes `joint`,
//! `jointinparent`, `tendon`, `site`, `refsite`, `gear`): for each actuator, its scalar length
//! and its moment arms (one row of `actuator_moment`), the row through which the scalar actuator
//! force becomes the generalized force, and whose product with v is `actuator_velocity`.
//!
//! | transmission | length | moment row |
//! | --- | --- | --- |
//! | hinge or slide joint | gear₀ · q | gear₀ on the joint's dof |
//! | ball joint | r · g, with r the rotation vector of the (normalized) joint quaternion | g on the 3 dofs |
//! | free joint | 0 | (gear₀₋₂, g) on the 6 dofs |
//! | fixed tendon | gear₀ · Σ coef · q | gear₀ · coef |
//! | spatial tendon | gear₀ · `ten_length` | gear₀ · `ten_J` (`crate::tendon`) |
//! | site | 0 | J_siteᵀ (R_site gear) |
//! | site with refsite | Rᵣᵀ(p_site − pᵣ) · gear₀₋₂ + log(Rᵣᵀ R_site) · gear₃₋₅ | (J_site − Jᵣ)ᵀ (Rᵣ gear), 0 on common ancestor dofs |
//! | slider-crank | gear₀ (a·d − √((a·d)² + r² − d·d)) | gear₀ ∂length/∂q through d and a |
//!
//! g is gear₀₋₂ (ball) or gear₃₋₅ (free) for `joint`; for `jointinparent` the same vector given in
//! the parent frame, i.e. Rᵀ g with R the joint's rotation. J are world-aligned Jacobians (linear
//! rows at the site's origin, angular rows), R world rotations, log the rotation vector with its
//! angle in (−π, π]. Without a reference site MuJoCo defines no length (0); the moment then
//! applies the gear as a wrench in the site's frame. With one, the common ancestor dofs of the two
//! sites move both together and get no moment, as in MuJoCo; the rotational rows use the angular
//! velocity in the reference frame, which is the derivative of the rotation-vector length only at
//! small relative rotations (MuJoCo's definition, kept for equality with it).
//!
//! Slider-crank (`cranksite`, `slidersite`, `cranklength` r): d = p_crank − p_slider, a the
//! slider site's z axis; the length is the slider's position along a at which the rod of length
//! r reaches the crank pin. When the rod cannot reach (the square root's argument ≤ 0) MuJoCo
//! takes length a·d and derivatives d (w.r.t. a) and a (w.r.t. d); so does this.

use crate::kinematics::for_each_ancestor_dof_at;
use crate::model::actuator::{Actuator, Transmission};
use crate::model::{JointKind, Model, TendonKind};
use crate::spatial::{Mat3, Motion, Transform, Vec3};
use nalgebra::DMatrix;

/// The poses a site transmission needs (from forward kinematics at the same q), and the
/// tendons' lengths and Jacobians at q (`crate::tendon`) for spatial-tendon transmissions.
#[derive(Clone, Copy)]
pub(crate) struct Poses<'a> {
    pub x_world_body: &'a [Transform],
    pub s_body: &'a [Motion],
    pub x_world_frame: &'a [Transform],
    pub ten_length: &'a nalgebra::DVector<f64>,
    pub ten_j: &'a DMatrix<f64>,
}

/// Whether the transmission needs body and site poses (a site, slider-crank or body
/// transmission).
pub(crate) fn needs_poses(a: &Actuator) -> bool {
    matches!(
        a.transmission,
        Transmission::Site { .. } | Transmission::SliderCrank { .. } | Transmission::Body(_)
    )
}

/// The rotation vector (axis · angle, angle in (−π, π]) of the unit quaternion (w, x, y, z):
/// MuJoCo's `mju_quat2Vel` with dt = 1.
pub(crate) fn rotation_vector(w: f64, x: f64, y: f64, z: f64) -> Vec3 {
    let axis = Vec3::new(x, y, z);
    let s = axis.norm();
    if s == 0.0 {
        return Vec3::zeros();
    }
    let mut angle = 2.0 * s.atan2(w);
    if angle > std::f64::consts::PI {
        angle -= 2.0 * std::f64::consts::PI;
    }
    axis * (angle / s)
}

/// The rotation vector of a rotation matrix (through its quaternion).
fn matrix_rotation_vector(r: &Mat3) -> Vec3 {
    let [w, x, y, z] = Transform::new(*r, Vec3::zeros()).quat_wxyz();
    rotation_vector(w, x, y, z)
}

/// The normalized quaternion at `q[adr..adr + 4]` and its rotation matrix.
fn joint_rotation(q: &[f64], adr: usize) -> ([f64; 4], Mat3) {
    let n = (q[adr] * q[adr] + q[adr + 1] * q[adr + 1] + q[adr + 2] * q[adr + 2] + q[adr + 3] * q[adr + 3])
        .sqrt();
    let n = if n > 0.0 { n } else { 1.0 };
    let u = [q[adr] / n, q[adr + 1] / n, q[adr + 2] / n, q[adr + 3] / n];
    (u, crate::spatial::quat_to_matrix(u[0], u[1], u[2], u[3]))
}

/// Whether body `a` is `b` or one of its ancestors.
fn is_ancestor_or_self(model: &Model, a: usize, mut b: usize) -> bool {
    loop {
        if a == b {
            return true;
        }
        if b == 0 {
            return false;
        }
        b = model.bodies[b].parent;
    }
}

/// Adds to `moment` row `i` the projection of the world-aligned Jacobian of the point `p` on
/// body `body` onto the wrench (`w_lin`, `w_ang`) (world axes), times `sign`, on every dof that
/// moves `body` except those that also move `other` (when given).
#[allow(clippy::too_many_arguments)]
fn add_projected_jacobian(
    model: &Model,
    poses: Poses,
    body: usize,
    p: &Vec3,
    (w_lin, w_ang): (&Vec3, &Vec3),
    sign: f64,
    other: Option<usize>,
    moment: &mut DMatrix<f64>,
    i: usize,
) {
    for_each_ancestor_dof_at(model, poses.x_world_body, poses.s_body, body, p, |k, lin, ang| {
        if let Some(o) = other {
            if is_ancestor_or_self(model, model.dof_body[k], o) {
                return;
            }
        }
        moment[(i, k)] += sign * (w_lin.dot(&lin) + w_ang.dot(&ang));
    });
}

/// The length of actuator `i` at q; adds its moment arms to row `i` of `moment` (the caller
/// zeroes it). `poses` must hold forward kinematics at q when [`needs_poses`], and the tendons
/// at q. Transmissions not simulated (planar joints, body) give length 0 and no moment.
/// The dofs where actuator `a`'s moment row can be nonzero: its joint's for a joint
/// transmission (the rest of the row stays zero), every dof otherwise.
pub(crate) fn moment_span(model: &Model, a: &Actuator) -> std::ops::Range<usize> {
    match &a.transmission {
        Transmission::Joint(j) | Transmission::JointInParent(j) => {
            let joint = &model.joints[*j];
            joint.dof_adr..joint.dof_adr + joint.kind.nv()
        }
        _ => 0..model.nv,
    }
}

pub(crate) fn transmission(
    model: &Model,
    a: &Actuator,
    q: &[f64],
    poses: Poses,
    moment: &mut DMatrix<f64>,
    i: usize,
) -> f64 {
    let gear = &a.gear;
    let lin_gear = Vec3::new(gear[0], gear[1], gear[2]);
    let ang_gear = Vec3::new(gear[3], gear[4], gear[5]);
    match &a.transmission {
        Transmission::Joint(j) | Transmission::JointInParent(j) => {
            let joint = &model.joints[*j];
            let (qa, da) = (joint.qpos_adr, joint.dof_adr);
            let in_parent = matches!(a.transmission, Transmission::JointInParent(_));
            match joint.kind {
                JointKind::Revolute { .. } | JointKind::Prismatic { .. } => {
                    moment[(i, da)] += gear[0];
                    gear[0] * q[qa]
                }
                JointKind::Ball => {
                    let (u, r) = joint_rotation(q, qa);
                    let g = if in_parent { r.tr_mul(&lin_gear) } else { lin_gear };
                    for k in 0..3 {
                        moment[(i, da + k)] += g[k];
                    }
                    rotation_vector(u[0], u[1], u[2], u[3]).dot(&g)
                }
                JointKind::Free => {
                    let g = if in_parent { joint_rotation(q, qa + 3).1.tr_mul(&ang_gear) } else { ang_gear };
                    for k in 0..3 {
                        moment[(i, da + k)] += gear[k];
                        moment[(i, da + 3 + k)] += g[k];
                    }
                    0.0
                }
                JointKind::Planar { .. } => 0.0,
            }
        }
        Transmission::Tendon(t) => match &model.tendons[*t].kind {
            TendonKind::Fixed { joints } => {
                let mut length = 0.0;
                for &(j, coef) in joints {
                    let joint = &model.joints[j];
                    moment[(i, joint.dof_adr)] += gear[0] * coef;
                    length += gear[0] * coef * q[joint.qpos_adr];
                }
                length
            }
            TendonKind::Spatial { .. } => {
                for k in 0..model.nv {
                    moment[(i, k)] += gear[0] * poses.ten_j[(*t, k)];
                }
                gear[0] * poses.ten_length[*t]
            }
        },
        Transmission::Site { site, refsite: None } => {
            let x = &poses.x_world_frame[*site];
            let wrench = (x.rot * lin_gear, x.rot * ang_gear);
            let body = model.frames[*site].body;
            add_projected_jacobian(model, poses, body, &x.pos, (&wrench.0, &wrench.1), 1.0, None, moment, i);
            0.0
        }
        Transmission::Site { site, refsite: Some(refsite) } => {
            let (x, xr) = (&poses.x_world_frame[*site], &poses.x_world_frame[*refsite]);
            let (body, ref_body) = (model.frames[*site].body, model.frames[*refsite].body);
            let length = xr.rot.tr_mul(&(x.pos - xr.pos)).dot(&lin_gear)
                + matrix_rotation_vector(&(xr.rot.transpose() * x.rot)).dot(&ang_gear);
            let wrench = (xr.rot * lin_gear, xr.rot * ang_gear);
            let w = (&wrench.0, &wrench.1);
            add_projected_jacobian(model, poses, body, &x.pos, w, 1.0, Some(ref_body), moment, i);
            add_projected_jacobian(model, poses, ref_body, &xr.pos, w, -1.0, Some(body), moment, i);
            length
        }
        Transmission::SliderCrank { cranksite, slidersite, cranklength } => {
            let (xc, xs) = (&poses.x_world_frame[*cranksite], &poses.x_world_frame[*slidersite]);
            let axis = xs.rot.column(2).into_owned();
            let d = xc.pos - xs.pos;
            let ad = axis.dot(&d);
            let det = ad * ad + cranklength * cranklength - d.dot(&d);
            let (length, dl_da, dl_dd) = if det > 0.0 {
                let s = det.sqrt();
                (ad - s, d * (1.0 - ad / s), axis * (1.0 - ad / s) + d / s)
            } else {
                (ad, d, axis)
            };
            let g = gear[0];
            // Through d: + the crank pin's Jacobian, − the slider site's; through a: ω × a.
            let crank_body = model.frames[*cranksite].body;
            for_each_ancestor_dof_at(
                model,
                poses.x_world_body,
                poses.s_body,
                crank_body,
                &xc.pos,
                |k, lin, _| {
                    moment[(i, k)] += g * dl_dd.dot(&lin);
                },
            );
            let slider_body = model.frames[*slidersite].body;
            for_each_ancestor_dof_at(
                model,
                poses.x_world_body,
                poses.s_body,
                slider_body,
                &xs.pos,
                |k, lin, ang| {
                    moment[(i, k)] += g * (dl_da.dot(&ang.cross(&axis)) - dl_dd.dot(&lin));
                },
            );
            g * length
        }
        Transmission::Body(_) => 0.0,
    }
}
