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
//! MuJoCo groups its facets by their normal's azimuth and polar angle rounded to 0.01 rad in the
//! mesh's inertial frame; lagrange merges connected triangles whose normals agree to
//! `COPLANAR`. Flat faces (boxes, prisms, CAD soles) merge alike; facets a few 1e-3 rad apart
//! that share MuJoCo's rounded angles are one polygon there and separate triangles here. Where a
//! polygon's quadrilateral areas tie exactly (a regular polygon), the choice is round-off's.

use super::plane::PlanePoint;

/// Two adjacent hull triangles whose unit normals' dot product exceeds 1 − this lie in one flat
/// face polygon (the mesh's single-precision vertices tilt coplanar triangles by up to ~1e-7).
const COPLANAR: f64 = 1e-6;
use crate::spatial::{Transform, Vec3};
use std::cmp::Ordering;

/// A mesh's convex hull prepared for plane contacts: vertices (geom frame), their neighbours and
/// incident triangles, the triangles' outward unit normals, and the hill climb's start vertices.
#[derive(Clone, Debug)]
pub struct PlaneHull {
    vertices: Vec<Vec3>,
    /// Vertex i's neighbours are `adj[adj_start[i]..adj_start[i + 1]]`.
    adj_start: Vec<u32>,
    adj: Vec<u32>,
    /// Vertex i's triangles are `tris[tri_start[i]..tri_start[i + 1]]`.
    tri_start: Vec<u32>,
    tris: Vec<u32>,
    triangles: Vec<[u32; 3]>,
    normals: Vec<Vec3>,
    extrema: [u32; 27],
    /// Face polygon p's vertices, counter-clockwise about its outward normal, are
    /// `poly[poly_start[p]..poly_start[p + 1]]`.
    poly_start: Vec<u32>,
    poly: Vec<u32>,
    /// Face polygon p's outward unit normal (its triangles' area-weighted mean).
    poly_normal: Vec<Vec3>,
    /// Vertex i's polygons are `vpolys[vpoly_start[i]..vpoly_start[i + 1]]`.
    vpoly_start: Vec<u32>,
    vpolys: Vec<u32>,
}

impl PlaneHull {
    /// The hull of `points` (geom frame; the mesh's hull vertices) with its adjacency; None when
    /// the points span no volume.
    pub fn new(points: &[Vec3]) -> Option<Self> {
        let hull = crate::mass::convex_hull(points).ok()?;
        let (vertices, triangles) = (hull.vertices, hull.triangles);
        let n = vertices.len();
        let mut neighbours: Vec<Vec<u32>> = vec![Vec::new(); n];
        let mut incident: Vec<Vec<u32>> = vec![Vec::new(); n];
        let mut normals = Vec::with_capacity(triangles.len());
        for (t, tri) in triangles.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                if !neighbours[a as usize].contains(&b) {
                    neighbours[a as usize].push(b);
                }
                if !neighbours[b as usize].contains(&a) {
                    neighbours[b as usize].push(a);
                }
                incident[a as usize].push(t as u32);
            }
            let [a, b, c] = tri.map(|i| vertices[i as usize]);
            let normal = (b - a).cross(&(c - a));
            let len = normal.norm();
            normals.push(if len > 0.0 { normal / len } else { normal });
        }
        let csr = |lists: Vec<Vec<u32>>| {
            let mut start = Vec::with_capacity(lists.len() + 1);
            start.push(0u32);
            let mut flat = Vec::new();
            for l in lists {
                flat.extend_from_slice(&l);
                start.push(flat.len() as u32);
            }
            (start, flat)
        };
        let (adj_start, adj) = csr(neighbours);
        let (tri_start, tris) = csr(incident);
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
        let mut hull = Self {
            vertices,
            adj_start,
            adj,
            tri_start,
            tris,
            triangles,
            normals,
            extrema,
            poly_start: vec![0],
            poly: Vec::new(),
            poly_normal: Vec::new(),
            vpoly_start: Vec::new(),
            vpolys: Vec::new(),
        };
        hull.build_polygons();
        Some(hull)
    }

    /// Merges connected coplanar triangles into face polygons and traces each one's boundary
    /// (counter-clockwise about the outward normal, following the triangles' own edge order); a
    /// group whose boundary is not one simple loop stays as its separate triangles.
    fn build_polygons(&mut self) {
        let nt = self.triangles.len();
        let mut group = vec![u32::MAX; nt];
        let mut members: Vec<Vec<usize>> = Vec::new();
        for t in 0..nt {
            if group[t] != u32::MAX {
                continue;
            }
            let g = members.len() as u32;
            let mut stack = vec![t];
            let mut list = Vec::new();
            group[t] = g;
            while let Some(u) = stack.pop() {
                list.push(u);
                for j in 0..3 {
                    if let Some(w) = self.across(u, j) {
                        if group[w] == u32::MAX && self.coplanar(u, w) {
                            group[w] = g;
                            stack.push(w);
                        }
                    }
                }
            }
            list.sort_unstable();
            members.push(list);
        }
        let n = self.vertices.len();
        let mut per_vertex: Vec<Vec<u32>> = vec![Vec::new(); n];
        let mut next = vec![u32::MAX; n];
        for list in &members {
            let loops = self.boundary(list, &mut next);
            let singles: Vec<Vec<u32>> = match loops {
                Some(l) => vec![l],
                None => list.iter().map(|&t| self.triangles[t].to_vec()).collect(),
            };
            for vs in singles {
                let mut normal = Vec3::zeros();
                if vs.len() == 3 {
                    let [a, b, c] = [vs[0], vs[1], vs[2]].map(|i| self.vertices[i as usize]);
                    normal = (b - a).cross(&(c - a));
                } else {
                    for &t in list {
                        let [a, b, c] = self.triangles[t].map(|i| self.vertices[i as usize]);
                        normal += (b - a).cross(&(c - a));
                    }
                }
                let len = normal.norm();
                let p = self.poly_normal.len() as u32;
                self.poly_normal.push(if len > 0.0 { normal / len } else { normal });
                for &v in &vs {
                    per_vertex[v as usize].push(p);
                }
                self.poly.extend_from_slice(&vs);
                self.poly_start.push(self.poly.len() as u32);
            }
        }
        self.vpoly_start.push(0);
        for l in per_vertex {
            self.vpolys.extend_from_slice(&l);
            self.vpoly_start.push(self.vpolys.len() as u32);
        }
    }

    /// The boundary loop of the triangles `list` (one coplanar group), or None when it is not a
    /// single simple loop. `next` is scratch (all `u32::MAX` on entry and on return).
    fn boundary(&self, list: &[usize], next: &mut [u32]) -> Option<Vec<u32>> {
        if list.len() == 1 {
            return Some(self.triangles[list[0]].to_vec());
        }
        let mut edges = Vec::new();
        for &t in list {
            for j in 0..3 {
                let inner = self.across(t, j).is_some_and(|w| list.binary_search(&w).is_ok());
                if !inner {
                    let tri = self.triangles[t];
                    edges.push((tri[j], tri[(j + 1) % 3]));
                }
            }
        }
        let mut simple = true;
        for &(a, b) in &edges {
            if next[a as usize] != u32::MAX {
                simple = false;
            }
            next[a as usize] = b;
        }
        let mut out = Vec::with_capacity(edges.len());
        if simple {
            let start = edges[0].0;
            let mut v = start;
            loop {
                out.push(v);
                v = next[v as usize];
                if v == u32::MAX || v == start || out.len() > edges.len() {
                    break;
                }
            }
            simple = v == start && out.len() == edges.len();
        }
        for &(a, _) in &edges {
            next[a as usize] = u32::MAX;
        }
        simple.then_some(out)
    }

    /// The triangle across edge (v_j, v_{j+1}) of triangle `t` (another incident triangle of both).
    fn across(&self, t: usize, j: usize) -> Option<usize> {
        let tri = self.triangles[t];
        let (a, b) = (tri[j], tri[(j + 1) % 3]);
        let (s, e) = (self.tri_start[a as usize] as usize, self.tri_start[a as usize + 1] as usize);
        self.tris[s..e].iter().map(|&u| u as usize).find(|&u| u != t && self.triangles[u].contains(&b))
    }

    /// Whether triangles `t` and `u` lie in one plane (normals equal to round-off).
    fn coplanar(&self, t: usize, u: usize) -> bool {
        self.normals[t].dot(&self.normals[u]) > 1.0 - COPLANAR
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
