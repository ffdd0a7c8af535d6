//! Spheres and capsules against each other in MuJoCo's closed forms (engine_collision_primitive.c:
//! `mjraw_SphereSphere`, `mjraw_SphereCapsule`, `mjraw_CapsuleCapsule`): every pair reduces to
//! sphere–sphere tests of points on the segments.
//!
//! - **sphere–sphere**: normal from centre 1 to centre 2; coincident centres take the cross product
//!   of the two z axes (the x axis when that is zero too).
//! - **sphere–capsule**: the sphere against the segment point nearest its centre.
//! - **capsule–capsule**: the segments' closest points, clipped first along segment 1, then along
//!   segment 2 (MuJoCo's order, which decides the points when a clip meets a clip); with parallel
//!   axes (determinant below 1e-15) up to two contacts: the end points of segment 1 against their
//!   projections on segment 2, then, while fewer than two touch, the end points of segment 2
//!   against theirs on segment 1.

use super::convex::PairPoint;
use crate::spatial::{Transform, Vec3};

/// MuJoCo's `mjMINVAL`.
const MIN_VALUE: f64 = 1e-15;

/// A sphere of radius `r` centred at `c`, in a geom whose z axis is `z` (for MuJoCo's normal of
/// coincident centres).
#[derive(Clone, Copy)]
struct Ball {
    c: Vec3,
    z: Vec3,
    r: f64,
}

/// Sphere–sphere within `margin` (MuJoCo's `mjraw_SphereSphere`).
fn sphere_sphere(a: Ball, b: Ball, margin: f64) -> Option<PairPoint> {
    let d = b.c - a.c;
    let reach = margin + a.r + b.r;
    let len2 = d.dot(&d);
    if len2 > reach * reach {
        return None;
    }
    let len = len2.sqrt();
    let dist = len - a.r - b.r;
    let normal = if len < MIN_VALUE {
        let n = a.z.cross(&b.z);
        let l = n.norm();
        if l < MIN_VALUE {
            Vec3::x()
        } else {
            n / l
        }
    } else {
        d / len
    };
    Some(PairPoint { p1: a.c + normal * a.r, p2: b.c - normal * b.r, normal, dist })
}

/// Sphere (radius `r1`, pose `x1`) against sphere (`r2`, `x2`), normal from 1 to 2.
pub fn sphere_sphere_pair(
    x1: &Transform,
    r1: f64,
    x2: &Transform,
    r2: f64,
    margin: f64,
) -> Option<PairPoint> {
    let (z1, z2) = (x1.rot.column(2).into_owned(), x2.rot.column(2).into_owned());
    sphere_sphere(Ball { c: x1.pos, z: z1, r: r1 }, Ball { c: x2.pos, z: z2, r: r2 }, margin)
}

/// A sphere (radius `rs`, pose `xs`) against a capsule (radius `rc`, half-length `hc` along its
/// z axis, pose `xc`), normal from the sphere to the capsule.
pub fn sphere_capsule(
    xs: &Transform,
    rs: f64,
    xc: &Transform,
    rc: f64,
    hc: f64,
    margin: f64,
) -> Option<PairPoint> {
    let axis = xc.rot.column(2).into_owned();
    let x = axis.dot(&(xs.pos - xc.pos)).clamp(-hc, hc);
    let zs = xs.rot.column(2).into_owned();
    sphere_sphere(Ball { c: xs.pos, z: zs, r: rs }, Ball { c: xc.pos + axis * x, z: axis, r: rc }, margin)
}

/// Capsule against capsule (radii `r1`, `r2`, half-lengths `h1`, `h2` along their z axes): one
/// contact, or two for parallel axes (module doc), each passed to `out`.
#[allow(clippy::too_many_arguments)]
pub fn capsule_capsule(
    x1: &Transform,
    r1: f64,
    h1: f64,
    x2: &Transform,
    r2: f64,
    h2: f64,
    margin: f64,
    out: &mut impl FnMut(PairPoint),
) {
    let (z1, z2) = (x1.rot.column(2).into_owned(), x2.rot.column(2).into_owned());
    let (a1, a2) = (z1 * h1, z2 * h2);
    let dif = x1.pos - x2.pos;
    let ma = a1.dot(&a1);
    let mb = -a1.dot(&a2);
    let mc = a2.dot(&a2);
    let u = -a1.dot(&dif);
    let v = a2.dot(&dif);
    let det = ma * mc - mb * mb;
    let ball = |on_1: bool, s: f64| {
        if on_1 {
            Ball { c: x1.pos + a1 * s, z: z1, r: r1 }
        } else {
            Ball { c: x2.pos + a2 * s, z: z2, r: r2 }
        }
    };
    if det.abs() >= MIN_VALUE {
        let mut s1 = (mc * u - mb * v) / det;
        let mut s2 = (ma * v - mb * u) / det;
        if s1 > 1.0 {
            s1 = 1.0;
            s2 = (v - mb) / mc;
        } else if s1 < -1.0 {
            s1 = -1.0;
            s2 = (v + mb) / mc;
        }
        if s2 > 1.0 {
            s2 = 1.0;
            s1 = ((u - mb) / ma).clamp(-1.0, 1.0);
        } else if s2 < -1.0 {
            s2 = -1.0;
            s1 = ((u + mb) / ma).clamp(-1.0, 1.0);
        }
        if let Some(p) = sphere_sphere(ball(true, s1), ball(false, s2), margin) {
            out(p);
        }
        return;
    }
    // Parallel axes: the ends of segment 1, then (while fewer than two touch) those of segment 2.
    let mut found = 0;
    for (end, s2) in [(1.0, (v - mb) / mc), (-1.0, (v + mb) / mc)] {
        if let Some(p) = sphere_sphere(ball(true, end), ball(false, s2.clamp(-1.0, 1.0)), margin) {
            out(p);
            found += 1;
        }
    }
    for (end, s1) in [(1.0, (u - mb) / ma), (-1.0, (u + mb) / ma)] {
        if found >= 2 {
            return;
        }
        if let Some(p) = sphere_sphere(ball(true, s1.clamp(-1.0, 1.0)), ball(false, end), margin) {
            out(p);
            found += 1;
        }
    }
}
