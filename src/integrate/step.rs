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
        Self { built_for: None, stepper: None, steps: self.steps }
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
/// [`SimError::Input`] when `data` was not made for `model` (its state has other sizes);
/// [`SimError::Diverged`] when the state became non-finite, naming the joint where it started.
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
    let h = model.options.timestep;
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
    })?;
    Ok(report)
}

impl Data {
    /// `Ok` when this data's state and inputs have `model`'s sizes (nq, nv, na, nu), else
    /// [`InputError::Length`] naming the first that differs and the function `function`.
    pub fn check_sizes(&self, model: &Model, function: &'static str) -> Result<(), InputError> {
        InputError::check_len(function, "data.qpos", self.qpos.len(), model.nq, "nq")?;
        InputError::check_len(function, "data.qvel", self.qvel.len(), model.nv, "nv")?;
        InputError::check_len(function, "data.act", self.act.len(), model.na(), "na")?;
        InputError::check_len(function, "data.ctrl", self.ctrl.len(), model.actuators.len(), "nu")?;
        InputError::check_len(function, "data.qfrc_applied", self.qfrc_applied.len(), model.nv, "nv")
    }
}
