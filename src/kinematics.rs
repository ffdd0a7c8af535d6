//! Forward kinematics, body velocities and frame Jacobians (RBDA §4.1, §8.1).

use crate::error::{check, InputError};
use crate::model::{Data, FrameKind, HingeAxis, JointKind, Model};
#[cfg(target_arch = "x86_64")]
use crate::spatial::fused::Fused;
use crate::spatial::fused::{self, MulAdd, Separate};
use crate::spatial::{Mat3, Motion, Transform, Vec3};
use nalgebra::DMatrix;

/// Updates one body's joint: `x_parent_body[b]` = placement · X_J(q) and its motion-subspace
/// columns `s_body` (body coordinates). Shared first step of every recursive algorithm.
///
/// Dispatched once on the joint type: a hinge or slide (the common case) composes the placement
/// with the joint's rotation or translation directly ([`revolute_placement`]), without forming
/// X_J(q) and multiplying two general transforms.
#[inline(always)]
pub(crate) fn update_joint(model: &Model, data: &mut Data, b: usize, q: &[f64]) {
    let body = &model.bodies[b];
    let j = model.joint_of(b);
    let (qa, da) = (j.qpos_adr, j.dof_adr);
    match &j.kind {
        JointKind::Revolute { axis, .. } => {
            data.x_parent_body[b] = revolute_placement(
                &body.x_parent_joint,
                axis,
                model.hinge_axis[b],
                model.placement_unrotated[b],
                q[qa],
            );
            set_hinge_column(data, da, axis);
        }
        JointKind::Prismatic { axis } => {
            let x_pj = &body.x_parent_joint;
            data.x_parent_body[b] = Transform::new(x_pj.rot, x_pj.pos + x_pj.rot * (axis * q[qa]));
            data.s_body[da] = Motion::new(Vec3::zeros(), *axis);
        }
        kind => {
            let x_joint = kind.transform(&q[qa..qa + kind.nq()]);
            data.x_parent_body[b] = body.x_parent_joint * x_joint;
            kind.motion_subspace(&x_joint, &mut data.s_body[da..da + kind.nv()]);
        }
    }
}

/// `x_parent_joint · X_J(angle)` for a rotation by `angle` about the unit `axis` (joint frame):
/// the translation is the placement's, the rotation `R_pj · R(axis, angle)` (RBDA Table 4.1,
/// revolute row). About a principal axis ±x, ±y, ±z (`principal`, the body's
/// [`Model::hinge_axis`](crate::Model::hinge_axis)) only two columns of `R_pj` turn (12
/// products; none when the placement is `unrotated`, R_pj = 1); any other axis goes through
/// Rodrigues' formula R = I + s[a]× + (1 − c)[a]×².
/// Sine and cosine come from the `libm` crate's `sincos` (musl's kernels, one range reduction
/// for both, < 1 ulp), compiled into lagrange: ~40% fewer instructions than the system library's
/// call, a measurable share of CRBA and FK on hinge chains.
#[inline(always)]
pub(crate) fn revolute_placement(
    x_pj: &Transform,
    axis: &Vec3,
    principal: HingeAxis,
    unrotated: bool,
    angle: f64,
) -> Transform {
    if principal == HingeAxis::Other {
        return Transform::new(x_pj.rot * crate::model::axis_angle(axis, angle), x_pj.pos);
    }
    let (s, c) = libm::sincos(angle);
    let rot = if unrotated {
        principal_rotation(axis, principal, s, c)
    } else {
        turn_columns::<Separate>(&x_pj.rot, axis, principal, s, c)
    };
    Transform::new(rot, x_pj.pos)
}

/// `r · R(axis, θ)` for a hinge about a coordinate axis (`principal` ≠ `Other`), from s = sin θ
/// and c = cos θ: the two columns (u, w) of r across the axis turn to (c u + s' w, c w − s' u),
/// s' = ±s by the axis's sign; the third is kept.
#[inline(always)]
fn turn_columns<A: MulAdd>(r: &Mat3, axis: &Vec3, principal: HingeAxis, s: f64, c: f64) -> Mat3 {
    let signed = match principal {
        HingeAxis::X => s * axis.x,
        HingeAxis::Y => s * axis.y,
        _ => s * axis.z,
    };
    turn_columns_signed::<A>(r, principal, signed, c)
}

/// [`turn_columns`] from s' = ±s (the sine times the axis's sign, as [`principal_rotation`]
/// stores it) and c.
#[inline(always)]
fn turn_columns_signed<A: MulAdd>(r: &Mat3, principal: HingeAxis, s: f64, c: f64) -> Mat3 {
    let col = |i: usize| r.column(i).into_owned();
    let turn = |u: Vec3, w: Vec3| {
        let f = |k: usize| (A::madd(w[k], s, u[k] * c), A::madd(-u[k], s, w[k] * c));
        let (a, b, d) = (f(0), f(1), f(2));
        (Vec3::new(a.0, b.0, d.0), Vec3::new(a.1, b.1, d.1))
    };
    match principal {
        HingeAxis::X => {
            let (n1, n2) = turn(col(1), col(2));
            Mat3::from_columns(&[col(0), n1, n2])
        }
        HingeAxis::Y => {
            let (n2, n0) = turn(col(2), col(0));
            Mat3::from_columns(&[n0, col(1), n2])
        }
        _ => {
            let (n0, n1) = turn(col(0), col(1));
            Mat3::from_columns(&[n0, n1, col(2)])
        }
    }
}

/// (s', c) back from a [`principal_rotation`] `rot` about `principal`: the entries it stored,
/// the same bits.
#[inline(always)]
fn principal_sin_cos(rot: &Mat3, principal: HingeAxis) -> (f64, f64) {
    match principal {
        HingeAxis::X => (rot[(2, 1)], rot[(1, 1)]),
        HingeAxis::Y => (rot[(0, 2)], rot[(0, 0)]),
        _ => (rot[(1, 0)], rot[(0, 0)]),
    }
}

/// R(axis, θ) itself for a hinge about a coordinate axis: [`turn_columns`] of the identity,
/// written out (no products).
#[inline(always)]
fn principal_rotation(axis: &Vec3, principal: HingeAxis, s: f64, c: f64) -> Mat3 {
    match principal {
        HingeAxis::X => {
            let s = s * axis.x;
            Mat3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c)
        }
        HingeAxis::Y => {
            let s = s * axis.y;
            Mat3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c)
        }
        _ => {
            let s = s * axis.z;
            Mat3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
        }
    }
}

/// For body b on a hinge about a coordinate axis (`model.hinge_axis[b]` ≠ `Other`): what
/// [`update_joint`] writes (`x_parent_body[b]`, `s_body`), and the body's world pose
/// `x_world_parent · x_parent_body`, returned (not stored). With an unrotated placement the world
/// rotation is the parent's with two columns turned ([`turn_columns`], 12 products) and the
/// position `R_wp p_pj + p_wp` (9): no 3×3 product, a third of the work of a general composition.
#[inline(always)]
pub(crate) fn hinge_world_pose<A: MulAdd>(model: &Model, data: &mut Data, b: usize, q: &[f64]) -> Transform {
    let body = &model.bodies[b];
    let j = model.joint_of(b);
    let JointKind::Revolute { axis, .. } = &j.kind else {
        unreachable!("hinge_world_pose on a body whose joint is not a hinge")
    };
    let principal = model.hinge_axis[b];
    set_hinge_column(data, j.dof_adr, axis);
    let x_world_parent = &data.x_world_body[body.parent];
    let x_pj = &body.x_parent_joint;
    if !model.placement_unrotated[b] {
        let x_parent_body = revolute_placement(x_pj, axis, principal, false, q[j.qpos_adr]);
        data.x_parent_body[b] = x_parent_body;
        return fused::compose::<A>(x_world_parent, &x_parent_body);
    }
    let (s, c) = libm::sincos(q[j.qpos_adr]);
    let rot = turn_columns::<A>(&x_world_parent.rot, axis, principal, s, c);
    let pos = fused::mat_vec_add::<A>(&x_world_parent.rot, &x_pj.pos, &x_world_parent.pos);
    data.x_parent_body[b] = Transform::new(principal_rotation(axis, principal, s, c), x_pj.pos);
    Transform::new(rot, pos)
}

/// A hinge's motion-subspace column (axis, 0) into `s_body[dof]`, field by field (a whole-`Motion`
/// store is staged through the stack).
#[inline(always)]
fn set_hinge_column(data: &mut Data, dof: usize, axis: &Vec3) {
    let s = &mut data.s_body[dof];
    s.ang = *axis;
    s.lin = Vec3::zeros();
}

/// [`body_world_pose`] of a body whose joint transform and subspace are already those of the
/// configuration (`x_parent_body[b]`, `s_body`: an earlier pass at the same q,
/// `Data::poses_stamp`): the same bits, without forming the joint again (no sine or cosine: a
/// hinge on an unrotated placement reads them back from its `x_parent_body` rotation).
#[inline(always)]
pub(crate) fn posed_world_pose<A: MulAdd, const HINGE: bool>(
    model: &Model,
    data: &Data,
    b: usize,
) -> Transform {
    let body = &model.bodies[b];
    let x_world_parent = &data.x_world_body[body.parent];
    let x_parent_body = &data.x_parent_body[b];
    if HINGE && model.placement_unrotated[b] {
        let principal = model.hinge_axis[b];
        let (s, c) = principal_sin_cos(&x_parent_body.rot, principal);
        let rot = turn_columns_signed::<A>(&x_world_parent.rot, principal, s, c);
        let pos = fused::mat_vec_add::<A>(&x_world_parent.rot, &body.x_parent_joint.pos, &x_world_parent.pos);
        return Transform::new(rot, pos);
    }
    fused::compose::<A>(x_world_parent, x_parent_body)
}

/// Body b's world pose `x_world_parent · x_parent_body` (returned, not stored), after its joint's
/// update ([`update_joint`]); `HINGE` (the body's hinge turns about a coordinate axis, checked by
/// the caller against `Model::hinge_axis`) takes [`hinge_world_pose`]. A constant, so that a
/// caller dispatching once per body gets each arm compiled on its own.
#[inline(always)]
pub(crate) fn body_world_pose<A: MulAdd, const HINGE: bool>(
    model: &Model,
    data: &mut Data,
    b: usize,
    q: &[f64],
) -> Transform {
    if HINGE {
        hinge_world_pose::<A>(model, data, b, q)
    } else {
        update_joint(model, data, b, q);
        fused::compose::<A>(&data.x_world_body[model.bodies[b].parent], &data.x_parent_body[b])
    }
}

/// Joint velocity `v_J = S q̇` of body `b`, body coordinates (needs `update_joint` first).
#[inline]
pub(crate) fn joint_velocity(model: &Model, data: &Data, b: usize, v: &[f64]) -> Motion {
    let j = model.joint_of(b);
    let mut v_joint = Motion::zero();
    for k in j.dof_adr..j.dof_adr + j.kind.nv() {
        v_joint += data.s_body[k] * v[k];
    }
    v_joint
}

/// Root to leaves: joint transforms and subspaces (`update_joint`), then
/// `x_world_body = x_world_parent · x_parent_body`. The first pass of FK and of CRBA.
#[inline]
/// Nothing when the poses already hold `q` (`Data::poses_stamp`, docs/architecture.md).
pub(crate) fn body_poses(model: &Model, data: &mut Data, q: &[f64]) {
    if data.poses_stamp.matches(q) {
        return;
    }
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2 (checked just above), all `body_poses_avx2` requires.
        unsafe { body_poses_avx2(model, data, q) };
        data.poses_stamp.set(q);
        return;
    }
    body_poses_with::<Separate>(model, data, q);
    data.poses_stamp.set(q);
}

/// [`body_poses`]' pass compiled for AVX2, as ABA's: separate multiplies and adds (no fused
/// multiply–add), so the bits of the baseline build.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn body_poses_avx2(model: &Model, data: &mut Data, q: &[f64]) {
    body_poses_with::<Separate>(model, data, q);
}

#[inline(always)]
fn body_poses_with<A: MulAdd>(model: &Model, data: &mut Data, q: &[f64]) {
    for b in 1..model.nbody() {
        data.x_world_body[b] = if model.hinge_axis[b] != HingeAxis::Other {
            body_world_pose::<A, true>(model, data, b, q)
        } else {
            body_world_pose::<A, false>(model, data, b, q)
        };
    }
}

/// Forward kinematics: pose of every body (`x_parent_body`, `x_world_body`) and of every named
/// frame (`x_world_frame`) at configuration `q`, and the motion subspaces (`s_body`).
///
/// On x86-64 CPUs with AVX2 and FMA3 it runs compiled for them, the compositions' products and
/// sums fused ([`fused`]), as CRBA does.
///
/// # Errors
/// [`InputError::Length`] when q is not nq long or `data` was made for another model.
pub fn forward_kinematics(model: &Model, data: &mut Data, q: &[f64]) -> Result<(), InputError> {
    check::data("forward_kinematics", model, data)?;
    check::q("forward_kinematics", model, q)?;
    data.poses_stamp.clear();
    data.velocity_stamp.clear();
    forward_kinematics_unchecked(model, data, q);
    Ok(())
}

/// [`forward_kinematics`] without the argument checks. The body poses are formed only when they
/// do not already hold `q` (`Data::poses_stamp`); the frames always are.
pub(crate) fn forward_kinematics_unchecked(model: &Model, data: &mut Data, q: &[f64]) {
    forward_kinematics_dispatch::<true>(model, data, q);
}

/// [`forward_kinematics_unchecked`] without the joint-anchor frames ([`FrameKind::Joint`]:
/// no sensor reads them; their entries of `x_world_frame` are left as they were): the link and
/// site frames the sensor stage reads, the same bits as [`forward_kinematics_unchecked`]'s.
pub(crate) fn forward_kinematics_sensed_unchecked(model: &Model, data: &mut Data, q: &[f64]) {
    forward_kinematics_dispatch::<false>(model, data, q);
}

/// [`forward_kinematics_with`] on the CPU's best path, with or without the joint-anchor frames.
#[inline(always)]
fn forward_kinematics_dispatch<const JOINT_FRAMES: bool>(model: &Model, data: &mut Data, q: &[f64]) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma") {
        // SAFETY: the CPU has AVX2 and FMA (checked just above), all `forward_kinematics_fma`
        // requires.
        unsafe { forward_kinematics_fma::<JOINT_FRAMES>(model, data, q) };
        return;
    }
    forward_kinematics_with::<Separate, JOINT_FRAMES>(model, data, q);
}

/// [`forward_kinematics_with`] compiled for AVX2 and FMA3, its multiply–adds fused.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn forward_kinematics_fma<const JOINT_FRAMES: bool>(model: &Model, data: &mut Data, q: &[f64]) {
    forward_kinematics_with::<Fused, JOINT_FRAMES>(model, data, q);
}

#[inline(always)]
fn forward_kinematics_with<A: MulAdd, const JOINT_FRAMES: bool>(model: &Model, data: &mut Data, q: &[f64]) {
    if !data.poses_stamp.matches(q) {
        body_poses_with::<A>(model, data, q);
        data.poses_stamp.set(q);
    }
    // Frames rigidly attached to bodies.
    for (f, frame) in model.frames.iter().enumerate() {
        if !JOINT_FRAMES && frame.kind == FrameKind::Joint {
            continue;
        }
        data.x_world_frame[f] = match frame.mocap {
            Some(m) => data.mocap_pose(m) * frame.x_body_frame,
            None => fused::compose::<A>(&data.x_world_body[frame.body], &frame.x_body_frame),
        };
    }
}

/// Spatial velocity of every body in body coordinates, `v_body` (RBDA eq. 5.7, first line), for
/// velocity `v`. Needs [`forward_kinematics`] (or any algorithm's first pass) at the same q.
///
/// # Errors
/// [`InputError::Length`] when v is not nv long or `data` was made for another model.
pub fn forward_velocities(model: &Model, data: &mut Data, v: &[f64]) -> Result<(), InputError> {
    check::data("forward_velocities", model, data)?;
    check::v("forward_velocities", "v", model, v)?;
    forward_velocities_unchecked(model, data, v);
    Ok(())
}

/// [`forward_velocities`] without the argument checks.
pub(crate) fn forward_velocities_unchecked(model: &Model, data: &mut Data, v: &[f64]) {
    data.velocity_stamp.clear();
    data.v_body[0] = Motion::zero();
    for b in 1..model.nbody() {
        let p = model.bodies[b].parent;
        let v_joint = joint_velocity(model, data, b, v);
        data.v_body[b] = data.x_parent_body[b].inv_act_motion(&data.v_body[p]) + v_joint;
    }
}

/// In which coordinates a frame velocity or Jacobian is expressed (Pinocchio's reference frames).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ReferenceFrame {
    /// Frame axes, velocity of the frame origin.
    Local,
    /// World axes, velocity of the frame origin (MuJoCo's `mj_jac` and Pinocchio's
    /// LOCAL_WORLD_ALIGNED).
    LocalWorldAligned,
    /// World axes, velocity of the body point passing through the world origin.
    World,
}

/// Calls `column(k, s_world)` for every degree of freedom `k` on the path from body `b` to the
/// root, with its motion-subspace column `s_world` in world coordinates (about the world origin).
/// The columns of all other degrees of freedom of a Jacobian of body `b` are zero. Far from the
/// world origin a point velocity formed from these columns (`lin + ang × p`) loses digits to
/// cancellation: use [`for_each_ancestor_dof_at`] for a point's. Needs
/// [`forward_kinematics`] (or any pass that fills `x_world_body` and `s_body`) at the same q.
/// `x_world_body` and `s_body` are those buffers of [`Data`] (passed apart so that the caller may
/// write another buffer of the same `Data`).
#[inline]
pub fn for_each_ancestor_dof(
    model: &Model,
    x_world_body: &[Transform],
    s_body: &[Motion],
    mut b: usize,
    mut column: impl FnMut(usize, Motion),
) {
    while b != 0 {
        let j = model.joint_of(b);
        for k in j.dof_adr..j.dof_adr + j.kind.nv() {
            column(k, x_world_body[b].act_motion(&s_body[k]));
        }
        b = model.bodies[b].parent;
    }
}

/// Calls `column(k, lin, ang)` for every degree of freedom `k` on the path from body `b` to the
/// root with the velocity its unit rate gives the body point at world position `p`: linear `lin`
/// of that point and angular `ang`, world axes (MuJoCo's `mj_jac` columns). The columns of all
/// other degrees of freedom are zero. Each column is formed about the moving body's own origin,
/// `R v + R ω × (p − p_b)`, not as `s_world.lin + ω × p` about the world origin
/// ([`for_each_ancestor_dof`]): far from the world origin the latter's two terms of size |p|
/// cancel and take the lever arm's digits with them. Needs [`forward_kinematics`] (or any pass
/// that fills `x_world_body` and `s_body`) at the same q.
#[inline]
pub fn for_each_ancestor_dof_at(
    model: &Model,
    x_world_body: &[Transform],
    s_body: &[Motion],
    mut b: usize,
    p: &Vec3,
    mut column: impl FnMut(usize, Vec3, Vec3),
) {
    while b != 0 {
        let j = model.joint_of(b);
        let x = &x_world_body[b];
        let r = p - x.pos;
        for k in j.dof_adr..j.dof_adr + j.kind.nv() {
            let ang = x.rot * s_body[k].ang;
            column(k, x.rot * s_body[k].lin + ang.cross(&r), ang);
        }
        b = model.bodies[b].parent;
    }
}

/// Jacobian of frame `frame` into `jac` (6 × nv): rows 0–2 linear, rows 3–5 angular velocity, in
/// `reference` coordinates (the row order of Pinocchio). Columns of degrees of freedom that do not
/// move the frame are zero. Needs [`forward_kinematics`] at the same q.
///
/// # Errors
/// [`InputError::Index`] when `frame` is not a frame of the model; [`InputError::Length`] when
/// `jac` is not 6 × nv or `data` was made for another model.
pub fn frame_jacobian(
    model: &Model,
    data: &Data,
    frame: usize,
    reference: ReferenceFrame,
    jac: &mut DMatrix<f64>,
) -> Result<(), InputError> {
    check::data("frame_jacobian", model, data)?;
    check::frame("frame_jacobian", model, frame)?;
    InputError::check_len("frame_jacobian", "jac (rows)", jac.nrows(), 6, "6")?;
    InputError::check_len("frame_jacobian", "jac (columns)", jac.ncols(), model.nv, "nv")?;
    frame_jacobian_unchecked(model, data, frame, reference, jac);
    Ok(())
}

/// [`frame_jacobian`] without the argument checks.
pub(crate) fn frame_jacobian_unchecked(
    model: &Model,
    data: &Data,
    frame: usize,
    reference: ReferenceFrame,
    jac: &mut DMatrix<f64>,
) {
    jac.fill(0.0);
    let x_world_frame = &data.x_world_frame[frame];
    let (b, rot_world_frame) = (model.frames[frame].body, &x_world_frame.rot);
    if reference == ReferenceFrame::World {
        for_each_ancestor_dof(model, &data.x_world_body, &data.s_body, b, |k, s_world| {
            jac.fixed_view_mut::<3, 1>(0, k).copy_from(&s_world.lin);
            jac.fixed_view_mut::<3, 1>(3, k).copy_from(&s_world.ang);
        });
        return;
    }
    // About the frame's origin directly (no round trip through the world origin).
    for_each_ancestor_dof_at(
        model,
        &data.x_world_body,
        &data.s_body,
        b,
        &x_world_frame.pos,
        |k, lin, ang| {
            let (lin, ang) = match reference {
                ReferenceFrame::Local => (rot_world_frame.tr_mul(&lin), rot_world_frame.tr_mul(&ang)),
                _ => (lin, ang),
            };
            jac.fixed_view_mut::<3, 1>(0, k).copy_from(&lin);
            jac.fixed_view_mut::<3, 1>(3, k).copy_from(&ang);
        },
    );
}

/// Spatial acceleration of every body at zero joint acceleration and without gravity, body
/// coordinates, into `data.a_bias_body`: a = X a_parent + c_J + v × v_J (RBDA eq. 5.7 with q̈ = 0).
/// It is what J̇v of a body-fixed point or frame is made of. Needs [`forward_velocities`] first.
///
/// # Errors
/// [`InputError::Length`] when v is not nv long or `data` was made for another model.
pub fn bias_accelerations(model: &Model, data: &mut Data, v: &[f64]) -> Result<(), InputError> {
    check::data("bias_accelerations", model, data)?;
    check::v("bias_accelerations", "v", model, v)?;
    bias_accelerations_unchecked(model, data, v);
    Ok(())
}

/// [`bias_accelerations`] without the argument checks.
pub(crate) fn bias_accelerations_unchecked(model: &Model, data: &mut Data, v: &[f64]) {
    data.a_bias_body[0] = Motion::zero();
    for b in 1..model.nbody() {
        let p = model.bodies[b].parent;
        let v_joint = joint_velocity(model, data, b, v);
        let j = model.joint_of(b);
        data.a_bias_body[b] = data.x_parent_body[b].inv_act_motion(&data.a_bias_body[p])
            + j.kind.bias_motion(&v_joint)
            + data.v_body[b].cross_motion(&v_joint);
    }
}

/// Classical (not spatial) acceleration and velocity of the point `r_body` fixed in body `b` at
/// zero joint acceleration, world coordinates: ä = R (a + α × r + ω × (v + ω × r)) with the body's
/// spatial velocity (ω, v) and bias acceleration (α, a) in body coordinates (RBDA §2.11). Also
/// returns the world angular bias acceleration R α. Needs [`bias_accelerations`].
#[inline]
pub fn point_bias_acceleration(data: &Data, b: usize, r_body: &Vec3) -> (Vec3, Vec3) {
    let (vb, ab) = (&data.v_body[b], &data.a_bias_body[b]);
    let v_point = vb.lin + vb.ang.cross(r_body);
    let a_point = ab.lin + ab.ang.cross(r_body) + vb.ang.cross(&v_point);
    let rot = &data.x_world_body[b].rot;
    (rot * a_point, rot * ab.ang)
}

/// Velocity (linear, angular) of frame `frame` in `reference` coordinates, from the body
/// velocities of [`forward_velocities`].
///
/// # Errors
/// [`InputError::Index`] when `frame` is not a frame of the model; [`InputError::Length`] when
/// `data` was made for another model.
pub fn frame_velocity(
    model: &Model,
    data: &Data,
    frame: usize,
    reference: ReferenceFrame,
) -> Result<(Vec3, Vec3), InputError> {
    check::data("frame_velocity", model, data)?;
    check::frame("frame_velocity", model, frame)?;
    Ok(frame_velocity_unchecked(model, data, frame, reference))
}

/// [`frame_velocity`] without the argument checks.
pub(crate) fn frame_velocity_unchecked(
    model: &Model,
    data: &Data,
    frame: usize,
    reference: ReferenceFrame,
) -> (Vec3, Vec3) {
    let b = model.frames[frame].body;
    let x_world_body = &data.x_world_body[b];
    if reference == ReferenceFrame::World {
        let v_world = x_world_body.act_motion(&data.v_body[b]);
        return (v_world.lin, v_world.ang);
    }
    // The frame origin's velocity from the body's own origin (R v + R ω × (p − p_b)), not through
    // the world origin: no cancellation far from it.
    let x_world_frame = &data.x_world_frame[frame];
    let ang = x_world_body.rot * data.v_body[b].ang;
    let lin = x_world_body.rot * data.v_body[b].lin + ang.cross(&(x_world_frame.pos - x_world_body.pos));
    match reference {
        ReferenceFrame::Local => (x_world_frame.rot.tr_mul(&lin), x_world_frame.rot.tr_mul(&ang)),
        _ => (lin, ang),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The fused (FMA3) build of forward kinematics gives the body and frame poses of the separate
    /// multiply–adds to round-off (cross-check tolerance).
    #[test]
    #[cfg(target_arch = "x86_64")]
    #[ignore = "compares the CPU-specific (AVX2/FMA) build of the kernel with the portable one; needs such a CPU: cargo test --release -p lagrange --lib -- --ignored (as .ci/run does)"]
    fn fma_kernel_matches_separate_multiply_adds() {
        if !crate::kernel_test_states::fma_available() {
            return;
        }
        for (file, model, q) in crate::kernel_test_states::robots() {
            let mut data = Data::new(&model);
            forward_kinematics_with::<Separate, true>(&model, &mut data, &q);
            let (bodies, frames) = (data.x_world_body.clone(), data.x_world_frame.clone());
            // SAFETY: AVX2 and FMA are present (checked above).
            unsafe { forward_kinematics_fma::<true>(&model, &mut data, &q) };
            for (a, b) in
                bodies.iter().chain(&frames).zip(data.x_world_body.iter().chain(&data.x_world_frame))
            {
                assert!((a.rot - b.rot).amax() <= 1e-12 && (a.pos - b.pos).amax() <= 1e-12, "{file}");
            }
        }
    }
}
