//! MuJoCo's `implicit` integrator (MuJoCo documentation, "Computation → Numerical integration";
//! `mj_implicit` in its engine_forward.c): velocity-implicit in the full derivative
//! D = ∂(qfrc_passive + qfrc_actuator − qfrc_bias)/∂v, Coriolis and centrifugal terms included:
//!
//!   (M − h D) a = M qacc,   v ← v + h a,   q ← q ⊕ h v,
//!
//! with qacc `forward`'s acceleration (M qacc = qfrc_smooth + qfrc_constraint, the right-hand side
//! MuJoCo solves with). D is not symmetric once −∂c/∂v ([`BiasDerivative`]) is in it, so the
//! system is solved by an LU factorization without pivoting, as MuJoCo's `mju_factorLUSparse`
//! (M − h D is M, positive definite, plus a small perturbation for reasonable h). The passive and
//! actuator part of D is [`add_force_derivative`]'s, shared with implicitfast, which drops ∂c/∂v.

use super::{add_force_derivative, correct_drift, Advance, State, StepReport, Stepper};
use crate::dynamics::crba_unchecked;
use crate::dynamics::BiasDerivative;
use crate::forward::{add_actuator_velocity_derivative, advance_activations, forward_at};
use crate::model::{Data, Model};
use nalgebra::{DMatrix, DVector};

/// The implicit stepper with its derivative pass, LU matrix and force buffer.
pub struct Implicit {
    /// The activations `forward` reads in a stage (`data.act` while the state is moved out).
    stage_act: DVector<f64>,
    derivative: BiasDerivative,
    lu: DMatrix<f64>,
    force: DVector<f64>,
}

impl Implicit {
    /// The stepper with its buffers sized for `model`.
    pub fn new(model: &Model) -> Self {
        Self {
            stage_act: DVector::zeros(model.na()),
            derivative: BiasDerivative::new(model),
            lu: DMatrix::zeros(model.nv, model.nv),
            force: DVector::zeros(model.nv),
        }
    }
}

/// In-place LU factorization without pivoting of the n × n leading block of the column-major
/// `a` with leading dimension `ld` (entry (i, j) at i + j·ld). Doolittle: unit lower L below the
/// diagonal, U on and above it.
pub(crate) fn lu_factor_in_place(a: &mut [f64], n: usize, ld: usize) {
    for k in 0..n {
        let pivot = a[k + k * ld];
        for i in k + 1..n {
            a[i + k * ld] /= pivot;
        }
        for j in k + 1..n {
            let akj = a[k + j * ld];
            if akj != 0.0 {
                for i in k + 1..n {
                    a[i + j * ld] -= a[i + k * ld] * akj;
                }
            }
        }
    }
}

/// Solves L U x = b in place (`x` holds b, length n) with the factor of [`lu_factor_in_place`].
pub(crate) fn lu_solve_in_place(a: &[f64], n: usize, ld: usize, x: &mut [f64]) {
    for j in 0..n {
        let xj = x[j];
        for i in j + 1..n {
            x[i] -= a[i + j * ld] * xj;
        }
    }
    for j in (0..n).rev() {
        x[j] /= a[j + j * ld];
        let xj = x[j];
        for i in 0..j {
            x[i] -= a[i + j * ld] * xj;
        }
    }
}

impl Stepper for Implicit {
    fn name(&self) -> &'static str {
        "implicit"
    }
    fn order(&self) -> u32 {
        1
    }
    fn step(&mut self, model: &Model, data: &mut Data, h: f64) -> StepReport {
        self.step_moved(model, data, h)
    }
}

impl Advance for Implicit {
    fn stage_act(&mut self) -> &mut DVector<f64> {
        &mut self.stage_act
    }

    fn advance(&mut self, model: &Model, data: &mut Data, state: &mut State, h: f64) -> StepReport {
        let nv = model.nv;
        data.act.copy_from(&state.act);
        forward_at(model, data, state.q.as_slice(), state.v.as_slice());
        // MuJoCo's mj_step: the sensors of the state the step starts from.
        crate::sensor::compute_at(model, data, state.q.as_slice(), state.v.as_slice(), state.time);
        // Activations as in MuJoCo's `mj_advance` (explicit in act_dot; filterexact exact).
        advance_activations(model, state.act.as_mut_slice(), data.act_dot.as_slice(), h);
        // MuJoCo's mj_advance: islands at rest fall asleep (their v zeroed) before v advances.
        crate::forward::sleep::sleep_islands(model, data, state.q.as_slice(), state.v.as_mut_slice());
        crba_unchecked(model, data, state.q.as_slice());
        self.force.gemv(1.0, &data.mass_matrix, &data.qacc, 0.0);
        self.derivative.compute(model, data, state.q.as_slice(), state.v.as_slice());
        // M − h D = M + h ∂c/∂v − h ∂(passive + actuator)/∂v.
        for (l, (m, d)) in
            self.lu.iter_mut().zip(data.mass_matrix.iter().zip(self.derivative.dbias_dv.iter()))
        {
            *l = m + h * d;
        }
        add_force_derivative(model, self.lu.as_mut_slice(), h);
        if !model.actuators.is_empty() && model.options.flags.actuation {
            add_actuator_velocity_derivative(
                model,
                data,
                &model.plan.actuator_bias_velocity,
                self.lu.as_mut_slice(),
                h,
            );
        }
        lu_factor_in_place(self.lu.as_mut_slice(), nv, nv);
        lu_solve_in_place(self.lu.as_slice(), nv, nv, self.force.as_mut_slice());
        state.v.axpy(h, &self.force, 1.0);
        crate::forward::sleep::hold_velocities(model, data, state.v.as_mut_slice());
        crate::forward::sleep::integrate_awake(model, data, state.q.as_mut_slice(), state.v.as_slice(), h);
        state.time += h;
        StepReport::fixed_step(h, correct_drift(model, data, state, h))
    }
}
