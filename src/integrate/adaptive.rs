//! Adaptive Dormand–Prince 5(4) (Dormand & Prince, *A family of embedded Runge–Kutta formulae*,
//! J. Comput. Appl. Math. 6, 1980; Hairer, Nørsett & Wanner, *Solving ODEs I*, §II.4–5 for the
//! error norm and step-size control) on the configuration manifold, with the same
//! Runge–Kutta–Munthe-Kaas stages as [`RungeKutta4`](super::RungeKutta4): stage configurations
//! q₀ ⊕ θᵢ, slopes of θ from dexp⁻¹.
//!
//! [`Stepper::step`] advances by exactly the requested interval `h` in as many internal steps as
//! the error control needs (so fixed-interval callers such as `simulate` and `workprec` can use
//! it); the internal step size carries over between calls. The error of an internal step is the
//! max over components of |y₅ − y₄| / (atol + rtol·s), with s = max(|y₀|, |y₁|) for v and flat
//! coordinates and s = 1 rad for the rotation-vector coordinates of quaternion joints; a step is
//! accepted when that is ≤ 1, and the next size is h·min(5, max(0.2, 0.9·err^(−1/5))).
//! Actuator activations are components of the same ODE (their rates `act_dot`, their error in the
//! norm with s = max(|w₀|, |w₁|)), clamped to `actrange` after each accepted internal step.
//!
//! **Limits.** Error control assumes a smooth right-hand side. With contact, limit or friction
//! rows the accelerations are only as accurate as the constraint solve (the soft solver stops at
//! its `tolerance`) and switch with the rows, so the error estimate has a floor that tight
//! tolerances cannot get under: the step size then collapses (a box resting on a floor at
//! rtol 1e-12 took minutes for 0.1 s). The stepper therefore keeps a work budget while such rows
//! exist: [`BUDGET_FACTOR`] times the force evaluations of fixed RK4 steps of the model's
//! timestep over the same time, plus [`BUDGET_GRACE`]; past it, it stops with an
//! [`AdaptiveStall`] (reported by [`Simulation::step`](crate::sim::Simulation::step) as
//! [`SimError::AdaptiveStalled`](crate::sim::SimError::AdaptiveStalled)), as it does when the
//! step size collapses below 1e-14 of the interval.

use super::stage::{evaluate_stage, StageInput};
use super::{correct_drift, Advance, State, StepReport, Stepper};
use crate::forward::clamp_activations;
use crate::model::EfcType;
use crate::model::{integrate_configuration_unchecked, Data, JointKind, Model};
use nalgebra::DVector;

/// Matrix and the two weight rows of Dormand–Prince 5(4) (the dynamics are autonomous: the
/// nodes cᵢ are not needed).
const A: [[f64; 6]; 7] = [
    [0.0; 6],
    [1.0 / 5.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
    [19372.0 / 6561.0, -25360.0 / 2187.0, 64448.0 / 6561.0, -212.0 / 729.0, 0.0, 0.0],
    [9017.0 / 3168.0, -355.0 / 33.0, 46732.0 / 5247.0, 49.0 / 176.0, -5103.0 / 18656.0, 0.0],
    [35.0 / 384.0, 0.0, 500.0 / 1113.0, 125.0 / 192.0, -2187.0 / 6784.0, 11.0 / 84.0],
];
const B5: [f64; 7] = [35.0 / 384.0, 0.0, 500.0 / 1113.0, 125.0 / 192.0, -2187.0 / 6784.0, 11.0 / 84.0, 0.0];
const B4: [f64; 7] =
    [5179.0 / 57600.0, 0.0, 7571.0 / 16695.0, 393.0 / 640.0, -92097.0 / 339200.0, 187.0 / 2100.0, 1.0 / 40.0];

/// Default tolerances of `--integrator adaptive`.
pub const DEFAULT_RTOL: f64 = 1e-8;
/// Default absolute tolerance of `--integrator adaptive`.
pub const DEFAULT_ATOL: f64 = 1e-10;

/// The adaptive stepper's work budget while contact, limit or friction rows exist: this many
/// times the force evaluations of fixed RK4 steps (4 per step) of the model's timestep.
pub const BUDGET_FACTOR: f64 = 10.0;
/// Force evaluations allowed beyond the budget (100 attempts of 7 stages: the start, where the
/// first step size is found, and the transients of contacts coming and going).
pub const BUDGET_GRACE: f64 = 700.0;

/// Why the adaptive stepper stopped before the end of its interval (the state is left where
/// error control stopped).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AdaptiveStall {
    /// Force evaluations (7 per attempt) since the stepper was built.
    pub evaluations: u64,
    /// What fixed RK4 steps of the model's timestep would have taken over the same time.
    pub fixed_step_evaluations: u64,
    /// Whether contact, limit or friction rows existed (the work budget applies then).
    pub rows: bool,
    /// Whether the step size collapsed (below 1e-14 of the interval) rather than the budget ran out.
    pub collapsed: bool,
    /// The last attempted internal step size (s).
    pub h: f64,
    /// The last attempt's scaled error norm.
    pub error: f64,
    /// The tolerances in use (rtol, atol).
    pub tolerances: [f64; 2],
}

/// Dormand–Prince 5(4) stepper with error control.
pub struct DormandPrince54 {
    /// The activations `forward` reads in a stage (`data.act` while the state is moved out).
    stage_act: DVector<f64>,
    /// Relative tolerance of the error control.
    pub rtol: f64,
    /// Absolute tolerance of the error control (m, rad, m/s, rad/s as the component is).
    pub atol: f64,
    /// The internal step size proposed for the next step (None before the first).
    h_proposed: Option<f64>,
    q_stage: DVector<f64>,
    v_stage: DVector<f64>,
    theta: DVector<f64>,
    theta_rate: [DVector<f64>; 7],
    a_stage: [DVector<f64>; 7],
    /// Stage rates of the activations (`act_dot`) and the stage activations (na each).
    act_rate: [DVector<f64>; 7],
    act_stage: DVector<f64>,
    /// Per dof: the qpos index of a flat coordinate, None for the rotation-vector coordinates
    /// of quaternion joints.
    flat_qpos: Vec<Option<usize>>,
    /// Force evaluations since the stepper was built, and the simulated time they covered.
    evaluations: u64,
    covered: f64,
    /// Whether the last attempt had contact, limit or friction rows.
    rows: bool,
    /// Why the last step stopped early, if it did.
    stall: Option<AdaptiveStall>,
}

impl DormandPrince54 {
    /// The stepper for `model` with tolerances `rtol` and `atol`.
    pub fn new(model: &Model, rtol: f64, atol: f64) -> Self {
        let z = || DVector::zeros(model.nv);
        let mut flat_qpos = vec![None; model.nv];
        for j in &model.joints {
            for k in 0..j.kind.nv() {
                let rotational =
                    matches!(j.kind, JointKind::Ball) || matches!(j.kind, JointKind::Free if k >= 3);
                flat_qpos[j.dof_adr + k] = (!rotational).then_some(j.qpos_adr + k);
            }
        }
        Self {
            stage_act: DVector::zeros(model.na()),
            rtol,
            atol,
            h_proposed: None,
            q_stage: DVector::zeros(model.nq),
            v_stage: z(),
            theta: z(),
            theta_rate: std::array::from_fn(|_| z()),
            a_stage: std::array::from_fn(|_| z()),
            act_rate: std::array::from_fn(|_| DVector::zeros(model.na())),
            act_stage: DVector::zeros(model.na()),
            flat_qpos,
            evaluations: 0,
            covered: 0.0,
            rows: false,
            stall: None,
        }
    }

    /// The force evaluations fixed RK4 steps of the model's timestep take over `time`.
    fn fixed_step_evaluations(model: &Model, time: f64) -> f64 {
        4.0 * (time / model.options.timestep).ceil().max(1.0)
    }

    /// One internal step of size h from `state` (left unchanged); the stages are left in the
    /// buffers. Returns the scaled error norm.
    fn attempt(&mut self, model: &Model, data: &mut Data, state: &State, h: f64) -> f64 {
        // The first stage picks the limit and contact rows; the later ones keep them. `rows`
        // says whether any stage had contact, limit or friction rows (the work budget).
        data.thaw_rows();
        for i in 0..7 {
            self.v_stage.copy_from(&state.v);
            self.theta.fill(0.0);
            data.act.copy_from(&state.act);
            for j in 0..i {
                self.v_stage.axpy(h * A[i][j], &self.a_stage[j], 1.0);
                self.theta.axpy(h * A[i][j], &self.theta_rate[j], 1.0);
                data.act.axpy(h * A[i][j], &self.act_rate[j], 1.0);
            }
            evaluate_stage(
                model,
                data,
                StageInput { q0: &state.q, theta: &self.theta, v_stage: &self.v_stage },
                &mut self.q_stage,
                (&mut self.a_stage[i], &mut self.theta_rate[i]),
            );
            self.act_rate[i].copy_from(&data.act_dot);
            if i == 0 {
                data.freeze_rows(false);
                self.rows = false;
            }
            self.rows |= data.efc_type[..data.nefc].iter().any(|t| *t != EfcType::Equality);
        }
        // Stage 7 sits at the fifth-order solution (C[6] = 1, A[6] = B5): θ and v_stage hold
        // y₅ − y₀ in θ and y₅ in v.
        let mut err: f64 = 0.0;
        for k in 0..model.nv {
            let (mut e_theta, mut e_v) = (0.0, 0.0);
            for i in 0..7 {
                let e = B5[i] - B4[i];
                e_theta += h * e * self.theta_rate[i][k];
                e_v += h * e * self.a_stage[i][k];
            }
            let s_v = state.v[k].abs().max(self.v_stage[k].abs());
            let s_q = match self.flat_qpos[k] {
                Some(i) => state.q[i].abs().max((state.q[i] + self.theta[k]).abs()),
                None => 1.0,
            };
            let e = (e_theta.abs() / (self.atol + self.rtol * s_q))
                .max(e_v.abs() / (self.atol + self.rtol * s_v));
            if e.is_nan() || !e_theta.is_finite() || !e_v.is_finite() {
                // A non-finite stage (f64::max would drop a NaN): reject the attempt.
                return f64::INFINITY;
            }
            err = err.max(e);
        }
        // Stage 7's activations are the fifth-order solution too.
        self.act_stage.copy_from(&data.act);
        for k in 0..self.act_stage.len() {
            let e_act: f64 = (0..7).map(|i| h * (B5[i] - B4[i]) * self.act_rate[i][k]).sum();
            let s = state.act[k].abs().max(self.act_stage[k].abs());
            let e = e_act.abs() / (self.atol + self.rtol * s);
            if !e.is_finite() {
                return f64::INFINITY;
            }
            err = err.max(e);
        }
        err
    }
}

impl Stepper for DormandPrince54 {
    fn name(&self) -> &'static str {
        "adaptive"
    }
    fn order(&self) -> u32 {
        5
    }
    fn step(&mut self, model: &Model, data: &mut Data, h: f64) -> StepReport {
        self.stall = None;
        self.step_moved(model, data, h)
    }
    fn stalled(&self) -> Option<AdaptiveStall> {
        self.stall
    }
}

impl Advance for DormandPrince54 {
    fn stage_act(&mut self) -> &mut DVector<f64> {
        &mut self.stage_act
    }

    fn advance(&mut self, model: &Model, data: &mut Data, state: &mut State, h: f64) -> StepReport {
        let (t_start, t_end) = (state.time, state.time + h);
        let mut h_try = self.h_proposed.unwrap_or(h).min(h);
        let mut max_err: f64 = 0.0;
        let (mut accepted, mut rejected) = (0u32, 0u32);
        let mut rows_seen = false;
        loop {
            let remaining = t_end - state.time;
            if remaining <= 1e-14 * t_end.abs().max(h) {
                break;
            }
            let last = h_try >= remaining;
            let h_step = if last { remaining } else { h_try };
            let err = self.attempt(model, data, state, h_step);
            self.evaluations += 7;
            let fixed = Self::fixed_step_evaluations(model, self.covered + (state.time - t_start));
            rows_seen |= self.rows;
            let over_budget = rows_seen && self.evaluations as f64 > BUDGET_FACTOR * fixed + BUDGET_GRACE;
            let factor = if err == 0.0 { 5.0 } else { (0.9 * err.powf(-0.2)).clamp(0.2, 5.0) };
            if err <= 1.0 && err.is_finite() {
                state.v.copy_from(&self.v_stage);
                state.act.copy_from(&self.act_stage);
                clamp_activations(model, state.act.as_mut_slice());
                integrate_configuration_unchecked(model, state.q.as_mut_slice(), self.theta.as_slice(), 1.0);
                state.time = if last { t_end } else { state.time + h_step };
                max_err = max_err.max(err);
                accepted += 1;
                if !last || self.h_proposed.is_none() {
                    h_try = h_step * factor;
                }
            } else {
                rejected += 1;
                h_try = h_step * if err.is_finite() { factor.min(1.0) } else { 0.2 };
            }
            let collapsed = h_try < 1e-14 * h || rejected > 100_000;
            if collapsed || (over_budget && state.time != t_end) {
                // Give up on this interval: the state stays where error control stopped,
                // and the report says so.
                self.covered += state.time - t_start;
                self.stall = Some(AdaptiveStall {
                    evaluations: self.evaluations,
                    fixed_step_evaluations: Self::fixed_step_evaluations(model, self.covered) as u64,
                    rows: rows_seen,
                    collapsed,
                    h: h_step,
                    error: err,
                    tolerances: [self.rtol, self.atol],
                });
                self.h_proposed = Some(h_try);
                return StepReport {
                    accepted: false,
                    h_used: state.time - (t_end - h),
                    h_next: h_try,
                    error_estimate: Some(err),
                    substeps: accepted,
                    rejected,
                    ..StepReport::fixed_step(h, correct_drift(model, data, state, h))
                };
            }
        }
        self.h_proposed = Some(h_try);
        self.covered += h;
        StepReport {
            h_next: h_try,
            error_estimate: Some(max_err),
            substeps: accepted,
            rejected,
            ..StepReport::fixed_step(h, correct_drift(model, data, state, h))
        }
    }
}
