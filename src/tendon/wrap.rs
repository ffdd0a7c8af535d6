//! The wrapping of a tendon segment around a sphere or a cylinder (MuJoCo's `mju_wrap` with its
//! helpers `wrap_circle` and `wrap_inside`, engine_util_misc.c; MuJoCo documentation,
//! "Modeling → Tendons" and "XML Reference → tendon/spatial/geom"), written from their
//! definitions:
//!
//! The two path points x₀, x₁ around the geom are taken into the geom's frame. A sphere's wrap
//! lies in the plane through its centre and both points (axes: x₀'s direction and its normal in
//! that plane); a cylinder's wrap is solved in its cross-section (x, y) and lifted along z
//! afterwards. In that plane the problem is a circle of radius r and two points d₀, d₁:
//!
//! - **outside** (no side site, or a side site outside the circle): if the segment d₀d₁ misses
//!   the circle (or passes on the side site's side, or the side site is not behind the circle:
//!   outside the cone spanned by −d₀ and −d₁, MuJoCo 4.0's rule), there is no wrap. Otherwise each point has
//!   two tangent points t = (d r² ± r d⊥ √(|d|² − r²)) / |d|²; of the two consistent pairs the
//!   one nearer the side site (its normalized mid-direction) or, without side site, the pair
//!   with the shorter chord is taken, a pair whose tangent lines cross being rejected. The wrap
//!   length is r times the arc angle between the tangent points, taken the long way round when
//!   the pair's orientation says so.
//! - **inside** (side site within the radius): the path goes through the circle from inside:
//!   one point t on the circle where the angles of incidence equal, found by Newton's method on
//!   asin(A z) + asin(B z) − 2 asin(z) + G = 0 (A = r/|d₀|, B = r/|d₁|, G the angle d₀–0–d₁);
//!   wrap length 0 and both wrap points at t.
//!
//! A cylinder's two tangent points are then given heights that split the height difference in
//! proportion to the in-plane lengths (straight, arc, straight), and the arc length becomes
//! √(arc² + Δz²) (the helix unrolled).

pub use crate::model::WrapShape;
use crate::spatial::{Mat3, Vec3};

/// MuJoCo's `mjMINVAL`: the smallest length or determinant treated as nonzero.
const MINVAL: f64 = 1e-15;

/// A wrap: the two tangent points in the world and the length of the path on the surface between
/// them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Wrapped {
    /// Where the path leaves the straight line from x₀ and touches the surface (world).
    pub p_world_in: Vec3,
    /// Where the path leaves the surface towards x₁ (world).
    pub p_world_out: Vec3,
    /// The length along the surface between them (0 for the inside wrap).
    pub length: f64,
}

/// 2-vector helpers (the circle problem).
type V2 = [f64; 2];

fn dot2(a: V2, b: V2) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

fn norm2(a: V2) -> f64 {
    dot2(a, a).sqrt()
}

/// `a` scaled to unit length, or (1, 0) if it is shorter than MINVAL (MuJoCo's `mju_normalize`).
fn unit2(a: V2) -> V2 {
    let n = norm2(a);
    if n < MINVAL {
        [1.0, 0.0]
    } else {
        [a[0] / n, a[1] / n]
    }
}

/// `a` scaled to unit length, or x if shorter than MINVAL (MuJoCo's `mju_normalize3`).
fn unit3(a: Vec3) -> (Vec3, f64) {
    let n = a.norm();
    if n < MINVAL {
        (Vec3::x(), n)
    } else {
        (a / n, n)
    }
}

/// Whether the 2-D segments p1p2 and p3p4 cross (closed segments, parallel ones never).
fn segments_cross(p1: V2, p2: V2, p3: V2, p4: V2) -> bool {
    let det = (p4[1] - p3[1]) * (p2[0] - p1[0]) - (p4[0] - p3[0]) * (p2[1] - p1[1]);
    if det.abs() < MINVAL {
        return false;
    }
    let a = ((p4[0] - p3[0]) * (p1[1] - p3[1]) - (p4[1] - p3[1]) * (p1[0] - p3[0])) / det;
    let b = ((p2[0] - p1[0]) * (p1[1] - p3[1]) - (p2[1] - p1[1]) * (p1[0] - p3[0])) / det;
    (0.0..=1.0).contains(&a) && (0.0..=1.0).contains(&b)
}

/// The arc length r·θ from tangent point `t0` to `t1`, θ ∈ [0, π] their angle, replaced by 2π − θ
/// when the orientation of the pair (`long_way`: the second solution) says the path goes round
/// the far side.
fn arc_length(t0: V2, t1: V2, long_way: bool, radius: f64) -> f64 {
    let mut angle = dot2(unit2(t0), unit2(t1)).clamp(-1.0, 1.0).acos();
    let cross = t0[1] * t1[0] - t0[0] * t1[1];
    if (cross > 0.0 && long_way) || (cross < 0.0 && !long_way) {
        angle = 2.0 * std::f64::consts::PI - angle;
    }
    radius * angle
}

/// Whether the side direction `s` points into the cone spanned by −d₀ and −d₁ (the circle's
/// centre inside the triangle d₀, d₁, s): the side site is behind the circle as seen from the
/// segment. MuJoCo 4.0 wraps a segment that misses the circle only then (measured against the
/// live MuJoCo 4.0.0 on 12 000 random planar cases; its 2026-08 source wraps whenever the
/// segment passes on the side away from the side site).
fn behind(s: V2, d0: V2, d1: V2) -> bool {
    let cross = |a: V2, b: V2| a[0] * b[1] - a[1] * b[0];
    let c = cross(d0, d1);
    if c.abs() < MINVAL {
        return false;
    }
    let alpha = -cross(s, d1) / c;
    let beta = cross(s, d0) / c;
    alpha >= 0.0 && beta >= 0.0
}

/// The outside wrap of the circle of radius `radius` at the origin between `d0` and `d1`, with
/// the side direction `side` (scaled to the radius) if any: (tangent points, arc length) or None.
fn wrap_outside(d0: V2, d1: V2, side: Option<V2>, radius: f64) -> Option<(V2, V2, f64)> {
    let (sq0, sq1, sqr) = (dot2(d0, d0), dot2(d1, d1), radius * radius);
    if sq0 < sqr || sq1 < sqr || radius < MINVAL {
        return None;
    }
    let dif = [d1[0] - d0[0], d1[1] - d0[1]];
    let dd = dot2(dif, dif);
    if dd < MINVAL {
        return None;
    }
    // The point of the segment nearest the centre: no wrap if it is outside the circle (and on
    // the side site's side).
    let a = (-dot2(dif, d0) / dd).clamp(0.0, 1.0);
    let near = [d0[0] + a * dif[0], d0[1] + a * dif[1]];
    if dot2(near, near) > sqr && side.is_none_or(|s| dot2(s, near) >= 0.0 || !behind(s, d0, d1)) {
        return None;
    }
    let (r0, r1) = ((sq0 - sqr).sqrt(), (sq1 - sqr).sqrt());
    let mut sol = [[[0.0; 2]; 2]; 2];
    let mut good = [0.0; 2];
    for (i, sgn) in [1.0, -1.0].into_iter().enumerate() {
        let t0 = [
            (d0[0] * sqr + sgn * radius * d0[1] * r0) / sq0,
            (d0[1] * sqr - sgn * radius * d0[0] * r0) / sq0,
        ];
        let t1 = [
            (d1[0] * sqr - sgn * radius * d1[1] * r1) / sq1,
            (d1[1] * sqr + sgn * radius * d1[0] * r1) / sq1,
        ];
        sol[i] = [t0, t1];
        good[i] = match side {
            Some(s) => dot2(unit2([t0[0] + t1[0], t0[1] + t1[1]]), s),
            None => {
                let c = [t0[0] - t1[0], t0[1] - t1[1]];
                -dot2(c, c)
            }
        };
        if segments_cross(d0, t0, d1, t1) {
            good[i] = -10000.0;
        }
    }
    let i = if good[0] > good[1] { 0 } else { 1 };
    let [t0, t1] = sol[i];
    if segments_cross(d0, t0, d1, t1) {
        return None;
    }
    Some((t0, t1, arc_length(t0, t1, i == 1, radius)))
}

/// The inside wrap between `d0` and `d1` (side site inside the circle): the single contact point
/// (twice) with arc length 0, or None when the segment crosses the circle or a point is inside.
fn wrap_inside(d0: V2, d1: V2, radius: f64) -> Option<(V2, V2, f64)> {
    const MAXITER: usize = 20;
    const ZINIT: f64 = 1.0 - 1e-7;
    const TOLERANCE: f64 = 1e-6;
    let (len0, len1) = (norm2(d0), norm2(d1));
    let dif = [d1[0] - d0[0], d1[1] - d0[1]];
    let dd = dot2(dif, dif);
    if len0 <= radius || len1 <= radius || radius < MINVAL || len0 < MINVAL || len1 < MINVAL {
        return None;
    }
    if dd > MINVAL {
        let a = -dot2(dif, d0) / dd;
        if a > 0.0 && a < 1.0 && norm2([d0[0] + a * dif[0], d0[1] + a * dif[1]]) <= radius {
            return None;
        }
    }
    // Fallback on numerical failure: the mid-direction on the circle.
    let m = unit2([0.5 * (d0[0] + d1[0]), 0.5 * (d0[1] + d1[1])]);
    let fallback = Some(([m[0] * radius, m[1] * radius], [m[0] * radius, m[1] * radius], 0.0));
    let (a, b) = (radius / len0, radius / len1);
    let cos_g = (len0 * len0 + len1 * len1 - dd) / (2.0 * len0 * len1);
    if cos_g < -1.0 + MINVAL {
        return None;
    }
    if cos_g > 1.0 - MINVAL {
        return fallback;
    }
    let g = cos_g.acos();
    let f_of = |z: f64| (a * z).asin() + (b * z).asin() - 2.0 * z.asin() + g;
    let mut z = ZINIT;
    let mut f = f_of(z);
    if f > 0.0 {
        return fallback;
    }
    let mut iter = 0;
    while iter < MAXITER && f.abs() > TOLERANCE {
        let df = a / (1.0 - z * z * a * a).sqrt().max(MINVAL) + b / (1.0 - z * z * b * b).sqrt().max(MINVAL)
            - 2.0 / (1.0 - z * z).sqrt().max(MINVAL);
        if df > -MINVAL {
            return fallback;
        }
        let z1 = z - f / df;
        if z1 > z {
            return fallback;
        }
        z = z1;
        f = f_of(z);
        if f > TOLERANCE {
            return fallback;
        }
        iter += 1;
    }
    if iter >= MAXITER {
        return fallback;
    }
    // Rotate from d₀ (or d₁, by the orientation of the pair) by the angle of incidence.
    let (from, ang) = if d0[0] * d1[1] - d0[1] * d1[0] > 0.0 {
        (d0, z.asin() - (a * z).asin())
    } else {
        (d1, z.asin() - (b * z).asin())
    };
    let v = unit2(from);
    let (s, c) = ang.sin_cos();
    let t = [radius * (c * v[0] - s * v[1]), radius * (s * v[0] + c * v[1])];
    Some((t, t, 0.0))
}

/// Wraps the segment from `x0` to `x1` (world) around the geom at `p_world_geom` with rotation
/// `r_world_geom` and radius `radius`, given the side site's world position `side` if any
/// (MuJoCo's `mju_wrap`). None when the straight segment is the path.
pub fn wrap(
    x0: &Vec3,
    x1: &Vec3,
    p_world_geom: &Vec3,
    r_world_geom: &Mat3,
    radius: f64,
    shape: WrapShape,
    side: Option<&Vec3>,
) -> Option<Wrapped> {
    let p0 = r_world_geom.tr_mul(&(x0 - p_world_geom));
    let p1 = r_world_geom.tr_mul(&(x1 - p_world_geom));
    if p0.norm() < MINVAL || p1.norm() < MINVAL {
        return None;
    }
    // The plane of the circle problem: axes e0, e1 in the geom frame.
    let (e0, e1) = match shape {
        WrapShape::Sphere => {
            let (e0, _) = unit3(p0);
            let (mut normal, n) = unit3(p0.cross(&p1));
            if n < MINVAL {
                // x₀, x₁ and the centre aligned: any plane through them; MuJoCo's choice.
                let i = if e0[1].abs() > e0[0].abs() && e0[1].abs() > e0[2].abs() {
                    1
                } else if e0[2].abs() > e0[0].abs() && e0[2].abs() > e0[1].abs() {
                    2
                } else {
                    0
                };
                let mut other = Vec3::new(1.0, 1.0, 1.0);
                other[i] = 0.0;
                normal = unit3(e0.cross(&other)).0;
            }
            (e0, unit3(normal.cross(&e0)).0)
        }
        WrapShape::Cylinder => (Vec3::x(), Vec3::y()),
    };
    let d0 = [p0.dot(&e0), p0.dot(&e1)];
    let d1 = [p1.dot(&e0), p1.dot(&e1)];
    let s_geom = side.map(|s| r_world_geom.tr_mul(&(s - p_world_geom)));
    let planar = match s_geom {
        Some(s) if s.norm() < radius => wrap_inside(d0, d1, radius),
        Some(s) => {
            let sd = unit2([s.dot(&e0), s.dot(&e1)]);
            wrap_outside(d0, d1, Some([sd[0] * radius, sd[1] * radius]), radius)
        }
        None => wrap_outside(d0, d1, None, radius),
    };
    let (t0, t1, mut length) = planar?;
    let mut res0 = e0 * t0[0] + e1 * t0[1];
    let mut res1 = e0 * t1[0] + e1 * t1[1];
    if shape == WrapShape::Cylinder {
        let l0 = ((p0[0] - res0[0]).powi(2) + (p0[1] - res0[1]).powi(2)).sqrt();
        let l1 = ((p1[0] - res1[0]).powi(2) + (p1[1] - res1[1]).powi(2)).sqrt();
        let total = l0 + length + l1;
        res0[2] = p0[2] + (p1[2] - p0[2]) * l0 / total;
        res1[2] = p0[2] + (p1[2] - p0[2]) * (l0 + length) / total;
        let height = (res1[2] - res0[2]).abs();
        length = (length * length + height * height).sqrt();
    }
    Some(Wrapped {
        p_world_in: r_world_geom * res0 + p_world_geom,
        p_world_out: r_world_geom * res1 + p_world_geom,
        length,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sphere_wrap_is_tangent_lines_and_arc() {
        // Points at (±2, 0.5, 0) around the unit sphere at the origin: the path bends over it.
        let (x0, x1) = (Vec3::new(-2.0, 0.5, 0.0), Vec3::new(2.0, 0.5, 0.0));
        let w = wrap(&x0, &x1, &Vec3::zeros(), &Mat3::identity(), 1.0, WrapShape::Sphere, None).unwrap();
        // Tangency: the radius to each tangent point is perpendicular to the straight piece.
        assert!((w.p_world_in.norm() - 1.0).abs() < 1e-12);
        assert!(w.p_world_in.dot(&(x0 - w.p_world_in)).abs() < 1e-12);
        assert!(w.p_world_out.dot(&(x1 - w.p_world_out)).abs() < 1e-12);
        // The arc is the short way over the top (y > 0).
        assert!(w.p_world_in[1] > 0.0 && w.length < std::f64::consts::PI);
        // A segment that misses the sphere does not wrap.
        let far = Vec3::new(0.0, 3.0, 0.0);
        assert!(wrap(
            &(x0 + far),
            &(x1 + far),
            &Vec3::zeros(),
            &Mat3::identity(),
            1.0,
            WrapShape::Sphere,
            None
        )
        .is_none());
    }
}
