//! The simulation (docs/architecture.md, "Layers"): a model behind `Arc`, its [`Data`] (the state, the
//! controls and every buffer), a [`Stepper`] and the controllers. The model's `<option>` timestep and integrator are
//! honoured unless the caller overrides them ([`SimOptions`]); a non-finite state is reported with
//! the step, time and joint, never propagated.

use crate::constraint::ConstraintMode;
use crate::dynamics;
use crate::forward::DriftCorrection;
use crate::integrate::{DormandPrince54, IntegratorKind, StepReport, Stepper};
use crate::kinematics::forward_kinematics_unchecked;
use crate::model::{Data, Model};
use std::sync::Arc;
use thiserror::Error;

/// Why a simulation stopped.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum SimError {
    /// The state became non-finite.
    #[error("the simulation diverged at t = {} s (step {step}): {quantity} of joint '{joint}' is {value}; {hint}", display_time(*.time))]
    Diverged {
        /// Simulation time at the end of the step that went non-finite (s).
        time: f64,
        /// The step's number (1 = the first).
        step: u64,
        /// What went non-finite: position, velocity, or the articulated inertia about an axis.
        quantity: &'static str,
        /// The joint where it started.
        joint: String,
        /// The non-finite value.
        value: f64,
        /// What to try.
        hint: String,
    },
    /// An implicit step's Newton iteration did not converge; the state is left at the step's start.
    #[error("the {integrator} integrator's Newton iteration did not converge in step {step} (t = {} s → {} s, dt = {dt} s): residual {residual:.3e} after {iterations} iterations (last update {update:.3e}, constraint violation {constraint:.3e}); the state is left at the start of the step; reduce SimOptions::timestep", display_time(*.time), display_time(*.time + *.dt))]
    NotConverged {
        /// The integrator's name.
        integrator: &'static str,
        /// Simulation time at the start of the step (s).
        time: f64,
        /// The step's number.
        step: u64,
        /// The step size (s).
        dt: f64,
        /// Newton iterations done.
        iterations: u32,
        /// Max-norm of the residual at the last iterate.
        residual: f64,
        /// Max-norm of the last Newton update.
        update: f64,
        /// max |φ| of the equality constraints at the last iterate.
        constraint: f64,
    },
    /// The adaptive integrator stopped before the end of a step: with contact, limit or friction
    /// rows it ran past its work budget (the constraint forces are only as accurate as their solve
    /// and switch with the rows, so error control cannot meet tight tolerances), or its step size
    /// collapsed. The state is left where error control stopped.
    #[error("the adaptive integrator stopped at t = {} s in step {step}: {why}; the state is left where error control stopped; use a fixed-step integrator (euler or implicitfast at the model's timestep, rk4 for accuracy) for contact-rich motion, or looser tolerances (SimOptions::tolerances, --rtol/--atol; now rtol {rtol:e}, atol {atol:e})", display_time(*.time))]
    AdaptiveStalled {
        /// Simulation time where the stepper stopped (s).
        time: f64,
        /// The step's number.
        step: u64,
        /// Why, with the figures (work done against fixed steps, the last step size and error).
        why: String,
        /// The relative tolerance in use.
        rtol: f64,
        /// The absolute tolerance in use.
        atol: f64,
    },
    /// A step was asked for after a failed one (diverged, not converged, stalled) without the
    /// state being reset or set since: stepping on would step the failed state.
    #[error("step refused: step {step} failed at t = {} s ({cause}); reset the state (reset, reset_keyframe) or set it (Simulation::set_state, Data::set_state) before stepping again", display_time(*.time))]
    Refused {
        /// The failed step's number.
        step: u64,
        /// The time when it failed (s).
        time: f64,
        /// What went wrong.
        cause: &'static str,
    },
    /// A state given to the simulation has the wrong length or a non-finite value.
    #[error("invalid initial state: {0}")]
    BadState(String),
    /// A call's argument or the data does not fit the model.
    #[error(transparent)]
    Input(#[from] crate::error::InputError),
}

/// A simulation time for display: rounded to 12 significant digits, so that a sum of steps
/// prints as 6.8, not 6.800000000000003 or 6.799999999999.
pub fn display_time(t: f64) -> f64 {
    format!("{t:.11e}").parse().unwrap_or(t)
}

/// Choices a caller may override; `None` takes the model's own (its `<option>` and the format's
/// constraint mode).
#[derive(Clone, Debug, Default)]
pub struct SimOptions {
    /// The integrator (the model's `<option integrator>` by default).
    pub integrator: Option<IntegratorKind>,
    /// The step size in seconds (the model's `<option timestep>` by default).
    pub timestep: Option<f64>,
    /// The constraint mode (MJCF soft, URDF exact by default).
    pub constraints: Option<ConstraintMode>,
    /// The exact mode's drift correction (projection after each step by default).
    pub drift: Option<DriftCorrection>,
    /// (rtol, atol) of the adaptive integrator (default: `DEFAULT_RTOL`, `DEFAULT_ATOL`).
    pub tolerances: Option<[f64; 2]>,
}

/// A model, its data (the state, the inputs and every buffer) and a stepper.
pub struct Simulation {
    /// The model, with the plan in use (the options' constraint mode and drift correction).
    pub model: Arc<Model>,
    /// The state (`time`, `qpos`, `qvel`, `act`), the inputs (`ctrl`, `qfrc_applied`) and the
    /// outputs of the last `forward`.
    pub data: Data,
    /// The integrator that advances `data`.
    pub stepper: Box<dyn Stepper>,
    /// The step size used by [`step`](Self::step). For a fixed-step integrator it is also the
    /// model's timestep (soft constraints' `refsafe`, `actearly`): set here after
    /// [`new`](Self::new), the model follows at the next step. [`set_timestep`](Self::set_timestep)
    /// checks the value; [`step`](Self::step) refuses 0, negative and non-finite values.
    pub timestep: f64,
    /// Steps taken since [`new`](Self::new).
    pub steps: u64,
    /// What was chosen for the caller and why (integrator fallbacks, constraint mode).
    pub notes: Vec<String>,
    /// Called before each step to set the controls ([`set_controller`](Self::set_controller)).
    controller: Option<Controller>,
    /// Called before each step to set the applied joint forces
    /// ([`set_torque_controller`](Self::set_torque_controller)).
    torque_controller: Option<Controller>,
    /// Whether the integrator steps by `timestep` (all but the adaptive one), which is then the
    /// model's timestep too ([`new`](Self::new)).
    fixed_step: bool,
}

/// A control law `f(time, q, v, out)`: it reads the state at the start of a step and writes the
/// controls (or, for a torque controller, the applied generalized forces), which are then held
/// for the whole step — every stage of RK4 and of the adaptive method sees the same values (a
/// zero-order hold, MuJoCo's `mjcb_control` called once per `mj_step`).
pub type Controller = Box<dyn FnMut(f64, &[f64], &[f64], &mut [f64]) + Send>;

impl Simulation {
    /// A simulation from the model's `qpos0` at rest, with `options` over the model's own. A
    /// constraint mode or drift correction other than the model's plan is written into (a copy
    /// of) the model, as the timestep is.
    ///
    /// A fixed-step integrator's `timestep` other than the model's is written into (a copy of)
    /// the model: as MuJoCo's `opt.timestep`, the step is also what the soft constraints'
    /// `refsafe` time constant (at least 2 · timestep) and the actuators' `actearly` look ahead
    /// by are computed from. The adaptive integrator's steps vary: its model keeps the file's.
    ///
    /// ```
    /// use lagrange::prelude::*;
    /// use std::sync::Arc;
    /// let model = Arc::new(Model::from_file("models/ur5/ur5.urdf")?);
    /// let mut sim = Simulation::new(model, &SimOptions::default());
    /// sim.set_torque_controller(|_t, q, v, tau| {
    ///     for i in 0..q.len() {
    ///         tau[i] = -50.0 * q[i] - 5.0 * v[i]; // a PD law on every joint
    ///     }
    /// });
    /// for _ in 0..100 {
    ///     sim.step()?;
    /// }
    /// assert!((sim.data.time - 0.2).abs() < 1e-12); // 100 steps of MuJoCo's default 2 ms
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn new(model: Arc<Model>, options: &SimOptions) -> Self {
        let mut notes = Vec::new();
        let integrator = options.integrator.unwrap_or_else(|| {
            let (kind, note) = IntegratorKind::from_option(model.options.integrator);
            notes.extend(note);
            kind
        });
        let fixed_step = integrator != IntegratorKind::Adaptive;
        let mut model = model;
        if let Some(mode) = options.constraints {
            Arc::make_mut(&mut model).set_constraint_mode(mode);
        }
        if integrator == IntegratorKind::Variational
            && model.plan.mode() == ConstraintMode::Soft
            && model.plan.has_constraints()
        {
            // The variational integrator holds constraints itself (equality multipliers, limits and
            // contacts by projection): the soft model's forces would be left out of its equations.
            let why = format!(
                "{}, but the variational integrator holds constraints exactly (multipliers and projection), so exact is used",
                model.plan.mode_reason
            );
            let m = Arc::make_mut(&mut model);
            m.set_constraint_mode(ConstraintMode::Exact);
            m.plan.mode_reason = why;
        }
        if let Some(drift) = options.drift {
            if let Some(e) = Arc::make_mut(&mut model).plan.solver.exact_mut() {
                e.drift = drift;
            }
        }
        if model.plan.has_constraints() {
            notes.push(format!("constraints: {} ({})", model.plan.mode().name(), model.plan.mode_reason));
        }
        let mut sim = Self {
            data: Data::new(&model),
            stepper: match (integrator, options.tolerances) {
                (IntegratorKind::Adaptive, Some([rtol, atol])) => {
                    Box::new(DormandPrince54::new(&model, rtol, atol))
                }
                _ => integrator.build(&model),
            },
            timestep: options.timestep.unwrap_or(model.options.timestep),
            steps: 0,
            notes,
            model,
            controller: None,
            torque_controller: None,
            fixed_step,
        };
        sim.sync_timestep();
        sim
    }

    /// For a fixed-step integrator, makes the model's timestep the step's (a copy of the model
    /// when they differ): what `refsafe` and `actearly` read.
    fn sync_timestep(&mut self) {
        if self.fixed_step && self.model.options.timestep != self.timestep {
            Arc::make_mut(&mut self.model).options.timestep = self.timestep;
        }
    }

    /// Installs a controller `f(time, q, v, ctrl)` that sets the controls, one per actuator in
    /// MuJoCo's order, before each step (see [`Controller`]).
    pub fn set_controller(&mut self, f: impl FnMut(f64, &[f64], &[f64], &mut [f64]) + Send + 'static) {
        self.controller = Some(Box::new(f));
    }

    /// Installs a controller `f(time, q, v, qfrc_applied)` that sets the applied generalized
    /// forces (joint torques, nv values) before each step: torque control of models without
    /// actuators, such as URDF robots (bounded by `<limit effort>` when loaded with
    /// `clamp_effort`).
    pub fn set_torque_controller(&mut self, f: impl FnMut(f64, &[f64], &[f64], &mut [f64]) + Send + 'static) {
        self.torque_controller = Some(Box::new(f));
    }

    /// Sets the state; rejects wrong lengths and non-finite values.
    pub fn set_state(&mut self, q: &[f64], v: &[f64]) -> Result<(), SimError> {
        if q.len() != self.model.nq || v.len() != self.model.nv {
            return Err(SimError::BadState(format!(
                "q has {} values and v {}, the model needs nq = {} and nv = {}",
                q.len(),
                v.len(),
                self.model.nq,
                self.model.nv
            )));
        }
        if let Some(i) = q.iter().chain(v).position(|x| !x.is_finite()) {
            return Err(SimError::BadState(format!("value {i} of (q, v) is not finite")));
        }
        self.data.qpos.copy_from_slice(q);
        self.data.qvel.copy_from_slice(v);
        self.data.stepper.failed = None;
        Ok(())
    }

    /// Sets the actuator activations (MuJoCo's `act`, one per actuator with activation dynamics,
    /// in actuator order); rejects a wrong length and non-finite values.
    pub fn set_act(&mut self, act: &[f64]) -> Result<(), SimError> {
        let na = self.model.na();
        if act.len() != na {
            return Err(SimError::BadState(format!(
                "act has {} values, the model has na = {na} activation states (one per actuator with a dyntype other than 'none')",
                act.len()
            )));
        }
        if let Some(i) = act.iter().position(|x| !x.is_finite()) {
            return Err(SimError::BadState(format!("value {i} of act is not finite")));
        }
        self.data.act.copy_from_slice(act);
        Ok(())
    }

    /// The actuator activations of the current state (MuJoCo's `act`).
    pub fn act(&self) -> &[f64] {
        self.data.act.as_slice()
    }

    /// Controls, one per actuator (MuJoCo's `ctrl`).
    pub fn ctrl_mut(&mut self) -> &mut [f64] {
        self.data.ctrl.as_mut_slice()
    }

    /// Applied generalized forces (MuJoCo's `qfrc_applied`), zero by default, held constant.
    pub fn qfrc_applied_mut(&mut self) -> &mut [f64] {
        self.data.qfrc_applied.as_mut_slice()
    }

    /// Advances one step of `timestep`; a non-finite result is reported, never propagated.
    ///
    /// # Errors
    /// [`SimError::Input`] for a `timestep` of 0, negative or not finite; after a step that
    /// failed ([`SimError::Diverged`], [`SimError::NotConverged`], [`SimError::AdaptiveStalled`])
    /// every further step is [`SimError::Refused`] until the state is set
    /// ([`set_state`](Self::set_state)) or reset ([`reset`](crate::model::reset::reset) on
    /// `data`).
    pub fn step(&mut self) -> Result<StepReport, SimError> {
        if let Some(f) = &self.data.stepper.failed {
            return Err(f.refusal());
        }
        crate::integrate::check_timestep("Simulation::step", "Simulation::timestep", self.timestep)?;
        let (model, d) = (&self.model, &mut self.data);
        d.warnings.check_quaternions(model, d.qpos.as_slice());
        let result = self.step_unguarded();
        if let Err(e) = &result {
            self.data.stepper.failed = crate::integrate::FailedStep::of(e, self.steps + 1, self.data.time);
        }
        result
    }

    /// Sets the step size of [`step`](Self::step) (see [`timestep`](Self::timestep)); rejects 0,
    /// negative and non-finite values.
    pub fn set_timestep(&mut self, timestep: f64) -> Result<(), SimError> {
        crate::integrate::check_timestep("Simulation::set_timestep", "timestep", timestep)?;
        self.timestep = timestep;
        Ok(())
    }

    fn step_unguarded(&mut self) -> Result<StepReport, SimError> {
        let d = &mut self.data;
        let (t, q, v) = (d.time, d.qpos.as_slice(), d.qvel.as_slice());
        if let Some(f) = self.controller.as_mut() {
            f(t, q, v, d.ctrl.as_mut_slice());
        }
        if let Some(f) = self.torque_controller.as_mut() {
            f(t, q, v, d.qfrc_applied.as_mut_slice());
        }
        // `timestep` may have been set after `new`.
        self.sync_timestep();
        let mut report = self.stepper.step(&self.model, &mut self.data, self.timestep);
        // The next soft solve's warm start: this step's acceleration, rows or not (MuJoCo's
        // mj_advance), so that a solve with no iterations starts where the motion is.
        self.data.qacc_warmstart.copy_from(&self.data.qacc);
        if self.model.plan.solver.soft_weights().is_some() && self.data.nefc > 0 {
            report.solver_improvement = self.data.solver_improvement;
        }
        if let Some(s) = self.stepper.stalled() {
            let why = if s.collapsed {
                format!(
                    "its step size collapsed to {:.3e} s (error estimate {:.3e} of the tolerance)",
                    s.h, s.error
                )
            } else {
                format!(
                    "with contact, limit or friction rows it took {} force evaluations where fixed rk4 steps of the model's timestep ({} s) take {} (budget {}x + {}; last step size {:.3e} s, error estimate {:.3e} of the tolerance): the constraint forces are only as accurate as their solve and switch with the rows, so the error estimate cannot get under these tolerances",
                    s.evaluations,
                    self.model.options.timestep,
                    s.fixed_step_evaluations,
                    crate::integrate::BUDGET_FACTOR,
                    crate::integrate::BUDGET_GRACE,
                    s.h,
                    s.error
                )
            };
            return Err(SimError::AdaptiveStalled {
                time: self.data.time,
                step: self.steps + 1,
                why,
                rtol: s.tolerances[0],
                atol: s.tolerances[1],
            });
        }
        if let Some(f) = self.stepper.failure() {
            return Err(SimError::NotConverged {
                integrator: self.stepper.name(),
                time: self.data.time,
                step: self.steps + 1,
                dt: self.timestep,
                iterations: f.iterations,
                residual: f.residual,
                update: f.update,
                constraint: f.constraint,
            });
        }
        self.steps += 1;
        self.check_finite()?;
        Ok(report)
    }

    /// What to try after a divergence, given what is in use: the first step points at the
    /// initial state, later ones at the step size and the integrators not yet in use.
    fn divergence_hint(&self) -> String {
        if self.steps <= 1 {
            return format!(
                "it diverged in the first step, so the step size ({} s) is unlikely the cause: check the initial state (a huge initial velocity, a configuration far outside the joint limits) and the model's inertias",
                self.timestep
            );
        }
        let mut hint = format!("reduce SimOptions::timestep (now {} s)", self.timestep);
        match self.integrator() {
            "rk4" | "adaptive" => {}
            "euler" => hint.push_str(", or use SimOptions::integrator = rk4 (or implicit for stiff damping)"),
            _ => hint.push_str(", or use SimOptions::integrator = rk4"),
        }
        hint.push_str("; if it persists, check the model's stiffnesses and inertias");
        hint
    }

    fn check_finite(&self) -> Result<(), SimError> {
        check_finite(&self.model, &self.data, self.steps, || self.divergence_hint())
    }

    /// Kinetic and potential energy (T, V: gravity and joint springs) at the current state
    /// (forward kinematics included).
    pub fn energies(&mut self) -> (f64, f64) {
        let (q, v) = (std::mem::take(&mut self.data.qpos), std::mem::take(&mut self.data.qvel));
        let kinetic =
            dynamics::kinetic_energy_unchecked(&self.model, &mut self.data, q.as_slice(), v.as_slice());
        let potential = dynamics::potential_energy(&self.model, &self.data)
            + self.model.spring_energy_unchecked(q.as_slice());
        (self.data.qpos, self.data.qvel) = (q, v);
        (kinetic, potential)
    }

    /// Forward kinematics at the current state (poses in `data`).
    pub fn kinematics(&mut self) {
        let q = std::mem::take(&mut self.data.qpos);
        self.data.poses_stamp.clear();
        self.data.velocity_stamp.clear();
        forward_kinematics_unchecked(&self.model, &mut self.data, q.as_slice());
        self.data.qpos = q;
    }

    /// max |φ| and max |J v| of the active constraint rows at the current state (0 without rows).
    pub fn constraint_violation(&mut self) -> [f64; 2] {
        if !self.model.plan.has_constraints() {
            return [0.0, 0.0];
        }
        let (q, v) = (std::mem::take(&mut self.data.qpos), std::mem::take(&mut self.data.qvel));
        self.model.plan.constraints.evaluate_unchecked(
            &self.model,
            &mut self.data,
            q.as_slice(),
            v.as_slice(),
        );
        (self.data.qpos, self.data.qvel) = (q, v);
        crate::constraint::row_violation(&self.data)
    }

    /// The stepper's name.
    pub fn integrator(&self) -> &'static str {
        self.stepper.name()
    }
}

/// `Ok` while the state in `data` is finite; else [`SimError::Diverged`] naming the joint where
/// it started (a singular articulated inertia first: that is the origin no step size fixes), the
/// time and `step`, with `hint` for a state that went non-finite.
pub(crate) fn check_finite(
    model: &Model,
    data: &Data,
    step: u64,
    hint: impl FnOnce() -> String,
) -> Result<(), SimError> {
    if data.qpos.iter().chain(data.qvel.iter()).all(|x| x.is_finite()) {
        return Ok(());
    }
    // Non-finite values spread through ABA to every joint; the origin is a joint whose
    // articulated inertia D = Sᵀ Iᴬ S was singular. Leaves first, the first such joint has
    // only finite descendants.
    for b in (1..model.nbody()).rev() {
        let j = model.joint_of(b);
        let d_inv = data.d_inv[b][(0, 0)];
        if !d_inv.is_finite() {
            return Err(SimError::Diverged {
                time: data.time,
                step,
                quantity: "articulated inertia about the axis (D⁻¹)",
                joint: j.name.clone(),
                value: d_inv,
                hint: "the joint carries no mass or inertia about its axis at this configuration, which no step size fixes: check the inertias of the bodies it moves".into(),
            });
        }
    }
    for (quantity, values, by_dof) in
        [("position", data.qpos.as_slice(), false), ("velocity", data.qvel.as_slice(), true)]
    {
        if let Some(i) = values.iter().position(|x| !x.is_finite()) {
            let joint = model
                .joints
                .iter()
                .find(|j| {
                    let (adr, n) = if by_dof { (j.dof_adr, j.kind.nv()) } else { (j.qpos_adr, j.kind.nq()) };
                    (adr..adr + n).contains(&i)
                })
                .map(|j| j.name.clone())
                .unwrap_or_default();
            return Err(SimError::Diverged {
                time: data.time,
                step,
                quantity,
                joint,
                value: values[i],
                hint: hint(),
            });
        }
    }
    Ok(())
}
