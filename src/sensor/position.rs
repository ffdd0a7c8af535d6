//! Position-stage sensors (MuJoCo's `mj_computeSensorPos`, engine_sensor.c): what depends on
//! `qpos` alone — joint and tendon positions, actuator lengths, ball quaternions, limit distances,
//! frame poses (optionally in a reference frame), subtree centres of mass, the magnetometer,
//! inside-site tests, geom distances, ray casts, energies and the clock.

use super::objects::{mul_quat, neg_quat, normalize_quat, object_pose, object_quat};
use super::types::{Sensor, SensorObject, SensorType};
use super::SensorWork;
use crate::model::{Data, EfcType, Model};
use crate::spatial::Vec3;

/// The first row of kind `kind` for element `id` (MuJoCo reads the first matching row).
pub(crate) fn limit_row(data: &Data, kind: EfcType, id: usize) -> Option<usize> {
    (data.ne + data.nf..data.nefc).find(|&r| data.efc_type[r] == kind && data.efc_id[r] == id)
}

fn copy3(out: &mut [f64], v: &Vec3) {
    out[..3].copy_from_slice(v.as_slice());
}

/// Writes position-stage sensor `s` into `out` (its `dim` values).
pub(crate) fn compute(model: &Model, data: &Data, work: &SensorWork, s: &Sensor, q: &[f64], out: &mut [f64]) {
    use SensorType::*;
    match (s.kind, s.object) {
        (Magnetometer, obj) => {
            let x = object_pose(model, data, obj);
            copy3(out, &x.rot.tr_mul(&Vec3::from(model.options.magnetic)));
        }
        (JointPos, SensorObject::Joint(j)) => out[0] = q[model.joints[j].qpos_adr],
        (TendonPos, SensorObject::Tendon(t)) => out[0] = data.ten_length[t],
        (ActuatorPos, SensorObject::Actuator(a)) => out[0] = data.actuator_length[a],
        (BallQuat, SensorObject::Joint(j)) => {
            let a = model.joints[j].qpos_adr;
            out[..4].copy_from_slice(&normalize_quat(&q[a..a + 4]));
        }
        (JointLimitPos, SensorObject::Joint(j)) => {
            out[0] =
                limit_row(data, EfcType::LimitJoint, j).map_or(0.0, |r| data.efc_pos[r] - data.efc_margin[r]);
        }
        (TendonLimitPos, SensorObject::Tendon(t)) => {
            out[0] = limit_row(data, EfcType::LimitTendon, t)
                .map_or(0.0, |r| data.efc_pos[r] - data.efc_margin[r]);
        }
        (FramePos | FrameXAxis | FrameYAxis | FrameZAxis, obj) => {
            let x = object_pose(model, data, obj);
            let value = match s.kind {
                FramePos => x.pos,
                FrameXAxis => x.rot.column(0).into_owned(),
                FrameYAxis => x.rot.column(1).into_owned(),
                _ => x.rot.column(2).into_owned(),
            };
            let value = if s.reference == SensorObject::None {
                value
            } else {
                let r = object_pose(model, data, s.reference);
                if s.kind == FramePos {
                    r.rot.tr_mul(&(value - r.pos))
                } else {
                    r.rot.tr_mul(&value)
                }
            };
            copy3(out, &value);
        }
        (FrameQuat, obj) => {
            let q_obj = object_quat(model, data, &work.quats, obj);
            let value = if s.reference == SensorObject::None {
                q_obj
            } else {
                mul_quat(&neg_quat(&object_quat(model, data, &work.quats, s.reference)), &q_obj)
            };
            out[..4].copy_from_slice(&value);
        }
        (SubtreeCom, SensorObject::Body(b)) => copy3(out, &work.subtree.com[b]),
        (EPotential, _) => {
            out[0] = crate::dynamics::potential_energy(model, data) + model_spring_energy(model, q)
        }
        (EKinetic, _) => out[0] = work.kinetic,
        (Clock, _) => out[0] = work.time,
        _ => {}
    }
}

/// The springs' potential energy ½ k (q − q_ref)² (MuJoCo's `mj_energyPos` adds it to gravity's).
fn model_spring_energy(model: &Model, q: &[f64]) -> f64 {
    model.springs.iter().map(|s| 0.5 * s.stiffness * (q[s.qpos_adr] - s.rest).powi(2)).sum()
}
