//! The support function of a mesh's convex hull by hill climbing on the hull's vertex adjacency,
//! as MuJoCo's `mjc_hillclimbSupport` (engine_collision_convex.c) walks its mesh graph: start at
//! the vertex farthest along the nearest of 27 grid directions (the corners, edges and faces of a
//! cube: MuJoCo's `mesh_extrema`), then move to a neighbour farther along the direction until
//! none is. On a convex polytope a vertex that no neighbour improves on is the farthest of all, so
//! the result is the exhaustive scan's (vertices exactly as far apart along the direction may give
//! another of them) at a cost that grows with the number of edges walked instead of the number of
//! vertices (parry3d's `ConvexPolyhedron` scans every vertex).

use parry3d_f64::math::Vector;
use parry3d_f64::shape::{ConvexPolyhedron, SupportMap};

/// A convex hull with its vertex adjacency, for hill-climbing support queries.
#[derive(Clone, Debug)]
pub struct HullSupport {
    polyhedron: ConvexPolyhedron,
    /// Vertex i's neighbours are `adj[adj_start[i]..adj_start[i + 1]]`.
    adj_start: Vec<u32>,
    adj: Vec<u32>,
    /// Per grid direction (x, y, z in {−1, 0, 1}, index 9x + 3y + z after adding 1 to each), the
    /// vertex farthest along it: the climb's start.
    extrema: [u32; 27],
}

impl HullSupport {
    /// The adjacency and start vertices of `polyhedron`'s vertex graph (its edges).
    pub fn new(polyhedron: ConvexPolyhedron) -> Self {
        let n = polyhedron.points().len();
        let mut count = vec![0u32; n + 1];
        for e in polyhedron.edges() {
            count[e.vertices[0] as usize + 1] += 1;
            count[e.vertices[1] as usize + 1] += 1;
        }
        for i in 0..n {
            count[i + 1] += count[i];
        }
        let adj_start = count.clone();
        let mut fill = count;
        let mut adj = vec![0u32; adj_start[n] as usize];
        for e in polyhedron.edges() {
            let [a, b] = e.vertices;
            adj[fill[a as usize] as usize] = b;
            fill[a as usize] += 1;
            adj[fill[b as usize] as usize] = a;
            fill[b as usize] += 1;
        }
        let mut extrema = [0u32; 27];
        for (k, slot) in extrema.iter_mut().enumerate() {
            let dir = Vector::new((k / 9) as f64 - 1.0, ((k / 3) % 3) as f64 - 1.0, (k % 3) as f64 - 1.0);
            *slot = scan(polyhedron.points(), dir) as u32;
        }
        Self { polyhedron, adj_start, adj, extrema }
    }

    /// The hull.
    pub fn polyhedron(&self) -> &ConvexPolyhedron {
        &self.polyhedron
    }

    /// The neighbours of vertex `v` along the hull's edges.
    pub fn neighbours(&self, v: usize) -> &[u32] {
        &self.adj[self.adj_start[v] as usize..self.adj_start[v + 1] as usize]
    }

    /// The index (in `polyhedron().points()`) of the vertex farthest along `dir`, by hill climbing.
    pub fn support_index(&self, dir: Vector) -> usize {
        self.support_index_warm(dir, -1)
    }

    /// [`Self::support_index`] warm-started as MuJoCo's `mjc_hillclimbSupport`: from the better of
    /// the grid seed and `cached` (the previous answer of the same query sequence; −1: none).
    pub fn support_index_warm(&self, dir: Vector, cached: i32) -> usize {
        let points = self.polyhedron.points();
        let cell = |a: f64| (a > 0.4) as usize + 1 - (a < -0.4) as usize;
        let seed = self.extrema[9 * cell(dir.x) + 3 * cell(dir.y) + cell(dir.z)] as usize;
        let mut best = seed;
        if let Some(c) = usize::try_from(cached).ok().filter(|&c| c < points.len()) {
            if points[seed].dot(dir) <= points[c].dot(dir) {
                best = c;
            }
        }
        let mut best_dot = points[best].dot(dir);
        loop {
            let current = best;
            let (s, e) = (self.adj_start[current] as usize, self.adj_start[current + 1] as usize);
            for &j in &self.adj[s..e] {
                let dot = points[j as usize].dot(dir);
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

/// The first vertex of `points` farthest along `dir` (the exhaustive scan).
pub(crate) fn scan(points: &[Vector], dir: Vector) -> usize {
    let mut best = 0;
    let mut best_dot = f64::NEG_INFINITY;
    for (i, p) in points.iter().enumerate() {
        let dot = p.dot(dir);
        if dot > best_dot {
            best_dot = dot;
            best = i;
        }
    }
    best
}

impl SupportMap for HullSupport {
    fn local_support_point(&self, dir: Vector) -> Vector {
        self.polyhedron.points()[self.support_index(dir)]
    }
}
