//! Velocity-stage sensors (MuJoCo's `mj_computeSensorVel`, engine_sensor.c): the velocimeter and
//! gyro (a site's linear and angular velocity in the site's axes), joint, tendon and actuator
//! velocities, limit velocities, frame velocities (optionally relative to a moving reference
//! frame) and the subtrees' linear velocity and angular momentum.
//!
//! Relative to a reference frame r (position p_r, rotation R_r, velocity (ω_r, v_r)) an object at
//! p with velocity (ω, v) moves, in r's axes, at
//!
//!   ω_rel = R_rᵀ (ω − ω_r),   v_rel = R_rᵀ (v − v_r − ω_r × (p − p_r)),
//!
//! the last term the transport by the rotating frame (MuJoCo adds (p − p_r) × ω_r).

use super::objects::{object_pose, object_velocity};
use super::position::limit_row;
use super::types::{Sensor, SensorObject, SensorType};
use super::SensorWork;
use crate::model::{Data, EfcType, Model};
use crate::spatial::Vec3;

fn copy3(out: &mut [f64], v: &Vec3) {
    out[..3].copy_from_slice(v.as_slice());
}

/// Writes velocity-stage sensor `s` into `out`.
pub(crate) fn compute(model: &Model, data: &Data, work: &SensorWork, s: &Sensor, v: &[f64], out: &mut [f64]) {
    use SensorType::*;
    match (s.kind, s.object) {
        (Velocimeter, obj) => copy3(out, &object_velocity(model, data, obj, true).1),
        (Gyro, obj) => copy3(out, &object_velocity(model, data, obj, true).0),
        (JointVel, SensorObject::Joint(j)) => out[0] = v[model.joints[j].dof_adr],
        (TendonVel, SensorObject::Tendon(t)) => out[0] = data.ten_velocity[t],
        (ActuatorVel, SensorObject::Actuator(a)) => out[0] = data.actuator_velocity[a],
        (BallAngVel, SensorObject::Joint(j)) => {
            let d = model.joints[j].dof_adr;
            out[..3].copy_from_slice(&v[d..d + 3]);
        }
        (JointLimitVel, SensorObject::Joint(j)) => {
            out[0] = limit_row(data, EfcType::LimitJoint, j).map_or(0.0, |r| data.efc_vel[r]);
        }
        (TendonLimitVel, SensorObject::Tendon(t)) => {
            out[0] = limit_row(data, EfcType::LimitTendon, t).map_or(0.0, |r| data.efc_vel[r]);
        }
        (FrameLinVel | FrameAngVel, obj) => {
            let (mut w, mut lin) = object_velocity(model, data, obj, false);
            if s.reference != SensorObject::None {
                let x = object_pose(model, data, obj);
                let r = object_pose(model, data, s.reference);
                let (w_ref, v_ref) = object_velocity(model, data, s.reference, false);
                let rel_lin = lin - v_ref + (x.pos - r.pos).cross(&w_ref);
                w = r.rot.tr_mul(&(w - w_ref));
                lin = r.rot.tr_mul(&rel_lin);
            }
            copy3(out, if s.kind == FrameLinVel { &lin } else { &w });
        }
        (SubtreeLinVel, SensorObject::Body(b)) => copy3(out, &work.subtree.linvel[b]),
        (SubtreeAngMom, SensorObject::Body(b)) => copy3(out, &work.subtree.angmom[b]),
        _ => {}
    }
}
