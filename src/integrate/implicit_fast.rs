//! MuJoCo's `implicitfast` integrator on its passive part (MuJoCo documentation, "Computation →
//! Numerical integration"): velocity-implicit in the derivative D = ∂qfrc/∂v of the forces that
//! depend on velocity, without the Coriolis/centrifugal derivatives (that is what "fast" drops):
//!
//!   (M − h D) a = M qacc,   v ← v + h a,   q ← q ⊕ h v,
//!
//! where qacc is `forward`'s acceleration (constraint forces included) and M qacc the total
//! force it balances. Today D = −diag(`dof_damping`), joint damping being the only
//! velocity-dependent passive force; actuators add their velocity derivatives
//! ([`add_actuator_velocity_derivative`], MuJoCo's `mjd_actuator_vel`: position servos' kv, velocity
//! servos, affine gains). With only joint damping this is also what MuJoCo's `Euler` does
//! (implicit damping), so its `mj_step` is the reference on damped passive scenes.
//! [`Implicit`](super::Implicit) adds the Coriolis derivatives −∂c/∂v to D.

use super::{correct_drift, Advance, State, StepReport, Stepper};
use crate::dynamics::{crba_unchecked, factorize_mass_matrix, solve_with_factor_unchecked};
use crate::forward::{add_actuator_velocity_derivative, advance_activations, forward_at};
use crate::model::{Data, Model};
use nalgebra::{DMatrix, DVector};

/// The implicitfast stepper with its force buffer.
pub struct ImplicitFast {
    /// The activations `forward` reads in a stage (`data.act` while the state is moved out).
    stage_act: DVector<f64>,
    force: DVector<f64>,
    /// M kept while M − h D is factored in its place.
    mass_copy: DMatrix<f64>,
}

impl ImplicitFast {
    /// The stepper with its buffers sized for `model`.
    pub fn new(model: &Model) -> Self {
        Self {
            stage_act: DVector::zeros(model.na()),
            force: DVector::zeros(model.nv),
            mass_copy: DMatrix::zeros(model.nv, model.nv),
        }
    }
}

/// Adds −h·D (D = ∂qfrc/∂v, without Coriolis terms) to `matrix` (column-major nv×nv): the joint
/// damping part (the actuators' part is
/// [`add_actuator_velocity_derivative`](crate::forward::add_actuator_velocity_derivative)).
pub(crate) fn add_force_derivative(model: &Model, matrix: &mut [f64], h: f64) {
    let nv = model.nv;
    for k in 0..nv {
        matrix[k + k * nv] += h * model.dof_damping[k];
    }
}

/// The velocity-implicit acceleration a = (M − h D)⁻¹ M qacc after `forward` at configuration
/// `q`, into `out`, with D the joint damping and, given `actuator_bias_velocity`, the actuators'
/// velocity derivatives. Returns false (and leaves `out` alone) when D is zero: the explicit
/// `qacc` is the step's acceleration then. M is left as CRBA gives it (kept in `mass_copy` while
/// M − h D takes its place); its factor is of M − h D.
pub(super) fn implicit_acceleration(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    out: &mut DVector<f64>,
    mass_copy: &mut DMatrix<f64>,
    h: f64,
    actuator_bias_velocity: Option<&[f64]>,
) -> bool {
    let damped = model.has_damping();
    if !damped && actuator_bias_velocity.is_none() {
        return false;
    }
    // M at q: the position stage's own when `forward` formed it there (CRBA again would
    // give the same bits), else formed here.
    if !data.forward_skip.mass_formed {
        crba_unchecked(model, data, q);
    }
    out.gemv(1.0, &data.mass_matrix, &data.qacc, 0.0);
    mass_copy.copy_from(&data.mass_matrix);
    add_force_derivative(model, data.mass_matrix.as_mut_slice(), h);
    let mut m = std::mem::take(&mut data.mass_matrix);
    let from_actuators = actuator_bias_velocity
        .is_some_and(|b| add_actuator_velocity_derivative(model, data, b, m.as_mut_slice(), h));
    data.mass_matrix = m;
    let implicit = damped || from_actuators;
    if implicit {
        factorize_mass_matrix(model, data);
        solve_with_factor_unchecked(model, &data.mass_factor, out.as_mut_slice());
    }
    // M itself again, bit for bit.
    data.mass_matrix.copy_from(mass_copy);
    implicit
}

impl Stepper for ImplicitFast {
    fn name(&self) -> &'static str {
        "implicitfast"
    }
    fn order(&self) -> u32 {
        1
    }
    fn step(&mut self, model: &Model, data: &mut Data, h: f64) -> StepReport {
        self.step_moved(model, data, h)
    }
}

impl Advance for ImplicitFast {
    fn stage_act(&mut self) -> &mut DVector<f64> {
        &mut self.stage_act
    }

    fn advance(&mut self, model: &Model, data: &mut Data, state: &mut State, h: f64) -> StepReport {
        data.act.copy_from(&state.act);
        forward_at(model, data, state.q.as_slice(), state.v.as_slice());
        // MuJoCo's mj_step: the sensors of the state the step starts from.
        crate::sensor::compute_at(model, data, state.q.as_slice(), state.v.as_slice(), state.time);
        // Activations as in MuJoCo's `mj_advance` (explicit in act_dot; filterexact exact).
        advance_activations(model, state.act.as_mut_slice(), data.act_dot.as_slice(), h);
        // MuJoCo's mj_advance: islands at rest fall asleep (their v zeroed) before v advances.
        crate::forward::sleep::sleep_islands(model, data, state.q.as_slice(), state.v.as_mut_slice());
        let actuated = !model.actuators.is_empty() && model.options.flags.actuation;
        let bias_velocity = actuated.then_some(model.plan.actuator_bias_velocity.as_slice());
        if implicit_acceleration(
            model,
            data,
            state.q.as_slice(),
            &mut self.force,
            &mut self.mass_copy,
            h,
            bias_velocity,
        ) {
            state.v.axpy(h, &self.force, 1.0);
        } else {
            state.v.axpy(h, &data.qacc, 1.0);
        }
        crate::forward::sleep::hold_velocities(model, data, state.v.as_mut_slice());
        crate::forward::sleep::integrate_awake(model, data, state.q.as_mut_slice(), state.v.as_slice(), h);
        state.time += h;
        StepReport::fixed_step(h, correct_drift(model, data, state, h))
    }
}
