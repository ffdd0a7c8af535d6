//! Sutherland–Hodgman clipping of a convex polygon (or a segment) by the side planes of a convex
//! face polygon, in MuJoCo's pass order: the passes of MuJoCo's `polygonClip`
//! (engine_collision_gjk.c, read for its semantics; written here anew), the same points in the
//! same order, at a cost that grows with the points a pass removes rather than with a walk of
//! every point through every pass.
//!
//! A pass over side plane k keeps the points inside it and puts, where an edge of the polygon
//! crosses the plane, the crossing point; its output starts at the polygon's second point
//! (the point an edge ends at is emitted with the edge). Three savings, none changing a point:
//! - a side that keeps every point only turns the polygon by one: such sides are counted and the
//!   turns applied (as an index offset) at the next side that cuts, and at the end;
//! - in a side that cuts, the runs of kept points between the crossings are copied as slices;
//! - when the polygon being clipped is convex about the face's normal (checked once, when
//!   first needed, with a margin far above rounding), the points a plane removes are one run of the polygon: a pass
//!   tests the crossing point the previous pass left beyond the face's next vertex and, when it is
//!   outside, walks from it to the two ends of the run — the other points are inside. Otherwise
//!   (no such point outside, or a polygon not certified convex) every point is tested.
//!
//! Small clips (face sides × polygon points up to 64: box and mesh faces of a few vertices, most
//! clips) run the passes as written, each point's side test shared by its two edges: there the
//! savings above cost more in bookkeeping than they save.
//!
//! A pad's face of 76 vertices clipping a box face (the Robotiq 2F-85's finger on a block) cuts
//! on most of its sides, each against a polygon of up to 76 points: the test of every point in
//! every pass was half of that scene's collision pass.
//!
//! The run walk decides each point as the full test would, except where a point's distance from
//! a plane is within rounding of MuJoCo's threshold (−mjMINVAL) while its neighbours' are not —
//! coincident edges far from the origin, where the points kept are decided by rounding in
//! MuJoCo too (whose side planes are rounded differently from these).

use crate::spatial::Vec3;

/// MuJoCo's `mjMINVAL`: a point counts as inside a side plane unless it is farther outside.
const MINVAL: f64 = 1e-15;

/// The sine of the turn at each vertex above which a polygon counts as strictly convex.
const CONVEX_SINE: f64 = 1e-9;

/// Scratch buffers of [`clip_by_face_sides`] (no allocation once grown).
#[derive(Clone, Debug, Default)]
pub struct ClipScratch {
    next: Vec<Vec3>,
    flags: Vec<bool>,
}

/// The signed distance of `p` from the side plane through `a` with unit normal `pn`, as the live
/// MuJoCo 4.0.0's `polygonClip` rounds it (read from its machine code): ((p − a)ₓ·pnₓ +
/// (p − a)ᵧ·pnᵧ) + (p − a)_z·pn_z.
#[inline(always)]
fn plane_distance(p: &Vec3, a: &Vec3, pn: &Vec3) -> f64 {
    let d = p - a;
    d.x * pn.x + d.y * pn.y + d.z * pn.z
}

/// Where edge p → q crosses the side plane through `a` (unit normal `pn`), if it does within the
/// edge: as the live MuJoCo 4.0.0 computes it (its machine code), t = d_p / (d_p − d_q) from the
/// two ends' distances ([`plane_distance`]), then p + (q − p)·t (the source snapshot's
/// (pn·a − pn·p) / pn·(q − p) rounds differently: the clipped cap's 16-gon of
/// cylinder_box/resting2 differed from the live one in the last bits). Not inlined: a pass
/// crosses its plane twice at most, and inlined into the passes' loops it cost `2f85_mesh`'s
/// collision pass 3.7M instructions over 200 steps (1.3M out of line).
#[inline(never)]
fn crossing_point(p: &Vec3, q: &Vec3, a: &Vec3, pn: &Vec3) -> Option<Vec3> {
    let dp = plane_distance(p, a, pn);
    let den = dp - plane_distance(q, a, pn);
    if den == 0.0 {
        return None;
    }
    let t = dp / den;
    (0.0..=1.0).contains(&t).then(|| p + (q - p) * t)
}

/// The unit inward normal of the side plane through edge a→b of a face with normal `n`, as the
/// live MuJoCo 4.0.0's `planeNormal` rounds it (read from its machine code): (b − a) × ((a + n)
/// − a), scaled by the reciprocal of its norm ((1, 0, 0) below 1e-15).
fn side_normal(a: &Vec3, b: &Vec3, n: &Vec3) -> Vec3 {
    let c = (b - a).cross(&((a + n) - a));
    let norm = c.norm();
    if norm < MINVAL {
        Vec3::x()
    } else {
        c * (1.0 / norm)
    }
}

/// Whether `poly` (3 points or more; fewer are convex) turns the same way at every vertex about
/// `n`, each turn's sine above [`CONVEX_SINE`] (no repeated or collinear points).
fn strictly_convex_about(poly: &[Vec3], n: &Vec3) -> bool {
    let np = poly.len();
    if np < 3 {
        return true;
    }
    let mut sign = 0.0;
    for i in 0..np {
        let (p, q, r) = (poly[i], poly[(i + 1) % np], poly[(i + 2) % np]);
        let (e1, e2) = (q - p, r - q);
        let turn = e1.cross(&e2).dot(n);
        // |turn| > sine·|e1|·|e2|, squared; a NaN turn is not convex either.
        let bound = CONVEX_SINE * CONVEX_SINE * e1.norm_squared() * e2.norm_squared();
        if (turn * turn).partial_cmp(&bound) != Some(std::cmp::Ordering::Greater) {
            return false;
        }
        if sign == 0.0 {
            sign = turn.signum();
        } else if turn.signum() != sign {
            return false;
        }
    }
    true
}

/// Clips `poly` in place by the side planes of the convex polygon `face` (outward normal `n`,
/// vertices clockwise about it, so that `(b − a) × n` points into the face for its edge a → b),
/// one pass per side in the face's order. A point is inside a side plane when
/// `(p − a)·pn > −mjMINVAL` (MuJoCo's `halfspace`). An empty result means no overlap.
///
/// ```
/// use lagrange::collision::polygon_clip::{clip_by_face_sides, ClipScratch};
/// use lagrange::spatial::Vec3;
/// // A unit square (clockwise about +z) clipping a square shifted by half its side.
/// let face = [Vec3::new(0.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0), Vec3::new(1.0, 1.0, 0.0), Vec3::new(1.0, 0.0, 0.0)];
/// let mut poly: Vec<Vec3> =
///     [(0.5, 0.5), (0.5, 1.5), (1.5, 1.5), (1.5, 0.5)].iter().map(|&(x, y)| Vec3::new(x, y, 0.0)).collect();
/// clip_by_face_sides(&face, &Vec3::z(), &mut poly, &mut ClipScratch::default());
/// assert_eq!(poly.len(), 4);
/// assert!(poly.iter().all(|p| (0.5..=1.0).contains(&p.x) && (0.5..=1.0).contains(&p.y)));
/// ```
pub fn clip_by_face_sides(face: &[Vec3], n: &Vec3, poly: &mut Vec<Vec3>, scratch: &mut ClipScratch) {
    let m = face.len();
    if m * poly.len() <= SMALL {
        return clip_small(face, n, poly, &mut scratch.next);
    }
    let ClipScratch { next, flags } = scratch;
    // Whether the polygon is strictly convex, found when first needed (a clipped convex polygon
    // stays convex).
    let mut convex: Option<bool> = None;
    // Physical index of the crossing point the last cut left farthest along its side.
    let mut hint: Option<usize> = None;
    // Pending turns: the polygon as the passes see it starts at poly[turns % len].
    let mut turns = 0;
    for k in 0..m {
        let np = poly.len();
        if np == 0 {
            return;
        }
        let (a, b) = (face[k], face[(k + 1) % m]);
        // Inward normal of the side plane through edge a→b (clockwise about n).
        let pn = side_normal(&a, &b, n);
        let inside = |p: &Vec3| plane_distance(p, &a, &pn) > -MINVAL;
        let side = b - a;
        // Where edge p → q (one end on each side) crosses the plane, if it does.
        let crossing = |p: Vec3, q: Vec3| crossing_point(&p, &q, &a, &pn);
        let walk = hint
            .filter(|&h| !inside(&poly[h]) && *convex.get_or_insert_with(|| strictly_convex_about(poly, n)));
        if let Some(h) = walk {
            // The run s..=e of outside points through h (its ends found by walking from h).
            let (prev, succ) = (
                |i: usize| if i == 0 { np - 1 } else { i - 1 },
                |i: usize| if i + 1 == np { 0 } else { i + 1 },
            );
            let (mut s, mut e, mut removed) = (h, h, 1);
            while removed < np && !inside(&poly[prev(s)]) {
                s = prev(s);
                removed += 1;
            }
            while removed < np && !inside(&poly[succ(e)]) {
                e = succ(e);
                removed += 1;
            }
            let r = turns % np;
            turns = 0;
            next.clear();
            hint = None;
            if removed < np {
                // Edge s − 1 → s gives crossing xa, edge e → e + 1 crossing xb and point e + 1,
                // edge k → k + 1 between kept points point k + 1: the output, from edge r on.
                let kept = np - removed;
                let (first_kept, last_kept) = (succ(e), prev(s));
                let xa = crossing(poly[last_kept], poly[s]);
                let xb = crossing(poly[e], poly[first_kept]);
                let offset = (r + np - first_kept) % np;
                let put_crossings =
                    |next: &mut Vec<Vec3>, hint: &mut Option<usize>, with_xa: bool, with_xb: bool| {
                        let mut along_best = f64::NEG_INFINITY;
                        for x in [xa.filter(|_| with_xa), xb.filter(|_| with_xb)].into_iter().flatten() {
                            let along = (x - a).dot(&side);
                            if along > along_best {
                                along_best = along;
                                *hint = Some(next.len());
                            }
                            next.push(x);
                        }
                    };
                if offset + 1 < kept {
                    push_rotated(poly, next, succ(r), kept - 1 - offset);
                    put_crossings(next, &mut hint, true, true);
                    push_rotated(poly, next, first_kept, offset + 1);
                } else if offset + 1 == kept {
                    put_crossings(next, &mut hint, true, true);
                    push_rotated(poly, next, first_kept, kept);
                } else {
                    put_crossings(next, &mut hint, false, true);
                    push_rotated(poly, next, first_kept, kept);
                    put_crossings(next, &mut hint, true, false);
                }
            }
            std::mem::swap(poly, next);
            continue;
        }
        flags.clear();
        flags.extend(poly.iter().map(inside));
        if flags.iter().all(|&f| f) {
            turns += 1;
            continue;
        }
        let r = turns % np;
        turns = 0;
        // Index of the rotated polygon's point i (0 ≤ i ≤ np, np wrapping to 0).
        let at = |i: usize| {
            let j = i + r;
            if j >= np {
                j - np
            } else {
                j
            }
        };
        next.clear();
        hint = None;
        let mut along_best = f64::NEG_INFINITY;
        let mut i = 0;
        while i < np {
            let (i0, i1) = (at(i), at(i + 1));
            let (ip, iq) = (flags[i0], flags[i1]);
            if ip && iq {
                // Edges i..=j all inside: their end points, rotated indices i + 1..=j + 1.
                let mut j = i;
                while j + 1 < np && flags[at(j + 2)] {
                    j += 1;
                }
                push_rotated(poly, next, at(i + 1), j - i + 1);
                i = j + 1;
                continue;
            }
            if ip || iq {
                if let Some(x) = crossing(poly[i0], poly[i1]) {
                    let along = (x - a).dot(&side);
                    if along > along_best {
                        along_best = along;
                        hint = Some(next.len());
                    }
                    next.push(x);
                }
                if iq {
                    next.push(poly[i1]);
                }
            }
            i += 1;
        }
        std::mem::swap(poly, next);
    }
    if !poly.is_empty() {
        let np = poly.len();
        poly.rotate_left(turns % np);
    }
}

/// Face sides × polygon points up to which [`clip_by_face_sides`] runs the passes as written
/// ([`clip_small`]): on a box face clipping a box face the run walk's bookkeeping costs more
/// than the tests it saves.
const SMALL: usize = 64;

/// [`clip_by_face_sides`] pass by pass, every point through every side (each point's side test
/// taken once per pass and shared by the two edges it ends): the same points in the same order.
fn clip_small(face: &[Vec3], n: &Vec3, poly: &mut Vec<Vec3>, next: &mut Vec<Vec3>) {
    let m = face.len();
    for k in 0..m {
        let np = poly.len();
        if np == 0 {
            return;
        }
        let (a, b) = (face[k], face[if k + 1 == m { 0 } else { k + 1 }]);
        let pn = side_normal(&a, &b, n);
        let inside = |p: &Vec3| plane_distance(p, &a, &pn) > -MINVAL;
        next.clear();
        let first_inside = inside(&poly[0]);
        let mut ip = first_inside;
        for i in 0..np {
            let (p, q) = (poly[i], if i + 1 == np { poly[0] } else { poly[i + 1] });
            let iq = if i + 1 == np { first_inside } else { inside(&q) };
            if ip && iq {
                next.push(q);
            } else if ip || iq {
                if let Some(x) = crossing_point(&p, &q, &a, &pn) {
                    next.push(x);
                }
                if iq {
                    next.push(q);
                }
            }
            ip = iq;
        }
        std::mem::swap(poly, next);
    }
}

/// Appends `count` points of `poly` from index `start`, wrapping past its end.
#[inline]
fn push_rotated(poly: &[Vec3], out: &mut Vec<Vec3>, start: usize, count: usize) {
    let first = count.min(poly.len() - start);
    out.extend_from_slice(&poly[start..start + first]);
    out.extend_from_slice(&poly[..count - first]);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The passes as written: every point through every side, the output of each pass rotated
    /// as Sutherland–Hodgman emits it (the reference the faster walk must equal bit for bit).
    fn reference(face: &[Vec3], n: &Vec3, input: &[Vec3]) -> Vec<Vec3> {
        let mut poly = input.to_vec();
        let m = face.len();
        for k in 0..m {
            let (a, b) = (face[k], face[(k + 1) % m]);
            let pn = side_normal(&a, &b, n);
            let inside = |p: &Vec3| plane_distance(p, &a, &pn) > -MINVAL;
            let np = poly.len();
            let mut out = Vec::new();
            for i in 0..np {
                let (p, q) = (poly[i], poly[(i + 1) % np]);
                let (ip, iq) = (inside(&p), inside(&q));
                if ip && iq {
                    out.push(q);
                } else if ip || iq {
                    if let Some(x) = crossing_point(&p, &q, &a, &pn) {
                        out.push(x);
                    }
                    if iq {
                        out.push(q);
                    }
                }
            }
            poly = out;
        }
        poly
    }

    /// A regular polygon of `count` vertices, clockwise about +z, about `centre`, turned by `phase`.
    fn regular(count: usize, radius: f64, centre: (f64, f64), phase: f64) -> Vec<Vec3> {
        (0..count)
            .map(|i| {
                let t = phase - std::f64::consts::TAU * i as f64 / count as f64;
                Vec3::new(centre.0 + radius * t.cos(), centre.1 + radius * t.sin(), 0.01 * t.sin())
            })
            .collect()
    }

    #[test]
    fn equals_the_pass_by_pass_clipping_bit_for_bit() {
        // Seeded poses: many-sided faces against squares, segments and many-sided polygons,
        // overlapping, nested, disjoint and touching.
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut uniform = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut scratch = ClipScratch::default();
        let mut cut = 0;
        for case in 0..400 {
            let m = [3, 4, 8, 33, 76][case % 5];
            let face = regular(m, 1.0, (0.0, 0.0), uniform());
            let count = [2, 4, 5, 40, 77][(case / 5) % 5];
            let centre = (2.5 * uniform() - 1.25, 2.5 * uniform() - 1.25);
            let input = regular(count, 0.3 + 1.2 * uniform(), centre, uniform());
            let expected = reference(&face, &Vec3::z(), &input);
            let mut poly = input.clone();
            clip_by_face_sides(&face, &Vec3::z(), &mut poly, &mut scratch);
            // The same points in the same order, to the bit.
            assert_eq!(poly, expected, "case {case}");
            cut += usize::from(!poly.is_empty() && poly.len() != input.len());
        }
        assert!(cut > 100, "only {cut} cases were cut");
    }

    #[test]
    fn equals_the_pass_by_pass_clipping_on_aligned_edges() {
        // Edges on the face's side lines (stacked boxes, a pad flat on a block): points at
        // distances of a rounding error from the planes, decided by the test itself.
        let square = |x0: f64, x1: f64, y0: f64, y1: f64, z: f64| {
            vec![Vec3::new(x0, y0, z), Vec3::new(x0, y1, z), Vec3::new(x1, y1, z), Vec3::new(x1, y0, z)]
        };
        let face = square(0.0, 1.0, 0.0, 1.0, 0.0);
        let mut scratch = ClipScratch::default();
        let turned = |p: &[Vec3], angle: f64, shift: f64| -> Vec<Vec3> {
            let (c, s) = (angle.cos(), angle.sin());
            p.iter()
                .map(|v| {
                    let (x, y) = (c * v.x - s * v.y + shift, s * v.x + c * v.y + shift);
                    // Mesh vertices are single precision.
                    Vec3::new(x as f32 as f64, y as f32 as f64, v.z)
                })
                .collect()
        };
        let fine = regular(70, 0.5, (0.5, 0.5), 0.1);
        let cases = [
            square(0.0, 1.0, 0.0, 1.0, 0.001),
            square(0.0, 1.0, 0.5, 1.5, -0.001),
            square(0.25, 0.75, 0.0, 1.0, 0.0),
            square(-0.5, 0.5, -0.5, 0.5, 0.0),
            square(-1.0, 2.0, -1.5, 2.0, 0.002),
            turned(&square(0.0, 1.0, 0.0, 1.0, 0.0), 1e-9, 0.0),
            turned(&square(0.0, 1.0, 0.0, 1.0, 0.0), -3e-8, 1e-12),
            turned(&fine, 0.0, 0.0),
            turned(&fine, 0.3, 0.2),
        ];
        for (case, input) in cases.iter().enumerate() {
            for face in [face.clone(), turned(&fine, 0.0, 0.0), turned(&fine, 1e-7, 0.0)] {
                let expected = reference(&face, &Vec3::z(), input);
                let mut poly = input.clone();
                clip_by_face_sides(&face, &Vec3::z(), &mut poly, &mut scratch);
                assert_eq!(poly, expected, "case {case}");
            }
        }
    }
}
