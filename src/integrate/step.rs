//! [`step`]: one step of the model's own integrator on the state in `Data` (MuJoCo's `mj_step`):
//! the integrator and timestep of the model's `<option>`, the stepper's buffers kept in `Data`
//! (built with it, so a step allocates nothing), the state checked after the step.

use super::{IntegratorKind, StepReport, Stepper};
use crate::error::InputError;
use crate::model::{Data, Model};
use crate::sim::{check_finite, SimError};

/// The stepper [`step`] uses, kept in `Data` with the sizes it was built for; rebuilt when the
/// model's integrator or sizes change. A clone of `Data` gets an empty slot (rebuilt at its first
/// step): a stepper holds only scratch between steps.
#[derive(Default)]
pub(crate) struct StepperSlot {
    built_for: Option<(IntegratorKind, usize, usize, usize)>,
    stepper: Option<Box<dyn Stepper>>,
    /// Steps taken by [`step`] since the data was made or reset (for the divergence report).
    pub steps: u64,
    /// The step that failed (diverged, did not converge, stalled), if one did since the state
    /// was last reset or set: [`step`] and [`Simulation::step`](crate::sim::Simulation::step)
    /// refuse to go on from it ([`SimError::Refused`]).
    pub failed: Option<FailedStep>,
}

/// A step that failed: its number, the time it started from, and what went wrong.
#[derive(Clone, Debug, PartialEq)]
pub struct FailedStep {
    /// The step's number.
    pub step: u64,
    /// The simulation time when it failed (s).
    pub time: f64,
    /// What went wrong (the error's kind).
    pub cause: &'static str,
}

impl FailedStep {
    /// The record of `error` from step `step` at `time` (None for an error that left the state
    /// untouched: a call refused on its input, or a refusal itself).
    pub(crate) fn of(error: &SimError, step: u64, time: f64) -> Option<Self> {
        let cause = match error {
            SimError::Diverged { .. } => "the state became non-finite",
            SimError::NotConverged { .. } => "the implicit step did not converge",
            SimError::AdaptiveStalled { .. } => "the adaptive integrator stopped",
            _ => return None,
        };
        Some(Self { step, time, cause })
    }

    /// The refusal of a step after this failure.
    pub(crate) fn refusal(&self) -> SimError {
        SimError::Refused { step: self.step, time: self.time, cause: self.cause }
    }
}

impl StepperSlot {
    /// The slot with the stepper of `model`'s integrator built.
    pub fn for_model(model: &Model) -> Self {
        let mut slot = Self::default();
        slot.ensure(model);
        slot
    }

    fn ensure(&mut self, model: &Model) -> &mut Box<dyn Stepper> {
        let (kind, _) = IntegratorKind::from_option(model.options.integrator);
        let key = (kind, model.nq, model.nv, model.na());
        if self.built_for != Some(key) || self.stepper.is_none() {
            self.stepper = Some(kind.build(model));
            self.built_for = Some(key);
        }
        self.stepper.get_or_insert_with(|| kind.build(model))
    }
}

impl Clone for StepperSlot {
    fn clone(&self) -> Self {
        Self { built_for: None, stepper: None, steps: self.steps, failed: self.failed.clone() }
    }
}

impl std::fmt::Debug for StepperSlot {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("StepperSlot")
            .field("built_for", &self.built_for)
            .field("steps", &self.steps)
            .finish_non_exhaustive()
    }
}

/// Advances the state in `data` (`time`, `qpos`, `qvel`, `act`) by one step of the model's
/// integrator (`<option integrator>`: Euler, RK4, implicit or implicitfast) and timestep, with
/// the controls `ctrl` and applied forces held over the step (MuJoCo's `mj_step`). After the
/// step, the other buffers of `data` hold the last stage's `forward`.
///
/// # Errors
/// [`SimError::Input`] when `data` was not made for `model` (its state has other sizes) or the
/// model's timestep is 0, negative or not finite;
/// [`SimError::Diverged`] when the state became non-finite, naming the joint where it started;
/// [`SimError::Refused`] for every step after one that failed, until the state is reset
/// ([`reset`](crate::model::reset::reset), [`reset_keyframe`](crate::model::reset::reset_keyframe))
/// or set ([`Data::set_state`]).
///
/// # Example
/// ```
/// use lagrange::prelude::*;
/// let model = Model::from_str(r#"<mujoco><option timestep="0.001"/><worldbody>
///     <body><joint type="hinge" axis="0 1 0"/><geom type="capsule" fromto="0 0 0 0 0 -1" size="0.05"/></body>
///     </worldbody></mujoco>"#)?;
/// let mut data = Data::new(&model);
/// data.qpos[0] = 0.5;
/// for _ in 0..1000 {
///     step(&model, &mut data)?;
/// }
/// assert!((data.time - 1.0).abs() < 1e-9);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn step(model: &Model, data: &mut Data) -> Result<StepReport, SimError> {
    data.check_sizes(model, "step")?;
    if let Some(f) = &data.stepper.failed {
        return Err(f.refusal());
    }
    let h = model.options.timestep;
    check_timestep("step", "model.options.timestep", h)?;
    let (q, warnings) = (data.qpos.as_slice(), &mut data.warnings);
    warnings.check_quaternions(model, q);
    let mut slot = std::mem::take(&mut data.stepper);
    let report = slot.ensure(model).step(model, data, h);
    // The next soft solve's warm start: this step's acceleration, rows or not (MuJoCo's
    // mj_advance), so that a solve with no iterations starts where the motion is.
    data.qacc_warmstart.copy_from(&data.qacc);
    slot.steps += 1;
    let steps = slot.steps;
    data.stepper = slot;
    check_finite(model, data, steps, || {
        format!(
            "reduce the model's timestep (now {h} s, `options.timestep`), or use a more stable integrator (`options.integrator`: rk4, or implicit for stiff damping); if it persists, check the model's stiffnesses and inertias"
        )
    })
    .inspect_err(|e| data.stepper.failed = FailedStep::of(e, steps, data.time))?;
    Ok(report)
}

/// `Ok` when the step size `h` is finite and positive, else [`InputError::Value`].
pub(crate) fn check_timestep(
    function: &'static str,
    argument: &'static str,
    h: f64,
) -> Result<(), InputError> {
    if h.is_finite() && h > 0.0 {
        Ok(())
    } else {
        Err(InputError::Value {
            function,
            argument,
            detail: format!("is {h}; it must be a finite step size > 0 s"),
        })
    }
}

impl Data {
    /// The step that failed since the state was last reset or set, if one did (steps are
    /// refused until then).
    pub fn failed_step(&self) -> Option<&FailedStep> {
        self.stepper.failed.as_ref()
    }

    /// Sets the state (`qpos`, `qvel`) and lets [`step`] go on after a failed step; rejects
    /// wrong lengths and non-finite values (nothing is changed then).
    ///
    /// # Errors
    /// [`InputError::Length`] or [`InputError::NonFinite`] naming the argument.
    pub fn set_state(&mut self, model: &Model, q: &[f64], v: &[f64]) -> Result<(), InputError> {
        InputError::check_len("Data::set_state", "q", q.len(), model.nq, "nq")?;
        InputError::check_len("Data::set_state", "v", v.len(), model.nv, "nv")?;
        InputError::check_finite("Data::set_state", "q", q)?;
        InputError::check_finite("Data::set_state", "v", v)?;
        self.qpos.copy_from_slice(q);
        self.qvel.copy_from_slice(v);
        self.stepper.failed = None;
        Ok(())
    }

    /// `Ok` when this data's state and inputs have `model`'s sizes (nq, nv, na, nu, nhistory), else
    /// [`InputError::Length`] naming the first that differs and the function `function`.
    pub fn check_sizes(&self, model: &Model, function: &'static str) -> Result<(), InputError> {
        InputError::check_len(function, "data.qpos", self.qpos.len(), model.nq, "nq")?;
        InputError::check_len(function, "data.qvel", self.qvel.len(), model.nv, "nv")?;
        InputError::check_len(function, "data.act", self.act.len(), model.na(), "na")?;
        InputError::check_len(function, "data.ctrl", self.ctrl.len(), model.actuators.len(), "nu")?;
        InputError::check_len(function, "data.history", self.history.len(), model.nhistory(), "nhistory")?;
        InputError::check_len(function, "data.qfrc_applied", self.qfrc_applied.len(), model.nv, "nv")
    }
}
