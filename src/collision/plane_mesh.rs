//! Plane against a mesh's convex hull as MuJoCo 4.0 does it (`mjc_PlaneConvex`, the plane row of
//! its collision table): at most four contacts, vertices of the hull face resting on the plane.
//!
//! 1. The hull vertex deepest below the plane (its support point along the plane's −normal,
//!    found by hill climbing on the hull's edges from the vertex farthest along the nearest of 27
//!    grid directions, as [`super::hull_support`]); none when it is farther than the margin.
//! 2. Of the hull's face polygons around that vertex (coplanar triangles merged, as MuJoCo's
//!    compiler merges its qhull facets into `mesh_polyvert` polygons), the one whose outward
//!    normal points most nearly along −normal (the face resting on the plane).
//! 3. That polygon's vertices in its outward (counter-clockwise) order starting at the deepest
//!    vertex; with more than four, a quadrilateral of them: the deepest vertex fixed as the first
//!    corner, the other three advanced along the polygon while the quadrilateral's area grows
//!    (the last corner first, then the third, then the second, repeated while the last one
//!    moves: [`quad_from_first`]). Each vertex after the deepest is kept when closer than the
//!    margin.
//!
//! This is what the live MuJoCo 4.0.0 returns, measured black-box (its 2026-08 source snapshot
//! took up to two edge neighbours of the deepest vertex farther than 0.3 of the bounding radius
//! from it instead): prisms with random 5- to 11-gon faces resting tilted on a plane (60 poses:
//! the same four vertices in the same order at every one, whatever the yaw and the tilt, the set
//! a function of the deepest vertex alone); the Spot, Spot-arm and Barkour feet at every step of
//! 300. The same quadrilateral rule, with the polygon's first vertex fixed, is the one MuJoCo
//! 4.0's multi-point clipping prunes with (40 box–prism faces, see [`super::multiccd`]). Each
//! contact lies midway between the vertex and the plane, with the plane's normal and distance
//! `n·(v − p_plane)`.
//!
//! The hull and its face polygons are MuJoCo's own ([`super::mesh_graph`]: qhull's hull, its
//! facets merged by their normals' rounded angles, in MuJoCo's polygon order and with MuJoCo's
//! starting vertices), so ties between polygons resolve as MuJoCo's do. Where a polygon's
//! quadrilateral areas tie exactly (a regular polygon), the choice is round-off's.

use super::mesh_graph::MeshGraph;
use super::plane::PlanePoint;
use crate::spatial::{Transform, Vec3};
use std::cmp::Ordering;

/// A mesh's convex hull prepared for plane contacts: vertices (geom frame), their neighbours,
/// the hill climb's start vertices and MuJoCo's face polygons (all from its mesh graph).
#[derive(Clone, Debug)]
pub struct PlaneHull {
    vertices: Vec<Vec3>,
    /// Vertex i's neighbours are `adj[adj_start[i]..adj_start[i + 1]]`.
    adj_start: Vec<u32>,
    adj: Vec<u32>,
    extrema: [u32; 27],
    /// Face polygon p's vertices, counter-clockwise about its outward normal, are
    /// `poly[poly_start[p]..poly_start[p + 1]]`.
    poly_start: Vec<u32>,
    poly: Vec<u32>,
    /// Face polygon p's outward unit normal (`mesh_polynormal`).
    poly_normal: Vec<Vec3>,
    /// Vertex i's polygons are `vpolys[vpoly_start[i]..vpoly_start[i + 1]]`.
    vpoly_start: Vec<u32>,
    vpolys: Vec<u32>,
}

impl PlaneHull {
    /// The hull of `graph` (MuJoCo's mesh graph and polygons of a mesh); None when it has no
    /// vertices.
    pub fn new(graph: &MeshGraph) -> Option<Self> {
        let vertices = graph.vertices.clone();
        if vertices.is_empty() {
            return None;
        }
        let mut extrema = [0u32; 27];
        for (k, slot) in extrema.iter_mut().enumerate() {
            let dir = Vec3::new((k / 9) as f64 - 1.0, ((k / 3) % 3) as f64 - 1.0, (k % 3) as f64 - 1.0);
            let mut best = (0, f64::NEG_INFINITY);
            for (i, v) in vertices.iter().enumerate() {
                let d = v.dot(&dir);
                if d > best.1 {
                    best = (i, d);
                }
            }
            *slot = best.0 as u32;
        }
        Some(Self {
            vertices,
            adj_start: graph.adj_start.clone(),
            adj: graph.adj.clone(),
            extrema,
            poly_start: graph.poly_start.clone(),
            poly: graph.poly.clone(),
            poly_normal: graph.poly_normal.clone(),
            vpoly_start: graph.vpoly_start.clone(),
            vpolys: graph.vpolys.clone(),
        })
    }

    /// The hull's vertices (geom frame).
    pub fn vertices(&self) -> &[Vec3] {
        &self.vertices
    }

    /// The index of the vertex farthest along `dir` (geom frame), by hill climbing.
    pub fn support_index(&self, dir: &Vec3) -> usize {
        let cell = |a: f64| (a > 0.4) as usize + 1 - (a < -0.4) as usize;
        let mut best = self.extrema[9 * cell(dir.x) + 3 * cell(dir.y) + cell(dir.z)] as usize;
        let mut best_dot = self.vertices[best].dot(dir);
        loop {
            let current = best;
            let (s, e) = (self.adj_start[current] as usize, self.adj_start[current + 1] as usize);
            for &j in &self.adj[s..e] {
                let dot = self.vertices[j as usize].dot(dir);
                if dot > best_dot {
                    best_dot = dot;
                    best = j as usize;
                }
            }
            if best == current {
                return best;
            }
        }
    }
}

/// The contacts of `hull` (pose `x`) with the plane (pose `plane`, normal its z axis) closer than
/// `reach` (the pair's margin), the deepest vertex and at most three more (see the module documentation). `feature` is the
/// hull vertex index.
pub fn plane_mesh(
    plane: &Transform,
    x: &Transform,
    hull: &PlaneHull,
    reach: f64,
    out: &mut impl FnMut(PlanePoint),
) {
    if hull.vertices.is_empty() {
        return;
    }
    let n = plane.rot.column(2).into_owned();
    // −normal in the geom frame: the direction of the deepest vertex.
    let down = x.rot.transpose() * (-n);
    let first = hull.support_index(&down);
    let point = |i: usize| x.pos + x.rot * hull.vertices[i];
    let p = point(first);
    let dist = n.dot(&(p - plane.pos));
    if dist > reach {
        return;
    }
    out(PlanePoint { surface: p, dist, hint: None, feature: first as u32 });
    // The face polygon around it facing the plane most (its normal nearest −normal).
    let (s, e) = (hull.vpoly_start[first] as usize, hull.vpoly_start[first + 1] as usize);
    let mut face = None;
    let mut facing = f64::INFINITY;
    for &p in &hull.vpolys[s..e] {
        let along = hull.poly_normal[p as usize].dot(&(-down));
        if along < facing {
            facing = along;
            face = Some(p as usize);
        }
    }
    let Some(face) = face else { return };
    let polygon = &hull.poly[hull.poly_start[face] as usize..hull.poly_start[face + 1] as usize];
    let len = polygon.len();
    let k = polygon.iter().position(|&v| v as usize == first).unwrap_or(0);
    let at = |i: usize| hull.vertices[polygon[(k + i) % len] as usize];
    let corners = if len > 4 { quad_from_first(len, at) } else { [0, 1, 2, 3] };
    // MuJoCo's inclusion test: along −normal beyond the geom centre's height less the margin.
    let threshold = n.dot(&(x.pos - plane.pos)) - reach;
    for &c in corners.iter().skip(1).take(len.min(4) - 1) {
        let i = polygon[(k + c) % len] as usize;
        if down.dot(&hull.vertices[i]) > threshold {
            let q = point(i);
            out(PlanePoint { surface: q, dist: n.dot(&(q - plane.pos)), hint: None, feature: i as u32 });
        }
    }
}

/// Four corners (indices into a convex polygon of `len` > 4 vertices, `at(i)` its i-th vertex,
/// increasing) of a large quadrilateral with its first vertex fixed: MuJoCo 4.0's pruning (the
/// last corner advanced while the area grows, after each advance the third and then the second;
/// not always the largest quadrilateral).
///
/// The areas are compared as squared norms of the diagonals' cross product and the square root
/// taken only where the two squares are too close for the order of the roots to be certain
/// (`grows`): the same decisions as comparing the areas, without a square root per candidate
/// (the pass's hot spot on polygons of many vertices, such as a finger pad's face).
pub fn quad_from_first(len: usize, at: impl Fn(usize) -> Vec3) -> [usize; 4] {
    let area2 = |q: [usize; 4]| (at(q[2]) - at(q[0])).cross(&(at(q[3]) - at(q[1]))).norm_squared();
    let mut q = [0, 1, 2, 3];
    let mut m = area2(q);
    while q[3] + 1 < len {
        let next = area2([q[0], q[1], q[2], q[3] + 1]);
        if !grows(next, m) {
            break;
        }
        m = next;
        q[3] += 1;
        while q[2] + 1 < q[3] {
            let next = area2([q[0], q[1], q[2] + 1, q[3]]);
            if !grows(next, m) {
                break;
            }
            m = next;
            q[2] += 1;
        }
        while q[1] + 1 < q[2] {
            let next = area2([q[0], q[1] + 1, q[2], q[3]]);
            if !grows(next, m) {
                break;
            }
            m = next;
            q[1] += 1;
        }
    }
    q
}

/// Whether the area `0.5·√next` exceeds `0.5·√best` (`next`, `best`: squared norms, as
/// [`quad_from_first`] compares its areas), deciding from the squares where that is certain:
/// `next ≤ best` gives a root no larger; `next > best·(1 + 8ε)` (best normal) a root larger by more
/// than the two roots' rounding. In between, and for NaN, the rounded roots themselves decide
/// (a NaN area grows, as `next <= best` is false for it).
#[inline]
fn grows(next: f64, best: f64) -> bool {
    if next <= best {
        return false;
    }
    if best >= f64::MIN_POSITIVE && next > best * (1.0 + 8.0 * f64::EPSILON) {
        return true;
    }
    // As the areas' own test, `next ≤ best` stops and anything else (NaN too) grows.
    !matches!((0.5 * next.sqrt()).partial_cmp(&(0.5 * best.sqrt())), Some(Ordering::Less | Ordering::Equal))
}
