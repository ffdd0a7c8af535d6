//! Cartesian forces applied by the user to bodies (MuJoCo's `xfrc_applied`, MuJoCo documentation
//! "Computation → Forward dynamics" and `mj_xfrcAccumulate`): per MuJoCo body — every URDF link
//! and MJCF body in file order, the world first (the model's frames of kind `Link`) — a force
//! `[fx fy fz]` and a torque `[tx ty tz]` in world axes, the force acting at the body's own centre
//! of mass. Its generalized force is
//!
//!   Q_k = S_kᵀ (τ + p × f, f)  for every dof k moving the body,
//!
//! with S_k the dof's motion subspace in world coordinates about the world origin and p the centre
//! of mass in the world (the wrench moved to the origin), i.e. Q = J_pᵀ f + J_ωᵀ τ.

use crate::kinematics::{body_poses, for_each_ancestor_dof_at};
use crate::model::{Data, FrameKind, Model};
use crate::spatial::Vec3;

/// Whether any applied wrench is nonzero (the generalized force is then formed).
pub(crate) fn has_xfrc(data: &Data) -> bool {
    data.xfrc_applied.iter().any(|w| w.iter().any(|&x| x != 0.0))
}

/// `data.qfrc_xfrc` ← the generalized force of `data.xfrc_applied` at configuration `q` (body
/// poses formed here). Zero when no wrench is applied.
pub(crate) fn accumulate_xfrc(model: &Model, data: &mut Data, q: &[f64]) {
    data.qfrc_xfrc.fill(0.0);
    if !has_xfrc(data) {
        return;
    }
    body_poses(model, data, q);
    let links = model.frames.iter().filter(|f| f.kind == FrameKind::Link);
    for (id, frame) in links.enumerate() {
        let w = data.xfrc_applied[id];
        if frame.body == 0 || w.iter().all(|&x| x == 0.0) {
            continue;
        }
        let f = Vec3::new(w[0], w[1], w[2]);
        let com_world =
            data.x_world_body[frame.body].act_point(&frame.x_body_frame.act_point(&frame.inertia.com()));
        let torque = Vec3::new(w[3], w[4], w[5]);
        let qfrc = &mut data.qfrc_xfrc;
        // The point Jacobian at the centre of mass (not the world origin's: digits far away).
        for_each_ancestor_dof_at(
            model,
            &data.x_world_body,
            &data.s_body,
            frame.body,
            &com_world,
            |k, lin, ang| {
                qfrc[k] += lin.dot(&f) + ang.dot(&torque);
            },
        );
    }
}
