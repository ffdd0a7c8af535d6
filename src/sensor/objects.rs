//! World poses, orientations and velocities of the objects sensors measure (MuJoCo's
//! `get_xpos_xmat`, `get_xquat` in engine_sensor.c and `mj_objectVelocity` in engine_core_util.c):
//! a body's own frame (`xbody`: MuJoCo's `xpos`, `xmat`, `xquat`), its inertial frame (`body`: the
//! centre of mass `xipos` and principal axes `ximat`), a geom's or a site's frame.
//!
//! Quaternions are composed as MuJoCo composes `xquat` — parent ⊗ fixed offset ⊗ joint rotation,
//! down the tree — so their sign is MuJoCo's (q and −q are the same rotation; a sensor reports one).

use super::types::SensorObject;
use crate::model::{Data, JointKind, Model};
use crate::spatial::{quat_to_matrix, Mat3, Transform, Vec3};

pub(crate) use crate::mass::eig3::{self, mul_quat, normalize_quat, Quat};

/// The conjugate (inverse of a unit quaternion, MuJoCo's `mju_negQuat`).
pub(crate) fn neg_quat(q: &Quat) -> Quat {
    [q[0], -q[1], -q[2], -q[3]]
}

/// The quaternion of a fixed rotation (w ≥ 0); exactly the identity for the identity matrix.
pub(crate) fn rot_quat(r: &Mat3) -> Quat {
    if *r == Mat3::identity() {
        [1.0, 0.0, 0.0, 0.0]
    } else {
        Transform::new(*r, Vec3::zeros()).quat_wxyz()
    }
}

/// The world orientation of every compiled body as MuJoCo's `xquat` chain, into `out`.
pub(crate) fn body_quats(model: &Model, q: &[f64], out: &mut [Quat]) {
    out[0] = [1.0, 0.0, 0.0, 0.0];
    for b in 1..model.nbody() {
        let body = &model.bodies[b];
        let joint = model.joint_of(b);
        let a = joint.qpos_adr;
        let q_joint = match joint.kind {
            JointKind::Revolute { axis, .. } => {
                let (s, c) = (0.5 * q[a]).sin_cos();
                [c, s * axis[0], s * axis[1], s * axis[2]]
            }
            JointKind::Ball | JointKind::Free => {
                let off = if matches!(joint.kind, JointKind::Free) { 3 } else { 0 };
                normalize_quat(&q[a + off..a + off + 4])
            }
            JointKind::Prismatic { .. } | JointKind::Planar { .. } => [1.0, 0.0, 0.0, 0.0],
        };
        let q_parent = mul_quat(&out[body.parent], &rot_quat(&body.x_parent_joint.rot));
        out[b] = mul_quat(&q_parent, &q_joint);
    }
}

/// The world pose of a frame of `model.frames` (mocap frames included).
fn frame_pose(model: &Model, data: &Data, f: usize) -> Transform {
    let frame = &model.frames[f];
    data.attached_pose(frame.body, frame.mocap, &frame.x_body_frame)
}

/// The world quaternion of a frame (mocap frames included), from the compiled bodies' chain.
fn frame_quat(model: &Model, data: &Data, quats: &[Quat], f: usize) -> Quat {
    let frame = &model.frames[f];
    let base = match frame.mocap {
        Some(m) => normalize_quat(&data.mocap_quat[m]),
        None => quats[frame.body],
    };
    mul_quat(&base, &rot_quat(&frame.x_body_frame.rot))
}

/// The principal axes of a symmetric inertia tensor as MuJoCo's compiler orients a body's
/// (`body_iquat`; [`crate::mass::eig3`]).
pub(crate) fn principal_quat(inertia: &Mat3) -> Quat {
    eig3::principal_quat(inertia, &eig3::BODY)
}

/// The inertial frame of MuJoCo body `b` in its own frame: centre of mass and principal axes
/// (MuJoCo's `body_ipos`, `body_iquat`, [`Links::iquat`](crate::model::Links::iquat)).
pub(crate) fn inertial_frame(model: &Model, b: usize) -> Transform {
    let inertia = &model.frames[model.links.frame[b]].inertia;
    let q = model.links.iquat[b];
    Transform::new(
        quat_to_matrix(q[0], q[1], q[2], q[3]),
        if inertia.mass > 0.0 { inertia.com() } else { Vec3::zeros() },
    )
}

/// The world pose of a sensed object (MuJoCo's `get_xpos_xmat`); the identity for
/// [`SensorObject::None`] and the objects without a frame.
pub(crate) fn object_pose(model: &Model, data: &Data, obj: SensorObject) -> Transform {
    match obj {
        SensorObject::XBody(b) => frame_pose(model, data, model.links.frame[b]),
        SensorObject::Body(b) => frame_pose(model, data, model.links.frame[b]) * inertial_frame(model, b),
        SensorObject::Site(f) => frame_pose(model, data, f),
        SensorObject::Geom(g) => {
            let geom = &model.geoms[g];
            data.attached_pose(geom.body, geom.mocap, &geom.x_body_geom)
        }
        _ => Transform::identity(),
    }
}

/// The world quaternion of a sensed object (MuJoCo's `get_xquat`), given the bodies' `xquat`.
pub(crate) fn object_quat(model: &Model, data: &Data, quats: &[Quat], obj: SensorObject) -> Quat {
    match obj {
        SensorObject::XBody(b) => frame_quat(model, data, quats, model.links.frame[b]),
        SensorObject::Body(b) => {
            let x = frame_quat(model, data, quats, model.links.frame[b]);
            mul_quat(&x, &model.links.iquat[b])
        }
        SensorObject::Site(f) => frame_quat(model, data, quats, f),
        SensorObject::Geom(g) => {
            let geom = &model.geoms[g];
            let base = match geom.mocap {
                Some(m) => normalize_quat(&data.mocap_quat[m]),
                None => quats[geom.body],
            };
            mul_quat(&base, &rot_quat(&geom.x_body_geom.rot))
        }
        _ => [1.0, 0.0, 0.0, 0.0],
    }
}

/// The compiled body an object moves with (0 for the world, mocap bodies and objects without one).
pub(crate) fn object_body(model: &Model, obj: SensorObject) -> usize {
    match obj {
        SensorObject::XBody(b) | SensorObject::Body(b) => model.frames[model.links.frame[b]].body,
        SensorObject::Site(f) => model.frames[f].body,
        SensorObject::Geom(g) => model.geoms[g].body,
        _ => 0,
    }
}

/// The velocity (angular, linear) of the point `p_world` moving with compiled body `body`, world
/// axes. Needs the body poses and `v_body` at the state.
pub(crate) fn point_velocity(data: &Data, body: usize, p_world: &Vec3) -> (Vec3, Vec3) {
    let v_world = data.x_world_body[body].act_motion(&data.v_body[body]);
    (v_world.ang, v_world.lin + v_world.ang.cross(p_world))
}

/// MuJoCo's `mj_objectVelocity`: the object's (angular, linear) velocity at its origin, in world
/// axes or, when `local`, in the object's axes.
pub(crate) fn object_velocity(model: &Model, data: &Data, obj: SensorObject, local: bool) -> (Vec3, Vec3) {
    let x = object_pose(model, data, obj);
    let (w, v) = point_velocity(data, object_body(model, obj), &x.pos);
    if local {
        (x.rot.tr_mul(&w), x.rot.tr_mul(&v))
    } else {
        (w, v)
    }
}
