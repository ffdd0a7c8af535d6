//! Contact rows from the collision layer's contact list (`Data::contacts`), exact mode.
//!
//! A contact between geom1 (body b₁) and geom2 (body b₂) at world point p with frame rows
//! (n, t₁, t₂), n pointing from geom1 towards geom2, gives `condim` rows (MuJoCo documentation,
//! "Computation → Constraint model → Contact"; the same rows as MuJoCo's `mj_contactJacobian`):
//!
//! | row | J v |
//! |---|---|
//! | normal | nᵀ (v₂(p) − v₁(p)), positive when separating; φ = `dist` |
//! | tangent 1, 2 (condim ≥ 3) | t₁ᵀ, t₂ᵀ (v₂(p) − v₁(p)): slip velocity |
//! | torsional (condim ≥ 4) | nᵀ (ω₂ − ω₁) |
//! | rolling 1, 2 (condim 6) | t₁ᵀ, t₂ᵀ (ω₂ − ω₁) |
//!
//! with v_b(p) the velocity of the material point of body b at p. The friction rows' forces lie in
//! the elliptic Coulomb cone Σ (λ_i / μ_i)² ≤ λ_n² with μ = `friction` (sliding, sliding,
//! torsional, rolling, rolling) — Coulomb's law of docs/physics.md §2.5 ("the surface can only provide a
//! force not larger than μ F_N"), extended to torsion and rolling as MuJoCo does.
//!
//! J̇v: the gap and slip of two smooth surfaces change with the motion of the contact point over
//! them, not with a material point. For a surface of curvature radius ρ the gap moves with the
//! material point at the centre of curvature (a sphere's centre, the nearest point of a capsule's
//! or a cylinder side's axis), and for a vertex, edge or flat face with the material point at p
//! itself; J̇v is the bias acceleration of those points (exact for a sphere, capsule or rolling
//! cylinder on a plane, and for box and mesh vertices; the rotation of n for two curved bodies in
//! contact is neglected — a second-order drift that the steppers' projection removes).

use crate::kinematics::{for_each_ancestor_dof_at, point_bias_acceleration};
use crate::model::spec::Shape;
use crate::model::{Contact, Data, EfcType, Model};
use crate::spatial::Vec3;

/// Distance (m) up to which a contact carries a row in exact mode: touching, up to the round-off
/// the position projection leaves (as for joint limits).
pub const CONTACT_ACTIVE_DISTANCE: f64 = 1e-10;

/// Number of rows of a contact of dimension `condim` when friction is `frictional`.
fn contact_dim(condim: u32, frictional: bool) -> usize {
    if frictional {
        condim.clamp(1, 6) as usize
    } else {
        1
    }
}

/// Appends the rows of every active contact (`dist` ≤ [`CONTACT_ACTIVE_DISTANCE`], or, while the
/// step's rows are frozen, every frozen contact) from row `r` on: `efc_j`, `efc_pos`, `efc_id` (the contact's index in `Data::contacts`) and `efc_type`.
/// With `frictional` false only the normal rows are written (the position projection). Returns
/// the next free row. Needs body poses and motion subspaces at the contacts' configuration.
pub(crate) fn contact_rows(model: &Model, data: &mut Data, mut r: usize, frictional: bool) -> usize {
    let needed: usize = data
        .contacts
        .iter()
        .filter(|c| c.dist <= CONTACT_ACTIVE_DISTANCE || data.contact_is_frozen(c))
        .map(|c| contact_dim(c.condim, frictional))
        .sum();
    data.reserve_rows(r + needed);
    for c in 0..data.contacts.len() {
        let contact = data.contacts[c];
        let active = contact.dist <= CONTACT_ACTIVE_DISTANCE || data.contact_is_frozen(&contact);
        if !active {
            continue;
        }
        let dim = contact_dim(contact.condim, frictional);
        let kind = if dim == 1 { EfcType::ContactFrictionless } else { EfcType::ContactElliptic };
        for i in r..r + dim {
            data.efc_id[i] = c;
            data.efc_type[i] = kind;
            data.efc_pos[i] = 0.0;
            // Row i of J cleared through its storage (every nrows-th entry): no index
            // checks per entry.
            let stride = data.efc_j.nrows();
            for x in data.efc_j.as_mut_slice()[i..].iter_mut().step_by(stride) {
                *x = 0.0;
            }
        }
        data.efc_pos[r] = contact.dist;
        add_contact_jacobian(model, data, &contact, r, dim);
        r += dim;
    }
    r
}

/// The `dim` frame-row values (normal, tangents, torsion, rolling) of a column with linear part
/// `lin` at the contact point and angular part `ang`, times `sign`; zero past `dim`.
#[inline]
pub(crate) fn frame_values(dirs: &[Vec3; 3], lin: &Vec3, ang: &Vec3, dim: usize, sign: f64) -> [f64; 6] {
    let mut v = [0.0; 6];
    v[0] = sign * dirs[0].dot(lin);
    if dim >= 3 {
        v[1] = sign * dirs[1].dot(lin);
        v[2] = sign * dirs[2].dot(lin);
        if dim >= 4 {
            v[3] = sign * dirs[0].dot(ang);
            if dim >= 6 {
                v[4] = sign * dirs[1].dot(ang);
                v[5] = sign * dirs[2].dot(ang);
            } else if dim == 5 {
                v[4] = sign * dirs[1].dot(ang);
            }
        }
    } else if dim == 2 {
        v[1] = sign * dirs[1].dot(lin);
    }
    v
}

/// Adds the contact-frame Jacobian of `contact` (normal, tangents, then torsion and rolling: the
/// relative velocity of geom 2's body over geom 1's at the contact point, in the contact frame)
/// to rows r..r+dim of `efc_j` (MuJoCo's `mj_contactJacobian`). Needs body poses and motion
/// subspaces.
pub(crate) fn add_contact_jacobian(model: &Model, data: &mut Data, contact: &Contact, r: usize, dim: usize) {
    let p = contact.pos;
    let f = contact.frame;
    let dirs = [f.row(0).transpose(), f.row(1).transpose(), f.row(2).transpose()];
    let bodies = [model.geoms[contact.geom[0]].body, model.geoms[contact.geom[1]].body];
    let Data { efc_j, x_world_body, s_body, .. } = data;
    for (body, sign) in bodies.into_iter().zip([-1.0, 1.0]) {
        for_each_ancestor_dof_at(model, x_world_body, s_body, body, &p, |k, lin, ang| {
            let v = frame_values(&dirs, &lin, &ang, dim, sign);
            for (i, &v_i) in v[..dim].iter().enumerate() {
                efc_j[(r + i, k)] += v_i;
            }
        });
    }
}

/// `efc_jdotv` of the contact rows r..r+dim of contact `c` (needs `bias_accelerations` at the
/// state): the bias accelerations of the curvature-centre points of the two surfaces (module doc).
pub(crate) fn contact_jdotv(model: &Model, data: &mut Data, r: usize, dim: usize, c: usize) {
    let contact = data.contacts[c];
    let f = contact.frame;
    let n = f.row(0).transpose();
    let mut a_rel = Vec3::zeros();
    let mut alpha_rel = Vec3::zeros();
    for (side, sign) in [(0, -1.0), (1, 1.0)] {
        let g = contact.geom[side];
        let b = model.geoms[g].body;
        // Outward normal of this geom's surface at the contact.
        let n_out = n * -sign;
        let centre_world = curvature_centre(model, data, g, &contact.pos, &n_out);
        let r_body = data.x_world_body[b].inverse().act_point(&centre_world);
        let (a, alpha) = point_bias_acceleration(data, b, &r_body);
        a_rel += a * sign;
        alpha_rel += alpha * sign;
    }
    for i in 0..dim {
        let dir = f.row(i % 3).transpose();
        data.efc_jdotv[r + i] = if i < 3 { dir.dot(&a_rel) } else { dir.dot(&alpha_rel) };
    }
}

/// The material point (world coordinates) whose motion carries the gap of geom `g` at contact
/// point `p` with outward normal `n_out`: the centre of a sphere, the nearest axis point of a
/// capsule or of a cylinder's side, else `p` (vertices, edges, flat faces, ellipsoids, meshes).
fn curvature_centre(model: &Model, data: &Data, g: usize, p: &Vec3, n_out: &Vec3) -> Vec3 {
    let geom = &model.geoms[g];
    let x_world_geom = data.x_world_body[geom.body] * geom.x_body_geom;
    let axis_point = |half_length: f64| {
        let axis = x_world_geom.rot.column(2).into_owned();
        let t = axis.dot(&(p - x_world_geom.pos)).clamp(-half_length, half_length);
        x_world_geom.pos + axis * t
    };
    match &geom.shape {
        Shape::Sphere { .. } => x_world_geom.pos,
        Shape::Capsule { length, .. } => axis_point(0.5 * length),
        Shape::Cylinder { length, .. } => {
            let axis = x_world_geom.rot.column(2).into_owned();
            if axis.dot(n_out).abs() < 1e-9 {
                axis_point(0.5 * length)
            } else {
                *p
            }
        }
        _ => *p,
    }
}
