//! Gravity compensation (MuJoCo's `mj_gravcomp`, engine_passive.c; MuJoCo documentation, "XML
//! Reference → body", attribute `gravcomp`, and "→ joint", attribute `actuatorgravcomp`): a body
//! with `gravcomp` c gets the force −c · m · g at its centre of mass, which cancels the fraction c
//! of its weight (c = 1: it floats; c > 1: it rises). As generalized forces,
//!
//!   `qfrc_gravcomp` = Σ_bodies J_com(b)ᵀ (−c_b m_b g),
//!
//! with J_com(b) the world-aligned linear Jacobian of the body's centre of mass. MuJoCo adds it to
//! `qfrc_passive` on every dof except those of joints with `actuatorgravcomp`, where it goes into
//! `qfrc_actuator` before the joint's `actuatorfrcrange` clamp (so a motor's force limit also
//! bounds the compensation). Nothing is computed when gravity is off or zero, or when springs and
//! dampers are both disabled (MuJoCo skips the whole passive stage then).
//!
//! Links fused into one compiled body add up to one force at their compensated-mass centroid
//! ([`GravComp`](crate::model::GravComp)): the forces are parallel, so this is exact.

use crate::kinematics::{for_each_ancestor_dof_at, forward_kinematics_unchecked};
use crate::model::{Data, Model};

/// Whether the model has gravity compensation that acts: some body with a nonzero `gravcomp`,
/// gravity on and nonzero, and not both springs and dampers disabled.
pub fn active(model: &Model) -> bool {
    let flags = &model.options.flags;
    !model.gravcomp.is_empty()
        && flags.gravity
        && model.gravity.norm() != 0.0
        && (flags.spring || flags.damper)
}

/// Fills `data.qfrc_gravcomp` at q (forward kinematics at q is recomputed here) and returns
/// whether any compensation acts ([`active`]); zero otherwise.
pub(crate) fn gravity_compensation(model: &Model, data: &mut Data, q: &[f64]) -> bool {
    data.qfrc_gravcomp.fill(0.0);
    if !active(model) {
        return false;
    }
    forward_kinematics_unchecked(model, data, q);
    let Data { qfrc_gravcomp, x_world_body, s_body, .. } = data;
    for g in &model.gravcomp {
        let x = &x_world_body[g.body];
        let p_world_com = x.pos + x.rot * g.com;
        let f_world = -g.mass * model.gravity;
        for_each_ancestor_dof_at(model, x_world_body, s_body, g.body, &p_world_com, |k, lin, _| {
            qfrc_gravcomp[k] += lin.dot(&f_world);
        });
    }
    true
}

/// Adds `qfrc_gravcomp` to `qfrc` on the dofs whose joint routes it through the actuators
/// (`actuatorgravcomp`: `through_actuators` true) or on the others (false).
pub(crate) fn add_gravcomp(model: &Model, data_gravcomp: &[f64], qfrc: &mut [f64], through_actuators: bool) {
    for j in &model.joints {
        if j.actuator_gravcomp != through_actuators {
            continue;
        }
        for k in j.dof_adr..j.dof_adr + j.kind.nv() {
            qfrc[k] += data_gravcomp[k];
        }
    }
}
