//! Time steppers (DESIGN.md, layer 7). Every integrator implements [`Integrator`]; each owns the
//! stage buffers it needs, allocated once, so a step allocates nothing.
//!
//! The continuous dynamics are q̇ = v (on the configuration manifold, see
//! [`integrate_configuration`](crate::model::integrate_configuration)) and v̇ = ABA(q, v, τ + τ_passive),
//! where τ_passive = −damping ⊙ v (the joint damping of the model file).

mod euler;
mod rk4;

pub use euler::SemiImplicitEuler;
pub use rk4::RungeKutta4;

use crate::dynamics::aba;
use crate::model::{Data, Model};
use nalgebra::DVector;

/// The state advanced by an integrator, in MuJoCo's qpos/qvel layout.
#[derive(Clone, Debug, PartialEq)]
pub struct State {
    pub time: f64,
    pub q: DVector<f64>,
    pub v: DVector<f64>,
}

impl State {
    /// The model's reference configuration (`qpos0`) at rest, time 0.
    pub fn neutral(model: &Model) -> Self {
        Self { time: 0.0, q: DVector::from_vec(model.qpos0.clone()), v: DVector::zeros(model.nv) }
    }
}

/// A fixed-step time stepper.
pub trait Integrator {
    /// Short name (`euler`, `rk4`, …).
    fn name(&self) -> &'static str;
    /// Order of the global error in the step size for smooth problems.
    fn order(&self) -> u32;
    /// Advances `state` by `dt` under applied generalized forces `tau`.
    fn step(&mut self, model: &Model, data: &mut Data, state: &mut State, tau: &[f64], dt: f64);
}

/// Accelerations v̇ = ABA(q, v, τ − damping ⊙ v − k ⊙ (q − q_rest)) into `qacc` (joint damping and
/// the springs of one-dof joints); `tau_total` is scratch (length nv).
pub(crate) fn accelerations(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    tau_total: &mut DVector<f64>,
    qacc: &mut DVector<f64>,
) {
    for k in 0..model.nv {
        tau_total[k] = tau[k] - model.dof_damping[k] * v[k];
    }
    for s in &model.springs {
        tau_total[s.dof_adr] -= s.stiffness * (q[s.qpos_adr] - s.rest);
    }
    qacc.copy_from(aba(model, data, q, v, tau_total.as_slice()));
}

/// The integrators `simulate` offers, by name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IntegratorKind {
    Euler,
    Rk4,
}

impl IntegratorKind {
    /// Builds the integrator with buffers sized for `model`.
    pub fn build(self, model: &Model) -> Box<dyn Integrator + Send> {
        match self {
            IntegratorKind::Euler => Box::new(SemiImplicitEuler::new(model)),
            IntegratorKind::Rk4 => Box::new(RungeKutta4::new(model)),
        }
    }
}
