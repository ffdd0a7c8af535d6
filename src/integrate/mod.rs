//! Time steppers (docs/architecture.md, "Layers"). Every integrator implements [`Stepper`] over the staged
//! [`forward`](crate::forward::forward) pipeline and returns a [`StepReport`]; each owns the stage
//! buffers it needs, allocated once, so a step allocates nothing.
//!
//! The continuous dynamics are q̇ = v (on the configuration manifold, see
//! [`integrate_configuration`](crate::model::integrate_configuration)) and v̇ = `qacc` of
//! `forward`. With constraint rows, drift is corrected after each step by the model's constraint solver
//! ([`ConstraintSolver`](crate::constraint::ConstraintSolver)): in exact mode q is projected onto
//! φ(q) = 0 and v onto J v = 0, as its [`DriftCorrection`](crate::constraint::DriftCorrection) says.

mod adaptive;
mod euler;
mod implicit;
mod implicit_fast;
mod lagrangian_terms;
mod rk4;
mod stage;
mod step;
mod variational;

pub use adaptive::{AdaptiveStall, DormandPrince54, BUDGET_FACTOR, BUDGET_GRACE, DEFAULT_ATOL, DEFAULT_RTOL};
pub use euler::SemiImplicitEuler;
pub use implicit::Implicit;
pub(crate) use implicit_fast::add_force_derivative;
pub use implicit_fast::ImplicitFast;
pub use lagrangian_terms::LagrangianTerms;
pub use rk4::RungeKutta4;
pub(crate) use step::check_timestep;
pub(crate) use step::StepperSlot;
pub use step::{step, FailedStep};
pub use variational::{Variational, CONSTRAINT_TOL, RESIDUAL_TOL};

use crate::model::{options, Data, Model};
use nalgebra::DVector;

/// A simulation state by value: a snapshot of [`Data`]'s state ([`State::of`]), and what a
/// stepper advances while the state is moved out of `Data` for the duration of one step
/// (`State::take`, `State::put`: the stages evaluate `forward` at other configurations,
/// velocities and activations than the step's start, which the stepper keeps here). `act` holds
/// the actuator activations (MuJoCo's `act`, `na` values; empty without activation dynamics),
/// integrated from the actuation stage's `act_dot` as MuJoCo does (`filterexact` exactly, then
/// clamped to `actrange`; `forward::advance_activations`).
#[derive(Clone, Debug, PartialEq)]
pub struct State {
    /// Simulation time (s).
    pub time: f64,
    /// Configuration (`qpos`, nq values).
    pub q: DVector<f64>,
    /// Velocity (`qvel`, nv values).
    pub v: DVector<f64>,
    /// Actuator activations (`act`, na values).
    pub act: DVector<f64>,
}

impl State {
    /// A copy of the state in `data` (`time`, `qpos`, `qvel`, `act`).
    pub fn of(data: &Data) -> Self {
        Self { time: data.time, q: data.qpos.clone(), v: data.qvel.clone(), act: data.act.clone() }
    }

    /// Moves the state out of `data` (no copy, no allocation): `data.qpos` and `data.qvel` are
    /// left empty and `data.act` becomes the stepper's stage buffer `act_stage` (na values),
    /// which the stages fill before each `forward`.
    pub(crate) fn take(data: &mut Data, act_stage: &mut DVector<f64>) -> Self {
        let act = std::mem::replace(&mut data.act, std::mem::take(act_stage));
        Self { time: data.time, q: std::mem::take(&mut data.qpos), v: std::mem::take(&mut data.qvel), act }
    }

    /// Moves the state back into `data` and the stage buffer back to the stepper.
    pub(crate) fn put(self, data: &mut Data, act_stage: &mut DVector<f64>) {
        *act_stage = std::mem::replace(&mut data.act, self.act);
        data.time = self.time;
        data.qpos = self.q;
        data.qvel = self.v;
    }
}

/// A method's step on the state moved out of `Data` for the duration of the step
/// ([`State::take`], [`State::put`]); every stepper's [`Stepper::step`] is [`step_moved`](Self::step_moved).
pub(crate) trait Advance {
    /// The stepper's buffer for the activations its stages evaluate at (na values).
    fn stage_act(&mut self) -> &mut DVector<f64>;

    /// One step of the method on `state`, with the inputs in `data`.
    fn advance(&mut self, model: &Model, data: &mut Data, state: &mut State, h: f64) -> StepReport;

    /// Moves the state out of `data`, advances it, and moves it back.
    fn step_moved(&mut self, model: &Model, data: &mut Data, h: f64) -> StepReport {
        let mut stage_act = std::mem::take(self.stage_act());
        let mut state = State::take(data, &mut stage_act);
        let start = state.time;
        let report = self.advance(model, data, &mut state, h);
        if state.time != start {
            // MuJoCo's mj_advance: the controls of the step just taken, at its start time.
            crate::forward::record_controls(model, data, start);
        }
        state.put(data, &mut stage_act);
        *self.stage_act() = stage_act;
        report
    }
}

/// What one step did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StepReport {
    /// Whether the step was taken (an adaptive stepper may reject and retry).
    pub accepted: bool,
    /// The step size used.
    pub h_used: f64,
    /// The step size proposed for the next step (= `h_used` for fixed-step methods).
    pub h_next: f64,
    /// Local error estimate, if the method has one.
    pub error_estimate: Option<f64>,
    /// Iterations of constraint solvers in this step (the exact solver is direct: 0; the
    /// Gauss–Newton iterations of the position projection are counted here; in soft mode the
    /// last soft solve's Newton/CG/PGS iterations, MuJoCo's `solver_niter`).
    pub solver_iterations: u32,
    /// Soft mode: the last solve's final improvement of the cost, scaled as MuJoCo scales it
    /// (1 / (meaninertia · nv)); set by `Simulation::step`, 0 otherwise.
    pub solver_improvement: f64,
    /// max |φ| and max |J v| after the step (0 without constraint rows).
    pub constraint_violation: [f64; 2],
    /// Internal steps accepted within the interval (1 for fixed-step methods; an adaptive
    /// method may take several, or none if it gave up).
    pub substeps: u32,
    /// Internal steps rejected by the error control within the interval (0 for fixed-step
    /// methods).
    pub rejected: u32,
}

impl StepReport {
    /// The report of an accepted fixed step `h`, with the (iterations, violation) of the drift
    /// correction.
    pub fn fixed_step(h: f64, (iterations, violation): (u32, [f64; 2])) -> Self {
        Self {
            accepted: true,
            h_used: h,
            h_next: h,
            error_estimate: None,
            solver_iterations: iterations,
            solver_improvement: 0.0,
            constraint_violation: violation,
            substeps: 1,
            rejected: 0,
        }
    }
}

/// Why a step was not taken: an implicit method's Newton iteration that did not converge (the
/// state is left at the start of the step).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepFailure {
    /// Newton iterations done.
    pub iterations: u32,
    /// Max-norm of the equations' residual at the last iterate (momentum units for the
    /// variational integrator's discrete Euler–Lagrange equations).
    pub residual: f64,
    /// max |φ| of the equality constraints at the last iterate (0 without them).
    pub constraint: f64,
    /// Max-norm of the last Newton update.
    pub update: f64,
}

/// A time stepper over [`forward`](crate::forward::forward).
pub trait Stepper: Send {
    /// Short name (`euler`, `rk4`, …).
    fn name(&self) -> &'static str;
    /// Order of the global error in the step size for smooth problems.
    fn order(&self) -> u32;
    /// Advances the state in `data` (`time`, `qpos`, `qvel`, `act`) by `h` with the inputs in
    /// `data` (`ctrl`, `qfrc_applied`) held over the step. The soft constraints' `refsafe` and
    /// `actearly` read `model.options.timestep`, as MuJoCo's read `opt.timestep`: for MuJoCo's
    /// behaviour it equals h ([`Simulation`](crate::sim::Simulation) keeps the two equal for the
    /// fixed-step integrators).
    fn step(&mut self, model: &Model, data: &mut Data, h: f64) -> StepReport;
    /// Why the last step was not taken, if it was not (a Newton iteration that failed).
    fn failure(&self) -> Option<StepFailure> {
        None
    }
    /// Why the last step of an adaptive stepper stopped before the end of its interval, if it
    /// did (its work budget with contacts, or a collapsed step size).
    fn stalled(&self) -> Option<AdaptiveStall> {
        None
    }
}

/// After a step `h` of a constrained model, the model's solver corrects the drift
/// ([`ConstraintSolver::correct_drift`](crate::constraint::ConstraintSolver)): the exact mode
/// projects q onto φ(q) = 0 and v onto J v = 0, the soft mode projects nothing. Returns
/// (iterations, [max |φ|, max |J v|]) after the correction.
pub(crate) fn correct_drift(model: &Model, data: &mut Data, state: &mut State, h: f64) -> (u32, [f64; 2]) {
    let plan = &model.plan;
    plan.solver.correct_drift(&plan.constraints, model, data, state, h)
}

/// The integrators `simulate` offers, by name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IntegratorKind {
    /// MuJoCo's semi-implicit Euler ([`SemiImplicitEuler`]).
    Euler,
    /// Classical fourth-order Runge–Kutta on the configuration manifold ([`RungeKutta4`]).
    Rk4,
    /// Dormand–Prince 5(4) with error control at [`DEFAULT_RTOL`]/[`DEFAULT_ATOL`]
    /// ([`DormandPrince54::new`] takes others).
    Adaptive,
    /// MuJoCo's implicitfast: implicit in the velocity derivatives of passive forces.
    ImplicitFast,
    /// MuJoCo's implicit: implicitfast plus the Coriolis/centrifugal derivatives ∂c/∂v.
    Implicit,
    /// The variational integrator (discrete Euler–Lagrange equations, trapezoidal discrete
    /// Lagrangian, Newton): symplectic, momentum-preserving.
    Variational,
}

impl IntegratorKind {
    /// Builds the stepper with buffers sized for `model`.
    pub fn build(self, model: &Model) -> Box<dyn Stepper> {
        match self {
            IntegratorKind::Euler => Box::new(SemiImplicitEuler::new(model)),
            IntegratorKind::Rk4 => Box::new(RungeKutta4::new(model)),
            IntegratorKind::Adaptive => Box::new(DormandPrince54::new(model, DEFAULT_RTOL, DEFAULT_ATOL)),
            IntegratorKind::ImplicitFast => Box::new(ImplicitFast::new(model)),
            IntegratorKind::Implicit => Box::new(Implicit::new(model)),
            IntegratorKind::Variational => Box::new(Variational::new(model)),
        }
    }

    /// The stepper for a model file's `<option integrator>` (each of MuJoCo's four has its
    /// twin here; the note is for integrators that are not).
    pub fn from_option(integrator: options::Integrator) -> (Self, Option<String>) {
        match integrator {
            options::Integrator::Euler => (IntegratorKind::Euler, None),
            options::Integrator::Rk4 => (IntegratorKind::Rk4, None),
            options::Integrator::ImplicitFast => (IntegratorKind::ImplicitFast, None),
            options::Integrator::Implicit => (IntegratorKind::Implicit, None),
        }
    }

    /// Short name (`euler`, `rk4`, …), as reports print it.
    pub fn name(self) -> &'static str {
        match self {
            IntegratorKind::Euler => "euler",
            IntegratorKind::Rk4 => "rk4",
            IntegratorKind::Adaptive => "adaptive",
            IntegratorKind::ImplicitFast => "implicitfast",
            IntegratorKind::Implicit => "implicit",
            IntegratorKind::Variational => "variational",
        }
    }
}
