//! The simulation loop and its per-step plan (DESIGN.md, layer 8): a stage runs only when the
//! model contains what it acts on, and the plan says why each stage runs or is skipped.

use crate::dynamics;
use crate::integrate::{Integrator, IntegratorKind, State};
use crate::kinematics::forward_kinematics;
use crate::model::{Data, Model};
use serde::Serialize;
use thiserror::Error;

/// One stage of the per-step pipeline and whether it runs.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct Stage {
    pub name: &'static str,
    /// `"runs"`, `"skipped"` or `"parsed, not simulated"`.
    pub status: &'static str,
    pub reason: String,
}

/// The stages `simulate` runs for a model, in order.
pub fn plan(model: &Model) -> Vec<Stage> {
    let mut stages = vec![Stage {
        name: "dynamics",
        status: "runs",
        reason: format!("articulated-body algorithm over {} bodies, nv = {}", model.nbody() - 1, model.nv),
    }];
    let damped = model.dof_damping.iter().filter(|&&d| d != 0.0).count();
    let springs = model.springs.len();
    stages.push(if damped + springs > 0 {
        Stage {
            name: "passive",
            status: "runs",
            reason: format!("joint damping on {damped} degrees of freedom, {springs} joint springs"),
        }
    } else {
        Stage { name: "passive", status: "skipped", reason: "no joint damping or springs".into() }
    });
    // Passive elements kept from the file but not simulated: springs of ball and free joints,
    // gravity compensation, spring-dampers, higher-order spring/damper coefficients.
    let multi_dof_springs = model.joints.iter().filter(|j| j.stiffness != 0.0 && j.kind.nq() > 1).count();
    let other_passive = count(model, &["body", "joint"]) + multi_dof_springs;
    if other_passive > 0 {
        stages.push(Stage {
            name: "passive (other)",
            status: "parsed, not simulated",
            reason: format!(
                "{other_passive} elements (gravity compensation, spring-dampers, polynomial or ball/free springs); see `info` elements"
            ),
        });
    }
    let friction = model.joints.iter().filter(|j| j.friction != 0.0).count();
    let limited = model.joints.iter().filter(|j| j.limits.is_some()).count();
    let mimics = model.joints.iter().filter(|j| j.mimic.is_some()).count();
    // A stage for `n` kept elements: "parsed, not simulated" with `why`, or skipped if none.
    let kept = |name: &'static str, n: usize, what: &str, why: &str| {
        if n > 0 {
            Stage { name, status: "parsed, not simulated", reason: format!("{n} {what}: {why}") }
        } else {
            Stage { name, status: "skipped", reason: format!("no {what}") }
        }
    };
    const SOLVER: &str = "stored; enforcement arrives with the constraint solver";
    stages.push(kept("joint limits", limited, "limited joints", SOLVER));
    stages.push(kept("joint friction", friction, "joints with Coulomb friction", SOLVER));
    let equalities = mimics + count(model, &["equality"]);
    stages.push(kept("equality constraints", equalities, "mimic joints and equality constraints", SOLVER));
    stages.push(kept("tendons", count(model, &["tendon"]), "tendons", SOLVER));
    let actuators = count(model, &["actuator"]);
    stages.push(kept("actuators", actuators, "actuators", "stored; simulate applies zero control"));
    stages.push(kept("sensors", count(model, &["sensor"]), "sensors", "stored, not evaluated"));
    let colliding = model.geoms.iter().filter(|g| g.collision).count();
    let pairs = count(model, &["contact"]);
    stages.push(if colliding + pairs > 0 {
        Stage {
            name: "collision",
            status: "parsed, not simulated",
            reason: format!(
                "{colliding} collision geoms, {pairs} contact pair/exclude entries: stored; contacts arrive with the constraint solver"
            ),
        }
    } else {
        Stage { name: "collision", status: "skipped", reason: "no collision geometry".into() }
    });
    stages
}

/// Number of kept elements in the given categories.
fn count(model: &Model, categories: &[&str]) -> usize {
    model.elements.iter().filter(|e| categories.contains(&e.category.as_str())).count()
}

/// Why a simulation stopped.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum SimError {
    #[error("the simulation diverged at t = {time} s (step {step}): {quantity} of joint '{joint}' is {value}; reduce --dt, use --integrator rk4, or check the model's inertias (a massless subtree has no finite acceleration)")]
    Diverged { time: f64, step: u64, quantity: &'static str, joint: String, value: f64 },
    #[error("invalid initial state: {0}")]
    BadState(String),
}

/// A model, its workspace, an integrator and the current state.
pub struct Simulation<'m> {
    pub model: &'m Model,
    pub data: Data,
    pub integrator: Box<dyn Integrator + Send>,
    pub state: State,
    pub steps: u64,
    tau: Vec<f64>,
}

impl<'m> Simulation<'m> {
    /// A simulation from the neutral configuration at rest.
    pub fn new(model: &'m Model, kind: IntegratorKind) -> Self {
        Self {
            model,
            data: Data::new(model),
            integrator: kind.build(model),
            state: State::neutral(model),
            steps: 0,
            tau: vec![0.0; model.nv],
        }
    }

    /// Sets the state; rejects wrong lengths and non-finite values.
    pub fn set_state(&mut self, q: &[f64], v: &[f64]) -> Result<(), SimError> {
        if q.len() != self.model.nq || v.len() != self.model.nv {
            return Err(SimError::BadState(format!(
                "q has {} values and v {}, the model needs nq = {} and nv = {}",
                q.len(),
                v.len(),
                self.model.nq,
                self.model.nv
            )));
        }
        if let Some(i) = q.iter().chain(v).position(|x| !x.is_finite()) {
            return Err(SimError::BadState(format!("value {i} of (q, v) is not finite")));
        }
        self.state.q.copy_from_slice(q);
        self.state.v.copy_from_slice(v);
        Ok(())
    }

    /// Constant applied generalized forces (zero by default).
    pub fn tau_mut(&mut self) -> &mut [f64] {
        &mut self.tau
    }

    /// Advances one step of `dt`; a non-finite result is reported, never propagated.
    pub fn step(&mut self, dt: f64) -> Result<(), SimError> {
        self.integrator.step(self.model, &mut self.data, &mut self.state, &self.tau, dt);
        self.steps += 1;
        self.check_finite()
    }

    fn check_finite(&self) -> Result<(), SimError> {
        if self.state.q.iter().chain(self.state.v.iter()).all(|x| x.is_finite()) {
            return Ok(());
        }
        // Non-finite values spread through ABA to every joint; the origin is a joint whose
        // articulated inertia D = Sᵀ Iᴬ S was singular. Leaves first, the first such joint has
        // only finite descendants.
        for b in (1..self.model.nbody()).rev() {
            let j = self.model.joint_of(b);
            let d_inv = self.data.d_inv[b][(0, 0)];
            if !d_inv.is_finite() {
                return Err(SimError::Diverged {
                    time: self.state.time,
                    step: self.steps,
                    quantity: "articulated inertia about the axis (D⁻¹)",
                    joint: j.name.clone(),
                    value: d_inv,
                });
            }
        }
        for (quantity, values, by_dof) in
            [("position", self.state.q.as_slice(), false), ("velocity", self.state.v.as_slice(), true)]
        {
            if let Some(i) = values.iter().position(|x| !x.is_finite()) {
                let joint = self
                    .model
                    .joints
                    .iter()
                    .find(|j| {
                        let (adr, n) =
                            if by_dof { (j.dof_adr, j.kind.nv()) } else { (j.qpos_adr, j.kind.nq()) };
                        (adr..adr + n).contains(&i)
                    })
                    .map(|j| j.name.clone())
                    .unwrap_or_default();
                return Err(SimError::Diverged {
                    time: self.state.time,
                    step: self.steps,
                    quantity,
                    joint,
                    value: values[i],
                });
            }
        }
        Ok(())
    }

    /// Kinetic and potential energy (T, V: gravity and joint springs) at the current state
    /// (forward kinematics included).
    pub fn energies(&mut self) -> (f64, f64) {
        let (q, v) = (self.state.q.as_slice(), self.state.v.as_slice());
        let kinetic = dynamics::kinetic_energy(self.model, &mut self.data, q, v);
        (kinetic, dynamics::potential_energy(self.model, &self.data) + self.model.spring_energy(q))
    }

    /// Forward kinematics at the current state (poses in `data`).
    pub fn kinematics(&mut self) {
        forward_kinematics(self.model, &mut self.data, self.state.q.as_slice());
    }
}
