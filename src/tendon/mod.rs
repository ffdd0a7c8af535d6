//! Tendon kinematics (MuJoCo's `mj_tendon`, engine_core_smooth.c; MuJoCo documentation,
//! "Computation → Tendons" and "XML Reference → tendon"): each tendon's length `ten_length`, its
//! Jacobian `ten_J` (the moment arms, ∂L/∂q) and rate `ten_velocity` = `ten_J` v, and a spatial
//! tendon's wrap points `wrap_xpos`/`wrap_obj` (`ten_wrapadr`, `ten_wrapnum`).
//!
//! - fixed: L = Σ coefᵢ qᵢ, J = coefᵢ on the joints' dofs;
//! - spatial: the path is cut at pulleys into branches; branch lengths count 1/divisor of the
//!   last pulley's divisor (1 before any). Consecutive sites are joined by straight segments; a
//!   geom between two sites replaces their segment by the wrap of [`wrap::wrap`] when the straight
//!   line would cross it (straight, surface, straight). The Jacobian of a straight segment from
//!   point a (on body A) to point b (on body B) is (J_b − J_a)ᵀ u with u the unit vector a → b and
//!   J the world point Jacobians; the tangent points are differentiated as points fixed to the
//!   geom's body (the path's length is stationary in their position along the surface, so their
//!   sliding adds nothing to first order), and the surface piece, on one body, adds nothing.
//!   Segments within one body are skipped.
//!
//! Runs at the start of every evaluation of a model with tendons ([`crate::forward`]), after
//! forward kinematics when a spatial tendon needs poses; allocation-free.

pub mod passive;
pub mod wrap;

use crate::kinematics::{for_each_ancestor_dof_at, forward_kinematics_unchecked};
use crate::model::{Data, Model, PathElement, TendonKind};
use crate::spatial::Vec3;

/// Whether `model` has a spatial tendon (forward kinematics is then needed for tendons).
pub(crate) fn has_spatial(model: &Model) -> bool {
    model.tendons.iter().any(|t| matches!(t.kind, TendonKind::Spatial { .. }))
}

/// Fills `ten_length`, `ten_j`, `ten_velocity` and the wrap arrays at (q, v); runs forward
/// kinematics first when the model has a spatial tendon.
pub(crate) fn compute(model: &Model, data: &mut Data, q: &[f64], v: &[f64]) {
    if model.tendons.is_empty() {
        return;
    }
    if has_spatial(model) {
        forward_kinematics_unchecked(model, data, q);
    }
    lengths_and_jacobians(model, data, q);
    for t in 0..model.tendons.len() {
        data.ten_velocity[t] = data.ten_j.row(t).iter().zip(v).map(|(j, v)| j * v).sum();
    }
}

/// `ten_length`, `ten_j` and the wrap arrays at q (body and site poses already at q).
pub(crate) fn lengths_and_jacobians(model: &Model, data: &mut Data, q: &[f64]) {
    data.ten_j.fill(0.0);
    let mut wrapcount = 0;
    for (t, tendon) in model.tendons.iter().enumerate() {
        data.ten_wrapadr[t] = wrapcount;
        data.ten_wrapnum[t] = 0;
        match &tendon.kind {
            TendonKind::Fixed { joints } => {
                let mut length = 0.0;
                for &(j, c) in joints {
                    let joint = &model.joints[j];
                    length += c * q[joint.qpos_adr];
                    data.ten_j[(t, joint.dof_adr)] += c;
                }
                data.ten_length[t] = length;
            }
            TendonKind::Spatial { wraps, .. } => {
                let n = spatial(model, data, t, wraps, wrapcount);
                data.ten_wrapnum[t] = n;
                wrapcount += n;
            }
        }
    }
}

/// A point of the path: world position and the compiled body it moves with.
#[derive(Clone, Copy)]
struct PathPoint {
    p_world: Vec3,
    body: usize,
}

/// Spatial tendon `t` with path `wraps`: its length into `ten_length[t]`, Jacobian into row `t`
/// of `ten_j`, wrap points from `wrap_xpos[adr]` on; returns the number of wrap points.
fn spatial(model: &Model, data: &mut Data, t: usize, wraps: &[PathElement], adr: usize) -> usize {
    let site =
        |data: &Data, f: usize| PathPoint { p_world: data.x_world_frame[f].pos, body: model.frames[f].body };
    let mut length = 0.0;
    let mut divisor = 1.0;
    let mut count = 0;
    let mut j = 0;
    let n = wraps.len();
    while j + 1 < n {
        let (e0, e1) = (wraps[j], wraps[j + 1]);
        if let PathElement::Pulley { divisor: d } = e0 {
            divisor = d;
            data.wrap_xpos[adr + count] = Vec3::zeros();
            data.wrap_obj[adr + count] = -2;
            count += 1;
            j += 1;
            continue;
        }
        if matches!(e1, PathElement::Pulley { .. }) {
            j += 1;
            continue;
        }
        // e0 is a site (the loader checks the path's grammar).
        let PathElement::Site(s0) = e0 else { return count };
        let a = site(data, s0);
        let (wrapped, s1, step) = match e1 {
            PathElement::Geom { geom, shape, radius, sidesite } => {
                let PathElement::Site(s1) = wraps[j + 2] else { return count };
                let g = &model.geoms[geom];
                let x = data.attached_pose(g.body, g.mocap, &g.x_body_geom);
                let b = data.x_world_frame[s1].pos;
                let side = sidesite.map(|s| data.x_world_frame[s].pos);
                let w = wrap::wrap(&a.p_world, &b, &x.pos, &x.rot, radius, shape, side.as_ref());
                (w.map(|w| (w, g.body)), s1, 2)
            }
            PathElement::Site(s1) => (None, s1, 1),
            PathElement::Pulley { .. } => unreachable!("handled above"),
        };
        let b = site(data, s1);
        data.wrap_xpos[adr + count] = a.p_world;
        data.wrap_obj[adr + count] = -1;
        count += 1;
        match wrapped {
            None => {
                length += (b.p_world - a.p_world).norm() / divisor;
                add_segment(model, data, t, a, b, divisor);
            }
            Some((w, body)) => {
                let t0 = PathPoint { p_world: w.p_world_in, body };
                let t1 = PathPoint { p_world: w.p_world_out, body };
                length +=
                    ((t0.p_world - a.p_world).norm() + w.length + (b.p_world - t1.p_world).norm()) / divisor;
                add_segment(model, data, t, a, t0, divisor);
                add_segment(model, data, t, t1, b, divisor);
                let geom = match e1 {
                    PathElement::Geom { geom, .. } => geom as i64,
                    _ => -1,
                };
                data.wrap_xpos[adr + count] = t0.p_world;
                data.wrap_xpos[adr + count + 1] = t1.p_world;
                data.wrap_obj[adr + count] = geom;
                data.wrap_obj[adr + count + 1] = geom;
                count += 2;
            }
        }
        j += step;
        // The last site before a pulley or the path's end closes the branch.
        if j == n - 1 || matches!(wraps.get(j + 1), Some(PathElement::Pulley { .. })) {
            data.wrap_xpos[adr + count] = b.p_world;
            data.wrap_obj[adr + count] = -1;
            count += 1;
        }
    }
    data.ten_length[t] = length;
    count
}

/// Adds the straight segment a → b's term (J_b − J_a)ᵀ u / divisor to row `t` of `ten_j`
/// (nothing when both ends move with the same body).
fn add_segment(model: &Model, data: &mut Data, t: usize, a: PathPoint, b: PathPoint, divisor: f64) {
    if a.body == b.body {
        return;
    }
    let d = b.p_world - a.p_world;
    let n = d.norm();
    let u = if n < 1e-15 { Vec3::x() } else { d / n };
    let Data { x_world_body, s_body, ten_j, .. } = data;
    for_each_ancestor_dof_at(model, x_world_body, s_body, b.body, &b.p_world, |k, lin, _| {
        ten_j[(t, k)] += u.dot(&lin) / divisor;
    });
    for_each_ancestor_dof_at(model, x_world_body, s_body, a.body, &a.p_world, |k, lin, _| {
        ten_j[(t, k)] -= u.dot(&lin) / divisor;
    });
}

/// `qpos_spring`: `qpos0` with each hinge and slide joint at its `springref` (MuJoCo's
/// `qpos_spring`; ball and free joints keep `qpos0`).
pub fn qpos_spring(model: &Model) -> Vec<f64> {
    let mut q = model.qpos0.as_slice().to_vec();
    for j in &model.joints {
        if j.kind.nq() == 1 {
            q[j.qpos_adr] = j.spring_ref;
        }
    }
    q
}

/// Replaces each `springlength="-1 -1"` (the default) by the tendon's length at `qpos_spring`,
/// as MuJoCo's `mj_setConst` does (compile time).
pub(crate) fn resolve_spring_lengths(model: &mut Model) {
    if !model.tendons.iter().any(|t| t.spring_length == [-1.0, -1.0]) {
        return;
    }
    let q = qpos_spring(model);
    let mut data = Data::new(model);
    forward_kinematics_unchecked(model, &mut data, &q);
    lengths_and_jacobians(model, &mut data, &q);
    for (t, tendon) in model.tendons.iter_mut().enumerate() {
        if tendon.spring_length == [-1.0, -1.0] {
            tendon.spring_length = [data.ten_length[t]; 2];
        }
    }
}
