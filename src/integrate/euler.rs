//! Semi-implicit (symplectic) Euler: v ← v + h·v̇(q, v); q ← q ⊕ h·v (first order; MuJoCo's
//! default `Euler` without implicit damping). Activations advance from the same evaluation
//! (MuJoCo's `mj_advance`: `filterexact` exactly, then clamped to `actrange`).

use super::{correct_drift, State, StepReport, Stepper};
use crate::forward::{advance_activations, forward, Plan};
use crate::model::{integrate_configuration, Data, Model};

/// Semi-implicit Euler stepper.
pub struct SemiImplicitEuler;

impl SemiImplicitEuler {
    pub fn new(_model: &Model) -> Self {
        Self
    }
}

impl Stepper for SemiImplicitEuler {
    fn name(&self) -> &'static str {
        "euler"
    }
    fn order(&self) -> u32 {
        1
    }
    fn step(&mut self, model: &Model, plan: &Plan, data: &mut Data, state: &mut State, h: f64) -> StepReport {
        data.act.copy_from(&state.act);
        forward(model, plan, data, state.q.as_slice(), state.v.as_slice());
        advance_activations(model, state.act.as_mut_slice(), data.act_dot.as_slice(), h);
        state.v.axpy(h, &data.qacc, 1.0);
        integrate_configuration(model, state.q.as_mut_slice(), state.v.as_slice(), h);
        state.time += h;
        StepReport::fixed_step(h, correct_drift(model, plan, data, state, h))
    }
}
