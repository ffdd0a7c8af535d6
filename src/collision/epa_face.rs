//! The contact features of two polytopes (boxes, mesh hulls) read off the face EPA ends on, as
//! MuJoCo 4.0's `multicontact` reads them (engine_collision_gjk.c: `simplexDim`, `boxNormals`,
//! `meshNormals`, `boxEdgeNormals`, `meshEdgeNormals`, `alignedFaces`, `alignedFaceEdge`; read for
//! their semantics, written here anew). What [`super::multiccd`] clips (docs/multiccd.md).
//!
//! - **Feature dimension.** Each of the face's three polytope vertices carries, per geom, the box
//!   corner or hull vertex its support point came from ([`EpaFace`]). The number of distinct ones
//!   on a geom is its feature's dimension: 1 a vertex, 2 an edge, 3 a face (`simplexDim`, which
//!   moves the second distinct vertex of an edge into the second place).
//! - **Candidate faces.** A hull vertex's polygons (ascending, MuJoCo's `mesh_polymap`); an edge's
//!   polygons holding both ends (up to two, in the first end's order); a face's one polygon holding
//!   all three. A box corner's three faces (x, y, z); an edge's two (x, y, z order); a face's one;
//!   when the corners name no such faces (a face diagonal, three corners off one face), the box
//!   face within ~5.1° of the contact direction, if any (`boxNormals2`).
//! - **Choice.** The live MuJoCo 4.0.0, read from its contacts (tests/convex_mujoco.rs: every
//!   box–mesh case without a margin and every mesh–mesh case match with these rules; without the
//!   second edge test 1 and 3 fewer, and with the source snapshot's first aligned face pair
//!   instead of the most opposite 3 and 1 fewer again — three of them a box resting on link5's
//!   two nearly coplanar faces), differs from its 2026-08 source snapshot in two places: of
//!   the face pairs within ~5.1° of opposite it takes the most nearly opposite (the first of
//!   equals, geom 1's faces outermost); failing one, the lower-dimensional feature's edges (geom
//!   1's of equal dimensions: an edge itself; at a vertex, per face around it the edge to the
//!   polygon's previous vertex, or a box corner's three edges x, y, z) against the other geom's
//!   faces, the first (faces outermost) within ~5.1° of parallel, and when none is, geom 2's
//!   edges against geom 1's faces (the snapshot stops at the first test). With faces on both
//!   geoms and none opposite, no choice (one contact).
//!
//! MuJoCo Warp 4.0.0 (the GPU port released with MuJoCo 4.0.0; its `collision_gjk.py` read for
//! semantics, docs/multiccd.md) agrees on the most opposite pair, but stops after geom 1's edges
//! and skips faces not facing the contact direction; tried against the goldens, its edge rule
//! loses 1 box–mesh and 3 mesh–mesh cases and its facing test changes none, so neither is taken.

use super::ccd::EpaFace;
use super::multiccd::{Poly, EDGE_TOL, FACE_TOL};
use crate::spatial::{Transform, Vec3};

/// One geom's feature to clip: a face (its index and world outward normal) or an edge (world
/// end points).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Feature {
    /// Face `index` of the geom (box face 2a: +axis a, 2a + 1: −axis a; hull polygon index).
    Face {
        /// The face's index.
        index: u32,
        /// Its outward unit normal (world).
        normal: Vec3,
    },
    /// An edge from its first to its second point (world).
    Edge([Vec3; 2]),
}

/// Scratch buffers of [`aligned_features`] (no allocation once grown).
#[derive(Default)]
pub(crate) struct FaceScratch {
    normals1: Vec<(Vec3, u32)>,
    normals2: Vec<(Vec3, u32)>,
    /// Edge directions (unit) and far ends.
    edges: Vec<(Vec3, Vec3)>,
}

/// MuJoCo's `mju_normalize3`: (1, 0, 0) for a vector shorter than `mjMINVAL`.
fn normalize3(v: Vec3) -> Vec3 {
    let n = v.norm();
    if n < 1e-15 {
        Vec3::x()
    } else {
        v * (1.0 / n)
    }
}

/// The dimension (1, 2, 3) of a geom's feature from its three indices, the second distinct one
/// moved into the second place as MuJoCo's `simplexDim` does (the vertices' points, formed from
/// the indices after it, follow them).
fn simplex_dim(vi: &mut [i32; 3]) -> usize {
    if vi[0] == vi[1] {
        if vi[0] == vi[2] {
            return 1;
        }
        vi[1] = vi[2];
        return 2;
    }
    if vi[2] == vi[0] || vi[2] == vi[1] {
        2
    } else {
        3
    }
}

/// The box face within ~5.1° of world direction `dir` (MuJoCo's `boxNormals2`), if any.
fn box_face_along(x: &Transform, dir: &Vec3, out: &mut Vec<(Vec3, u32)>) {
    let r = &x.rot;
    let mut local = Vec3::new(
        r[(0, 0)] * dir.x + r[(1, 0)] * dir.y + r[(2, 0)] * dir.z,
        r[(0, 1)] * dir.x + r[(1, 1)] * dir.y + r[(2, 1)] * dir.z,
        r[(0, 2)] * dir.x + r[(1, 2)] * dir.y + r[(2, 2)] * dir.z,
    );
    local *= 1.0 / local.dot(&local).sqrt();
    for f in 0..6u32 {
        let a = (f / 2) as usize;
        let c = if f.is_multiple_of(2) { local[a] } else { -local[a] };
        if c > FACE_TOL {
            out.push((x.rot * face_axis(f), f));
            return;
        }
    }
}

/// Box face `f`'s outward unit normal in the box frame.
fn face_axis(f: u32) -> Vec3 {
    let mut n = Vec3::zeros();
    n[(f / 2) as usize] = if f.is_multiple_of(2) { 1.0 } else { -1.0 };
    n
}

/// The candidate faces of a feature of dimension `dim` with vertex indices `vi` (world normals and
/// face indices, MuJoCo's order) into `out`; `dir` is the geom's outward contact direction (a box's
/// fallback).
fn candidate_faces(
    poly: &Poly,
    x: &Transform,
    dim: usize,
    vi: &[i32; 3],
    dir: &Vec3,
    out: &mut Vec<(Vec3, u32)>,
) {
    out.clear();
    match poly {
        Poly::Cuboid(_) => {
            let [v1, v2, v3] = *vi;
            // +1 when every corner has the bit, −1 when none has it, 0 otherwise.
            let shared = |bit: i32, corners: &[i32]| {
                corners.iter().all(|&v| v & bit != 0) as i32 - corners.iter().all(|&v| v & bit == 0) as i32
            };
            match dim {
                1 => {
                    for a in 0..3u32 {
                        let f = 2 * a + (v1 & (1 << a) == 0) as u32;
                        out.push((x.rot * face_axis(f), f));
                    }
                }
                _ => {
                    let corners: &[i32] = if dim == 2 { &[v1, v2] } else { &[v1, v2, v3] };
                    for a in 0..3u32 {
                        let s = shared(1 << a, corners);
                        if s != 0 {
                            let f = 2 * a + (s < 0) as u32;
                            out.push((x.rot * face_axis(f), f));
                        }
                    }
                    // Two corners name two faces (an edge), three one (a face); else the fallback.
                    if out.len() != 4 - dim {
                        out.clear();
                        box_face_along(x, dir, out);
                    }
                }
            }
        }
        Poly::Hull(s) => {
            let g = s.graph();
            let polys = |v: i32| g.vertex_polygons(v as usize);
            let mut push = |f: u32| out.push((x.rot * g.poly_normal[f as usize], f));
            match dim {
                1 => polys(vi[0]).iter().for_each(|&f| push(f)),
                _ => {
                    // Up to two polygons holding the first two vertices (the first's order) ...
                    let mut common = [0u32; 2];
                    let mut n = 0;
                    'outer: for &a in polys(vi[0]) {
                        for &b in polys(vi[1]) {
                            if a == b {
                                common[n] = a;
                                n += 1;
                                if n == 2 {
                                    break 'outer;
                                }
                            }
                        }
                    }
                    if dim == 2 {
                        common[..n].iter().for_each(|&f| push(f));
                    } else if let Some(&f) = common[..n].iter().find(|&&f| polys(vi[2]).contains(&f)) {
                        // ... and the first of them holding the third.
                        push(f);
                    }
                }
            }
        }
    }
}

/// The edges of a feature of dimension 1 or 2 (unit directions from `v[0]` and far ends, MuJoCo's
/// order) into `out`.
fn candidate_edges(
    poly: &Poly,
    x: &Transform,
    dim: usize,
    v: &[Vec3; 3],
    v0: i32,
    out: &mut Vec<(Vec3, Vec3)>,
) {
    out.clear();
    if dim == 2 {
        out.push((normalize3(v[1] - v[0]), v[1]));
        return;
    }
    match poly {
        Poly::Cuboid(_) => {
            for a in 0..3 {
                let end = x.act_point(&poly.vertex((v0 as u32) ^ (1 << a)));
                out.push((normalize3(end - v[0]), end));
            }
        }
        Poly::Hull(s) => {
            let g = s.graph();
            for &f in g.vertex_polygons(v0 as usize) {
                let p = g.polygon(f as usize);
                if let Some(j) = p.iter().position(|&u| u as i32 == v0) {
                    let prev = p[if j == 0 { p.len() - 1 } else { j - 1 }];
                    let end = x.act_point(&poly.vertex(prev));
                    out.push((normalize3(end - v[0]), end));
                }
            }
        }
    }
}

/// The first edge (index into `edges`) and face (index into `faces`) within ~5.1° of parallel,
/// faces outermost (MuJoCo's `alignedFaceEdge`).
fn edge_face(edges: &[(Vec3, Vec3)], faces: &[(Vec3, u32)]) -> Option<(usize, usize)> {
    for (i, (n, _)) in faces.iter().enumerate() {
        for (j, (d, _)) in edges.iter().enumerate() {
            if d.dot(n).abs() < EDGE_TOL {
                return Some((j, i));
            }
        }
    }
    None
}

/// Whether every index of `vi` names a vertex of `poly`.
#[inline]
fn valid(poly: &Poly, vi: &[i32; 3]) -> bool {
    let n = poly.nvert();
    let ok = |v: i32| usize::try_from(v).is_ok_and(|v| v < n);
    ok(vi[0]) && ok(vi[1]) && ok(vi[2])
}

/// The world points of the vertices `vi` of `poly` at pose `x`.
#[inline]
fn world_points(poly: &Poly, x: &Transform, vi: &[i32; 3]) -> [Vec3; 3] {
    vi.map(|i| x.act_point(&poly.vertex(i as u32)))
}

/// The features of geoms 1 (`p1` at `x1`) and 2 to clip against each other, from EPA's final
/// face `face` and its witness points `w1`, `w2` (module documentation); None when nothing lines
/// up (or the face names no vertex of a geom, or a hull has no polygons): one contact.
#[allow(clippy::too_many_arguments)]
pub(crate) fn aligned_features(
    p1: &Poly,
    x1: &Transform,
    p2: &Poly,
    x2: &Transform,
    face: &EpaFace,
    w1: &Vec3,
    w2: &Vec3,
    s: &mut FaceScratch,
) -> Option<(Feature, Feature)> {
    let (mut vi1, mut vi2) = (face.index1, face.index2);
    if !valid(p1, &vi1) || !valid(p2, &vi2) || !p1.has_faces() || !p2.has_faces() {
        return None;
    }
    let dim1 = simplex_dim(&mut vi1);
    let dim2 = simplex_dim(&mut vi2);
    let (dir, dir_neg) = (w2 - w1, w1 - w2);
    candidate_faces(p1, x1, dim1, &vi1, &dir_neg, &mut s.normals1);
    candidate_faces(p2, x2, dim2, &vi2, &dir, &mut s.normals2);
    let face_of = |(normal, index): (Vec3, u32)| Feature::Face { index, normal };
    // The most nearly opposite pair (the first of equals).
    let mut best: Option<(f64, usize, usize)> = None;
    for (i, a) in s.normals1.iter().enumerate() {
        for (j, b) in s.normals2.iter().enumerate() {
            let c = a.0.dot(&b.0);
            if c < -FACE_TOL && best.is_none_or(|(bc, ..)| c < bc) {
                best = Some((c, i, j));
            }
        }
    }
    if let Some((_, i, j)) = best {
        return Some((face_of(s.normals1[i]), face_of(s.normals2[j])));
    }
    // An edge of the lower-dimensional feature (geom 1's of equals) against a face of the other,
    // then, failing that, an edge of geom 2 against a face of geom 1.
    // The vertices' world points, formed only for the edges.
    if dim1 < 3 && dim1 <= dim2 {
        let v1 = world_points(p1, x1, &vi1);
        candidate_edges(p1, x1, dim1, &v1, vi1[0], &mut s.edges);
        if let Some((e, j)) = edge_face(&s.edges, &s.normals2) {
            return Some((Feature::Edge([v1[0], s.edges[e].1]), face_of(s.normals2[j])));
        }
    }
    if dim2 < 3 {
        let v2 = world_points(p2, x2, &vi2);
        candidate_edges(p2, x2, dim2, &v2, vi2[0], &mut s.edges);
        let (e, i) = edge_face(&s.edges, &s.normals1)?;
        return Some((face_of(s.normals1[i]), Feature::Edge([v2[0], s.edges[e].1])));
    }
    None
}

/// The candidate faces of geom 2 (polytope `p2` at `x2`) named by EPA's final face `face` (its
/// feature's faces, as MuJoCo 4.0's `multicontact` gathers them for a capsule's or a cylinder's
/// edge against a polytope), `dir` the contact direction from geom 1 to geom 2 (a box's
/// fallback); empty when the face names no vertex of `p2` or a hull has no polygons.
pub(crate) fn geom2_faces(p2: &Poly, x2: &Transform, face: &EpaFace, dir: &Vec3, out: &mut Vec<(Vec3, u32)>) {
    geom2_feature(p2, x2, face, dir, out, None);
}

/// [`geom2_faces`], and with `edges` geom 2's feature edges (unit directions from its first
/// vertex and far ends, MuJoCo's order; none for a face) with that first vertex. Returns the
/// feature's dimension (0 when the face names no vertex of `p2` or a hull has no polygons).
pub(crate) fn geom2_feature(
    p2: &Poly,
    x2: &Transform,
    face: &EpaFace,
    dir: &Vec3,
    out: &mut Vec<(Vec3, u32)>,
    edges: Option<(&mut Vec<(Vec3, Vec3)>, &mut Vec3)>,
) -> usize {
    out.clear();
    let mut vi2 = face.index2;
    if !valid(p2, &vi2) || !p2.has_faces() {
        return 0;
    }
    let dim2 = simplex_dim(&mut vi2);
    candidate_faces(p2, x2, dim2, &vi2, dir, out);
    if let Some((e, start)) = edges {
        e.clear();
        let v2 = world_points(p2, x2, &vi2);
        if dim2 < 3 {
            candidate_edges(p2, x2, dim2, &v2, vi2[0], e);
        }
        *start = v2[0];
    }
    dim2
}
