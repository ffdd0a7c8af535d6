//! `lagrange eval MODEL --states FILE --step N`: N steps of the model's own integrator and
//! timestep from each given state, as MuJoCo's `mj_step` advances `mjData` — the interface of
//! `validation/crossval_scenes.py`, which compares one lagrange step against one `mj_step` from
//! MuJoCo's own state.
//!
//! Each state starts a fresh run ([`reset`], MuJoCo's `mj_resetData`): time, qpos, qvel, act,
//! ctrl and qfrc_applied from the state, the soft solver's warm start from its optional
//! `qacc_warmstart` (else zero). The result is the state after the N steps (`qpos`, `qvel`,
//! `act`, `time`), the contacts of the last step's collision pass — with N = 1 those of the given
//! state, what MuJoCo's `d.contact` holds after one `mj_step` — and two wall times: `step_us`,
//! the N steps (µs per step), and `collide_us`, one collision pass alone (broad and narrow phase,
//! body poses computed first and untimed; MuJoCo's `mjTIMER_POS_COLLISION`) at the given state,
//! the mean of [`COLLIDE_REPEATS`] passes.

use super::eval::StateIn;
use super::CliError;
use lagrange::collision::{collide, EXACT_REACH};
use lagrange::integrate::step;
use lagrange::kinematics::forward_kinematics;
use lagrange::model::reset::reset;
use lagrange::{Data, Model};
use serde_json::{json, Value};
use std::time::Instant;

/// Collision passes timed per state for `collide_us`.
pub const COLLIDE_REPEATS: u32 = 5;

/// The largest `--step` accepted (a run of steps per state, not a simulation).
pub const MAX_STEPS: u32 = 100_000;

/// Checks `--step N`: at least 1, at most [`MAX_STEPS`].
pub fn check_steps(n: u32) -> Result<u32, CliError> {
    if (1..=MAX_STEPS).contains(&n) {
        Ok(n)
    } else {
        Err(CliError::Usage(format!(
            "--step {n}: give a number of steps from 1 to {MAX_STEPS}, e.g. --step 1"
        )))
    }
}

/// Steps `data` `n` times from state `s` (see the module doc); the result object.
pub fn evaluate(model: &Model, data: &mut Data, s: &StateIn, n: u32) -> Result<Value, CliError> {
    reset(model, data)?;
    data.time = s.time.unwrap_or(0.0);
    data.qpos.copy_from_slice(&s.q);
    let copy = |dst: &mut [f64], src: &Option<Vec<f64>>| {
        if let Some(x) = src {
            dst.copy_from_slice(x);
        }
    };
    copy(data.qvel.as_mut_slice(), &s.v);
    copy(data.qfrc_applied.as_mut_slice(), &s.tau);
    copy(data.ctrl.as_mut_slice(), &s.ctrl);
    copy(data.act.as_mut_slice(), &s.act);
    copy(data.qacc_warmstart.as_mut_slice(), &s.qacc_warmstart);
    super::eval::set_history(model, data, s);
    let collide_us = collide_time(model, data, &s.q)?;
    let t0 = Instant::now();
    for _ in 0..n {
        step(model, data)?;
    }
    let step_us = t0.elapsed().as_secs_f64() * 1e6 / f64::from(n);
    let contacts: Vec<Value> = data
        .contacts
        .iter()
        .map(|c| {
            json!({
                "geoms": c.geom.map(|g| super::eval::geom_name(model, g)), "geom_ids": c.geom,
                "pos": c.pos.as_slice(), "dist": c.dist,
                "frame": [c.frame.row(0).transpose().as_slice(), c.frame.row(1).transpose().as_slice(),
                          c.frame.row(2).transpose().as_slice()],
            })
        })
        .collect();
    let vec = |x: &nalgebra::DVector<f64>| x.as_slice().to_vec();
    let mut result = json!({
        "qpos": vec(&data.qpos), "qvel": vec(&data.qvel), "act": vec(&data.act), "time": data.time,
        "contacts": contacts, "nefc": data.nefc, "step_us": step_us, "collide_us": collide_us,
    });
    if model.nhistory() > 0 {
        result["history"] = json!(vec(&data.history));
    }
    Ok(result)
}

/// Mean µs of one collision pass at `q` (body poses first, untimed), with the reach of the
/// model's constraint mode; 0 for a model without candidate pairs.
fn collide_time(model: &Model, data: &mut Data, q: &[f64]) -> Result<f64, CliError> {
    let constraints = &model.plan.constraints;
    if !constraints.has_collision() {
        return Ok(0.0);
    }
    forward_kinematics(model, data, q)?;
    let reach = if model.plan.solver.soft_weights().is_some() { 0.0 } else { EXACT_REACH };
    let t0 = Instant::now();
    for _ in 0..COLLIDE_REPEATS {
        collide(model, &constraints.collision, data, reach);
    }
    Ok(t0.elapsed().as_secs_f64() * 1e6 / f64::from(COLLIDE_REPEATS))
}
