//! Compile-time actuator constants a muscle needs (MuJoCo's `mj_setConst` and
//! `mj_setLengthRange`, engine_setconst.c): `actuator_lengthrange`, the range of the actuator's
//! length its gain and bias are normalized by, and `actuator_acc0`, the acceleration norm a unit
//! actuator force gives at `qpos0`.
//!
//! `lengthrange` follows MuJoCo's `<compiler><lengthrange>` defaults (mode `muscle`,
//! `useexisting`): a range written with lower < upper is kept; else, with `uselimit="true"`, a
//! muscle on a limited joint takes the joint's range (not scaled by the gear, as MuJoCo) and one on
//! a limited tendon the tendon's range. MuJoCo otherwise finds the range by simulating the
//! actuator pushed both ways; that simulation is not implemented, so such a muscle keeps [0, 0]
//! and is listed as not simulated ([`crate::model::actuator::unsimulated_reason`]).

use super::actuator::{BiasType, GainType, Transmission};
use super::spec::ActuatorSpec;
use super::tendon::Tendon;
use super::{Data, Joint, Model};
use crate::forward::transmission::{transmission, Poses};

/// Whether the actuator's gain or bias is MuJoCo's muscle model (`mjLRMODE_MUSCLE`'s test).
pub fn is_muscle(gaintype: GainType, biastype: BiasType) -> bool {
    gaintype == GainType::Muscle || biastype == BiasType::Muscle
}

/// `actuator_lengthrange` of actuator `a` with the compiled `transmission` (see the module doc).
pub(crate) fn resolve(
    a: &ActuatorSpec,
    transmission: &Transmission,
    joints: &[Joint],
    tendons: &[Tendon],
) -> [f64; 2] {
    if !is_muscle(a.gaintype, a.biastype) || a.lengthrange[0] < a.lengthrange[1] {
        return a.lengthrange;
    }
    if a.lengthrange_uselimit {
        let limits = match transmission {
            Transmission::Joint(j) | Transmission::JointInParent(j) => joints[*j].limits,
            Transmission::Tendon(t) => tendons[*t].range,
            _ => None,
        };
        if let Some(range) = limits {
            return range;
        }
    }
    a.lengthrange
}

/// Sets every actuator's `acc0` = |M₀⁻¹ momentᵀ| at `qpos0` (MuJoCo's `actuator_acc0`, with M₀
/// including armature); 0 for the transmissions the actuation stage does not evaluate (body,
/// planar joint).
pub(crate) fn set_acc0(model: &mut Model) {
    if model.actuators.is_empty() {
        return;
    }
    let q0 = model.qpos0.clone();
    let mut data = Data::new(model);
    crate::dynamics::crba_unchecked(model, &mut data, &q0);
    crate::dynamics::factorize_mass_matrix(model, &mut data);
    crate::kinematics::forward_kinematics_unchecked(model, &mut data, &q0);
    crate::tendon::lengths_and_jacobians(model, &mut data, &q0);
    let mut acc0 = vec![0.0; model.actuators.len()];
    for (i, a) in model.actuators.iter().enumerate() {
        let planar = match &a.transmission {
            Transmission::Joint(j) | Transmission::JointInParent(j) => {
                matches!(model.joints[*j].kind, super::JointKind::Planar { .. })
            }
            Transmission::Body(_) => true,
            _ => false,
        };
        if planar {
            continue;
        }
        let Data { actuator_moment, x_world_body, s_body, x_world_frame, ten_length, ten_j, .. } = &mut data;
        let poses = Poses { x_world_body, s_body, x_world_frame, ten_length, ten_j };
        actuator_moment.row_mut(i).fill(0.0);
        transmission(model, a, &q0, poses, actuator_moment, i);
        let mut x = actuator_moment.row(i).transpose();
        crate::dynamics::solve_with_factor_unchecked(model, &data.mass_factor, x.as_mut_slice());
        acc0[i] = x.norm();
    }
    for (a, v) in model.actuators.iter_mut().zip(acc0) {
        a.acc0 = v;
    }
}
