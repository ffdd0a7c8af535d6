//! Acceleration-stage sensors (MuJoCo's `mj_computeSensorAcc`, engine_sensor.c) that read the
//! forces and accelerations of the last `forward`: actuator forces (per actuator, at a joint,
//! summed on a tendon), limit forces, and from the post-constraint Newton–Euler pass
//! ([`crate::dynamics::rne_post`]) the accelerometer (a site's linear acceleration with the
//! gravity offset, in the site's axes: what an IMU measures), the force and torque a site's body
//! receives from its parent (in the site's axes, torque about the site) and frame accelerations.
//! The contact sensor is in `contact_sensor`.

use super::objects::object_pose;
use super::position::limit_row;
use super::types::{Sensor, SensorObject, SensorType};
use crate::dynamics::rne_post::{interaction_wrench_unchecked, object_acceleration_unchecked};
use crate::model::actuator::Transmission;
use crate::model::{Data, EfcType, Model};

/// Writes acceleration-stage sensor `s` into `out` (the force sensors of this file).
pub(crate) fn compute(model: &Model, data: &Data, s: &Sensor, out: &mut [f64]) {
    use SensorType::*;
    match (s.kind, s.object) {
        (ActuatorFrc, SensorObject::Actuator(a)) => out[0] = data.actuator_force[a],
        (JointActuatorFrc, SensorObject::Joint(j)) => out[0] = data.qfrc_actuator[model.joints[j].dof_adr],
        (TendonActuatorFrc, SensorObject::Tendon(t)) => {
            out[0] = model
                .actuators
                .iter()
                .enumerate()
                .filter(|(_, a)| a.transmission == Transmission::Tendon(t))
                .map(|(i, _)| data.actuator_force[i])
                .sum();
        }
        (JointLimitFrc, SensorObject::Joint(j)) => {
            out[0] = limit_row(data, EfcType::LimitJoint, j).map_or(0.0, |r| data.efc_force[r]);
        }
        (TendonLimitFrc, SensorObject::Tendon(t)) => {
            out[0] = limit_row(data, EfcType::LimitTendon, t).map_or(0.0, |r| data.efc_force[r]);
        }
        (Accelerometer | Force | Torque, SensorObject::Site(f)) => {
            let x = &data.x_world_frame[f];
            let b = model.links.of_frame[f];
            let value = match s.kind {
                Accelerometer => object_acceleration_unchecked(data, b, &x.pos).1,
                Force => interaction_wrench_unchecked(data, b, &x.pos).0,
                _ => interaction_wrench_unchecked(data, b, &x.pos).1,
            };
            out[..3].copy_from_slice(x.rot.tr_mul(&value).as_slice());
        }
        (FrameLinAcc | FrameAngAcc, obj) => {
            let b = match obj {
                SensorObject::Body(b) | SensorObject::XBody(b) => b,
                SensorObject::Site(f) => model.links.of_frame[f],
                SensorObject::Geom(g) => model.links.of_geom[g],
                _ => return,
            };
            let p = object_pose(model, data, obj).pos;
            let (ang, lin) = object_acceleration_unchecked(data, b, &p);
            out[..3].copy_from_slice(if s.kind == FrameLinAcc { lin.as_slice() } else { ang.as_slice() });
        }
        _ => {}
    }
}
