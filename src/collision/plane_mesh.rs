//! Plane against a mesh's convex hull as MuJoCo 4.0 does it (`mjc_PlaneConvex`, the plane row of
//! its collision table): at most four contacts, hull vertices of the face resting on the plane.
//!
//! 1. The hull vertex deepest below the plane (its support point along the plane's −normal,
//!    found by hill climbing on the hull's edges from the vertex farthest along the nearest of 27
//!    grid directions, as [`super::hull_support`]); none when it is farther than the margin.
//! 2. Of the hull triangles around that vertex, the one whose outward normal points most nearly
//!    along −normal (the face resting on the plane).
//! 3. That triangle's other two vertices, in its outward (counter-clockwise) order starting after
//!    the deepest vertex, each when it is closer than the margin.
//!
//! This is what the live MuJoCo 4.0.0 returns (checked on the Spot, Spot-arm and Barkour feet at
//! every step of 300: the same vertices in the same order; its 2026-08 source snapshot took up to
//! two edge neighbours of the deepest vertex farther than 0.3 of the bounding radius from it
//! instead). Each contact lies midway between the vertex and the plane, with the plane's normal
//! and distance `n·(v − p_plane)`.
//!
//! Where the facing triangle and one coplanar neighbour form a flat quadrilateral of the hull (a
//! box-like mesh resting on a face), MuJoCo 4.0 takes the quadrilateral's four corners, and so
//! does lagrange (the neighbour's far vertex between the shared edge's ends). Larger flat
//! polygons keep the triangle's three (not yet compared with MuJoCo; MuJoCo triangulates with
//! qhull, lagrange with parry3d's quickhull, so at exact ties the triangle may differ too).

use super::plane::PlanePoint;

/// Two hull triangles whose unit normals' dot product exceeds 1 − this lie in one flat face
/// (the mesh's single-precision vertices tilt coplanar triangles by up to ~1e-7).
const COPLANAR: f64 = 1e-6;
use crate::spatial::{Transform, Vec3};

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
        Some(Self { vertices, adj_start, adj, tri_start, tris, triangles, normals, extrema })
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

    /// When triangle `t` and exactly one neighbour form a flat quadrilateral of the hull (no
    /// further coplanar triangle): the shared edge's index j in `t` (edge v_j → v_{j+1}) and the
    /// neighbour's far vertex.
    fn coplanar_quad(&self, t: usize) -> Option<(usize, u32)> {
        let mut found = None;
        for j in 0..3 {
            let Some(u) = self.across(t, j) else { continue };
            if !self.coplanar(t, u) {
                continue;
            }
            if found.is_some() {
                return None;
            }
            found = Some((j, u));
        }
        let (j, u) = found?;
        // The neighbour's two other edges must not continue the polygon.
        let shared = [self.triangles[t][j], self.triangles[t][(j + 1) % 3]];
        for i in 0..3 {
            let edge = [self.triangles[u][i], self.triangles[u][(i + 1) % 3]];
            if shared.contains(&edge[0]) && shared.contains(&edge[1]) {
                continue;
            }
            if self.across(u, i).is_some_and(|w| w != t && self.coplanar(u, w)) {
                return None;
            }
        }
        let far = *self.triangles[u].iter().find(|v| !shared.contains(v))?;
        Some((j, far))
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
/// `reach` (the pair's margin), at most three (see the module documentation). `feature` is the
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
    // The triangle around it facing the plane most (its normal nearest −normal).
    let (s, e) = (hull.tri_start[first] as usize, hull.tri_start[first + 1] as usize);
    let mut face = None;
    let mut facing = f64::INFINITY;
    for &t in &hull.tris[s..e] {
        let along = hull.normals[t as usize].dot(&(-down));
        if along < facing {
            facing = along;
            face = Some(t as usize);
        }
    }
    let Some(face) = face else { return };
    let tri = hull.triangles[face];
    // The face's polygon: the triangle, or the quadrilateral it forms with one coplanar
    // neighbour (its far vertex inserted between the shared edge's ends, keeping the outward
    // counter-clockwise order).
    let mut polygon = [0u32; 4];
    let len = match hull.coplanar_quad(face) {
        Some((edge, w)) => {
            for (slot, v) in polygon.iter_mut().zip(
                tri.iter()
                    .take(edge + 1)
                    .copied()
                    .chain(std::iter::once(w))
                    .chain(tri.iter().skip(edge + 1).copied()),
            ) {
                *slot = v;
            }
            4
        }
        None => {
            polygon[..3].copy_from_slice(&tri);
            3
        }
    };
    let k = polygon[..len].iter().position(|&v| v as usize == first).unwrap_or(0);
    // MuJoCo's inclusion test: along −normal beyond the geom centre's height less the margin.
    let threshold = n.dot(&(x.pos - plane.pos)) - reach;
    for step in 1..len {
        let i = polygon[(k + step) % len] as usize;
        if down.dot(&hull.vertices[i]) > threshold {
            let q = point(i);
            out(PlanePoint { surface: q, dist: n.dot(&(q - plane.pos)), hint: None, feature: i as u32 });
        }
    }
}
