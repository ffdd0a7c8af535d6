//! Classical fourth-order Runge–Kutta on the configuration manifold: stage configurations are
//! reached by `q ⊕ c·h·vᵢ` and the final update uses the weighted mean velocity, as MuJoCo's
//! `mj_RungeKutta` does. Fourth order for joints whose configuration space is flat (hinge,
//! slide, planar); for quaternion joints the tangent-space averaging is an approximation.

use super::{correct_drift, State, StepReport, Stepper};
use crate::forward::{forward, Plan};
use crate::model::{integrate_configuration, Data, Model};
use nalgebra::DVector;

/// RK4 stepper with its stage buffers.
pub struct RungeKutta4 {
    q_stage: DVector<f64>,
    v_stage: [DVector<f64>; 4],
    a_stage: [DVector<f64>; 4],
    v_mean: DVector<f64>,
}

impl RungeKutta4 {
    pub fn new(model: &Model) -> Self {
        let z = || DVector::zeros(model.nv);
        Self {
            q_stage: DVector::zeros(model.nq),
            v_stage: [z(), z(), z(), z()],
            a_stage: [z(), z(), z(), z()],
            v_mean: z(),
        }
    }
}

impl Stepper for RungeKutta4 {
    fn name(&self) -> &'static str {
        "rk4"
    }
    fn order(&self) -> u32 {
        4
    }
    fn step(&mut self, model: &Model, plan: &Plan, data: &mut Data, state: &mut State, h: f64) -> StepReport {
        // Stage i evaluates at q ⊕ cᵢ h v_{i−1}, v + cᵢ h a_{i−1}, with c = (0, ½, ½, 1).
        const C: [f64; 4] = [0.0, 0.5, 0.5, 1.0];
        for i in 0..4 {
            self.q_stage.copy_from(&state.q);
            self.v_stage[i].copy_from(&state.v);
            if i > 0 {
                let (before, after) = self.v_stage.split_at_mut(i);
                after[0].axpy(C[i] * h, &self.a_stage[i - 1], 1.0);
                integrate_configuration(
                    model,
                    self.q_stage.as_mut_slice(),
                    before[i - 1].as_slice(),
                    C[i] * h,
                );
            }
            forward(model, plan, data, self.q_stage.as_slice(), self.v_stage[i].as_slice());
            self.a_stage[i].copy_from(&data.qacc);
            if i == 0 {
                // The later stages keep the limit and contact rows the step starts with.
                data.freeze_rows(false);
            }
        }
        // Weighted means (1, 2, 2, 1)/6 of stage velocities and accelerations.
        let [v1, v2, v3, v4] = &self.v_stage;
        let [a1, a2, a3, a4] = &self.a_stage;
        for k in 0..model.nv {
            self.v_mean[k] = (v1[k] + 2.0 * v2[k] + 2.0 * v3[k] + v4[k]) / 6.0;
            state.v[k] += h * (a1[k] + 2.0 * a2[k] + 2.0 * a3[k] + a4[k]) / 6.0;
        }
        integrate_configuration(model, state.q.as_mut_slice(), self.v_mean.as_slice(), h);
        state.time += h;
        StepReport::fixed_step(h, correct_drift(model, plan, data, state, h))
    }
}
