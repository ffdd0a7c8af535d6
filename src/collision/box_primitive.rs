//! A sphere or a capsule against a box, in closed form with MuJoCo's point sets (MuJoCo
//! documentation, "Computation → Collision detection"; MuJoCo's `mjc_SphereBox` and
//! `mjc_CapsuleBox`, engine_collision_box.c). Geom 1 is the sphere or capsule, geom 2 the box
//! (MuJoCo's order, lower geom type first); normals point from geom 1 to geom 2.
//!
//! - **sphere–box**: one contact. With the centre outside the box, between the sphere's point
//!   nearest the box and the box's point nearest the centre (the centre clamped to the box). With
//!   the centre inside (or on) the box, through the nearest face: the normal is that face's inward
//!   normal (ties go to the first of −x, +x, −y, +y, −z, +z) and the depth the centre's distance
//!   to the face plus the radius.
//! - **capsule–box**: the sphere–box contact of the capsule's segment point closest to the box,
//!   and a second one, of another point of the segment, when the segment lies along a face or an
//!   edge of the box: up to two contacts. The closest point is the best of the two segment ends
//!   against the faces and the segment against the twelve edges. The second point depends on what
//!   is closest: an end near a face takes the farthest point of the segment that still lies over
//!   that face; a segment crossing an edge, the farthest point over the face it leans on (or along
//!   the edge); a segment near a corner, the farthest point along the edge or over the face it
//!   runs by. A segment pointing at a corner, or crossing an edge at a right angle ("T"), gets no
//!   second point. Each point is reported only if its sphere is within the margin.
//!
//! Contact frames are MuJoCo's default from the normal alone (these functions set no tangent).
//! Feature ids: 0 for the closest point, 1 for the capsule's second point.

use super::convex::PairPoint;
use crate::spatial::{Transform, Vec3};

/// MuJoCo's smallest denominator (`mjMINVAL`).
const MINVAL: f64 = 1e-15;

/// Sphere (centre `c` in world coordinates, `radius`) against the box at pose `x` with
/// half-extents `half`: at most one contact, reported when its distance is at most `reach`.
pub fn sphere_box(
    c: &Vec3,
    radius: f64,
    x: &Transform,
    half: &Vec3,
    reach: f64,
    feature: u32,
    out: &mut impl FnMut(PairPoint, u32),
) {
    let centre = x.rot.transpose() * (c - x.pos);
    // The box's point nearest the centre (a zero extent does not clamp, as in MuJoCo).
    let mut nearest = centre;
    for k in 0..3 {
        if half[k] > 0.0 {
            nearest[k] = nearest[k].clamp(-half[k], half[k]);
        }
    }
    let towards = nearest - centre;
    let gap = towards.norm();
    if gap - radius > reach {
        return;
    }
    let (normal, sphere_side, box_side, dist) = if gap <= MINVAL {
        // Centre inside or on the box: leave through the nearest face; the normal points into
        // the box, against that face's outward normal.
        let mut closest = 2.0 * (half.x + half.y + half.z);
        let mut face = 0;
        for k in 0..6 {
            let plane = if k % 2 == 1 { half[k / 2] } else { -half[k / 2] };
            let d = (plane - centre[k / 2]).abs();
            if d < closest {
                closest = d;
                face = k;
            }
        }
        let mut n = Vec3::zeros();
        n[face / 2] = if face % 2 == 1 { -1.0 } else { 1.0 };
        (n, centre + n * radius, centre - n * closest, -closest - radius)
    } else {
        let n = towards / gap;
        (n, centre + n * radius, nearest, gap - radius)
    };
    out(
        PairPoint { p1: x.act_point(&sphere_side), p2: x.act_point(&box_side), normal: x.rot * normal, dist },
        feature,
    );
}

/// Where the segment comes closest to the box (MuJoCo's classification of the closest pair).
#[derive(Clone, Copy, Debug)]
enum Closest {
    /// A segment end (−1 or +1) over a face (`face` the clamped axis, None for an end inside
    /// the box).
    End { end: f64, face: Option<usize> },
    /// An edge along axis `axis` of the box, its lower corner `corner` (bits: +x, +y, +z), the
    /// point on it at `along` ∈ [−1, 1] (half-edge units); `at_corner` when that is an end of the
    /// edge (then `corner` is the end's corner).
    Edge { axis: usize, corner: usize, along: f64, at_corner: bool },
}

/// Capsule (pose `xc`, axis z, `radius`, half-length `half_length`) against the box at pose `xb`
/// with half-extents `half`: up to two contacts (see the module documentation).
pub fn capsule_box(
    xc: &Transform,
    radius: f64,
    half_length: f64,
    xb: &Transform,
    half: &Vec3,
    reach: f64,
    out: &mut impl FnMut(PairPoint, u32),
) {
    // The capsule in the box frame: centre, unit axis, half axis.
    let centre = xb.rot.transpose() * (xc.pos - xb.pos);
    let axis = xb.rot.transpose() * xc.rot.column(2);
    let ha = axis * half_length;
    // Octant of the half axis (bit k: component k positive); the opposite octant 7 − bits is the
    // same line.
    let octant = (0..3).filter(|&k| ha[k] > 0.0).map(|k| 1usize << k).sum::<usize>();

    let start = reach + 2.0 * (radius + half_length + half.x + half.y + half.z);
    let mut best = start; // squared distance of the best candidate
    let mut at = 0.0; // its point on the segment, in half lengths
    let mut closest: Option<Closest> = None;

    // Segment ends against the faces: an end whose clamped point moves along at most one axis.
    for end in [-1.0, 1.0] {
        let p = centre + ha * end;
        let (mut clamped, mut moved, mut face) = (p, 0, None);
        for k in 0..3 {
            if p[k] < -half[k] || p[k] > half[k] {
                clamped[k] = p[k].clamp(-half[k], half[k]);
                moved += 1;
                face = Some(k);
            }
        }
        if moved > 1 {
            continue;
        }
        let d = (clamped - p).norm_squared();
        if d < best {
            best = d;
            at = end;
            closest = Some(Closest::End { end, face });
        }
    }

    // The segment against the twelve edges: edge (axis j, corner bits i with bit j clear) is
    // m + x₁ hⱼ eⱼ with m the edge's midpoint, the segment c + x₂ a; both parameters in [−1, 1].
    for j in 0..3 {
        for i in (0..8usize).filter(|i| i & (1 << j) == 0) {
            let mut mid = Vec3::new(
                if i & 1 != 0 { half.x } else { -half.x },
                if i & 2 != 0 { half.y } else { -half.y },
                if i & 4 != 0 { half.z } else { -half.z },
            );
            mid[j] = 0.0;
            let dif = mid - centre;
            // Normal equations of min |dif + x₁ hⱼ eⱼ − x₂ a|²: [ma mb; mb mc] x = (u, v).
            let ma = half[j] * half[j];
            let mb = -half[j] * ha[j];
            let mc = half_length * half_length;
            let u = -half[j] * dif[j];
            let v = ha.dot(&dif);
            let det = ma * mc - mb * mb;
            if det.abs() < MINVAL {
                continue;
            }
            let inv = 1.0 / det;
            let mut x1 = (mc * u - mb * v) * inv;
            let mut x2 = (ma * v - mb * u) * inv;
            // Clamp state of the edge parameter: 0 at −1, 1 inside, 2 at +1 (re-solved inside
            // after the segment's clamp, it keeps the state it had).
            let mut s1 = 1;
            if x1 > 1.0 {
                (x1, s1, x2) = (1.0, 2, (v - mb) * (1.0 / mc));
            } else if x1 < -1.0 {
                (x1, s1, x2) = (-1.0, 0, (v + mb) * (1.0 / mc));
            }
            let resolved = if x2 > 1.0 {
                x2 = 1.0;
                Some((u - mb) * (1.0 / ma))
            } else if x2 < -1.0 {
                x2 = -1.0;
                Some((u + mb) * (1.0 / ma))
            } else {
                None
            };
            if let Some(x) = resolved {
                x1 = x;
                if x1 > 1.0 {
                    (x1, s1) = (1.0, 2);
                } else if x1 < -1.0 {
                    (x1, s1) = (-1.0, 0);
                }
            }
            let mut gap = dif - ha * x2;
            gap[j] += half[j] * x1;
            let d = gap.norm_squared();
            // (Strictly better by MINVAL: a segment parallel to a face keeps the face's end.)
            if d < best - MINVAL {
                best = d;
                at = x2;
                closest = Some(Closest::Edge {
                    axis: j,
                    corner: if s1 == 2 { i | (1 << j) } else { i },
                    along: x1,
                    at_corner: s1 != 1,
                });
            }
        }
    }
    let Some(closest) = closest else { return };

    // The second point, as an offset from the first along the segment (half lengths).
    let second = match closest {
        Closest::Edge { corner, at_corner: true, .. } => {
            // Near a corner: the segment's direction relative to the corner's octant.
            let mut rel = octant ^ corner;
            if rel == 0 || rel == 7 {
                None // pointing at the corner (or away)
            } else {
                // (room towards the end the direction leads to, room back.)
                let (sign, ahead, behind) = if rel.count_ones() == 1 {
                    (1.0, 1.0 - at, 1.0 + at)
                } else {
                    rel = 7 - rel;
                    (-1.0, 1.0 + at, 1.0 - at)
                };
                let ax = rel.trailing_zeros() as usize;
                let (ax1, ax2) = ((ax + 1) % 3, (ax + 2) % 3);
                Some(if axis[ax] * axis[ax] > 0.5 {
                    // Along the edge of axis `ax`, at most its length.
                    sign * ahead.min(2.0 * half[ax] / ha[ax].abs())
                } else {
                    // Over the face across `ax`, at most its extents.
                    -sign * behind.min(2.0 * half[ax1] / ha[ax1].abs()).min(2.0 * half[ax2] / ha[ax2].abs())
                })
            }
        }
        Closest::Edge { axis: edge, corner, along, at_corner: false } => {
            // Crossing an edge: a second point only in a slanted ("X") crossing, over the face
            // the segment leans on.
            let rel = (octant ^ corner) & (7 - (1 << edge));
            if rel.count_ones() != 1 {
                None
            } else {
                let (mut ax1, ax2) = ((edge + 1) % 3, (edge + 2) % 3);
                if axis[ax1].abs() > axis[ax2].abs() {
                    ax1 = ax2;
                }
                let ax2 = 3 - edge - ax1;
                let (sign, room) = if rel & (1 << ax2) != 0 { (1.0, 1.0 - at) } else { (-1.0, 1.0 + at) };
                let across = 2.0 * half[ax2] / ha[ax2].abs();
                let same = (octant & (1 << edge) != 0) == (rel & (1 << ax2) != 0);
                let edge_room = if same { 1.0 - along } else { 1.0 + along };
                let lengthwise = half[edge] * edge_room / ha[edge].abs();
                Some(sign * room.min(across).min(lengthwise))
            }
        }
        Closest::End { face: None, .. } => None, // the end is inside the box
        Closest::End { end, face: Some(face) } => {
            // An end over a face: the farthest point of the segment, going from that end
            // towards the other, that still projects onto the face (at most the other end).
            let sign = -end;
            let near = centre - ha * sign;
            let mut room: f64 = 2.0;
            for k in (0..3).filter(|&k| k != face) {
                for bound in [half[k], -half[k]] {
                    let e = (bound - near[k]) / ha[k] * sign;
                    if e > 0.0 && e < room {
                        room = e;
                    }
                }
            }
            Some(room * sign)
        }
    };

    for (offset, feature) in [(Some(at), 0), (second.map(|s| s + at), 1)] {
        if let Some(offset) = offset {
            let c = xb.act_point(&(centre + ha * offset));
            sphere_box(&c, radius, xb, half, reach, feature, &mut *out);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spatial::Mat3;

    fn collect(f: impl FnOnce(&mut dyn FnMut(PairPoint, u32))) -> Vec<(PairPoint, u32)> {
        let mut v = Vec::new();
        f(&mut |p, k| v.push((p, k)));
        v
    }

    #[test]
    fn sphere_outside_and_inside_a_box() {
        let x = Transform { rot: Mat3::identity(), pos: Vec3::new(0.0, 0.0, 1.0) };
        let half = Vec3::new(0.3, 0.2, 0.1);
        // Beside the +x face, 0.05 deep: normal −x (sphere → box).
        let c =
            collect(|o| sphere_box(&Vec3::new(0.35, 0.0, 1.0), 0.1, &x, &half, 0.0, 0, &mut |p, k| o(p, k)));
        assert_eq!(c.len(), 1);
        let p = c[0].0;
        assert!((p.dist + 0.05).abs() < 1e-15 && (p.normal + Vec3::x()).norm() < 1e-15);
        assert!(((p.p1 + p.p2) * 0.5 - Vec3::new(0.275, 0.0, 1.0)).norm() < 1e-15);
        // Centre inside, nearest the +z face: normal −z, depth 0.04 + radius.
        let c =
            collect(|o| sphere_box(&Vec3::new(0.0, 0.0, 1.06), 0.1, &x, &half, 0.0, 0, &mut |p, k| o(p, k)));
        assert!((c[0].0.dist + 0.14).abs() < 1e-15 && (c[0].0.normal + Vec3::z()).norm() < 1e-15);
        // Separated by more than the reach: nothing.
        assert!(collect(|o| sphere_box(&Vec3::new(0.5, 0.0, 1.0), 0.1, &x, &half, 0.05, 0, &mut |p, k| o(
            p, k
        )))
        .is_empty());
    }

    #[test]
    fn capsule_lying_on_a_box_touches_at_both_ends() {
        // Capsule along x (axis z turned onto x), resting 0.01 deep on the +z face of a big box.
        let xb = Transform { rot: Mat3::identity(), pos: Vec3::zeros() };
        let rot = Mat3::new(0.0, 0.0, 1.0, 0.0, 1.0, 0.0, -1.0, 0.0, 0.0);
        let xc = Transform { rot, pos: Vec3::new(0.0, 0.0, 0.14) };
        let half = Vec3::new(1.0, 1.0, 0.05);
        let c = collect(|o| capsule_box(&xc, 0.1, 0.2, &xb, &half, 0.0, &mut |p, k| o(p, k)));
        assert_eq!(c.len(), 2);
        let mut xs: Vec<f64> = c.iter().map(|(p, _)| (p.p1.x + p.p2.x) * 0.5).collect();
        xs.sort_by(f64::total_cmp);
        assert!((xs[0] + 0.2).abs() < 1e-15 && (xs[1] - 0.2).abs() < 1e-15, "{xs:?}");
        for (p, _) in &c {
            assert!((p.dist + 0.01).abs() < 1e-15 && (p.normal + Vec3::z()).norm() < 1e-15);
        }
        assert_ne!(c[0].1, c[1].1);
    }
}
