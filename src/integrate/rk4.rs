//! Classical fourth-order Runge–Kutta on the configuration manifold as a Runge–Kutta–Munthe-Kaas
//! method (Munthe-Kaas, *High order Runge–Kutta methods on manifolds*, Appl. Numer. Math. 29,
//! 1999; Iserles et al., *Lie-group methods*, Acta Numerica 2000, §3.3): every stage is a
//! tangent increment θᵢ from the step's base point q₀, the stage configuration is q₀ ⊕ θᵢ, and
//! the stage slope of θ is dexp⁻¹(θᵢ) vᵢ ([`dexp_inv_configuration`](crate::model::dexp_inv_configuration)), so the Butcher tableau
//! acts on a vector space and keeps its order 4 on ball and free joints too. For flat joints
//! (hinge, slide, planar) dexp⁻¹ is the identity and the method is MuJoCo's `mj_RungeKutta`.
//! (Averaging the body-frame stage velocities without dexp⁻¹, as before, is second order on
//! quaternion joints.) Activations are stages of the same tableau, and the step applies
//! their weighted mean rate as MuJoCo's `mj_RungeKutta` does (through `mj_advance`: `filterexact`
//! with its exponential factor, then clamped to `actrange`).

use super::stage::{evaluate_stage, StageInput};
use super::{correct_drift, Advance, State, StepReport, Stepper};
use crate::forward::advance_activations;
use crate::model::{Data, Model};
use nalgebra::DVector;

/// RK4 stepper with its stage buffers.
pub struct RungeKutta4 {
    /// The activations `forward` reads in a stage (`data.act` while the state is moved out).
    stage_act: DVector<f64>,
    q_stage: DVector<f64>,
    v_stage: DVector<f64>,
    theta: DVector<f64>,
    theta_rate: [DVector<f64>; 4],
    a_stage: [DVector<f64>; 4],
    /// Stage rates of the activations (`act_dot`) and their weighted mean (na each).
    act_rate: [DVector<f64>; 4],
    act_mean: DVector<f64>,
}

impl RungeKutta4 {
    /// The stepper with its buffers sized for `model`.
    pub fn new(model: &Model) -> Self {
        let z = || DVector::zeros(model.nv);
        Self {
            stage_act: DVector::zeros(model.na()),
            q_stage: DVector::zeros(model.nq),
            v_stage: z(),
            theta: z(),
            theta_rate: [z(), z(), z(), z()],
            a_stage: [z(), z(), z(), z()],
            act_rate: std::array::from_fn(|_| DVector::zeros(model.na())),
            act_mean: DVector::zeros(model.na()),
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
    fn step(&mut self, model: &Model, data: &mut Data, h: f64) -> StepReport {
        self.step_moved(model, data, h)
    }
}

impl Advance for RungeKutta4 {
    fn stage_act(&mut self) -> &mut DVector<f64> {
        &mut self.stage_act
    }

    fn advance(&mut self, model: &Model, data: &mut Data, state: &mut State, h: f64) -> StepReport {
        // Stage i evaluates at q₀ ⊕ θᵢ, v₀ + cᵢ h a_{i−1} with θᵢ = cᵢ h θ̇_{i−1}, c = (0, ½, ½, 1).
        const C: [f64; 4] = [0.0, 0.5, 0.5, 1.0];
        for i in 0..4 {
            self.v_stage.copy_from(&state.v);
            self.theta.fill(0.0);
            if i > 0 {
                self.v_stage.axpy(C[i] * h, &self.a_stage[i - 1], 1.0);
                self.theta.axpy(C[i] * h, &self.theta_rate[i - 1], 0.0);
            }
            data.act.copy_from(&state.act);
            if i > 0 {
                data.act.axpy(C[i] * h, &self.act_rate[i - 1], 1.0);
            }
            // The stage's time, which delayed controls are read at (MuJoCo's mj_RungeKutta).
            data.time = state.time + C[i] * h;
            evaluate_stage(
                model,
                data,
                StageInput { q0: &state.q, theta: &self.theta, v_stage: &self.v_stage },
                &mut self.q_stage,
                (&mut self.a_stage[i], &mut self.theta_rate[i]),
            );
            self.act_rate[i].copy_from(&data.act_dot);
            if i == 0 {
                // MuJoCo's mj_step: the sensors of the state the step starts from.
                crate::sensor::compute_at(model, data, state.q.as_slice(), state.v.as_slice(), state.time);
                // The later stages keep the limit and contact rows the step starts with.
                data.freeze_rows(false);
            }
        }
        // MuJoCo's mj_advance: islands at rest fall asleep (their v zeroed) before v advances.
        crate::forward::sleep::sleep_islands(model, data, state.q.as_slice(), state.v.as_mut_slice());
        // Weighted means (1, 2, 2, 1)/6 of the stage slopes of θ and v.
        let [r1, r2, r3, r4] = &self.theta_rate;
        let [a1, a2, a3, a4] = &self.a_stage;
        for k in 0..model.nv {
            self.theta[k] = h * (r1[k] + 2.0 * r2[k] + 2.0 * r3[k] + r4[k]) / 6.0;
            state.v[k] += h * (a1[k] + 2.0 * a2[k] + 2.0 * a3[k] + a4[k]) / 6.0;
        }
        let [w1, w2, w3, w4] = &self.act_rate;
        for k in 0..self.act_mean.len() {
            self.act_mean[k] = (w1[k] + 2.0 * w2[k] + 2.0 * w3[k] + w4[k]) / 6.0;
        }
        advance_activations(model, state.act.as_mut_slice(), self.act_mean.as_slice(), h);
        crate::forward::sleep::hold_velocities(model, data, state.v.as_mut_slice());
        crate::forward::sleep::integrate_awake(
            model,
            data,
            state.q.as_mut_slice(),
            self.theta.as_slice(),
            1.0,
        );
        state.time += h;
        StepReport::fixed_step(h, correct_drift(model, data, state, h))
    }
}
