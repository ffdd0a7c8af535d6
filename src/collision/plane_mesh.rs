//! Plane against a mesh's convex hull as MuJoCo 4.0 does it (`mjc_PlaneConvex`, the plane row of
//! its collision table): at most three contacts, all hull vertices of one triangle.
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
//! Not yet as MuJoCo: where the facing triangle lies in a flat polygon of the hull (coplanar
//! triangles, e.g. a quadrilateral), MuJoCo 4.0 takes the polygon's vertices (4 of them in
//! tests/collision_mujoco.rs's 84 plane–mesh cases), lagrange the triangle's 3 (MuJoCo triangulates
//! with qhull, lagrange with parry3d's quickhull, so at exact ties the triangle may differ too).

use super::plane::PlanePoint;
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
    let k = tri.iter().position(|&v| v as usize == first).unwrap_or(0);
    // MuJoCo's inclusion test: along −normal beyond the geom centre's height less the margin.
    let threshold = n.dot(&(x.pos - plane.pos)) - reach;
    for step in 1..3 {
        let i = tri[(k + step) % 3] as usize;
        if down.dot(&hull.vertices[i]) > threshold {
            let q = point(i);
            out(PlanePoint { surface: q, dist: n.dot(&(q - plane.pos)), hint: None, feature: i as u32 });
        }
    }
}
