//! Semi-implicit (symplectic) Euler: v ← v + h·v̇(q, v); q ← q ⊕ h·v (first order; MuJoCo's
//! default `Euler` without implicit damping).

use super::{accelerations, Integrator, State};
use crate::model::{integrate_configuration, Data, Model};
use nalgebra::DVector;

/// Semi-implicit Euler stepper.
pub struct SemiImplicitEuler {
    tau_total: DVector<f64>,
    qacc: DVector<f64>,
}

impl SemiImplicitEuler {
    pub fn new(model: &Model) -> Self {
        Self { tau_total: DVector::zeros(model.nv), qacc: DVector::zeros(model.nv) }
    }
}

impl Integrator for SemiImplicitEuler {
    fn name(&self) -> &'static str {
        "euler"
    }
    fn order(&self) -> u32 {
        1
    }
    fn step(&mut self, model: &Model, data: &mut Data, state: &mut State, tau: &[f64], dt: f64) {
        accelerations(
            model,
            data,
            state.q.as_slice(),
            state.v.as_slice(),
            tau,
            &mut self.tau_total,
            &mut self.qacc,
        );
        state.v.axpy(dt, &self.qacc, 1.0);
        integrate_configuration(model, state.q.as_mut_slice(), state.v.as_slice(), dt);
        state.time += dt;
    }
}
