//! The staged forward pipeline (docs/architecture.md, "Layers"), with MuJoCo's stage names (MuJoCo
//! documentation, "Computation → Forward dynamics"): position → velocity → passive → actuation →
//! acceleration → constraint, each writing named buffers of [`Data`]:
//!
//! | stage | writes |
//! |---|---|
//! | position | body poses, `mass_matrix` and its factor, constraint rows `efc_j`, `efc_pos` |
//! | velocity | `qfrc_bias` = RNEA(q, v, 0), `efc_vel` = J v, `efc_jdotv` = J̇ v |
//! | passive | `qfrc_passive` = −damping ⊙ v − k ⊙ (q − q_spring) + `qfrc_fluid` |
//! | actuation | `actuator_length`, `actuator_velocity`, `actuator_force`, `act_dot`, `qfrc_actuator` from `ctrl` and `act` |
//! | acceleration | `qacc_smooth` (ABA, or M⁻¹`qfrc_smooth` on the M path), `qfrc_smooth` on the M path |
//! | constraint | `efc_force` (λ), `qfrc_constraint` = Jᵀλ, `qacc` |
//!
//! Which stages run is decided once by the [`Plan`]; [`forward`] walks it. Without constraint rows
//! the position and velocity stages are skipped and ABA gives `qacc_smooth` directly (M is never
//! built); `qacc` = `qacc_smooth` then. A model whose only rows are joint limits takes the same
//! ABA path at every state where no joint is at a limit, unless the stepper asks for M
//! (`ForwardSkip::mass_wanted`: the implicitly damped Euler step, which factors M anyway), when
//! the position and velocity stages form M, its factor and the bias without rows. `qfrc_applied`, `ctrl` and `act` are
//! inputs set by the caller (`act` by the integrators, from their state).

mod activation;
mod actuation;
mod actuator_layout;
pub(crate) mod adhesion;
pub mod history;
pub mod muscle;
mod plan;
mod skip;
pub(crate) mod sleep;
pub(crate) mod transmission;
mod xfrc;

pub use activation::{activation_rate, next_activation};
pub(crate) use activation::{advance_activations, clamp_activations};
pub use actuation::{
    actuation, add_actuator_velocity_derivative, resolved_bias_velocity, unsimulated_reason,
};
pub(crate) use actuation::{actuation_unchecked, add_actuator_length_derivative};
pub(crate) use history::{record_controls, reset_actuator_buffers};

pub use crate::constraint::DriftCorrection;
pub use actuator_layout::{ActuatorEntry, ActuatorLayout};
pub use plan::{Plan, Stage, StageKind, Status};
pub(crate) use skip::{ForwardSkip, SkipStage};
pub(crate) use xfrc::accumulate_xfrc;

use crate::dynamics::{
    aba_unchecked, bias_forces_unchecked, crba_unchecked, factorize_mass_matrix, solve_with_factor_unchecked,
};
use crate::model::{Data, Model};

/// Forward dynamics at the state in `data` (`qpos`, `qvel`, `act`, `ctrl`, `qfrc_applied`):
/// every stage of the model's [`Plan`] that runs, in order (MuJoCo's `mj_forward`). The result
/// is `data.qacc`; the other stages' outputs are in their named buffers.
///
/// ```
/// use lagrange::prelude::*;
/// let model = Model::from_file("models/mjcf/unitree_go1/scene.xml")?;
/// let mut data = Data::new(&model);
/// reset_keyframe(&model, &mut data, "home")?;
/// forward(&model, &mut data);
/// assert!(data.qacc.iter().all(|a| a.is_finite()));
/// assert!(contacts(&model, &data).any(|c| c.active)); // the feet touch the floor
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn forward(model: &Model, data: &mut Data) {
    // The stages read the state beside the buffers they write: moved out for the call (no copy,
    // no allocation) and back.
    let q = std::mem::take(&mut data.qpos);
    let v = std::mem::take(&mut data.qvel);
    data.warnings.check_quaternions(model, q.as_slice());
    forward_at(model, data, q.as_slice(), v.as_slice());
    crate::sensor::compute_at(model, data, q.as_slice(), v.as_slice(), data.time);
    data.qpos = q;
    data.qvel = v;
}

/// [`forward`] at a configuration and velocity other than the state's: the steppers' stages
/// (`q₀ ⊕ θ`, a stage velocity) and the drift correction evaluate here; `data.qpos` and
/// `data.qvel` are neither read nor written.
pub(crate) fn forward_at(model: &Model, data: &mut Data, q: &[f64], v: &[f64]) {
    // Every evaluation forms its body poses afresh, once (`Data::poses_stamp`).
    data.poses_stamp.clear();
    data.velocity_stamp.clear();
    let plan = &model.plan;
    let (rows, solver) = (&plan.constraints, &plan.solver);
    // Tendon lengths, Jacobians and velocities first: limits, passive forces, actuators and
    // sensors read them.
    crate::tendon::compute(model, data, q, v);
    // Collision and the rows at q: the M path only while a row exists (an equality, a joint at
    // a limit, a touching contact, or MuJoCo's activation rules in soft mode); ABA otherwise,
    // as for a model without constraints.
    // A skip request (finite differences, `SkipStage`) reuses the last evaluation's leading
    // stages, its collision and its M-path decision included.
    let skip = std::mem::take(&mut data.forward_skip.stage);
    let m_path = if skip == SkipStage::None {
        // Sleeping islands (`sleep`): the user's changes wake trees before collision, a touch
        // by an awake tree after it (collided again, for the woken trees' own contacts), then
        // an equality to an awake tree.
        sleep::wake_perturbed(model, data, q, v);
        let mut exist = plan.has_constraints() && solver.rows_exist(rows, model, data, q);
        if sleep::wake_touched(model, data) > 0 {
            exist = plan.has_constraints() && solver.rows_exist(rows, model, data, q);
        }
        sleep::wake_joined(model, data);
        exist
    } else {
        data.forward_skip.m_path
    };
    data.forward_skip.m_path = m_path;
    // M formed without rows, at a stepper's request (`ForwardSkip::mass_wanted`): the position
    // and velocity stages' smooth parts and the acceleration by the factor, no solver (a model
    // without constraints skips those stages: ABA there).
    let mass = if skip == SkipStage::None {
        m_path || (data.forward_skip.mass_wanted && plan.has_constraints())
    } else {
        data.forward_skip.mass_formed
    };
    data.forward_skip.mass_formed = mass;
    for stage in &plan.stages {
        if stage.status != Status::Runs {
            continue;
        }
        match stage.kind {
            StageKind::Position | StageKind::Velocity | StageKind::Passive if skip == SkipStage::Velocity => {
            }
            StageKind::Position if skip == SkipStage::Position => {}
            StageKind::Position if mass => {
                crba_unchecked(model, data, q);
                factorize_mass_matrix(model, data);
                if m_path {
                    solver.positions(rows, model, data, q);
                }
            }
            StageKind::Velocity if mass => {
                bias_forces_unchecked(model, data, q, v);
                data.qfrc_bias.copy_from(&data.tau);
                // RNEA left the body velocities at v in `v_body`.
                if m_path {
                    solver.velocities(rows, model, data, q, v);
                }
            }
            StageKind::Passive => passive(model, data, q, v),
            StageKind::Actuation => actuation_unchecked(model, data, q, v, &plan.actuator_bias_velocity),
            // Sleeping islands: with every tree asleep nothing accelerates (MuJoCo skips the
            // sleeping dofs' smooth dynamics).
            StageKind::Acceleration if !m_path && data.sleep.all_asleep(model) => data.qacc_smooth.fill(0.0),
            StageKind::Acceleration => acceleration(model, data, q, v, mass),
            StageKind::Constraint if m_path => solver.solve(model, data),
            // Row sources are built by the position stage; the rest are listings.
            _ => {}
        }
    }
    if !m_path {
        data.qacc.copy_from(&data.qacc_smooth);
        data.qfrc_constraint.fill(0.0);
        data.nefc = 0;
        data.ne = 0;
        data.nf = 0;
    }
    sleep::zero_sleeping_acceleration(model, data);
}

/// Passive forces: joint damping −d ⊙ v and the springs of hinge and slide joints
/// −k (q − q_spring), the fluid forces, the tendons' springs and dampers, and gravity
/// compensation `qfrc_gravcomp` on the joints without `actuatorgravcomp` (MuJoCo's `mj_passive`
/// for these elements).
pub(crate) fn passive(model: &Model, data: &mut Data, q: &[f64], v: &[f64]) {
    for k in 0..model.nv {
        data.qfrc_passive[k] = -model.dof_damping[k] * v[k];
    }
    for s in &model.springs {
        data.qfrc_passive[s.dof_adr] -= s.stiffness * (q[s.qpos_adr] - s.rest);
    }
    if let Some(fluid) = &model.plan.fluid {
        crate::dynamics::fluid::fluid_forces(model, fluid, data, q, v);
    }
    crate::tendon::passive::add_tendon_passive(model, data);
    // Gravity compensation (body `gravcomp`), except on `actuatorgravcomp` joints.
    if crate::dynamics::gravcomp::gravity_compensation(model, data, q) {
        let Data { qfrc_gravcomp, qfrc_passive, .. } = data;
        crate::dynamics::gravcomp::add_gravcomp(
            model,
            qfrc_gravcomp.as_slice(),
            qfrc_passive.as_mut_slice(),
            false,
        );
    }
}

/// The driving force on dof k: actuator plus applied, clamped to the dof's effort limit (URDF
/// `<limit effort>` with `--clamp-effort`; +∞ otherwise).
pub(crate) fn drive(model: &Model, data: &Data, k: usize) -> f64 {
    let limit = model.dof_effort_limit[k];
    (data.qfrc_actuator[k] + data.qfrc_applied[k]).clamp(-limit, limit)
}

/// The unconstrained acceleration. ABA path: `qacc_smooth` = ABA(q, v, passive + drive + xfrc).
/// M path: `qfrc_smooth` = passive + drive + xfrc − bias, `qacc_smooth` = M⁻¹ `qfrc_smooth` with
/// the factor of the position stage. The drive is actuator + applied, clamped to the effort limits
/// ([`drive`]); xfrc the bodies' applied wrenches as generalized forces (`qfrc_xfrc`).
fn acceleration(model: &Model, data: &mut Data, q: &[f64], v: &[f64], m_path: bool) {
    accumulate_xfrc(model, data, q);
    if m_path {
        for k in 0..model.nv {
            data.qfrc_smooth[k] =
                data.qfrc_passive[k] + drive(model, data, k) + data.qfrc_xfrc[k] - data.qfrc_bias[k];
        }
        data.qacc_smooth.copy_from(&data.qfrc_smooth);
        let mut x = std::mem::take(&mut data.qacc_smooth);
        solve_with_factor_unchecked(model, &data.mass_factor, x.as_mut_slice());
        data.qacc_smooth = x;
    } else {
        let mut tau = std::mem::take(&mut data.scratch_v);
        for k in 0..model.nv {
            tau[k] = data.qfrc_passive[k] + drive(model, data, k) + data.qfrc_xfrc[k];
        }
        aba_unchecked(model, data, q, v, tau.as_slice());
        data.scratch_v = tau;
        data.qacc_smooth.copy_from(&data.aba_qacc);
    }
}
