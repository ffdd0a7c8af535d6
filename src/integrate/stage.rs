//! One Runge–Kutta–Munthe-Kaas stage evaluation, shared by [`RungeKutta4`](super::RungeKutta4)
//! and [`DormandPrince54`](super::DormandPrince54): at the tangent increment θ from the step's
//! base point q₀ and the stage velocity v, the configuration q₀ ⊕ θ is formed, `forward` gives
//! the acceleration, and the slope of θ is dexp⁻¹(θ) v (Iserles et al., *Lie-group methods*,
//! Acta Numerica 2000, §3.3).

use crate::forward::forward_at;
use crate::model::{dexp_inv_configuration_unchecked, integrate_configuration_unchecked, Data, Model};
use nalgebra::DVector;

/// Stage inputs: base configuration, increment θ, stage velocity; `q_stage` is scratch.
pub(super) struct StageInput<'a> {
    pub q0: &'a DVector<f64>,
    pub theta: &'a DVector<f64>,
    pub v_stage: &'a DVector<f64>,
}

/// Evaluates the stage: `accel` ← qacc(q₀ ⊕ θ, v), `theta_rate` ← dexp⁻¹(θ) v.
pub(super) fn evaluate_stage(
    model: &Model,
    data: &mut Data,
    input: StageInput,
    q_stage: &mut DVector<f64>,
    (accel, theta_rate): (&mut DVector<f64>, &mut DVector<f64>),
) {
    q_stage.copy_from(input.q0);
    integrate_configuration_unchecked(model, q_stage.as_mut_slice(), input.theta.as_slice(), 1.0);
    forward_at(model, data, q_stage.as_slice(), input.v_stage.as_slice());
    accel.copy_from(&data.qacc);
    dexp_inv_configuration_unchecked(
        model,
        input.theta.as_slice(),
        input.v_stage.as_slice(),
        theta_rate.as_mut_slice(),
    );
}
