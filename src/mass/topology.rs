//! Edge topology of a triangle mesh: is the surface closed, and are its triangles consistently
//! oriented? This decides whether the mesh bounds a solid whose volume integrals (divergence
//! theorem over the surface) are meaningful.
//!
//! Vertices are first welded by exact position (files often repeat a vertex per face or per
//! texture seam). Triangles with a repeated welded vertex have zero area and are left out. Then
//! for every undirected edge {a, b} let `f` be the number of triangles traversing it as a→b and
//! `r` as b→a. A closed, consistently oriented 2-manifold has `f = r = 1` on every edge. The edge
//! is
//! - a *boundary* edge when `f + r` is odd: the surface taken modulo 2 has a boundary there (a
//!   hole);
//! - a *misoriented* edge when `f ≥ 2` or `r ≥ 2`: two triangles traverse it in the same
//!   direction, so one of them is wound against its neighbour — MuJoCo's test for its exact mode
//!   ("faces of mesh have inconsistent orientation", a repeated half-edge in `mjCMesh::Process`),
//!   which also catches non-manifold edges shared by four triangles and duplicated triangles.
//!
//! Combinatorial holes are not always geometric ones: at a T-junction (a vertex of one triangle
//! on an edge of its neighbour) the edges on both sides are boundary edges although the surface
//! is watertight, and CAD exports leave pinholes of 1e-9 of the surface. So the boundary edges
//! are also joined into closed polygons whose vector areas `|½ ∮ x × dx|` add up to
//! [`Topology::hole_area`]: zero for T-junctions, the area of the missing patch for a real hole.
//! A hole of area `A_h` can change the enclosed volume by at most about `d·A_h/3` (`d` the mesh's
//! diameter), which is how [`super::mesh_inertia`] decides whether a mesh is closed enough.

use super::fast_hash::{point_key, FastMap};
use super::mesh::TriangleMesh;
use crate::spatial::Vec3;

/// The edge defects of a mesh, with one example edge of each kind (as vertex indices of the mesh).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Topology {
    /// Edges used by an odd number of triangles (holes).
    pub boundary_edges: usize,
    /// Edges traversed at least twice in the same direction.
    pub misoriented_edges: usize,
    /// Σ over misoriented edges of the area of the smallest triangle running the edge in the
    /// repeated direction (m²): a bound on the area wound the wrong way. Flipping a triangle of
    /// area `A` changes the enclosed volume by at most `2·d·A/3` (`d` the mesh's diameter).
    pub misoriented_area: f64,
    /// Triangles with two corners at the same position (left out of the edge count).
    pub collapsed_triangles: usize,
    /// One boundary edge as (from, to) vertex indices, if any.
    pub boundary_example: Option<(u32, u32)>,
    /// One misoriented edge as (from, to) vertex indices, if any.
    pub misoriented_example: Option<(u32, u32)>,
    /// Number of closed polygons the boundary edges form.
    pub boundary_loops: usize,
    /// `Σ |½ ∮ x × dx|` over those loops (m²): the area of the patches that would close the
    /// holes. Zero for edges that are "open" only combinatorially — T-junctions, where a vertex
    /// of one triangle lies on an edge of its neighbour, give collinear loops of zero area.
    pub hole_area: f64,
}

impl Topology {
    /// Closed and consistently oriented.
    pub fn is_closed_oriented(&self) -> bool {
        self.boundary_edges == 0 && self.misoriented_edges == 0
    }
}

/// Edge analysis of `mesh` (see the module documentation). Vertex indices must be in range.
pub fn analyze(mesh: &TriangleMesh) -> Topology {
    // Weld vertices by exact position (−0 and +0 alike): each vertex maps to the first one at
    // its position.
    let n = mesh.vertices.len();
    let mut weld: FastMap<[u64; 3], u32> = FastMap::with_capacity_and_hasher(n, Default::default());
    let canon: Vec<u32> = mesh
        .vertices
        .iter()
        .enumerate()
        .map(|(i, v)| *weld.entry(point_key(v.x, v.y, v.z)).or_insert(i as u32))
        .collect();
    drop(weld);
    // Edges bucketed by their lower vertex (a counting sort): entry (higher vertex, triangle·2 +
    // forward), where forward means the triangle runs the edge from low to high.
    let mut topo = Topology::default();
    let mut start = vec![0u32; n + 1];
    let welded: Vec<Option<[u32; 3]>> = mesh
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| canon[i as usize]);
            (a != b && b != c && c != a).then_some([a, b, c])
        })
        .collect();
    topo.collapsed_triangles = welded.iter().filter(|w| w.is_none()).count();
    for [a, b, c] in welded.iter().flatten() {
        for (u, v) in [(a, b), (b, c), (c, a)] {
            start[*u.min(v) as usize + 1] += 1;
        }
    }
    for i in 0..n {
        start[i + 1] += start[i];
    }
    let mut fill = start.clone();
    let mut entries = vec![(0u32, 0u32); start[n] as usize];
    for (k, w) in welded.iter().enumerate() {
        let Some([a, b, c]) = w else { continue };
        for (u, v) in [(*a, *b), (*b, *c), (*c, *a)] {
            let (lo, hi, forward) = if u < v { (u, v, 1) } else { (v, u, 0) };
            entries[fill[lo as usize] as usize] = (hi, ((k as u32) << 1) | forward);
            fill[lo as usize] += 1;
        }
    }
    drop(fill);
    let area = |k: u32| {
        let [a, b, c] = mesh.triangles[k as usize].map(|i| mesh.vertices[i as usize]);
        0.5 * (b - a).cross(&(c - a)).norm()
    };
    // Edges used an odd number of times: the boundary of the surface taken modulo 2, which does
    // not depend on orientation.
    let mut odd: Vec<(u32, u32)> = Vec::new();
    for u in 0..n {
        let bucket = &mut entries[start[u] as usize..start[u + 1] as usize];
        bucket.sort_unstable();
        let u = u as u32;
        for group in bucket.chunk_by(|x, y| x.0 == y.0) {
            let v = group[0].0;
            let f = group.iter().filter(|e| e.1 & 1 == 1).count();
            let r = group.len() - f;
            if (f + r) % 2 == 1 {
                topo.boundary_edges += 1;
                topo.boundary_example.get_or_insert((u, v));
                odd.push((u, v));
            }
            if f >= 2 || r >= 2 {
                topo.misoriented_edges += 1;
                topo.misoriented_example.get_or_insert(if f >= 2 { (u, v) } else { (v, u) });
                // At least one of the triangles running the same way is wound wrongly: charge the
                // smallest of them.
                let dir = u32::from(f >= 2);
                let smallest = group
                    .iter()
                    .filter(|e| e.1 & 1 == dir)
                    .map(|e| area(e.1 >> 1))
                    .fold(f64::INFINITY, f64::min);
                topo.misoriented_area += smallest;
            }
        }
    }
    if !odd.is_empty() {
        let (loops, area) = loop_areas(&mesh.vertices, &odd);
        topo.boundary_loops = loops;
        topo.hole_area = area;
    }
    topo
}

/// Splits the boundary edges into closed polygons and returns their number and the sum of the
/// magnitudes of their vector areas `|½ Σ xᵢ × xᵢ₊₁|` (each taken about the polygon's first
/// vertex, to limit round-off). Every vertex meets an even number of boundary edges (the
/// boundary of a chain modulo 2 is a cycle), so a walk that never reuses an edge can only get
/// stuck where it started.
fn loop_areas(vertices: &[Vec3], odd: &[(u32, u32)]) -> (usize, f64) {
    // Incidence list sorted by vertex: (vertex, edge index).
    let mut inc: Vec<(u32, u32)> = Vec::with_capacity(2 * odd.len());
    for (e, &(u, v)) in odd.iter().enumerate() {
        inc.push((u, e as u32));
        inc.push((v, e as u32));
    }
    inc.sort_unstable();
    let mut first: FastMap<u32, usize> = FastMap::with_capacity_and_hasher(inc.len(), Default::default());
    for (i, &(v, _)) in inc.iter().enumerate().rev() {
        first.insert(v, i);
    }
    let mut used = vec![false; odd.len()];
    let (mut loops, mut total) = (0, 0.0);
    for e0 in 0..odd.len() {
        if used[e0] {
            continue;
        }
        used[e0] = true;
        let (start, mut at) = odd[e0];
        let o = vertices[start as usize];
        let mut area = Vec3::zeros();
        let mut prev = Vec3::zeros(); // position of `start` relative to o
        loop {
            let p = vertices[at as usize] - o;
            area += prev.cross(&p);
            prev = p;
            if at == start {
                break;
            }
            // Next unused edge at `at`.
            let mut next = None;
            let Some(cursor) = first.get_mut(&at) else { break };
            while *cursor < inc.len() && inc[*cursor].0 == at {
                let e = inc[*cursor].1 as usize;
                *cursor += 1;
                if !used[e] {
                    used[e] = true;
                    next = Some(if odd[e].0 == at { odd[e].1 } else { odd[e].0 });
                    break;
                }
            }
            match next {
                Some(n) => at = n,
                None => break, // cannot happen for a cycle; close the polygon here
            }
        }
        loops += 1;
        total += 0.5 * area.norm();
    }
    (loops, total)
}
