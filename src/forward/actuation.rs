//! The actuation stage (MuJoCo's `mj_fwdActuation`, MuJoCo documentation "Computation →
//! Actuation model"): for each simulated actuator, its moment arms (`actuator_moment`), length and
//! velocity through the
//! transmission (`actuator_length` = gear · x, `actuator_velocity` = gear · ẋ with x a hinge or
//! slide coordinate, or a fixed tendon's length Σ coef · q), the control clamped to `ctrlrange`
//! (unless `<flag clampctrl="disable">`), the force
//!
//!   force = gain · ctrl + bias,  gain = g₀ (fixed) or g₀ + g₁ length + g₂ velocity (affine),
//!   bias = 0 (none) or b₀ + b₁ length + b₂ velocity (affine),
//!
//! clamped to `forcerange` (`actuator_force`), and the generalized force `qfrc_actuator` = Σ
//! momentᵀ force, the moment being ∂length/∂q (gear on the joint's dof, gear · coef on a tendon's),
//! clamped on each joint with an `actuatorfrcrange`.
//!
//! Simulated: actuators without activation state (`dyntype` none) with fixed or affine gain and
//! none or affine bias (MuJoCo's `motor`, `position`, `velocity`, `damper` and such `general`
//! ones) on hinge or slide joints (`joint`, `jointinparent`) and fixed tendons. Every other kind is
//! kept, listed by `info` as not simulated, and contributes no force ([`unsimulated_reason`]).

use crate::model::actuator::{Actuator, BiasType, DynType, GainType, Transmission};
use crate::model::{Data, Model, TendonKind};

/// Why `a` is not simulated yet, or None if it is.
pub fn unsimulated_reason(model: &Model, a: &Actuator) -> Option<&'static str> {
    if a.dyntype != DynType::None {
        return Some("activation dynamics");
    }
    if !matches!(a.gaintype, GainType::Fixed | GainType::Affine) {
        return Some("muscle or user gain");
    }
    if !matches!(a.biastype, BiasType::None | BiasType::Affine) {
        return Some("muscle or user bias");
    }
    match &a.transmission {
        Transmission::Joint(j) | Transmission::JointInParent(j) if model.joints[*j].kind.nv() == 1 => None,
        Transmission::Joint(_) | Transmission::JointInParent(_) => Some("a ball or free joint transmission"),
        Transmission::Tendon(t) if matches!(model.tendons[*t].kind, TendonKind::Fixed { .. }) => None,
        Transmission::Tendon(_) => Some("a spatial tendon transmission"),
        Transmission::Site { .. } => Some("a site transmission"),
        Transmission::Body(_) => Some("a body (adhesion) transmission"),
        Transmission::SliderCrank { .. } => Some("a slider-crank transmission"),
    }
}

/// Calls `term(dof, qpos address, d length / d q)` for each (hinge or slide) coordinate of the
/// transmission, gear included.
fn for_each_moment(model: &Model, a: &Actuator, mut term: impl FnMut(usize, usize, f64)) {
    let mut joint = |j: usize, m: f64| term(model.joints[j].dof_adr, model.joints[j].qpos_adr, m);
    match &a.transmission {
        Transmission::Joint(j) | Transmission::JointInParent(j) => joint(*j, a.gear[0]),
        Transmission::Tendon(t) => {
            if let TendonKind::Fixed { joints } = &model.tendons[*t].kind {
                for &(j, coef) in joints {
                    joint(j, a.gear[0] * coef);
                }
            }
        }
        _ => {}
    }
}

/// Each actuator's `biasprm[2]` as MuJoCo 4.0's `mj_setConst` resolves it: a position-like
/// actuator (gain₀ = −bias₁) with a positive `biasprm[2]` holds a `dampratio`, which becomes the
/// damping −dampratio · 2 √(kp · m), with m = 1 / (moment · M₀⁻¹ · momentᵀ) the inertia reflected
/// through the transmission at `qpos0` (M₀ with armature; checked against MuJoCo 4.0.0 on the
/// Menagerie g1 by `validation/crossval_actuators`); every other value is kept.
pub fn resolved_bias_velocity(model: &Model) -> Vec<f64> {
    let mut data: Option<Data> = None;
    model
        .actuators
        .iter()
        .map(|a| {
            let (kp, b2) = (a.gainprm[0], a.biasprm[2]);
            if kp != -a.biasprm[1] || b2 <= 0.0 || unsimulated_reason(model, a).is_some() {
                return b2;
            }
            let data = data.get_or_insert_with(|| {
                let mut data = Data::new(model);
                crate::dynamics::crba(model, &mut data, &model.qpos0);
                crate::dynamics::factorize_mass_matrix(model, &mut data);
                data
            });
            let mut moment = nalgebra::DVector::zeros(model.nv);
            for_each_moment(model, a, |dof, _, m| moment[dof] += m);
            let mut x = moment.clone();
            crate::dynamics::solve_mass_matrix(model, data, &mut x);
            let inverse_mass = moment.dot(&x);
            if inverse_mass <= 0.0 {
                return b2;
            }
            -b2 * 2.0 * (kp / inverse_mass).sqrt()
        })
        .collect()
}

/// The actuation stage at (q, v) with `data.ctrl`: `actuator_length`, `actuator_velocity`,
/// `actuator_force` and `qfrc_actuator` (zero for actuators not simulated); `bias_velocity` is
/// [`resolved_bias_velocity`] (the plan holds it).
pub fn actuation(model: &Model, data: &mut Data, q: &[f64], v: &[f64], bias_velocity: &[f64]) {
    data.qfrc_actuator.fill(0.0);
    let clamp = model.options.flags.clampctrl;
    for (i, a) in model.actuators.iter().enumerate() {
        data.actuator_moment.row_mut(i).fill(0.0);
        if unsimulated_reason(model, a).is_some() {
            data.actuator_length[i] = 0.0;
            data.actuator_velocity[i] = 0.0;
            data.actuator_force[i] = 0.0;
            continue;
        }
        // Length and velocity: gear · (joint coordinate or tendon length), through the moment
        // (a joint's coordinate is its q; a fixed tendon is linear in q).
        let (mut length, mut velocity) = (0.0, 0.0);
        let Data { actuator_moment, .. } = data;
        for_each_moment(model, a, |dof, qpos, m| {
            length += m * q[qpos];
            velocity += m * v[dof];
            actuator_moment[(i, dof)] += m;
        });
        let mut ctrl = data.ctrl[i];
        if let (true, Some([lo, hi])) = (clamp, a.ctrlrange) {
            ctrl = ctrl.clamp(lo, hi);
        }
        let gain = match a.gaintype {
            GainType::Affine => a.gainprm[0] + a.gainprm[1] * length + a.gainprm[2] * velocity,
            _ => a.gainprm[0],
        };
        let bias = match a.biastype {
            BiasType::Affine => a.biasprm[0] + a.biasprm[1] * length + bias_velocity[i] * velocity,
            _ => 0.0,
        };
        let mut force = gain * ctrl + bias;
        if let Some([lo, hi]) = a.forcerange {
            force = force.clamp(lo, hi);
        }
        data.actuator_length[i] = length;
        data.actuator_velocity[i] = velocity;
        data.actuator_force[i] = force;
        let Data { qfrc_actuator, .. } = data;
        for_each_moment(model, a, |dof, _, m| qfrc_actuator[dof] += m * force);
    }
    // Joints' `actuatorfrcrange`: the total actuator force on each of their dofs is clamped.
    for j in &model.joints {
        if let Some([lo, hi]) = j.actuator_force_range {
            for dof in j.dof_adr..j.dof_adr + j.kind.nv() {
                data.qfrc_actuator[dof] = data.qfrc_actuator[dof].clamp(lo, hi);
            }
        }
    }
}
