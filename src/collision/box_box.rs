//! Box against box in closed form, with MuJoCo's contact manifold (MuJoCo documentation,
//! "Computation → Collision detection"; MuJoCo's `mjc_BoxBox`, engine_collision_box.c): up to 8
//! contacts, normals from geom 1 to geom 2.
//!
//! 1. **Separating axes.** The 15 candidate axes are the 3 face normals of each box and the 9
//!    cross products of an edge direction of each. The pair is separated when the boxes' extents
//!    along some axis leave a gap larger than the margin (plus a rounding slack of 1e-13 times the
//!    sum of the half-extents); otherwise the axis of largest separation (least penetration)
//!    wins, the faces first: an edge axis must beat the best face axis by a relative 1e-6 (a
//!    face gives several points, an edge one), cross products of nearly parallel edges
//!    (sin² < 1e-16) are skipped, and a winning edge axis within ~8° of the best face axis
//!    (|cos| > 0.99) gives way to the face unless it is better by 5 % of the face's depth.
//! 2. **Edge against edge.** One contact, midway between the closest points of the two edges
//!    that support the axis (both candidate edges tried when the axis is nearly orthogonal to a
//!    face, keeping the closer pair), the distance measured along the axis (oriented from box 1
//!    to box 2).
//! 3. **Face against face.** The box owning the winning face is the reference, the other the
//!    incident box; its face most opposed to the reference normal is clipped against the four
//!    side planes of the reference face (Sutherland–Hodgman, at most 8 vertices). Every clipped
//!    vertex no farther than the margin above the reference face is a contact (near-duplicates,
//!    within 1e-7 of the face's size, dropped): the distance is its height above the reference
//!    face, the position midway between the reference face and the vertex.
//!
//! Contact frames are MuJoCo's default from the normal alone. Feature ids say which features of
//! the two boxes made a point (see [`box_box`]), so a face point keeps its id while the boxes
//! move a little.

use super::convex::PairPoint;
use crate::spatial::{Mat3, Transform, Vec3};

/// MuJoCo's smallest denominator (`mjMINVAL`).
const MINVAL: f64 = 1e-15;
/// Rounding slack of the separation tests, times the sum of the half-extents.
const SEPARATION_SLACK: f64 = 1e-13;
/// sin² of the angle between two edges below which their cross product is noise.
const PARALLEL: f64 = 1e-16;
/// Axis component below which the supporting edge's corner is ambiguous.
const AMBIGUOUS: f64 = 1e-9;
/// Squared distance, relative to the reference face's squared size, below which two clipped
/// vertices are one.
const DUPLICATE: f64 = 1e-14;
/// Relative advantage an edge axis needs over the best face axis.
const EDGE_BIAS: f64 = 1e-6;
/// Clipped polygon capacity (a quadrilateral clipped by four half-planes has at most 8).
const MAX_VERTICES: usize = 12;

/// Feature id of the edge–edge contact: this bit and the edge pair 3 i + j (edge i of box 1,
/// edge j of box 2).
pub const EDGE_FEATURE: u32 = 1 << 15;

/// A vertex of the clipped polygon: (x, y) in the reference face's axes, z the height above the
/// reference face; and the lines it lies on (bits 0–3: the incident face's edges, bits 4–7: the
/// reference face's side planes +x, −x, +y, −y).
#[derive(Clone, Copy, Default)]
struct Vertex {
    p: [f64; 3],
    lines: u32,
}

/// Clips `poly[..n]` against the half-plane sign · v[coord] ≤ limit (side plane `plane`), into
/// `spare`, and swaps the two; left as it is when every vertex is inside. Returns the new count.
fn clip(
    poly: &mut [Vertex; MAX_VERTICES],
    spare: &mut [Vertex; MAX_VERTICES],
    n: usize,
    coord: usize,
    sign: f64,
    limit: f64,
    plane: u32,
) -> usize {
    let mut d = [0.0; MAX_VERTICES];
    for k in 0..n {
        d[k] = sign * poly[k].p[coord] - limit;
    }
    if d[..n].iter().all(|&x| x <= 0.0) {
        return n;
    }
    let mut m = 0;
    for k in 0..n {
        let k1 = if k + 1 == n { 0 } else { k + 1 };
        let (dp, dq) = (d[k], d[k1]);
        if dp <= 0.0 && m < MAX_VERTICES {
            spare[m] = poly[k];
            m += 1;
        }
        if ((dp < 0.0 && dq > 0.0) || (dp > 0.0 && dq < 0.0)) && m < MAX_VERTICES {
            let (p, q) = (poly[k].p, poly[k1].p);
            let t = dp / (dp - dq);
            spare[m] = Vertex {
                p: [0, 1, 2].map(|r| p[r] + t * (q[r] - p[r])),
                lines: (poly[k].lines & poly[k1].lines) | (1 << (4 + plane)),
            };
            m += 1;
        }
    }
    std::mem::swap(poly, spare);
    m
}

/// Boxes at poses `x1`, `x2` with half-extents `h1`, `h2`: the contacts no farther apart than
/// `reach`, at most 8, each with its feature id (face contacts: bits 0–7 the lines the clipped
/// vertex lies on, bits 8–10 the winning face axis 0–5 (3–5: box 2's), bit 11 its side, bits
/// 12–13 the incident face's axis, bit 14 its side; the edge contact: [`EDGE_FEATURE`] + the edge
/// pair).
pub fn box_box(
    x1: &Transform,
    h1: &Vec3,
    x2: &Transform,
    h2: &Vec3,
    reach: f64,
    out: &mut impl FnMut(PairPoint, u32),
) {
    // rot: box 2's axes in box 1's frame (columns); the centres in each other's frames.
    let rot: Mat3 = x1.rot.transpose() * x2.rot;
    let rot_abs = rot.abs();
    let pos21 = x1.rot.transpose() * (x2.pos - x1.pos);
    let pos12 = x2.rot.transpose() * (x1.pos - x2.pos);
    let slack = reach + SEPARATION_SLACK * (h1.x + h1.y + h1.z + h2.x + h2.y + h2.z);

    // Separating axes: code 0–2 a face axis of box 1, 3–5 of box 2, 6 + 3 i + j edge i × edge j.
    let mut best = f64::NEG_INFINITY;
    let mut code = 0;
    for i in 0..3 {
        let sep = pos21[i].abs() - h1[i] - rot_abs.row(i).transpose().dot(h2);
        if sep > slack {
            return;
        }
        if sep > best {
            (best, code) = (sep, i);
        }
    }
    for j in 0..3 {
        let sep = pos12[j].abs() - h2[j] - rot_abs.column(j).dot(h1);
        if sep > slack {
            return;
        }
        if sep > best {
            (best, code) = (sep, 3 + j);
        }
    }
    let (face_sep, face_code) = (best, code);
    // Edge i of box 1 × edge j of box 2 in box 1's frame: zero along i, (−rot[i2][j], rot[i1][j]).
    let edge_axis = |i: usize, j: usize| {
        let (i1, i2) = ((i + 1) % 3, (i + 2) % 3);
        (i1, i2, -rot[(i2, j)], rot[(i1, j)])
    };
    for i in 0..3 {
        for j in 0..3 {
            let (i1, i2, mut a1, mut a2) = edge_axis(i, j);
            let norm2 = a1 * a1 + a2 * a2;
            if norm2 < PARALLEL {
                continue;
            }
            let inv = 1.0 / norm2.sqrt();
            a1 *= inv;
            a2 *= inv;
            let r1 = h1[i1] * a1.abs() + h1[i2] * a2.abs();
            let (j1, j2) = ((j + 1) % 3, (j + 2) % 3);
            let b1 = a1 * rot[(i1, j1)] + a2 * rot[(i2, j1)];
            let b2 = a1 * rot[(i1, j2)] + a2 * rot[(i2, j2)];
            let r2 = h2[j1] * b1.abs() + h2[j2] * b2.abs();
            let sep = (a1 * pos21[i1] + a2 * pos21[i2]).abs() - r1 - r2;
            if sep > slack {
                return;
            }
            if sep - EDGE_BIAS * sep.abs() > best && sep > face_sep {
                (best, code) = (sep, 6 + 3 * i + j);
            }
        }
    }
    // The unit edge axis of `code` in box 1's frame (MuJoCo's normalisation).
    let unit_edge_axis = |code: usize| {
        let (i, j) = ((code - 6) / 3, (code - 6) % 3);
        let (i1, i2, a1, a2) = edge_axis(i, j);
        let mut a = Vec3::zeros();
        (a[i1], a[i2]) = (a1, a2);
        let n = a.norm();
        if n < MINVAL {
            Vec3::x()
        } else {
            a * (1.0 / n)
        }
    };
    // An edge axis nearly parallel to the best face axis gives way to it unless clearly better.
    if code >= 6 {
        let a = unit_edge_axis(code);
        let cos = if face_code < 3 { a[face_code].abs() } else { a.dot(&rot.column(face_code - 3)).abs() };
        if cos > 0.99 && best < face_sep + 0.05 * face_sep.abs() + MINVAL {
            code = face_code;
        }
    }

    if code >= 6 {
        edge_edge(x1, h1, h2, &rot, &pos21, code, unit_edge_axis(code), slack, out);
    } else {
        face_face(x1, h1, x2, h2, &rot, &pos21, &pos12, code, reach, out);
    }
}

/// The edge–edge contact of edge axis `code` (unit `axis` in box 1's frame).
#[allow(clippy::too_many_arguments)]
fn edge_edge(
    x1: &Transform,
    h1: &Vec3,
    h2: &Vec3,
    rot: &Mat3,
    pos21: &Vec3,
    code: usize,
    mut axis: Vec3,
    slack: f64,
    out: &mut impl FnMut(PairPoint, u32),
) {
    let (i, j) = ((code - 6) / 3, (code - 6) % 3);
    let (i1, i2) = ((i + 1) % 3, (i + 2) % 3);
    let (j1, j2) = ((j + 1) % 3, (j + 2) % 3);
    if axis.dot(pos21) < 0.0 {
        axis = -axis;
    }
    // The axis in box 2's frame.
    let a2 = rot.transpose() * axis;
    // A nearly zero component leaves the supporting corner ambiguous: try both signs (at most
    // one such component per box).
    let amb1 = if axis[i1].abs() < AMBIGUOUS {
        Some(i1)
    } else if axis[i2].abs() < AMBIGUOUS {
        Some(i2)
    } else {
        None
    };
    let amb2 = if a2[j1].abs() < AMBIGUOUS {
        Some(j1)
    } else if a2[j2].abs() < AMBIGUOUS {
        Some(j2)
    } else {
        None
    };
    let d2 = rot.column(j).into_owned();
    let b = d2[i]; // cosine between the edges
    let denom = 1.0 - b * b;
    let mut witness = (Vec3::zeros(), Vec3::zeros());
    let mut closest = f64::INFINITY;
    for v1 in 0..if amb1.is_some() { 2 } else { 1 } {
        for v2 in 0..if amb2.is_some() { 2 } else { 1 } {
            // Box 1's edge: along eᵢ through its corner supporting +axis.
            let mut c1 = Vec3::zeros();
            c1[i1] = if axis[i1] >= 0.0 { h1[i1] } else { -h1[i1] };
            c1[i2] = if axis[i2] >= 0.0 { h1[i2] } else { -h1[i2] };
            if let (Some(k), 1) = (amb1, v1) {
                c1[k] = -c1[k];
            }
            // Box 2's edge: along its axis j through its corner supporting −axis.
            let mut cc = Vec3::zeros();
            cc[j1] = if a2[j1] >= 0.0 { -h2[j1] } else { h2[j1] };
            cc[j2] = if a2[j2] >= 0.0 { -h2[j2] } else { h2[j2] };
            if let (Some(k), 1) = (amb2, v2) {
                cc[k] = -cc[k];
            }
            let c2 = rot * cc + pos21;
            // Closest points of the two edges (unit directions), each clamp re-solving the other.
            let e = c2 - c1;
            let (d1e, d2e) = (e[i], d2.dot(&e));
            let s = if denom < MINVAL { 0.0 } else { (d1e - b * d2e) / denom };
            let s = s.clamp(-h1[i], h1[i]);
            let t = (b * s - d2e).clamp(-h2[j], h2[j]);
            let s = (d1e + b * t).clamp(-h1[i], h1[i]);
            let mut p1 = c1;
            p1[i] += s;
            let p2 = c2 + d2 * t;
            let gap = (p2 - p1).norm_squared();
            if gap < closest {
                closest = gap;
                witness = (p1, p2);
            }
        }
    }
    let dist = (witness.1 - witness.0).dot(&axis);
    if dist > slack {
        return;
    }
    out(
        PairPoint { p1: x1.act_point(&witness.0), p2: x1.act_point(&witness.1), normal: x1.rot * axis, dist },
        EDGE_FEATURE | (code as u32 - 6),
    );
}

/// The face contacts of face axis `code` (0–2: box 1's face is the reference, 3–5: box 2's).
#[allow(clippy::too_many_arguments)]
fn face_face(
    x1: &Transform,
    h1: &Vec3,
    x2: &Transform,
    h2: &Vec3,
    rot: &Mat3,
    pos21: &Vec3,
    pos12: &Vec3,
    code: usize,
    reach: f64,
    out: &mut impl FnMut(PairPoint, u32),
) {
    let ref1 = code < 3;
    let a = if ref1 { code } else { code - 3 };
    let (href, hinc, xref) = if ref1 { (h1, h2, x1) } else { (h2, h1, x2) };
    // The incident box's centre and axes (columns) in the reference frame.
    let (pinc, rinc) = if ref1 { (pos21, *rot) } else { (pos12, rot.transpose()) };
    let side = if pinc[a] >= 0.0 { 1.0 } else { -1.0 };
    // Incident face: the incident axis most aligned with the reference normal, on the side
    // facing the reference box.
    let mut binc = 0;
    for k in 1..3 {
        if rinc[(a, k)].abs() > rinc[(a, binc)].abs() {
            binc = k;
        }
    }
    let tinc = if side * rinc[(a, binc)] > 0.0 { -1.0 } else { 1.0 };
    // The incident face in (x, y, z) = (reference axis a+1, a+2, height above the face).
    let (ax, ay) = ((a + 1) % 3, (a + 2) % 3);
    let (bu, bv) = ((binc + 1) % 3, (binc + 2) % 3);
    let (mut centre, mut du, mut dv) = ([0.0; 3], [0.0; 3], [0.0; 3]);
    for (r, c) in [ax, ay, a].into_iter().enumerate() {
        centre[r] = pinc[c] + tinc * hinc[binc] * rinc[(c, binc)];
        du[r] = hinc[bu] * rinc[(c, bu)];
        dv[r] = hinc[bv] * rinc[(c, bv)];
    }
    centre[2] = side * centre[2] - href[a];
    du[2] *= side;
    dv[2] *= side;
    let mut poly = [Vertex::default(); MAX_VERTICES];
    let mut spare = [Vertex::default(); MAX_VERTICES];
    // Corners in cyclic order; edge k joins corner k to corner k + 1.
    for (k, (su, sv)) in [(1.0, 1.0), (-1.0, 1.0), (-1.0, -1.0), (1.0, -1.0)].into_iter().enumerate() {
        poly[k] = Vertex {
            p: [0, 1, 2].map(|r| centre[r] + su * du[r] + sv * dv[r]),
            lines: (1 << k) | (1 << ((k + 3) % 4)),
        };
    }
    let mut n = 4;
    n = clip(&mut poly, &mut spare, n, 0, 1.0, href[ax], 0);
    n = clip(&mut poly, &mut spare, n, 0, -1.0, href[ax], 1);
    n = clip(&mut poly, &mut spare, n, 1, 1.0, href[ay], 2);
    n = clip(&mut poly, &mut spare, n, 1, -1.0, href[ay], 3);

    let normal = xref.rot.column(a) * if ref1 { side } else { -side };
    let face = ((code as u32) << 8)
        | (u32::from(side > 0.0) << 11)
        | ((binc as u32) << 12)
        | (u32::from(tinc > 0.0) << 14);
    let duplicate = DUPLICATE * (href[ax] * href[ax] + href[ay] * href[ay]);
    let mut accepted = [Vertex::default(); MAX_VERTICES];
    let mut count = 0;
    for v in &poly[..n] {
        if v.p[2] > reach
            || accepted[..count].iter().any(|w| {
                let (dx, dy) = (w.p[0] - v.p[0], w.p[1] - v.p[1]);
                dx * dx + dy * dy < duplicate
            })
        {
            continue;
        }
        accepted[count] = *v;
        count += 1;
    }
    for (k, v) in accepted[..count].iter().enumerate() {
        // Points on the reference face and on the incident box (its vertex), in the reference
        // frame; the contact lies midway.
        let mut on_ref = Vec3::zeros();
        (on_ref[ax], on_ref[ay], on_ref[a]) = (v.p[0], v.p[1], side * href[a]);
        let mut on_inc = on_ref;
        on_inc[a] = side * (href[a] + v.p[2]);
        let (pr, pi) = (xref.act_point(&on_ref), xref.act_point(&on_inc));
        let (p1, p2) = if ref1 { (pr, pi) } else { (pi, pr) };
        // Two vertices on the same two lines only in degenerate polygons: keep ids distinct.
        let clash = accepted[..k].iter().any(|w| w.lines == v.lines);
        let lines = if clash { v.lines | ((k as u32 + 1) << 16) } else { v.lines };
        out(PairPoint { p1, p2, normal, dist: v.p[2] }, face | lines);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn collect(x1: &Transform, h1: &Vec3, x2: &Transform, h2: &Vec3, reach: f64) -> Vec<(PairPoint, u32)> {
        let mut v = Vec::new();
        box_box(x1, h1, x2, h2, reach, &mut |p, k| v.push((p, k)));
        v
    }

    fn at(pos: Vec3, angle_z: f64) -> Transform {
        let (s, c) = angle_z.sin_cos();
        Transform { rot: Mat3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0), pos }
    }

    #[test]
    fn stacked_boxes_touch_at_the_corners_of_their_overlap() {
        let h = Vec3::new(0.2, 0.2, 0.1);
        // Same size, aligned, 0.01 deep: the four corners of the top box's bottom face.
        let c = collect(&at(Vec3::zeros(), 0.0), &h, &at(Vec3::new(0.0, 0.0, 0.19), 0.0), &h, 0.0);
        assert_eq!(c.len(), 4);
        for (p, _) in &c {
            let pos = (p.p1 + p.p2) * 0.5;
            assert!((p.dist + 0.01).abs() < 1e-15 && (p.normal - Vec3::z()).norm() < 1e-15);
            assert!((pos.x.abs() - 0.2).abs() < 1e-15 && (pos.z - 0.095).abs() < 1e-15);
        }
        // Turned by 45°: an octagon, eight distinct features.
        let c = collect(
            &at(Vec3::zeros(), 0.0),
            &h,
            &at(Vec3::new(0.0, 0.0, 0.19), 0.25 * std::f64::consts::PI),
            &h,
            0.0,
        );
        assert_eq!(c.len(), 8);
        let mut ids: Vec<u32> = c.iter().map(|(_, k)| *k).collect();
        ids.sort_unstable();
        ids.dedup();
        assert_eq!(ids.len(), 8);
        // Lifted 0.02 apart: nothing without a margin, all eight within a margin of 0.03.
        let lifted = at(Vec3::new(0.0, 0.0, 0.22), 0.25 * std::f64::consts::PI);
        assert!(collect(&at(Vec3::zeros(), 0.0), &h, &lifted, &h, 0.0).is_empty());
        assert_eq!(collect(&at(Vec3::zeros(), 0.0), &h, &lifted, &h, 0.03).len(), 8);
    }

    #[test]
    fn crossed_edges_make_one_contact() {
        // Two long bars crossing at right angles, edge on edge (each turned 45° about its length).
        let h = Vec3::new(1.0, 0.1, 0.1);
        let r = std::f64::consts::FRAC_1_SQRT_2;
        let x1 = Transform { rot: Mat3::new(1.0, 0.0, 0.0, 0.0, r, -r, 0.0, r, r), pos: Vec3::zeros() };
        let x2 = Transform {
            rot: Mat3::new(0.0, -r, r, 1.0, 0.0, 0.0, 0.0, r, r),
            pos: Vec3::new(0.0, 0.0, 0.2 * std::f64::consts::SQRT_2 - 0.01),
        };
        let c = collect(&x1, &h, &x2, &h, 0.0);
        assert_eq!(c.len(), 1);
        let (p, k) = c[0];
        assert!((p.dist + 0.01).abs() < 1e-12 && (p.normal - Vec3::z()).norm() < 1e-12, "{p:?}");
        assert!(k & EDGE_FEATURE != 0);
    }
}
