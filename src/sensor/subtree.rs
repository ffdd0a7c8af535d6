//! Per-body subtree quantities of MuJoCo's bodies (`Model::links`): the subtree's centre of mass
//! (MuJoCo's `subtree_com`, `mj_comPos`), its linear velocity and its angular momentum about its
//! centre of mass (`subtree_linvel`, `subtree_angmom`, `mj_subtreeVel`, engine_core_smooth.c).
//!
//! With m_i, c_i, v_i, ω_i, I_i a body's mass, centre of mass, its velocity, angular velocity and
//! inertia about c_i (world axes), and the sums over the subtree S(b):
//!
//!   M_b = Σ m_i,  c_b = Σ m_i c_i / M_b,  v_b = Σ m_i v_i / M_b,
//!   L_b = Σ [ I_i ω_i + m_i (c_i − c_b) × (v_i − v_b) ],
//!
//! accumulated leaves to root with the parallel-axis terms MuJoCo uses (a subtree lighter than
//! 1e-15 kg takes its body's own centre of mass).

use super::objects::point_velocity;
use crate::model::{Data, Model};
use crate::spatial::Vec3;

/// MuJoCo's `mjMINVAL`.
const MIN_MASS: f64 = 1e-15;

/// The subtree buffers, one entry per MuJoCo body (sized by `Data::new`).
#[derive(Clone, Debug, Default)]
pub(crate) struct Subtree {
    /// Each body's centre of mass, world (MuJoCo's `xipos`).
    pub xipos: Vec<Vec3>,
    /// The subtree's mass (MuJoCo's `body_subtreemass`).
    pub mass: Vec<f64>,
    /// `subtree_com`.
    pub com: Vec<Vec3>,
    /// Each body's (angular, linear) velocity at its centre of mass, world axes.
    pub body_vel: Vec<(Vec3, Vec3)>,
    /// `subtree_linvel`.
    pub linvel: Vec<Vec3>,
    /// `subtree_angmom`.
    pub angmom: Vec<Vec3>,
}

impl Subtree {
    /// Buffers for `model`'s bodies.
    pub fn new(model: &Model) -> Self {
        let n = model.links.len();
        Subtree {
            xipos: vec![Vec3::zeros(); n],
            mass: vec![0.0; n],
            com: vec![Vec3::zeros(); n],
            body_vel: vec![(Vec3::zeros(), Vec3::zeros()); n],
            linvel: vec![Vec3::zeros(); n],
            angmom: vec![Vec3::zeros(); n],
        }
    }
}

/// `xipos`, the subtree masses and `subtree_com`, from the frame poses at the state.
pub(crate) fn subtree_com(model: &Model, data: &Data, s: &mut Subtree) {
    let links = &model.links;
    for b in 0..links.len() {
        let f = links.frame[b];
        let inertia = &model.frames[f].inertia;
        s.xipos[b] = data.x_world_frame[f].act_point(&inertia.com());
        s.mass[b] = inertia.mass;
        s.com[b] = s.xipos[b] * inertia.mass;
    }
    for b in (1..links.len()).rev() {
        let p = links.parent[b];
        let (m, c) = (s.mass[b], s.com[b]);
        s.mass[p] += m;
        s.com[p] += c;
    }
    for b in 0..links.len() {
        s.com[b] = if s.mass[b] < MIN_MASS { s.xipos[b] } else { s.com[b] / s.mass[b] };
    }
}

/// `subtree_linvel` and, with `angmom`, `subtree_angmom` (otherwise left as they were), after
/// [`subtree_com`] and with `v_body` at the state.
pub(crate) fn subtree_velocities(model: &Model, data: &Data, s: &mut Subtree, angmom: bool) {
    let links = &model.links;
    for b in 0..links.len() {
        let f = links.frame[b];
        let frame = &model.frames[f];
        let inertia = &frame.inertia;
        let (w, v) = point_velocity(data, frame.body, &s.xipos[b]);
        s.body_vel[b] = (w, v);
        s.linvel[b] = v * inertia.mass;
        if angmom {
            let r = data.x_world_frame[f].rot;
            s.angmom[b] = r * (inertia.i_com() * r.tr_mul(&w));
        }
    }
    for b in (0..links.len()).rev() {
        if b > 0 {
            let lv = s.linvel[b];
            s.linvel[links.parent[b]] += lv;
        }
        s.linvel[b] /= s.mass[b].max(MIN_MASS);
    }
    if !angmom {
        return;
    }
    for b in (1..links.len()).rev() {
        let p = links.parent[b];
        let m = model.frames[links.frame[b]].inertia.mass;
        let dx = s.xipos[b] - s.com[b];
        let dv = s.body_vel[b].1 - s.linvel[b];
        let own = dx.cross(&(dv * m));
        s.angmom[b] += own;
        let child = s.angmom[b];
        s.angmom[p] += child;
        let dx = s.com[b] - s.com[p];
        let dv = (s.linvel[b] - s.linvel[p]) * s.mass[b];
        s.angmom[p] += dx.cross(&dv);
    }
}
