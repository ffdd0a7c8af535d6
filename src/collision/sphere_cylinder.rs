//! Sphere against cylinder in closed form, point for point MuJoCo's `mjc_SphereCylinder`
//! (engine_collision_primitive.c): the sphere's centre projected on the cylinder's axis and on its
//! cross-section decides the feature —
//!
//! | centre | contact |
//! |---|---|
//! | beside the side (|axial| < half-length, outside the radius) | sphere against the sphere of the cylinder's radius centred on the axis at the same height |
//! | over a cap (inside the radius, beyond the half-length) | sphere against the cap's plane (touching exactly at distance 0 is a contact) |
//! | inside the cylinder | the shallower of the two above (the side on a tie) |
//! | beyond a rim | sphere against the rim's nearest point |
//!
//! One contact, the normal from the sphere (geom 1, MuJoCo's lower type) towards the cylinder.
//! Coincident centres (the sphere's centre on the axis, nearer the side) take MuJoCo's normal:
//! the cross product of the two z axes, or x when they are parallel.

use super::convex::PairPoint;
use crate::spatial::{Transform, Vec3};

/// MuJoCo's `mjMINVAL`: below it a length counts as zero.
const MINVAL: f64 = 1e-15;

/// The contact of a sphere (centre `c`, z axis `z_sphere`, `r`) and a cylinder at `x` (axis z,
/// `radius`, half-length `half`) closer than `reach`: witness points on the sphere and the
/// cylinder, normal from the sphere towards the cylinder, signed distance.
pub fn sphere_cylinder(
    c: &Vec3,
    z_sphere: &Vec3,
    r: f64,
    x: &Transform,
    radius: f64,
    half: f64,
    reach: f64,
) -> Option<PairPoint> {
    let axis = x.rot.column(2).into_owned();
    let vec = c - x.pos;
    let along = axis.dot(&vec);
    let a_proj = axis * along;
    let p_proj = vec - a_proj;
    let p_proj_sqr = p_proj.dot(&p_proj);
    let mut side = along.abs() < half;
    let mut cap = p_proj_sqr < radius * radius;
    if side && cap {
        // The centre inside: the shallower way out.
        if half - along.abs() < radius - p_proj_sqr.sqrt() {
            side = false;
        } else {
            cap = false;
        }
    }
    let spheres = |q: Vec3, rq: f64| {
        // MuJoCo's sphere–sphere from the sphere's centre to a sphere of radius rq at q.
        let d = q - c;
        let len_sqr = d.dot(&d);
        let reach_total = reach + r + rq;
        if len_sqr > reach_total * reach_total {
            return None;
        }
        let len = len_sqr.sqrt();
        let dist = len - r - rq;
        let normal = if len < MINVAL {
            let n = z_sphere.cross(&axis);
            let l = n.norm();
            if l < MINVAL {
                Vec3::x()
            } else {
                n / l
            }
        } else {
            d / len
        };
        Some(PairPoint { p1: c + normal * r, p2: c + normal * (r + dist), normal, dist })
    };
    if side {
        return spheres(x.pos + a_proj, radius);
    }
    if cap {
        // The cap's plane, its normal outward; the contact normal points into the cylinder.
        let n_cap = if along > 0.0 { axis } else { -axis };
        let cap_pos = x.pos + n_cap * half;
        let cdist = (c - cap_pos).dot(&n_cap);
        if cdist > reach + r {
            return None;
        }
        let dist = cdist - r;
        return Some(PairPoint { p1: c - n_cap * r, p2: c - n_cap * (r + dist), normal: -n_cap, dist });
    }
    // Beyond a rim: the rim point nearest the centre.
    let rim = p_proj * (radius / p_proj_sqr.sqrt()) + axis * if along > 0.0 { half } else { -half };
    spheres(x.pos + rim, 0.0)
}
