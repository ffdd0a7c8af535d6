//! Actuator activation dynamics (MuJoCo documentation, "Computation → Actuation model →
//! Activation dynamics" and "XML Reference → actuator → general", attributes `dyntype`,
//! `dynprm`, `actlimited`, `actrange`, `actearly`): an actuator with a `dyntype` other than
//! `none` owns one activation state w (MuJoCo's `act`), and its force is gain · w + bias instead
//! of gain · u + bias, u being the clamped control. Its time derivative (MuJoCo's `act_dot`) is
//!
//! | dyntype | ẇ |
//! | --- | --- |
//! | integrator | u |
//! | filter, filterexact | (u − w) / τ, τ = max(`dynprm[0]`, 10⁻¹⁵) |
//!
//! A step of size h advances w to ([`next_activation`], MuJoCo's `mj_nextActivation`)
//! w + h ẇ, except `filterexact`, which integrates the filter exactly for a control held over
//! the step: w + ẇ τ (1 − e^(−h/τ)); then w is clamped to `actrange` when `actlimited`. With
//! `actearly` the force uses that next activation instead of the current one, which removes the
//! one-step delay between a control and its force.
//!
//! | muscle | MuJoCo's muscle activation ([`muscle`](super::muscle)) |
//!
//! `user` dynamics own an activation too (so `act` has MuJoCo's layout) but are not simulated:
//! their ẇ is 0.

use crate::model::actuator::{Actuator, DynType};
use crate::model::Model;

/// MuJoCo's `mjMINVAL`: the smallest time constant a filter divides by.
const MIN_TIME_CONSTANT: f64 = 1e-15;

/// The filter time constant τ of `a` (`dynprm[0]`, at least 10⁻¹⁵).
fn time_constant(a: &Actuator) -> f64 {
    a.dynprm[0].max(MIN_TIME_CONSTANT)
}

/// ẇ of actuator `a` at clamped control `ctrl` and activation `act` (MuJoCo's `act_dot`).
pub fn activation_rate(a: &Actuator, ctrl: f64, act: f64) -> f64 {
    match a.dyntype {
        DynType::Integrator => ctrl,
        DynType::Filter | DynType::FilterExact => (ctrl - act) / time_constant(a),
        DynType::Muscle => super::muscle::muscle_activation_rate(ctrl, act, &a.dynprm),
        DynType::None | DynType::User => 0.0,
    }
}

/// The activation after a step `h` from `act` at rate `act_dot` (MuJoCo's `mj_nextActivation`):
/// exact for `filterexact`, explicit Euler otherwise, then clamped to `actrange`.
pub fn next_activation(a: &Actuator, act: f64, act_dot: f64, h: f64) -> f64 {
    let next = if a.dyntype == DynType::FilterExact {
        let tau = time_constant(a);
        act + act_dot * tau * (1.0 - (-h / tau).exp())
    } else {
        act + h * act_dot
    };
    match a.actrange {
        Some([lo, hi]) => next.clamp(lo, hi),
        None => next,
    }
}

/// Clamps every activation to its `actrange` (the adaptive integrator's step: activations are
/// integrated as ODE components there, then clamped as MuJoCo clamps after a step).
pub(crate) fn clamp_activations(model: &Model, act: &mut [f64]) {
    let mut adr = 0;
    for a in &model.actuators {
        if a.actnum() == 1 {
            if let Some([lo, hi]) = a.actrange {
                act[adr] = act[adr].clamp(lo, hi);
            }
            adr += 1;
        }
    }
}

/// Advances every activation by a step `h` at the rates `act_dot` ([`next_activation`]; MuJoCo's
/// `mj_advance` for `act`). Nothing moves while actuation is switched off
/// (`<flag actuation="disable">`), as in MuJoCo.
pub(crate) fn advance_activations(model: &Model, act: &mut [f64], act_dot: &[f64], h: f64) {
    if !model.options.flags.actuation {
        return;
    }
    let mut adr = 0;
    for a in &model.actuators {
        if a.actnum() == 1 {
            act[adr] = next_activation(a, act[adr], act_dot[adr], h);
            adr += 1;
        }
    }
}
