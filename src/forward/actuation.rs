//! The actuation stage (MuJoCo's `mj_fwdActuation`, MuJoCo documentation "Computation →
//! Actuation model"): for each simulated actuator, its length and moment arms through the
//! transmission ([`transmission`](super::transmission), `actuator_length`, `actuator_moment`),
//! its velocity `actuator_velocity` = moment · v, the control clamped to `ctrlrange` (unless
//! `<flag clampctrl="disable">`), the activation derivative `act_dot`
//! ([`activation`](super::activation)), the force
//!
//!   force = gain · x + bias,  x = ctrl (dyntype none) or act (or, with `actearly`, the next act),
//!   gain = g₀ (fixed) or g₀ + g₁ length + g₂ velocity (affine),
//!   bias = 0 (none) or b₀ + b₁ length + b₂ velocity (affine),
//!
//! scaled down together with the other actuators on the same tendon when their total is outside
//! the tendon's `actuatorfrcrange`, then clamped to `forcerange` (`actuator_force`; MuJoCo 4.0's
//! order, checked against it), and the generalized force `qfrc_actuator` = Σ momentᵀ force,
//! clamped on each joint with an `actuatorfrcrange`.
//!
//! Simulated: dyntype none, integrator, filter, filterexact, muscle; fixed, affine or muscle gain;
//! none, affine or muscle bias ([`muscle`](super::muscle), with `actuator_lengthrange` resolved); joint (hinge, slide, ball, free), jointinparent, fixed-tendon, slider-crank and site
//! (with or without refsite), body (adhesion, [`adhesion`](super::adhesion)) transmissions — MuJoCo's `motor`, `position`, `velocity`, `intvelocity`, `damper`,
//! `cylinder`, `muscle` and such `general` ones. Every other kind is kept, listed by `info` as not
//! simulated, and contributes no force ([`unsimulated_reason`]).

use super::activation::{activation_rate, next_activation};
use super::adhesion::body_moment;
use super::muscle::{muscle_bias, muscle_gain};
use super::transmission::{transmission, Poses};
use crate::error::{check, InputError};
use crate::kinematics::forward_kinematics_unchecked;
pub use crate::model::actuator::unsimulated_reason;
use crate::model::actuator::{BiasType, GainType, Transmission};
use crate::model::warning::MAX_CTRL;
use crate::model::{Data, Model};

/// Each actuator's `biasprm[2]` as MuJoCo 4.0's `mj_setConst` resolves it: a position-like
/// actuator (gain₀ = −bias₁) with a positive `biasprm[2]` holds a `dampratio`, which becomes the
/// damping −dampratio · 2 √(kp · m), with m = 1 / (moment · M₀⁻¹ · momentᵀ) the inertia reflected
/// through the transmission at `qpos0` (M₀ with armature; checked against MuJoCo 4.0.0 on the
/// Menagerie g1 by `validation/crossval_actuators`); every other value is kept.
pub fn resolved_bias_velocity(model: &Model) -> Vec<f64> {
    let mut data: Option<Data> = None;
    let q0 = &model.qpos0;
    (0..model.actuators.len())
        .map(|i| {
            let a = &model.actuators[i];
            let (kp, b2) = (a.gainprm[0], a.biasprm[2]);
            if kp != -a.biasprm[1] || b2 <= 0.0 || unsimulated_reason(model, a).is_some() {
                return b2;
            }
            let data = data.get_or_insert_with(|| {
                let mut data = Data::new(model);
                crate::dynamics::crba_unchecked(model, &mut data, q0);
                crate::dynamics::factorize_mass_matrix(model, &mut data);
                forward_kinematics_unchecked(model, &mut data, q0);
                crate::tendon::lengths_and_jacobians(model, &mut data, q0);
                data
            });
            let Data { actuator_moment, x_world_body, s_body, x_world_frame, ten_length, ten_j, .. } = data;
            let poses = Poses { x_world_body, s_body, x_world_frame, ten_length, ten_j };
            actuator_moment.row_mut(i).fill(0.0);
            transmission(model, a, q0, poses, actuator_moment, i);
            let moment = actuator_moment.row(i).transpose();
            let mut x = moment.clone();
            crate::dynamics::solve_with_factor_unchecked(model, &data.mass_factor, x.as_mut_slice());
            let inverse_mass = moment.dot(&x);
            if inverse_mass <= 0.0 {
                return b2;
            }
            -b2 * 2.0 * (kp / inverse_mass).sqrt()
        })
        .collect()
}

/// Actuator i's control, clamped to its `ctrlrange` unless `clampctrl` is disabled.
fn clamped_ctrl(model: &Model, data: &Data, i: usize) -> f64 {
    clamp_ctrl(model, i, data.ctrl[i])
}

/// `ctrl` of actuator i clamped to its `ctrlrange` unless `clampctrl` is disabled.
#[inline]
fn clamp_ctrl(model: &Model, i: usize, ctrl: f64) -> f64 {
    match (model.options.flags.clampctrl, model.actuators[i].ctrlrange) {
        (true, Some([lo, hi])) => ctrl.clamp(lo, hi),
        _ => ctrl,
    }
}

/// MuJoCo's `mju_isBad`: NaN or beyond ±mjMAXVAL.
fn is_bad(x: f64) -> bool {
    x.is_nan() || x.abs() > MAX_CTRL
}

/// The actuation stage at (q, v) with `data.ctrl` and `data.act`: `actuator_length`,
/// `actuator_velocity`, `actuator_moment`, `act_dot`, `actuator_force` and `qfrc_actuator` (zero
/// for actuators not simulated); `bias_velocity` is [`resolved_bias_velocity`] (the plan holds
/// it). `actearly` looks one step of the model's `<option timestep>` ahead, as MuJoCo does.
///
/// # Errors
/// [`InputError::Length`] when q is not nq long, v not nv long, `bias_velocity` not one value per
/// actuator, or `data` was made for another model.
pub fn actuation(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    v: &[f64],
    bias_velocity: &[f64],
) -> Result<(), InputError> {
    check::data("actuation", model, data)?;
    data.check_sizes(model, "actuation")?;
    check::q("actuation", model, q)?;
    check::v("actuation", "v", model, v)?;
    InputError::check_len("actuation", "bias_velocity", bias_velocity.len(), model.actuators.len(), "nu")?;
    data.poses_stamp.clear();
    data.velocity_stamp.clear();
    crate::tendon::compute(model, data, q, v);
    actuation_unchecked(model, data, q, v, bias_velocity);
    Ok(())
}

/// [`actuation`] without the argument checks. Reads the plan's
/// [`ActuatorLayout`](super::ActuatorLayout) (worked out here when the plan is not built for
/// this model's actuators).
pub(crate) fn actuation_unchecked(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    v: &[f64],
    bias_velocity: &[f64],
) {
    let built;
    let layout = if model.plan.actuators.fits(model) {
        &model.plan.actuators
    } else {
        built = super::ActuatorLayout::new(model);
        &built
    };
    data.qfrc_actuator.fill(0.0);
    if layout.needs_poses {
        forward_kinematics_unchecked(model, data, q);
    }
    // MuJoCo's mjWARN_BADCTRL (mj_fwdActuation): a control NaN, infinite or beyond ±MAX_CTRL
    // after its range clamp zeroes every control of this evaluation, with a warning.
    // The stage's controls: each actuator's control, or with a `delay` its recorded control at
    // `data.time` − delay (`forward::history`), clamped as [`clamp_ctrl`]; kept in
    // `actuator_force` until each actuator's force replaces its own.
    let mut bad = None;
    for i in 0..model.actuators.len() {
        let ctrl = clamp_ctrl(model, i, super::history::delayed_ctrl(model, data, i));
        data.actuator_force.as_mut_slice()[i] = ctrl;
        if bad.is_none() && is_bad(ctrl) {
            bad = Some(i);
        }
    }
    if let Some(i) = bad {
        data.warnings.bad_control(i);
    }
    let zeroed = bad.is_some();
    let Data {
        act,
        act_dot,
        actuator_moment,
        actuator_length,
        actuator_velocity,
        actuator_force,
        qfrc_actuator,
        x_world_body,
        s_body,
        x_world_frame,
        ten_length,
        ten_j,
        contacts,
        ..
    } = data;
    let (x_world_body, s_body, x_world_frame) = (&x_world_body[..], &s_body[..], &x_world_frame[..]);
    let (ten_length, ten_j, contacts) = (&*ten_length, &*ten_j, &contacts[..]);
    let (act, act_dot) = (act.as_slice(), act_dot.as_mut_slice());
    let (lengths, velocities) = (actuator_length.as_mut_slice(), actuator_velocity.as_mut_slice());
    let forces = actuator_force.as_mut_slice();
    let nu = actuator_moment.nrows();
    for ((i, a), e) in model.actuators.iter().enumerate().zip(&layout.entries) {
        if !e.simulated {
            // The moment row from zero over its span; nothing writes the rest, zero since
            // `Data::new`.
            for k in e.span() {
                actuator_moment[(i, k)] = 0.0;
            }
            lengths[i] = 0.0;
            velocities[i] = 0.0;
            forces[i] = 0.0;
            if let Some(j) = e.act {
                act_dot[j] = 0.0;
            }
            continue;
        }
        let (length, velocity) = if let Some((qa, da)) = e.one_dof {
            // A hinge or slide joint transmission: the moment row is gear₀ at the joint's dof
            // (0 + gear₀, as added to the zeroed row), the length gear₀ · q, the velocity the
            // one product of the row with v.
            let gear = a.gear[0];
            let moment = 0.0 + gear;
            actuator_moment.as_mut_slice()[i + da * nu] = moment;
            (gear * q[qa], moment * v[da])
        } else {
            // The moment row from zero over the entries its transmission can write.
            for k in e.span() {
                actuator_moment[(i, k)] = 0.0;
            }
            let poses = Poses { x_world_body, s_body, x_world_frame, ten_length, ten_j };
            let length = transmission(model, a, q, poses, actuator_moment, i);
            if let Transmission::Body(b) = a.transmission {
                body_moment(model, contacts, x_world_body, s_body, b, actuator_moment, i);
            }
            let actuator_moment = &*actuator_moment;
            (length, e.span().map(|k| actuator_moment[(i, k)] * v[k]).sum::<f64>())
        };
        let ctrl = if zeroed { 0.0 } else { forces[i] };
        // The input of the gain: the control, or the activation (the next one with actearly).
        let input = match e.act {
            None => ctrl,
            Some(j) => {
                let rate = activation_rate(a, ctrl, act[j]);
                act_dot[j] = rate;
                if a.actearly {
                    next_activation(a, act[j], rate, model.options.timestep)
                } else {
                    act[j]
                }
            }
        };
        let gain = match a.gaintype {
            GainType::Affine => a.gainprm[0] + a.gainprm[1] * length + a.gainprm[2] * velocity,
            GainType::Muscle => muscle_gain(length, velocity, a.lengthrange, a.acc0, &a.gainprm),
            _ => a.gainprm[0],
        };
        let bias = match a.biastype {
            BiasType::Affine => a.biasprm[0] + a.biasprm[1] * length + bias_velocity[i] * velocity,
            BiasType::Muscle => muscle_bias(length, a.lengthrange, a.acc0, &a.biasprm),
            _ => 0.0,
        };
        lengths[i] = length;
        velocities[i] = velocity;
        forces[i] = gain * input + bias;
    }
    if layout.tendon_force_range {
        scale_tendon_forces(model, forces);
    }
    let qfrc = qfrc_actuator.as_mut_slice();
    for ((i, a), e) in model.actuators.iter().enumerate().zip(&layout.entries) {
        let mut force = forces[i];
        if let Some([lo, hi]) = a.forcerange {
            force = force.clamp(lo, hi);
        }
        forces[i] = force;
        if force == 0.0 {
            continue;
        }
        if let Some((_, da)) = e.one_dof {
            qfrc[da] += actuator_moment.as_slice()[i + da * nu] * force;
        } else {
            for k in e.span() {
                qfrc[k] += actuator_moment[(i, k)] * force;
            }
        }
    }
    // `actuatorgravcomp` joints: their gravity compensation (the passive stage's
    // `qfrc_gravcomp`) is an actuator force, inside the clamp below (MuJoCo's mj_fwdActuation).
    if crate::dynamics::gravcomp::active(model) {
        crate::dynamics::gravcomp::add_gravcomp(model, data.qfrc_gravcomp.as_slice(), qfrc, true);
    }
    // Joints' `actuatorfrcrange`: the total actuator force on each of their dofs is clamped.
    for &j in &layout.force_range_joints {
        let j = &model.joints[j];
        if let Some([lo, hi]) = j.actuator_force_range {
            for dof in j.dof_adr..j.dof_adr + j.kind.nv() {
                qfrc[dof] = qfrc[dof].clamp(lo, hi);
            }
        }
    }
}

/// Tendons' `actuatorfrcrange`: when the total force of the actuators on a limited tendon is
/// outside its range, each of their `forces` is scaled by bound / total (MuJoCo's
/// `mj_fwdActuation`, before the actuators' own `forcerange`).
fn scale_tendon_forces(model: &Model, forces: &mut [f64]) {
    for (t, tendon) in model.tendons.iter().enumerate() {
        let Some([lo, hi]) = tendon.actuator_force_range else { continue };
        let total = tendon_total_force(model, forces, t);
        let scale = if total == 0.0 {
            continue;
        } else if total < lo {
            lo / total
        } else if total > hi {
            hi / total
        } else {
            continue;
        };
        for (a, f) in model.actuators.iter().zip(forces.iter_mut()) {
            if a.transmission == Transmission::Tendon(t) {
                *f *= scale;
            }
        }
    }
}

/// Adds −h · Σᵢ momentᵢᵀ (∂forceᵢ/∂velocityᵢ) momentᵢ to `matrix` (column-major nv × nv): the
/// actuators' part of M − h ∂qfrc/∂v in the implicitfast step (MuJoCo's `mjd_actuator_vel`).
/// ∂force/∂velocity = b₂ (affine bias, `dampratio` resolved: `bias_velocity`) + g₂ · x (affine
/// gain; x the control as given, or the activation — the next one with `actearly`), zero for an
/// actuator whose force is at its `forcerange` bound. Reads the actuation stage's buffers at the
/// same state. Returns whether any actuator contributed.
pub fn add_actuator_velocity_derivative(
    model: &Model,
    data: &Data,
    bias_velocity: &[f64],
    matrix: &mut [f64],
    h: f64,
) -> bool {
    add_actuator_derivative(model, data, matrix, h, false, |a, i, x| {
        if total_force_clamped(model, data, a) {
            return 0.0;
        }
        let mut d = if a.biastype == BiasType::Affine { bias_velocity[i] } else { 0.0 };
        if a.gaintype == GainType::Affine {
            d += a.gainprm[2] * x;
        }
        d
    })
}

/// Adds −h · Σᵢ momentᵢᵀ (∂forceᵢ/∂lengthᵢ) momentᵢ to `matrix` (column-major nv × nv), with
/// ∂force/∂length = b₁ (affine bias) + g₁ · x (affine gain), zero at a `forcerange` bound: the
/// actuators' configuration derivative ∂qfrc_actuator/∂q with the moment arms held fixed (exact
/// for hinge and slide joint transmissions and fixed tendons, whose moments do not depend on q;
/// the moment arms' own q-derivative of site, slider-crank, ball and free transmissions is not
/// included). Reads the actuation stage's buffers at the same state.
pub(crate) fn add_actuator_length_derivative(model: &Model, data: &Data, matrix: &mut [f64], h: f64) -> bool {
    add_actuator_derivative(model, data, matrix, h, true, |a, _, x| {
        let mut d = if a.biastype == BiasType::Affine { a.biasprm[1] } else { 0.0 };
        if a.gaintype == GainType::Affine {
            d += a.gainprm[1] * x;
        }
        d
    })
}

/// The sum of `forces` (one per actuator) over the actuators pulling on tendon `t`, in actuator
/// order.
fn tendon_total_force(model: &Model, forces: &[f64], t: usize) -> f64 {
    model
        .actuators
        .iter()
        .zip(forces)
        .filter(|(a, _)| a.transmission == Transmission::Tendon(t))
        .map(|(_, f)| f)
        .sum()
}

/// Whether the total actuator force on actuator `a`'s joint or tendon sits at that joint's or
/// tendon's `actuatorfrcrange` bound (the joint's clamped `qfrc_actuator`; the tendon's summed
/// actuator forces within 1e-5 of a bound, relative): MuJoCo 4.0 then leaves the actuator out of
/// the velocity derivative (`mjd_actuator_vel`; MuJoCo Warp 4.0.0's `_jnt_actfrc_clamped`,
/// `_tendon_actfrc_clamped`), as it does at the actuator's own `forcerange`.
fn total_force_clamped(model: &Model, data: &Data, a: &crate::model::Actuator) -> bool {
    match a.transmission {
        Transmission::Joint(j) | Transmission::JointInParent(j) => {
            let joint = &model.joints[j];
            joint.actuator_force_range.is_some_and(|[lo, hi]| {
                let f = data.qfrc_actuator[joint.dof_adr];
                f <= lo || f >= hi
            })
        }
        Transmission::Tendon(t) => model.tendons[t].actuator_force_range.is_some_and(|[lo, hi]| {
            let total = tendon_total_force(model, data.actuator_force.as_slice(), t);
            const TOL: f64 = 1e-5;
            total <= lo + TOL * lo.abs() || total >= hi - TOL * hi.abs()
        }),
        _ => false,
    }
}

/// Adds −h · Σᵢ momentᵢᵀ dᵢ momentᵢ to `matrix`, dᵢ = `d(actuator, i, x)` with x the gain's input
/// (control — clamped to its range with `clamp`, as given otherwise, which is what MuJoCo's
/// `mjd_actuator_vel` reads — or activation), for the simulated actuators whose force is inside
/// its range.
fn add_actuator_derivative(
    model: &Model,
    data: &Data,
    matrix: &mut [f64],
    h: f64,
    clamp: bool,
    d: impl Fn(&crate::model::Actuator, usize, f64) -> f64,
) -> bool {
    if !model.options.flags.actuation {
        return false;
    }
    let nv = model.nv;
    let mut any = false;
    let mut act_adr = 0;
    // Bad controls are zeroed here too (the actuation stage's rule).
    let zeroed = (0..model.actuators.len()).any(|i| is_bad(clamped_ctrl(model, data, i)));
    for (i, a) in model.actuators.iter().enumerate() {
        let act_index = (a.actnum() == 1).then_some(act_adr);
        act_adr += a.actnum();
        if unsimulated_reason(model, a).is_some() {
            continue;
        }
        if let Some([lo, hi]) = a.forcerange {
            let f = data.actuator_force[i];
            if f <= lo || f >= hi {
                continue;
            }
        }
        let x = match act_index {
            None if zeroed => 0.0,
            None if clamp => clamped_ctrl(model, data, i),
            None => data.ctrl[i],
            Some(j) if a.actearly => next_activation(a, data.act[j], data.act_dot[j], model.options.timestep),
            Some(j) => data.act[j],
        };
        let d = d(a, i, x);
        if d == 0.0 {
            continue;
        }
        any = true;
        // Row i of the column-major nu × nv moment matrix, read in place; the products with its
        // zeros (most of a joint or tendon transmission's row) are skipped: subtracting them
        // changes nothing.
        let (nu, moments) = (data.actuator_moment.nrows(), data.actuator_moment.as_slice());
        let hd = h * d;
        for c in 0..nv {
            let mc = moments[i + c * nu];
            if mc == 0.0 {
                continue;
            }
            let column = &mut matrix[c * nv..(c + 1) * nv];
            for (r, entry) in column.iter_mut().enumerate() {
                let mr = moments[i + r * nu];
                if mr != 0.0 {
                    *entry -= hd * mr * mc;
                }
            }
        }
    }
    any
}
