//! Compile-time actuator constants a muscle needs (MuJoCo's `mj_setConst` and
//! `mj_setLengthRange`, engine_setconst.c): `actuator_lengthrange`, the range of the actuator's
//! length its gain and bias are normalized by, and `actuator_acc0`, the acceleration norm a unit
//! actuator force gives at `qpos0`.
//!
//! `lengthrange` follows MuJoCo's `<compiler><lengthrange>` ([`LengthRangeOptions`], MuJoCo's
//! `mjLROpt` and its defaults): the actuators its `mode` selects (muscles by default) keep a range
//! written with lower < upper (`useexisting`); else, with `uselimit`, one on a limited joint takes
//! the joint's range (not scaled by the gear, as MuJoCo) and one on a limited tendon the tendon's
//! range; else the range comes from simulating the actuator pushed both ways
//! (`model::lengthrange_sim`, the compiler's).

use super::actuator::{BiasType, GainType, Transmission};
use super::spec::ActuatorSpec;
use super::tendon::Tendon;
use super::{Data, Joint, Model};
use crate::forward::transmission::{transmission, Poses};

/// Which actuators get a computed length range (`<compiler><lengthrange mode>`, MuJoCo's
/// `mjtLRMode`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LengthRangeMode {
    /// None.
    None,
    /// Muscles (gain or bias `muscle`): the default.
    #[default]
    Muscle,
    /// Muscles and actuators with a user gain or bias.
    MuscleUser,
    /// Every actuator.
    All,
}

/// `<compiler><lengthrange>`: how the compiler finds `actuator_lengthrange` (MuJoCo's `mjLROpt`;
/// defaults MuJoCo's `mj_defaultLROpt`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LengthRangeOptions {
    /// Which actuators (`mode`).
    pub mode: LengthRangeMode,
    /// Keep a range written with lower < upper (`useexisting`, true).
    pub useexisting: bool,
    /// Take a limited joint's or tendon's range (`uselimit`, false).
    pub uselimit: bool,
    /// The acceleration the simulation pushes with, m/s² or rad/s² (`accel`, 20).
    pub accel: f64,
    /// A cap on the pushing force's norm, 0 for none (`maxforce`, 0).
    pub maxforce: f64,
    /// The velocity decay's time constant, s (`timeconst`, 1).
    pub timeconst: f64,
    /// The simulation's step, s; 0 keeps the model's (`timestep`, 0.01).
    pub timestep: f64,
    /// The simulated time per side, s (`inttotal`, 10).
    pub inttotal: f64,
    /// The final interval whose lengths count, s (`interval`, 2).
    pub interval: f64,
    /// The largest spread of those lengths, relative to the range (`tolrange`, 0.05).
    pub tolrange: f64,
}

impl Default for LengthRangeOptions {
    fn default() -> Self {
        Self {
            mode: LengthRangeMode::Muscle,
            useexisting: true,
            uselimit: false,
            accel: 20.0,
            maxforce: 0.0,
            timeconst: 1.0,
            timestep: 0.01,
            inttotal: 10.0,
            interval: 2.0,
            tolrange: 0.05,
        }
    }
}

/// Whether the actuator's gain or bias is MuJoCo's muscle model (`mjLRMODE_MUSCLE`'s test).
pub fn is_muscle(gaintype: GainType, biastype: BiasType) -> bool {
    gaintype == GainType::Muscle || biastype == BiasType::Muscle
}

/// `actuator_lengthrange` of actuator `a` with the compiled `transmission` when the options
/// settle it without simulating (see the module doc); None when the simulation must find it.
pub(crate) fn resolve(
    a: &ActuatorSpec,
    transmission: &Transmission,
    joints: &[Joint],
    tendons: &[Tendon],
    options: &LengthRangeOptions,
) -> Option<[f64; 2]> {
    let muscle = is_muscle(a.gaintype, a.biastype);
    let user = a.gaintype == GainType::User || a.biastype == BiasType::User;
    let selected = match options.mode {
        LengthRangeMode::None => false,
        LengthRangeMode::Muscle => muscle,
        LengthRangeMode::MuscleUser => muscle || user,
        LengthRangeMode::All => true,
    };
    if !selected || (options.useexisting && a.lengthrange[0] < a.lengthrange[1]) {
        return Some(a.lengthrange);
    }
    if options.uselimit {
        let limits = match transmission {
            Transmission::Joint(j) | Transmission::JointInParent(j) => joints[*j].limits,
            Transmission::Tendon(t) => tendons[*t].range,
            _ => None,
        };
        if limits.is_some() {
            return limits;
        }
    }
    None
}

/// Sets every actuator's `acc0` = |M₀⁻¹ momentᵀ| at `qpos0` (MuJoCo's `actuator_acc0`, with M₀
/// including armature); 0 for the transmissions the actuation stage does not evaluate (body,
/// planar joint).
pub(crate) fn set_acc0(model: &mut Model) {
    if model.actuators.is_empty() {
        return;
    }
    let q0 = model.qpos0.clone();
    let mut data = Data::scratch(model);
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
