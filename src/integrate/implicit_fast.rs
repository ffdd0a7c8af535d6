//! MuJoCo's `implicitfast` integrator on its passive part (MuJoCo documentation, "Computation →
//! Numerical integration"): velocity-implicit in the derivative D = ∂qfrc/∂v of the forces that
//! depend on velocity, without the Coriolis/centrifugal derivatives (that is what "fast" drops):
//!
//!   (M − h D) a = M qacc,   v ← v + h a,   q ← q ⊕ h v,
//!
//! where qacc is `forward`'s acceleration (constraint forces included) and M qacc the total
//! force it balances. Today D = −diag(`dof_damping`), joint damping being the only
//! velocity-dependent passive force; actuator derivatives add to D in [`add_force_derivative`]
//! when actuators exist. With only joint damping this is also what MuJoCo's `Euler` does
//! (implicit damping), so its `mj_step` is the reference on damped passive scenes.
//! [`Implicit`](super::Implicit) adds the Coriolis derivatives −∂c/∂v to D.

use super::{correct_drift, State, StepReport, Stepper};
use crate::dynamics::{crba, factorize_mass_matrix, solve_with_factor};
use crate::forward::{forward, Plan};
use crate::model::{integrate_configuration, Data, Model};
use nalgebra::DVector;

/// The implicitfast stepper with its force buffer.
pub struct ImplicitFast {
    force: DVector<f64>,
}

impl ImplicitFast {
    pub fn new(model: &Model) -> Self {
        Self { force: DVector::zeros(model.nv) }
    }
}

/// Adds −h·D (D = ∂qfrc/∂v, without Coriolis terms) to `matrix` (column-major nv×nv): joint
/// damping today; the place where actuator velocity derivatives (−∂qfrc_actuator/∂v) plug in.
pub fn add_force_derivative(model: &Model, matrix: &mut [f64], h: f64) {
    let nv = model.nv;
    for k in 0..nv {
        matrix[k + k * nv] += h * model.dof_damping[k];
    }
}

impl Stepper for ImplicitFast {
    fn name(&self) -> &'static str {
        "implicitfast"
    }
    fn order(&self) -> u32 {
        1
    }
    fn step(&mut self, model: &Model, plan: &Plan, data: &mut Data, state: &mut State, h: f64) -> StepReport {
        forward(model, plan, data, state.q.as_slice(), state.v.as_slice());
        if model.has_damping() {
            crba(model, data, state.q.as_slice());
            self.force.gemv(1.0, &data.mass_matrix, &data.qacc, 0.0);
            add_force_derivative(model, data.mass_matrix.as_mut_slice(), h);
            factorize_mass_matrix(model, data);
            solve_with_factor(model, &data.mass_factor, self.force.as_mut_slice());
            // Leave M as crba computed it.
            add_force_derivative(model, data.mass_matrix.as_mut_slice(), -h);
            state.v.axpy(h, &self.force, 1.0);
        } else {
            state.v.axpy(h, &data.qacc, 1.0);
        }
        integrate_configuration(model, state.q.as_mut_slice(), state.v.as_slice(), h);
        state.time += h;
        StepReport::fixed_step(h, correct_drift(model, plan, data, state, h))
    }
}
