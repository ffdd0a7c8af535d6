//! The compiler's actuator length-range simulation (MuJoCo's `mj_setLengthRange` and `evalAct`,
//! engine_setconst.c, run by `mjCModel::LengthRange`, user_model.cc): for an actuator whose
//! `actuator_lengthrange` neither the file nor a limit gives ([`super::lengthrange::resolve`]),
//! push the actuator both ways and take the lengths it settles at.
//!
//! For each side (shortening, then lengthening) the model starts at `qpos0` at rest and is
//! stepped for `inttotal` seconds with step `timestep`, contacts, springs, dampers, gravity,
//! friction loss and actuation off (every other constraint on, whatever the file's `<flag>`s say),
//! RK4 replaced by Euler as MuJoCo's split step does. Before each step the velocity decays by
//! exp(−h / max(0.01, `timeconst`)) and the applied force becomes
//! ±`accel` · m / |M⁻¹ m| along the actuator's moment m (so that the actuator's own coordinate
//! accelerates at about `accel`), its norm capped at `maxforce` when positive. The side's bound is
//! the least (shortening) or greatest (lengthening) actuator length over the last `interval`
//! seconds; the range fails when the bounds do not straddle, when either side's lengths still
//! spread by more than `tolrange` of the range (not converged), or when the simulation diverges.

use super::lengthrange::LengthRangeOptions;
use super::options::Integrator;
use super::{Data, Model};
use crate::forward::transmission::{transmission, Poses};
use crate::io::LoadError;

/// MuJoCo's `mjMINVAL`, the floor of the norm the pushing force is divided by.
const MIN_VALUE: f64 = 1e-15;

/// The most steps a side may take (a resource limit of the loader; MuJoCo's defaults take 1000).
const MAX_STEPS: f64 = 1e6;

/// MuJoCo's `actuator_lengthrange` of the actuators `which` of `model`, found by simulation (see
/// the module doc), written into `model.actuators[i].lengthrange`.
///
/// # Errors
/// [`LoadError::Invalid`] naming the actuator when its simulation diverges, its range is empty
/// or it does not converge within `tolrange` (MuJoCo refuses such a model the same way).
pub(crate) fn simulate_ranges(
    model: &mut Model,
    which: &[usize],
    options: &LengthRangeOptions,
) -> Result<(), LoadError> {
    if which.is_empty() {
        return Ok(());
    }
    let sim = simulation_model(model, options);
    // A resource limit: MuJoCo's defaults take 1000 steps per side.
    let steps = options.inttotal / sim.options.timestep;
    if steps.is_nan() || steps > MAX_STEPS {
        let a = &model.actuators[which[0]];
        return Err(LoadError::Invalid {
            loc: a.loc.clone(),
            element: "lengthrange".into(),
            detail: format!(
                "the lengthrange simulation would take {steps:e} steps per side (inttotal {} s / timestep {} s), more than {MAX_STEPS:e}: lower <compiler><lengthrange inttotal>, raise its timestep, or give the actuators lengthrange=\"min max\"",
                options.inttotal, sim.options.timestep
            ),
        });
    }
    let mut data = Data::new(&sim);
    for &i in which {
        let range = range_of(&sim, &mut data, i, options)?;
        model.actuators[i].lengthrange = range;
    }
    Ok(())
}

/// The model the simulation steps: MuJoCo's `LengthRange` option overrides.
fn simulation_model(model: &Model, options: &LengthRangeOptions) -> Model {
    let mut sim = model.clone();
    let o = &mut sim.options;
    if options.timestep > 0.0 {
        o.timestep = options.timestep;
    }
    if !matches!(o.integrator, Integrator::Implicit | Integrator::ImplicitFast) {
        o.integrator = Integrator::Euler;
    }
    // MuJoCo sets disableflags to exactly these six: every other constraint is on.
    let f = &mut o.flags;
    f.constraint = true;
    f.equality = true;
    f.limit = true;
    f.refsafe = true;
    f.clampctrl = true;
    f.warmstart = true;
    f.filterparent = true;
    f.eulerdamp = true;
    f.frictionloss = false;
    f.contact = false;
    f.spring = false;
    f.damper = false;
    f.gravity = false;
    f.actuation = false;
    // What lagrange's compiler folds in from those flags: springs, damping, gravity and the
    // contact pairs.
    sim.gravity = crate::spatial::Vec3::zeros();
    sim.springs.clear();
    sim.dof_damping.iter_mut().for_each(|d| *d = 0.0);
    sim.collision_pairs.clear();
    sim.sensors.clear();
    sim.nsensordata = 0;
    sim.plan = crate::forward::Plan::new(&sim, None);
    sim
}

/// One actuator's range: both sides simulated, then MuJoCo's checks.
fn range_of(
    sim: &Model,
    data: &mut Data,
    i: usize,
    options: &LengthRangeOptions,
) -> Result<[f64; 2], LoadError> {
    let a = &sim.actuators[i];
    let fail = |detail: String| LoadError::Invalid {
        loc: a.loc.clone(),
        element: a.shortcut.name().to_string(),
        detail,
    };
    let name = if a.name.is_empty() { format!("actuator {i}") } else { format!("actuator '{}'", a.name) };
    let mut spread = [[0.0; 2]; 2];
    for (side, bounds) in spread.iter_mut().enumerate() {
        *bounds = push(sim, data, i, side, options).map_err(|e| {
            fail(format!(
                "the lengthrange simulation of {name} is unstable ({e}); give lengthrange=\"min max\", or change <compiler><lengthrange accel timestep timeconst>"
            ))
        })?;
    }
    let range = [spread[0][0], spread[1][1]];
    let width = range[1] - range[0];
    if width.is_nan() || width <= 0.0 {
        return Err(fail(format!(
            "the lengthrange simulation of {name} gives the invalid range ({}, {}); give lengthrange=\"min max\"",
            range[0], range[1]
        )));
    }
    for (side, [lo, hi]) in spread.iter().enumerate() {
        if hi - lo > options.tolrange * width {
            return Err(fail(format!(
                "the lengthrange simulation of {name} did not converge: its lengths over the last {} s of the {} side span ({lo}, {hi}) in the range ({}, {}); give lengthrange=\"min max\", or raise <compiler><lengthrange inttotal> or tolrange",
                options.interval,
                if side == 0 { "shortening" } else { "lengthening" },
                range[0],
                range[1]
            )));
        }
    }
    Ok(range)
}

/// One side (0: shortening, 1: lengthening) from `qpos0` at rest: the least and greatest
/// actuator length over the last `interval` seconds, or why the simulation stopped.
fn push(
    sim: &Model,
    data: &mut Data,
    i: usize,
    side: usize,
    o: &LengthRangeOptions,
) -> Result<[f64; 2], String> {
    super::reset::reset(sim, data).map_err(|e| e.to_string())?;
    let a = &sim.actuators[i];
    let h = sim.options.timestep;
    let decay = (-h / o.timeconst.max(0.01)).exp();
    let sign = if side == 0 { -1.0 } else { 1.0 };
    let (mut lo, mut hi, mut updated) = (0.0, 0.0, false);
    let mut moment = nalgebra::DVector::zeros(sim.nv);
    while data.time < o.inttotal {
        for v in data.qvel.iter_mut() {
            *v *= decay;
        }
        // The position stage at q: the actuator's length and moment, and M's factor.
        let q = std::mem::take(&mut data.qpos);
        crate::kinematics::forward_kinematics_unchecked(sim, data, q.as_slice());
        crate::tendon::lengths_and_jacobians(sim, data, q.as_slice());
        crate::dynamics::crba_unchecked(sim, data, q.as_slice());
        crate::dynamics::factorize_mass_matrix(sim, data);
        let Data { actuator_moment, x_world_body, s_body, x_world_frame, ten_length, ten_j, .. } = &mut *data;
        actuator_moment.row_mut(i).fill(0.0);
        let poses = Poses { x_world_body, s_body, x_world_frame, ten_length, ten_j };
        let length = transmission(sim, a, q.as_slice(), poses, actuator_moment, i);
        data.qpos = q;
        for k in 0..sim.nv {
            moment[k] = data.actuator_moment[(i, k)];
        }
        // qfrc_applied = ± accel · m / |M⁻¹ m|, capped at maxforce.
        data.qfrc_applied.copy_from(&moment);
        crate::dynamics::solve_with_factor_unchecked(
            sim,
            &data.mass_factor,
            data.qfrc_applied.as_mut_slice(),
        );
        let scale = sign * o.accel / data.qfrc_applied.norm().max(MIN_VALUE);
        for k in 0..sim.nv {
            data.qfrc_applied[k] = moment[k] * scale;
        }
        let norm = data.qfrc_applied.norm();
        if o.maxforce > 0.0 && norm > o.maxforce {
            data.qfrc_applied *= o.maxforce / norm.max(MIN_VALUE);
        }
        crate::integrate::step(sim, data).map_err(|e| e.to_string())?;
        if data.time > o.inttotal - o.interval {
            if length < lo || !updated {
                lo = length;
            }
            if length > hi || !updated {
                hi = length;
            }
            updated = true;
        }
    }
    Ok([lo, hi])
}
