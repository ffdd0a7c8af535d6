//! MuJoCo 4.0's multi-point contacts of convex pairs (`multiccd`, `mjDSBL_MULTICCD`: on by
//! default; MuJoCo's `mjc_Convex` in engine_collision_convex.c and `multicontact` /
//! `polygonClip` in engine_collision_gjk.c, read for their semantics; written here anew).
//!
//! # Which pairs MuJoCo sends through its convex solver
//! MuJoCo's collision table (`mjCOLLISIONFUNC`, engine_collision_driver.c) calls `mjc_Convex` for
//! sphere–ellipsoid, sphere–mesh, capsule–ellipsoid, capsule–cylinder, capsule–mesh, ellipsoid
//! against ellipsoid, cylinder, box and mesh, cylinder against cylinder, box and mesh, box–mesh and
//! mesh–mesh; every other pair has a closed form (planes, sphere–sphere/capsule/cylinder/box,
//! capsule–capsule/box, box–box). `mjc_Convex` runs GJK and EPA on the geoms (each inflated by
//! half the pair's margin + gap) and then, with `multiccd` on:
//!
//! - **box and mesh against box and mesh** (`mj_maxContact` 4, 5 with a margin): the polytope
//!   path. MuJoCo reads each geom's contact feature (vertex, edge or face) off the face EPA ends
//!   on and gathers the faces around it (`collision/epa_face.rs`); two faces within ~5.1° of opposite
//!   (normals' dot below −0.996) clip one another: the face of geom 1 clips geom 2's face polygon
//!   (Sutherland–Hodgman), the clipped vertices farther than the margin + gap above geom 1's face
//!   plane are dropped (MuJoCo 4.0 clips margin pairs too; its older source turned them), more
//!   than four are pruned to a quadrilateral. Failing that, an edge of the lower-dimensional
//!   feature (then one of geom 2's) within ~5.1° of parallel to a face of the other (|dot| below
//!   0.0888) is clipped against that face (its two farthest points). Otherwise the single EPA
//!   point stays. Each point has its own depth (below the clipping face), its normal along the
//!   clipped face's normal.
//! - **a capsule or a cylinder against a box or a mesh** (`mj_maxContact` 5): MuJoCo's source
//!   snapshot turns both geoms by ±1e-3 rad about the contact's tangents and reruns the solver;
//!   the live 4.0.0 does not (its contacts show it): a capsule's surface line through its
//!   witness point, or a cylinder's side line through the support point of the first vertex of
//!   EPA's final face (of GJK's simplex for a shallow contact), clipped by the first face of the
//!   polytope's feature on that face within ~5.1° of parallel (points on the line and on the
//!   face's plane, normal the face's reversed: a capsule lying on a face gets its two ends; the
//!   faces at the support plane when no face is at hand); a cylinder's cap within ~5.1° of facing a face is clipped as a polygon
//!   (the cap as MuJoCo 4.0's regular 16-gon, vertex k at k·22.5° about the cylinder's x axis,
//!   clockwise seen from outside the cap: MuJoCo Warp 4.0.0's `_cylinder_face`, and every
//!   contact of the golden resting poses lies at a multiple of 22.5°); otherwise one contact.
//! - **capsule–cylinder, cylinder–cylinder** (`mj_maxContact` 5): geom 1's edge (as against a
//!   polytope) within ~5.1° of parallel to geom 2's cap, when the final face's feature on geom 2
//!   is that cap (the cylinder support marks the cap), clipped by the cap's 16-gon; otherwise
//!   one contact.
//! - **a sphere or an ellipsoid**: one contact.
//!
//! With `multiccd` off every convex pair gives one contact. lagrange reproduces these on its port
//! of MuJoCo's GJK/EPA (`collision/ccd.rs`), the features read off its final face as MuJoCo does
//! (`collision/epa_face.rs`, where the live 4.0.0's choice among aligned features is set out: it
//! differs from the source snapshot), box and mesh pairs with a margin included. A first point
//! that comes with no EPA face takes as features the vertices of each geom within a small
//! tolerance of its support plane along the contact normal (`support_plane_features`). The witness points follow the live 4.0.0, not the snapshot (see
//! `polytope_contacts`' clipping).

use super::ccd::EpaFace;
use super::convex::{ConvexShape, PairPoint};
use super::epa_face::Feature;
use crate::spatial::{Transform, Vec3};
use parry3d_f64::math::Vector;
use std::cell::RefCell;

/// Cosine above which two face normals count as opposite (MuJoCo's `mjFACE_TOL`, ~5.1°).
pub(crate) const FACE_TOL: f64 = 0.996;
/// |cosine| below which an edge counts as parallel to a face (MuJoCo's `mjEDGE_TOL`, ~5.1°).
pub(crate) const EDGE_TOL: f64 = 0.0888;
/// Cosine and sine of k·22.5° (k = 0..16), the vertices of the regular 16-gon standing in for a
/// cylinder's cap, as the live MuJoCo 4.0.0's table holds them (its cap polygons dumped under gdb:
/// exact 0 and ±1, the others to 15 significant digits, cos 45° = 0.707106781186548 and
/// sin 45° = 0.707106781186547).
// MuJoCo's table values, not the correctly rounded constants: the approximation is the point.
#[allow(clippy::approx_constant)]
const CAP_COS_SIN: [(f64, f64); 16] = {
    const C1: f64 = 0.923879532511287;
    const S1: f64 = 0.38268343236509;
    const C2: f64 = 0.707106781186548;
    const S2: f64 = 0.707106781186547;
    [
        (1.0, 0.0),
        (C1, S1),
        (C2, S2),
        (S1, C1),
        (0.0, 1.0),
        (-S1, C1),
        (-S2, C2),
        (-C1, S1),
        (-1.0, 0.0),
        (-C1, -S1),
        (-C2, -S2),
        (-S1, -C1),
        (0.0, -1.0),
        (S1, -C1),
        (S2, -C2),
        (C1, -S1),
    ]
};

/// Scratch buffers of the clipping, reused per thread (no allocation once grown).
#[derive(Default)]
struct Scratch {
    face1: Vec<Vec3>,
    face2: Vec<Vec3>,
    poly: Vec<Vec3>,
    clip: super::polygon_clip::ClipScratch,
    normals1: Vec<(Vec3, u32)>,
    normals2: Vec<(Vec3, u32)>,
    feature1: Vec<u32>,
    feature2: Vec<u32>,
    tmp: Vec<u32>,
    faces: Vec<u32>,
    epa: super::epa_face::FaceScratch,
    edges: Vec<(Vec3, Vec3)>,
}

thread_local! {
    static SCRATCH: RefCell<Scratch> = RefCell::new(Scratch::default());
}

/// A polytope geom: a box (half-extents) or a mesh's hull.
pub(crate) enum Poly<'a> {
    Cuboid(Vec3),
    Hull(&'a super::hull_support::HullSupport),
}

impl<'a> Poly<'a> {
    fn of(shape: &'a ConvexShape) -> Option<Self> {
        match shape {
            ConvexShape::Cuboid(c) => {
                let h = c.half_extents;
                Some(Poly::Cuboid(Vec3::new(h.x, h.y, h.z)))
            }
            ConvexShape::Hull(s) => Some(Poly::Hull(s)),
            _ => None,
        }
    }

    /// The number of vertices.
    pub(crate) fn nvert(&self) -> usize {
        match self {
            Poly::Cuboid(_) => 8,
            Poly::Hull(s) => s.points().len(),
        }
    }

    /// Whether the geom has face polygons (a box always; a hull unless MuJoCo's polygon merge
    /// left none).
    pub(crate) fn has_faces(&self) -> bool {
        match self {
            Poly::Cuboid(_) => true,
            Poly::Hull(s) => s.graph().npoly() > 0,
        }
    }

    /// Vertex `i` in the geom frame (box corner i: bit 0 +x, bit 1 +y, bit 2 +z).
    pub(crate) fn vertex(&self, i: u32) -> Vec3 {
        match self {
            Poly::Cuboid(h) => Vec3::new(
                if i & 1 != 0 { h.x } else { -h.x },
                if i & 2 != 0 { h.y } else { -h.y },
                if i & 4 != 0 { h.z } else { -h.z },
            ),
            Poly::Hull(s) => {
                let v: Vector = s.points()[i as usize];
                Vec3::new(v.x, v.y, v.z)
            }
        }
    }

    /// Outward normal of face `f` in the geom frame (box face 2a: +axis a, 2a+1: −axis a).
    fn face_normal(&self, f: u32) -> Vec3 {
        match self {
            Poly::Cuboid(_) => {
                let mut n = Vec3::zeros();
                n[(f / 2) as usize] = if f.is_multiple_of(2) { 1.0 } else { -1.0 };
                n
            }
            Poly::Hull(s) => s.graph().poly_normal[f as usize],
        }
    }

    /// The vertices of face `f`, clockwise seen from outside (MuJoCo's order: its box faces
    /// corner for corner, a mesh polygon reversed), into `out`.
    fn face_vertices(&self, f: u32, out: &mut Vec<u32>) {
        out.clear();
        match self {
            Poly::Cuboid(_) => {
                const BOX_FACES: [[u32; 4]; 6] =
                    [[7, 3, 1, 5], [2, 6, 4, 0], [2, 3, 7, 6], [4, 5, 1, 0], [6, 7, 5, 4], [3, 2, 0, 1]];
                out.extend_from_slice(&BOX_FACES[f as usize]);
            }
            // MuJoCo's polygon (`mesh_polyvert`, counter-clockwise) read backwards (`meshFace`).
            Poly::Hull(s) => out.extend(s.graph().polygon(f as usize).iter().rev()),
        }
    }

    /// Whether face `f` holds vertex `v` (a hull's from the vertex's ascending polygon list,
    /// MuJoCo's `mesh_polymap`, without forming the face).
    fn face_has(&self, f: u32, v: u32) -> bool {
        match self {
            Poly::Hull(s) => s.graph().vertex_polygons(v as usize).binary_search(&f).is_ok(),
            // Box face 2a (+axis a) holds the corners with bit a set, face 2a + 1 the others.
            Poly::Cuboid(_) => ((v >> (f / 2)) & 1 == 1) == f.is_multiple_of(2),
        }
    }
}

/// The vertices of `poly` (at pose `x`) within `tol` of its support plane along world `dir`, in
/// ascending order. A hull's are found from its support vertex (hill climbing) by walking its
/// edges through the vertices within `tol`: the vertices of a convex polytope on one side of a
/// plane are connected along its edges (from any of them a neighbour farther along `dir` leads to
/// the support vertex), so the walk finds all of them without visiting the others.
fn support_feature(poly: &Poly, x: &Transform, dir: &Vec3, tol: f64, out: &mut Vec<u32>) {
    out.clear();
    let local = x.rot.transpose() * dir;
    if let Poly::Hull(support) = poly {
        let top = support.support_index(Vector::new(local.x, local.y, local.z)) as u32;
        let threshold = poly.vertex(top).dot(&local) - tol;
        out.push(top);
        let mut k = 0;
        while k < out.len() {
            let v = out[k] as usize;
            k += 1;
            for &j in support.neighbours(v) {
                if poly.vertex(j).dot(&local) >= threshold && !out.contains(&j) {
                    out.push(j);
                }
            }
        }
        out.sort_unstable();
        return;
    }
    let mut best = f64::NEG_INFINITY;
    for i in 0..poly.nvert() as u32 {
        best = best.max(poly.vertex(i).dot(&local));
    }
    for i in 0..poly.nvert() as u32 {
        if poly.vertex(i).dot(&local) >= best - tol {
            out.push(i);
        }
    }
}

/// The faces around vertex `v`, in ascending order, into `out` (a box's three by scanning its six).
fn vertex_faces(poly: &Poly, v: u32, out: &mut Vec<u32>) {
    out.clear();
    match poly {
        // MuJoCo's `mesh_polymap`: ascending polygon indices.
        Poly::Hull(s) => out.extend_from_slice(s.graph().vertex_polygons(v as usize)),
        Poly::Cuboid(_) => {
            for f in 0..6 {
                if poly.face_has(f, v) {
                    out.push(f);
                }
            }
        }
    }
}

/// The faces holding every vertex of `feature` (one face, the one most along `dir`, when the
/// feature has three or more vertices), with their world normals.
fn feature_faces(
    poly: &Poly,
    x: &Transform,
    feature: &[u32],
    dir: &Vec3,
    faces: &mut Vec<u32>,
    out: &mut Vec<(Vec3, u32)>,
) {
    out.clear();
    let Some(&v0) = feature.first() else { return };
    vertex_faces(poly, v0, faces);
    for &f in faces.iter() {
        if feature.iter().skip(1).take(2).all(|&v| poly.face_has(f, v)) {
            out.push((x.rot * poly.face_normal(f), f));
        }
    }
    if feature.len() >= 3 && out.len() > 1 {
        let best = out.iter().copied().max_by(|a, b| a.0.dot(dir).total_cmp(&b.0.dot(dir)));
        out.clear();
        out.extend(best);
    }
}

/// The world polygon of face `f` (clockwise seen from outside) into `out`.
fn face_polygon(poly: &Poly, x: &Transform, f: u32, tmp: &mut Vec<u32>, out: &mut Vec<Vec3>) {
    out.clear();
    match poly {
        // A hull's polygon read backwards straight into world points (no index list first).
        Poly::Hull(s) => {
            let points = s.points();
            out.extend(s.graph().polygon(f as usize).iter().rev().map(|&v| {
                let p = points[v as usize];
                x.act_point(&Vec3::new(p.x, p.y, p.z))
            }));
        }
        Poly::Cuboid(_) => {
            poly.face_vertices(f, tmp);
            out.extend(tmp.iter().map(|&v| x.act_point(&poly.vertex(v))));
        }
    }
}

/// The edges of a feature of one or two vertices as (start, end) world points: the edge itself,
/// or every edge from the vertex (along the faces around it).
fn feature_edges(
    poly: &Poly,
    x: &Transform,
    feature: &[u32],
    tmp: &mut Vec<u32>,
    faces: &mut Vec<u32>,
    out: &mut Vec<Vec3>,
) {
    out.clear();
    let v0 = feature[0];
    let p0 = x.act_point(&poly.vertex(v0));
    if feature.len() == 2 {
        out.push(p0);
        out.push(x.act_point(&poly.vertex(feature[1])));
        return;
    }
    vertex_faces(poly, v0, faces);
    for &f in faces.iter() {
        poly.face_vertices(f, tmp);
        if let Some(k) = tmp.iter().position(|&v| v == v0) {
            // MuJoCo's: the polygon's previous vertex in its own (counter-clockwise) order.
            let prev = tmp[(k + 1) % tmp.len()];
            out.push(p0);
            out.push(x.act_point(&poly.vertex(prev)));
        }
    }
}

/// The contacts of two polytopes (boxes, mesh hulls) from the penetrating point `first`, by
/// MuJoCo's face and edge clipping (module documentation): the features from EPA's final face
/// `face` when the point is EPA's (`collision/epa_face.rs`), else from the support planes along its
/// normal (`support_plane_features`); `emit` receives each (the single `first` when no faces
/// or edges line up). Returns the number emitted.
#[allow(clippy::too_many_arguments)]
pub(crate) fn polytope_contacts(
    x1: &Transform,
    s1: &ConvexShape,
    x2: &Transform,
    s2: &ConvexShape,
    first: PairPoint,
    face: Option<&EpaFace>,
    margin: f64,
    emit: &mut impl FnMut(PairPoint),
) -> usize {
    let (Some(p1), Some(p2)) = (Poly::of(s1), Poly::of(s2)) else {
        emit(first);
        return 1;
    };
    SCRATCH.with(|s| {
        let s = &mut *s.borrow_mut();
        let chosen = match face {
            Some(f) => {
                super::epa_face::aligned_features(&p1, x1, &p2, x2, f, &first.p1, &first.p2, &mut s.epa)
            }
            None => support_plane_features(&p1, x1, &p2, x2, &first, s),
        };
        let mut count = 0;
        // The normal is the clipped face's reversed (face–face), the face's (an edge of geom 2)
        // or the face's reversed (an edge of geom 1): the direction from w1 to w2 of a penetrating
        // point, kept for the points within the margin above the face.
        let mut out = |w1: Vec3, w2: Vec3, dist: f64, swap: bool, normal: Vec3| {
            let (w1, w2) = if swap { (w2, w1) } else { (w1, w2) };
            emit(PairPoint { p1: w1, p2: w2, normal, dist });
            count += 1;
        };
        let mut tmp = std::mem::take(&mut s.tmp);
        match chosen {
            Some((Feature::Face { index: f1, normal: n1 }, Feature::Face { index: f2, normal: n2 })) => {
                face_polygon(&p1, x1, f1, &mut tmp, &mut s.face1);
                face_polygon(&p2, x2, f2, &mut tmp, &mut s.face2);
                clip(
                    &s.face1,
                    &s.face2,
                    &n1,
                    &n2,
                    margin,
                    false,
                    &mut s.poly,
                    &mut s.clip,
                    &mut |w1, w2, d| out(w1, w2, d, false, -n2),
                );
            }
            // An edge of geom 1 against a face of geom 2.
            Some((Feature::Edge(edge), Feature::Face { index: f2, normal: n2 })) => {
                face_polygon(&p2, x2, f2, &mut tmp, &mut s.face2);
                clip(
                    &s.face2,
                    &edge,
                    &n2,
                    &-n2,
                    margin,
                    false,
                    &mut s.poly,
                    &mut s.clip,
                    &mut |w1, w2, d| out(w1, w2, d, true, -n2),
                );
            }
            // An edge of geom 2 against a face of geom 1.
            Some((Feature::Face { index: f1, normal: n1 }, Feature::Edge(edge))) => {
                face_polygon(&p1, x1, f1, &mut tmp, &mut s.face1);
                clip(
                    &s.face1,
                    &edge,
                    &n1,
                    &-n1,
                    margin,
                    false,
                    &mut s.poly,
                    &mut s.clip,
                    &mut |w1, w2, d| out(w1, w2, d, false, n1),
                );
            }
            Some((Feature::Edge(_), Feature::Edge(_))) | None => {}
        }
        s.tmp = tmp;
        if count == 0 {
            emit(first);
            count = 1;
        }
        count
    })
}

/// The features to clip when no EPA face is at hand (a pair with a margin, whose first point is
/// parry's): the vertices of each geom within a small tolerance of its support plane along the
/// normal of `first`, their faces and edges; the most nearly opposite face pair, else the edge of
/// the lower-dimensional feature most nearly parallel to a face of the other.
fn support_plane_features(
    p1: &Poly,
    x1: &Transform,
    p2: &Poly,
    x2: &Transform,
    first: &PairPoint,
    s: &mut Scratch,
) -> Option<(Feature, Feature)> {
    let n = first.normal;
    let scale = (x1.pos - x2.pos).norm().max(first.dist.abs()).max(1e-3);
    let tol = 1e-9 * scale;
    support_feature(p1, x1, &n, tol, &mut s.feature1);
    support_feature(p2, x2, &-n, tol, &mut s.feature2);
    feature_faces(p1, x1, &s.feature1, &n, &mut s.faces, &mut s.normals1);
    feature_faces(p2, x2, &s.feature2, &-n, &mut s.faces, &mut s.normals2);
    let (dim1, dim2) = (s.feature1.len().min(3), s.feature2.len().min(3));
    let face_of = |(normal, index): (Vec3, u32)| Feature::Face { index, normal };
    // The most nearly opposite face pair within the tolerance.
    let mut aligned: Option<(f64, usize, usize)> = None;
    for (i, (a, _)) in s.normals1.iter().enumerate() {
        for (j, (b, _)) in s.normals2.iter().enumerate() {
            let c = a.dot(b);
            if c < -FACE_TOL && aligned.is_none_or(|(best, ..)| c < best) {
                aligned = Some((c, i, j));
            }
        }
    }
    if let Some((_, i, j)) = aligned {
        return Some((face_of(s.normals1[i]), face_of(s.normals2[j])));
    }
    if dim1 < 3 && dim1 <= dim2 {
        feature_edges(p1, x1, &s.feature1, &mut s.tmp, &mut s.faces, &mut s.face1);
        let (e, j) = edge_face(&s.face1, &s.normals2)?;
        Some((Feature::Edge([s.face1[2 * e], s.face1[2 * e + 1]]), face_of(s.normals2[j])))
    } else if dim2 < 3 {
        feature_edges(p2, x2, &s.feature2, &mut s.tmp, &mut s.faces, &mut s.face2);
        let (e, i) = edge_face(&s.face2, &s.normals1)?;
        Some((face_of(s.normals1[i]), Feature::Edge([s.face2[2 * e], s.face2[2 * e + 1]])))
    } else {
        None
    }
}

/// The edge (index into `edges`' pairs) most nearly parallel to one of the faces (index into
/// `faces`), within [`EDGE_TOL`].
fn edge_face(edges: &[Vec3], faces: &[(Vec3, u32)]) -> Option<(usize, usize)> {
    let mut best: Option<(f64, usize, usize)> = None;
    for (j, (n, _)) in faces.iter().enumerate() {
        for e in 0..edges.len() / 2 {
            let d = (edges[2 * e + 1] - edges[2 * e]).normalize();
            let c = d.dot(n).abs();
            if c < EDGE_TOL && best.is_none_or(|(b, ..)| c < b) {
                best = Some((c, e, j));
            }
        }
    }
    best.map(|(_, e, j)| (e, j))
}

/// Geom 1's segment (`s.face1`) clipped against geom 2's face polygon (`s.face2`, outward normal
/// `n2`), each clipped point emitted as a contact with normal −`n2` (geom 2's point moved out by
/// `inflated`, the margin share a core was shrunk by, and the depth with it); how many.
fn clip_segment_on_face(
    s: &mut Scratch,
    n2: &Vec3,
    margin: f64,
    inflated: f64,
    emit: &mut impl FnMut(PairPoint),
) -> usize {
    let mut count = 0;
    let n2 = *n2;
    clip(
        &s.face2,
        &s.face1,
        &n2,
        &-n2,
        margin - inflated,
        false,
        &mut s.poly,
        &mut s.clip,
        &mut |w1, w2, d| {
            let p2 = if inflated != 0.0 { w1 + n2 * inflated } else { w1 };
            emit(PairPoint { p1: w2, p2, normal: -n2, dist: d + inflated });
            count += 1;
        },
    );
    count
}

/// Clips polygon (or edge) `clipped_in` by face polygon `face` (outward normal `n`, vertices
/// clockwise about it), keeps the points not above the face's plane and reports each as
/// witness points (on `face`'s plane along `wit_dir`, on `clipped_in`) and signed distance below
/// the face: MuJoCo's `polygonClip`, with its pruning of more than 4 points to a quadrilateral
/// and of an edge to its two farthest points. The quadrilateral is MuJoCo 4.0's (the clipped
/// polygon's first point fixed, [`super::plane_mesh::quad_from_first`]: measured black-box on 40
/// box–prism faces, 38 the same points in the same order, the 2 others misread by the
/// measurement); with `cap` (a cylinder's cap clipping a face) the live
/// MuJoCo 4.0.0's own rule ([`cap_quad`]).
#[allow(clippy::too_many_arguments)]
fn clip(
    face: &[Vec3],
    clipped_in: &[Vec3],
    n: &Vec3,
    wit_dir: &Vec3,
    margin: f64,
    cap: bool,
    poly: &mut Vec<Vec3>,
    scratch: &mut super::polygon_clip::ClipScratch,
    out: &mut impl FnMut(Vec3, Vec3, f64),
) {
    if face.len() < 3 {
        return;
    }
    poly.clear();
    poly.extend_from_slice(clipped_in);
    super::polygon_clip::clip_by_face_sides(face, n, poly, scratch);
    poly.retain(|p| (p - face[0]).dot(n) <= margin);
    if poly.is_empty() {
        return;
    }
    // MuJoCo 4.0: the point on the face's plane (along its normal) and, from it, one against
    // `wit_dir` by the signed distance (the snapshot of MuJoCo's source kept the clipped vertex itself;
    // the live 4.0.0 contacts show this form).
    // The distance is the one below the face scaled by the cosine between the face's normal and
    // `wit_dir` (the live contacts again).
    let witness = |v: &Vec3| {
        let d = (v - face[0]).dot(n);
        let w1 = v - n * d;
        let dist = -d * n.dot(wit_dir);
        (w1, w1 - wit_dir * dist, dist)
    };
    let mut report = |v: &Vec3| {
        let (w1, w2, d) = witness(v);
        out(w1, w2, d);
    };
    if poly.len() > 4 {
        let q =
            if cap { cap_quad(poly) } else { super::plane_mesh::quad_from_first(poly.len(), |i| poly[i]) };
        for i in q {
            report(&poly[i]);
        }
        return;
    }
    if clipped_in.len() == 2 && poly.len() > 2 {
        let (mut b1, mut b2, mut d) = (0, 1, 0.0);
        for i in 0..poly.len() {
            for j in i + 1..poly.len() {
                let d2 = (poly[j] - poly[i]).norm_squared();
                if d2 > d {
                    (b1, b2, d) = (i, j, d2);
                }
            }
        }
        report(&poly[b1]);
        report(&poly[b2]);
        return;
    }
    for v in poly.iter() {
        report(v);
    }
}

/// Area of the quadrilateral abcd (half the norm of its diagonals' cross product).
fn area4d(a: &Vec3, b: &Vec3, c: &Vec3, d: &Vec3) -> f64 {
    0.5 * (a - c).cross(&(b - d)).norm()
}

/// Four vertices of a cylinder cap's clipped polygon (more than four) enclosing a large area, as
/// the live MuJoCo 4.0.0's `polygonClip` picks them (read from its machine code; Warp 4.0.0's
/// `_polygon_quad` is the same): from (0, 1, 2, 3), for each first vertex a in turn, the fourth
/// advances while the area grows, and after each advance the third, then the second, advance
/// while it grows; the second (third, fourth) steps off a when they coincide.
fn cap_quad(p: &[Vec3]) -> [usize; 4] {
    let n = p.len();
    let area = |a: usize, b: usize, c: usize, d: usize| area4d(&p[a], &p[b], &p[c], &p[d]);
    let (mut b, mut c, mut d) = (1, 2, 3);
    let mut res = [0, b, c, d];
    let mut m = area(0, b, c, d);
    for a in 0..n {
        loop {
            let next = area(a, b, c, (d + 1) % n);
            if next <= m {
                break;
            }
            m = next;
            d = (d + 1) % n;
            res = [a, b, c, d];
            loop {
                let next = area(a, b, (c + 1) % n, d);
                if next <= m {
                    break;
                }
                m = next;
                c = (c + 1) % n;
                res = [a, b, c, d];
            }
            loop {
                let next = area(a, (b + 1) % n, c, d);
                if next <= m {
                    break;
                }
                m = next;
                b = (b + 1) % n;
                res = [a, b, c, d];
            }
        }
        if b == a {
            b = (b + 1) % n;
            if c == b {
                c = (c + 1) % n;
                if d == c {
                    d = (d + 1) % n;
                }
            }
        }
    }
    res
}

/// The contacts of a convex pair from GJK/EPA's first point `first` (penetrating or within the
/// margin + gap), as MuJoCo 4.0 gives them with `multiccd` on (the caller asks only for pairs
/// whose contact limit exceeds one; module documentation): polytopes by face and edge clipping
/// ([`polytope_contacts`]), a capsule or a cylinder's side against a polytope face by segment
/// clipping, a cylinder's cap against a polytope face as a 16-gon; `first` alone otherwise.
#[allow(clippy::too_many_arguments)]
pub(crate) fn convex_contacts(
    x1: &Transform,
    s1: &ConvexShape,
    x2: &Transform,
    s2: &ConvexShape,
    first: PairPoint,
    face: Option<&EpaFace>,
    margin_gap: f64,
    emit: &mut impl FnMut(PairPoint),
) {
    let polytopes = Poly::of(s1).is_some() && Poly::of(s2).is_some();
    if polytopes {
        if first.dist < margin_gap {
            polytope_contacts(x1, s1, x2, s2, first, face, margin_gap, emit);
        } else {
            emit(first);
        }
        return;
    }
    match (s1, Poly::of(s2)) {
        (ConvexShape::Capsule(c), Some(p2)) => {
            // MuJoCo 4.0.0: the capsule's surface line through its witness point, parallel to
            // the axis, as long as the segment; already inflated by half the margin.
            let axis = x1.rot.column(2).into_owned();
            let w = first.p1;
            let pr = (w - x1.pos).dot(&axis);
            let len = c.segment.b.z;
            let seg = [w + axis * (-pr - len), w + axis * (-pr + len)];
            segment_polytope(x1, seg, 0.5 * margin_gap, x2, &p2, first, face, margin_gap, emit);
        }
        (ConvexShape::Cylinder(c), Some(p2)) => {
            // The side's line at the contact when the axis is within ~5.1° of the contact plane;
            // the cap as a 16-gon when it is within ~5.1° of the normal; else one contact.
            let axis = x1.rot.column(2).into_owned();
            let along = axis.dot(&first.normal);
            if along.abs() < EDGE_TOL {
                // MuJoCo 4.0.0: the side line through the support point of EPA's face's first
                // vertex on the cylinder (on a rim; moved back onto it from the margin), to the
                // other cap.
                let seg = match face {
                    Some(f) => cylinder_side(x1, c, f, margin_gap),
                    None => {
                        let radial = (first.normal - axis * along).normalize();
                        let centre = x1.pos + radial * c.radius;
                        let h = axis * c.half_height;
                        [centre - h, centre + h]
                    }
                };
                segment_polytope(x1, seg, 0.0, x2, &p2, first, face, margin_gap, emit);
            } else if along.abs() > FACE_TOL {
                cap_polytope(x1, c, along.signum(), x2, &p2, first, face, margin_gap, emit);
            } else if cap_features(x1, c, x2, &p2, &first, face, margin_gap, false, emit) == 0 {
                emit(first);
            }
        }
        // Capsule–cylinder, cylinder–cylinder: geom 1's edge against geom 2's cap.
        (ConvexShape::Capsule(_) | ConvexShape::Cylinder(_), None) => match s2 {
            ConvexShape::Cylinder(c2) if edge_cap(x1, s1, x2, c2, &first, face, margin_gap, emit) > 0 => {}
            _ => emit(first),
        },
        _ => emit(first),
    }
}

/// A capsule's or a cylinder's edge (geom 1) against a cylinder's cap (geom 2), as MuJoCo 4.0.0's
/// `multicontact` takes it (Warp 4.0.0's `_cylinder_normals`, `_cylinder_face`, and the live
/// contacts): when geom 2's feature on EPA's final face (or GJK's simplex) is one cap, geom 1's
/// edge (a capsule's surface line through its witness point; a cylinder's side line through the
/// support point of the face's first vertex) within ~5.1° of parallel to that cap is clipped by
/// the cap's 16-gon. Returns the number of contacts emitted (0: none, the caller keeps `first`);
/// two caps facing each other are left to `first`.
#[allow(clippy::too_many_arguments)]
fn edge_cap(
    x1: &Transform,
    s1: &ConvexShape,
    x2: &Transform,
    c2: &parry3d_f64::shape::Cylinder,
    first: &PairPoint,
    face: Option<&EpaFace>,
    margin: f64,
    emit: &mut impl FnMut(PairPoint),
) -> usize {
    let Some(f) = face else { return 0 };
    let idx = f.index2[0];
    if idx < 0 || f.index2.iter().any(|&i| i != idx) {
        return 0;
    }
    let z2 = x2.rot.column(2).into_owned();
    let n2 = if idx != 0 { -z2 } else { z2 };
    let axis = x1.rot.column(2).into_owned();
    let (seg, inflated) = match s1 {
        ConvexShape::Capsule(c) => {
            let w = first.p1;
            let pr = (w - x1.pos).dot(&axis);
            let len = c.segment.b.z;
            ([w + axis * (-pr - len), w + axis * (-pr + len)], 0.5 * margin)
        }
        ConvexShape::Cylinder(c) => {
            // Geom 1's own cap facing geom 2's: MuJoCo clips the two caps (not here).
            let i1 = f.index1[0];
            if f.index1.iter().all(|&i| i == i1) {
                let n1 = if i1 != 0 { -axis } else { axis };
                if n1.dot(&n2) < -FACE_TOL {
                    return 0;
                }
            }
            (cylinder_side(x1, c, f, margin), 0.0)
        }
        _ => return 0,
    };
    let d = (seg[1] - seg[0]).normalize();
    if d.dot(&n2).abs() >= EDGE_TOL {
        return 0;
    }
    SCRATCH.with(|s| {
        let s = &mut *s.borrow_mut();
        let sgn = if idx != 0 { -1.0 } else { 1.0 };
        let centre = z2 * (sgn * c2.half_height) + x2.pos;
        let (e1, e2) = (x2.rot.column(0).into_owned(), x2.rot.column(1).into_owned());
        let (col0, col1) = (e1 * c2.radius, e2 * (c2.radius * sgn));
        s.face2.clear();
        for (c, sn) in CAP_COS_SIN {
            s.face2.push(col0 * c - col1 * sn + centre);
        }
        s.face1.clear();
        s.face1.extend_from_slice(&seg);
        clip_segment_on_face(s, &n2, margin, inflated, emit)
    })
}

/// A cylinder's side line (geom 1) as MuJoCo 4.0.0's `multicontact` takes it: through the
/// support point of EPA's face's first vertex on the cylinder (on a rim; moved back onto it from
/// the margin), to the other cap.
fn cylinder_side(x1: &Transform, c: &parry3d_f64::shape::Cylinder, f: &EpaFace, margin: f64) -> [Vec3; 2] {
    let axis = x1.rot.column(2).into_owned();
    let mut v = f.vert1[0];
    let up = (v - x1.pos).dot(&axis) < 0.0;
    let sgn = if up { 1.0 } else { -1.0 };
    if margin > 0.0 {
        let d = v - x1.pos;
        let (l0, l1) = (x1.rot.column(0).dot(&d), x1.rot.column(1).dot(&d));
        let n2 = l0 * l0 + l1 * l1;
        let scl = if n2 >= 1e-30 { c.radius / n2.sqrt() } else { 0.0 };
        v = x1.rot * Vec3::new(scl * l0, scl * l1, -sgn * c.half_height) + x1.pos;
    }
    [v, v + axis * (sgn * 2.0 * c.half_height)]
}

/// A cylinder's cap (geom 1; `side` +1 the top, −1 the bottom) against a box or mesh hull: the
/// cap as MuJoCo 4.0's regular 16-gon (vertex k at k·22.5° about the cylinder's x axis, on the
/// rim, clockwise seen from outside the cap: MuJoCo Warp 4.0.0's `_cylinder_face`; its source
/// snapshot turned the geoms instead) clipping the polytope's face opposite it like two polytope
/// faces. With it the first contact of all 8 golden resting poses is MuJoCo's (the octagon at
/// 22.5° + k·45° used before could not give MuJoCo's points at 0°, 45°, 90°…). `first` alone
/// when no face is opposite.
#[allow(clippy::too_many_arguments)]
fn cap_polytope(
    x1: &Transform,
    c: &parry3d_f64::shape::Cylinder,
    side: f64,
    x2: &Transform,
    p2: &Poly,
    first: PairPoint,
    face: Option<&EpaFace>,
    margin: f64,
    emit: &mut impl FnMut(PairPoint),
) {
    let (r, h) = (c.radius, c.half_height);
    let axis = x1.rot.column(2).into_owned();
    let (e1, e2) = (x1.rot.column(0).into_owned(), x1.rot.column(1).into_owned());
    let n1 = axis * side;
    let centre = x1.pos + n1 * h;
    let n = first.normal;
    let emitted = SCRATCH.with(|s| {
        let s = &mut *s.borrow_mut();
        let mut tmp = std::mem::take(&mut s.tmp);
        let scale = (x1.pos - x2.pos).norm().max(first.dist.abs()).max(1e-3);
        support_feature(p2, x2, &-n, 1e-9 * scale, &mut s.feature2);
        feature_faces(p2, x2, &s.feature2, &-n, &mut s.faces, &mut s.normals2);
        let opposite = s
            .normals2
            .iter()
            .copied()
            .filter(|(m, _)| m.dot(&n1) < -FACE_TOL)
            .min_by(|a, b| a.0.dot(&n1).total_cmp(&b.0.dot(&n1)));
        let mut count = 0;
        if let Some((n2, f2)) = opposite {
            // Clockwise seen from outside the cap.
            s.face1.clear();
            let (col0, col1) = (e1 * r, e2 * (r * side));
            for (c, sn) in CAP_COS_SIN {
                s.face1.push(col0 * c - col1 * sn + centre);
            }
            face_polygon(p2, x2, f2, &mut tmp, &mut s.face2);
            clip(&s.face1, &s.face2, &n1, &n2, margin, true, &mut s.poly, &mut s.clip, &mut |w1, w2, d| {
                emit(PairPoint { p1: w1, p2: w2, normal: -n2, dist: d });
                count += 1;
            });
        }
        s.tmp = tmp;
        count
    });
    if emitted == 0 && cap_features(x1, c, x2, p2, &first, face, margin, true, emit) == 0 {
        emit(first);
    }
}

/// The cap (16-gon) of a cylinder (geom 1) against a polytope's edge, as MuJoCo 4.0.0's
/// `multicontact` reads the features off EPA's final face (Warp 4.0.0's `multicontact`, and the
/// live library's contacts): when the cylinder's feature is one cap (every face vertex's support
/// marks the same cap), the cylinder's side line is tried first against the polytope's feature's
/// faces (the first within ~5.1° of parallel: clipped by it, nothing else tried), then the first
/// of the polytope's feature edges (an edge, or a vertex's edges) within ~5.1° of parallel to
/// the cap is clipped by the cap's 16-gon (points on the cap's plane and along its normal, the
/// contact normal the cap's). With `skip_opposite`
/// the cap against an opposite face was tried already; else such a face is clipped by the cap.
/// Returns the number of contacts emitted (0: none).
#[allow(clippy::too_many_arguments)]
fn cap_features(
    x1: &Transform,
    c: &parry3d_f64::shape::Cylinder,
    x2: &Transform,
    p2: &Poly,
    first: &PairPoint,
    face: Option<&EpaFace>,
    margin: f64,
    skip_opposite: bool,
    emit: &mut impl FnMut(PairPoint),
) -> usize {
    let Some(f) = face else { return 0 };
    let idx = f.index1[0];
    if idx < 0 || f.index1.iter().any(|&i| i != idx) {
        return 0;
    }
    let side = if idx != 0 { -1.0 } else { 1.0 };
    let axis = x1.rot.column(2).into_owned();
    let n1 = axis * side;
    SCRATCH.with(|s| {
        let s = &mut *s.borrow_mut();
        let mut start = Vec3::zeros();
        let mut edges = std::mem::take(&mut s.edges);
        let dim2 = super::epa_face::geom2_feature(
            p2,
            x2,
            f,
            &(first.p2 - first.p1),
            &mut s.normals2,
            Some((&mut edges, &mut start)),
        );
        let mut count = 0;
        let mut tmp = std::mem::take(&mut s.tmp);
        let cap = |s: &mut Scratch| {
            s.face1.clear();
            let centre = x1.pos + n1 * c.half_height;
            let (col0, col1) = (x1.rot.column(0) * c.radius, x1.rot.column(1) * (c.radius * side));
            for (cs, sn) in CAP_COS_SIN {
                s.face1.push(col0 * cs - col1 * sn + centre);
            }
        };
        if dim2 > 0 {
            let opposite = s
                .normals2
                .iter()
                .copied()
                .filter(|(m, _)| !skip_opposite && m.dot(&n1) < -FACE_TOL)
                .min_by(|a, b| a.0.dot(&n1).total_cmp(&b.0.dot(&n1)));
            if let Some((n2, f2)) = opposite {
                cap(s);
                face_polygon(p2, x2, f2, &mut tmp, &mut s.face2);
                clip(
                    &s.face1,
                    &s.face2,
                    &n1,
                    &n2,
                    margin,
                    true,
                    &mut s.poly,
                    &mut s.clip,
                    &mut |w1, w2, d| {
                        emit(PairPoint { p1: w1, p2: w2, normal: -n2, dist: d });
                        count += 1;
                    },
                );
            } else {
                // The side line against the polytope's faces ...
                let seg = cylinder_side(x1, c, f, margin);
                let d = (seg[1] - seg[0]).normalize();
                let parallel = s.normals2.iter().find(|(m, _)| d.dot(m).abs() < EDGE_TOL).copied();
                if let Some((n2, f2)) = parallel {
                    // A clip that keeps no point leaves the single contact (no edge tried: drop
                    // scene d2_13).
                    s.face1.clear();
                    s.face1.extend_from_slice(&seg);
                    face_polygon(p2, x2, f2, &mut tmp, &mut s.face2);
                    count = clip_segment_on_face(s, &n2, margin, 0.0, emit);
                } else if let Some(&(_, end)) = edges.iter().find(|(e, _)| e.dot(&n1).abs() < EDGE_TOL) {
                    // ... then the polytope's edges against the cap.
                    cap(s);
                    let edge = [start, end];
                    clip(
                        &s.face1,
                        &edge,
                        &n1,
                        &-n1,
                        margin,
                        false,
                        &mut s.poly,
                        &mut s.clip,
                        &mut |w1, w2, d| {
                            emit(PairPoint { p1: w1, p2: w2, normal: n1, dist: d });
                            count += 1;
                        },
                    );
                }
            }
        }
        s.tmp = tmp;
        s.edges = edges;
        count
    })
}

/// A segment of geom 1 (a capsule's surface line, inflated by `inflated` = half the margin; a
/// cylinder's side line, `inflated` 0) against a box or mesh hull from the first contact `first`,
/// as MuJoCo 4.0.0 gives it (its `multicontact`'s edge–face case, read from Warp 4.0.0 and the
/// live contacts): when the segment lies within ~5.1° of parallel to a face of the polytope at
/// the contact, the segment clipped by that face's sides, each point within `margin` (less
/// `inflated`) above the face a contact — witness on the segment and on the face's plane (moved
/// out by `inflated`), normal the face's reversed (the two farthest when more). Otherwise
/// `first` alone.
#[allow(clippy::too_many_arguments)]
fn segment_polytope(
    x1: &Transform,
    seg: [Vec3; 2],
    inflated: f64,
    x2: &Transform,
    p2: &Poly,
    first: PairPoint,
    face: Option<&EpaFace>,
    margin: f64,
    emit: &mut impl FnMut(PairPoint),
) {
    let n = first.normal;
    let emitted = SCRATCH.with(|s| {
        let s = &mut *s.borrow_mut();
        let mut tmp = std::mem::take(&mut s.tmp);
        s.face1.clear();
        s.face1.extend_from_slice(&seg);
        // MuJoCo 4.0.0: the faces of geom 2's feature on EPA's final face, the first (in their
        // order) within ~5.1° of parallel to the segment; without a face, the faces at geom 2's
        // support plane, the most nearly parallel.
        if let Some(f) = face {
            super::epa_face::geom2_faces(p2, x2, f, &(first.p2 - first.p1), &mut s.normals2);
        } else {
            s.normals2.clear();
        }
        let chosen = if s.normals2.is_empty() {
            let scale = (x1.pos - x2.pos).norm().max(first.dist.abs()).max(1e-3);
            support_feature(p2, x2, &-n, 1e-9 * scale, &mut s.feature2);
            feature_faces(p2, x2, &s.feature2, &-n, &mut s.faces, &mut s.normals2);
            edge_face(&s.face1, &s.normals2)
        } else {
            let d = (seg[1] - seg[0]).normalize();
            s.normals2.iter().position(|(m, _)| d.dot(m).abs() < EDGE_TOL).map(|j| (0, j))
        };
        let mut count = 0;
        if let Some((_, j)) = chosen {
            let (n2, f2) = s.normals2[j];
            face_polygon(p2, x2, f2, &mut tmp, &mut s.face2);
            count = clip_segment_on_face(s, &n2, margin, inflated, emit);
        }
        s.tmp = tmp;
        count
    });
    if emitted == 0 {
        emit(first);
    }
}
