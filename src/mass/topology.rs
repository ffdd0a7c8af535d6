//! Edge topology of a triangle mesh: is the surface closed, and are its triangles consistently
//! oriented? This decides whether the mesh bounds a solid whose volume integrals (divergence
//! theorem over the surface) are meaningful.
//!
//! Vertices are first welded by exact position (files often repeat a vertex per face or per
//! texture seam). Triangles with a repeated welded vertex have zero area and are left out. Then
//! for every undirected edge {a, b} let `f` be the number of triangles traversing it as a→b and
//! `r` as b→a. A closed, consistently oriented surface has `f = r` on every edge (its boundary as
//! a chain is zero, which is exactly what makes the signed volume independent of the reference
//! point); this allows non-manifold edges shared by 4, 6, ... triangles. Otherwise the edge is a
//! *boundary* edge when `f + r` is odd (a hole), and a *misoriented* edge when `f + r` is even (a
//! neighbour wound the other way).

use super::mesh::TriangleMesh;
use std::collections::HashMap;

/// The edge defects of a mesh, with one example edge of each kind (as vertex indices of the mesh).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Topology {
    /// Edges used by an odd number of triangles (holes).
    pub boundary_edges: usize,
    /// Edges used an even number of times, but not equally often in both directions.
    pub misoriented_edges: usize,
    /// Triangles with two corners at the same position (left out of the edge count).
    pub collapsed_triangles: usize,
    pub boundary_example: Option<(u32, u32)>,
    pub misoriented_example: Option<(u32, u32)>,
}

impl Topology {
    /// Closed and consistently oriented.
    pub fn is_closed_oriented(&self) -> bool {
        self.boundary_edges == 0 && self.misoriented_edges == 0
    }
}

/// Edge analysis of `mesh` (see the module documentation). Vertex indices must be in range.
pub fn analyze(mesh: &TriangleMesh) -> Topology {
    // Weld vertices by exact position (−0 and +0 alike).
    let mut weld: HashMap<[u64; 3], u32> = HashMap::with_capacity(mesh.vertices.len());
    let canon: Vec<u32> = mesh
        .vertices
        .iter()
        .enumerate()
        .map(|(i, v)| {
            let key = [(v.x + 0.0).to_bits(), (v.y + 0.0).to_bits(), (v.z + 0.0).to_bits()];
            *weld.entry(key).or_insert(i as u32)
        })
        .collect();
    // Directed edges as (low, high, forward?) packed for one sort.
    let mut edges: Vec<(u32, u32, bool)> = Vec::with_capacity(3 * mesh.triangles.len());
    let mut topo = Topology::default();
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| canon[i as usize]);
        if a == b || b == c || c == a {
            topo.collapsed_triangles += 1;
            continue;
        }
        for (u, v) in [(a, b), (b, c), (c, a)] {
            edges.push(if u < v { (u, v, true) } else { (v, u, false) });
        }
    }
    edges.sort_unstable();
    let mut k = 0;
    while k < edges.len() {
        let (u, v, _) = edges[k];
        let (mut f, mut r) = (0usize, 0usize);
        while k < edges.len() && edges[k].0 == u && edges[k].1 == v {
            if edges[k].2 {
                f += 1;
            } else {
                r += 1;
            }
            k += 1;
        }
        if f != r {
            if (f + r) % 2 == 1 {
                topo.boundary_edges += 1;
                topo.boundary_example.get_or_insert((u, v));
            } else {
                topo.misoriented_edges += 1;
                topo.misoriented_example.get_or_insert((u, v));
            }
        }
    }
    topo
}
