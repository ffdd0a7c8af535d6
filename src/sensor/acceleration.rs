//! Acceleration-stage sensors (MuJoCo's `mj_computeSensorAcc`, engine_sensor.c) that read the
//! forces of the last `forward`: actuator forces (per actuator, at a joint, summed on a tendon)
//! and limit forces. The contact sensor is in `contact_sensor`.

use super::position::limit_row;
use super::types::{Sensor, SensorObject, SensorType};
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
        _ => {}
    }
}
