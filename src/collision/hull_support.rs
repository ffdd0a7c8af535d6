//! The support function of a mesh's convex hull by hill climbing on the hull's vertex adjacency,
//! as MuJoCo's `mjc_hillclimbSupport` (engine_collision_convex.c) walks its mesh graph: start at
//! the vertex farthest along the nearest of 27 grid directions (the corners, edges and faces of a
//! cube: MuJoCo's `mesh_extrema`), then move to a neighbour farther along the direction until
//! none is. On a convex polytope a vertex that no neighbour improves on is the farthest of all, so
//! the result is the exhaustive scan's (vertices exactly as far apart along the direction may give
//! another of them) at a cost that grows with the number of edges walked instead of the number of
//! vertices. The hull, its vertex order and its edges' order are MuJoCo's mesh graph (qhull's,
//! [`super::mesh_graph`]), and the climb runs where MuJoCo's does — in MuJoCo's mesh frame (the
//! mesh's centre of mass and principal axes), on the vertices' `f32` copies, from the grid seeds
//! MuJoCo's compiler finds in that frame (`mesh_extrema`) — so ties, warm starts and the local
//! maxima of a hull made slightly non-convex by the `f32` rounding walk as MuJoCo's climb does.
//! (With the seeds and grid cells taken in the geom's file frame, the Robotiq 2F-85's spring link
//! climbed from another seed across its flat face to a vertex 4.5e-10 m farther than MuJoCo's
//! local maximum; EPA then ended on another face, one contact 6 mm from MuJoCo's:
//! docs/multiccd.md.)

use super::mesh_graph::MeshGraph;
use parry3d_f64::math::Vector;
use parry3d_f64::shape::SupportMap;
use std::sync::Arc;

/// A convex hull with its vertex adjacency, for hill-climbing support queries.
#[derive(Clone, Debug)]
pub struct HullSupport {
    graph: Arc<MeshGraph>,
    /// The hull's vertices (the graph's, geom frame, as parry vectors): the support points.
    points: Vec<Vector>,
    /// The hull's vertices as MuJoCo stores them (`f32` in its mesh frame,
    /// [`MeshGraph::mujoco_vertices`]): what the climb compares, as MuJoCo's does.
    mj_points: Vec<Vector>,
    /// The transpose of the mesh frame's axes in the geom frame (`box_frame`): a geom-frame
    /// direction into the mesh frame; None when the two frames' axes are the same.
    mj_axes_t: Option<crate::spatial::Mat3>,
    /// Per grid direction of the mesh frame (x, y, z in {−1, 0, 1}, index 9x + 3y + z after
    /// adding 1 to each), the first vertex farthest along it in `f32` arithmetic on
    /// `mj_points` (MuJoCo's `mesh_extrema`): the climb's start.
    extrema: [u32; 27],
    /// The hull vertices in the order of the mesh's vertex list (ascending `globalid`): the order
    /// MuJoCo's exhaustive support (`mjc_meshSupport`) scans them in, which decides ties.
    scan_order: Vec<u32>,
    /// The hull's vertices in `scan_order` (`scan_points[k]` is `points[scan_order[k]]`): the
    /// exhaustive scan reads them in a row, without an index per vertex.
    scan_points: Vec<Vector>,
    /// Whether the hull has vertices and every edge of the graph joins two of them (`adj_start`
    /// ascending within `adj`, every entry of `adj` below the vertex count), checked once here:
    /// the climb then reads the vertices and edges without bounds checks (a quarter of its cost).
    valid_graph: bool,
}

impl HullSupport {
    /// The support function of `graph`'s hull: its vertices and edges, and the climb's start
    /// vertices.
    pub fn new(graph: Arc<MeshGraph>) -> Self {
        let points: Vec<Vector> = graph.vertices.iter().map(|v| Vector::new(v.x, v.y, v.z)).collect();
        let mj_points: Vec<Vector> = if graph.mujoco_vertices.len() == points.len() {
            graph.mujoco_vertices.iter().map(|v| Vector::new(v.x, v.y, v.z)).collect()
        } else {
            points.clone()
        };
        let axes = graph.box_frame.1;
        let mj_axes_t = (axes != crate::spatial::Mat3::identity()).then(|| axes.transpose());
        let extrema = grid_extrema(&mj_points);
        let mut scan_order: Vec<u32> = (0..points.len() as u32).collect();
        scan_order.sort_by_key(|&i| graph.globalid[i as usize]);
        let scan_points = scan_order.iter().map(|&i| points[i as usize]).collect();
        let n = points.len();
        let valid_graph = n > 0
            && graph.adj_start.len() == n + 1
            && graph.adj_start.windows(2).all(|w| w[0] <= w[1])
            && graph.adj_start[n] as usize <= graph.adj.len()
            && graph.adj.iter().all(|&j| (j as usize) < n);
        Self { graph, points, mj_points, mj_axes_t, extrema, scan_order, scan_points, valid_graph }
    }

    /// The hull's graph and face polygons.
    pub fn graph(&self) -> &MeshGraph {
        &self.graph
    }

    /// The hull's vertices (geom frame).
    pub fn points(&self) -> &[Vector] {
        &self.points
    }

    /// Hull vertex `i` as MuJoCo stores it (`f32` coordinates in its mesh frame, the graph's
    /// `box_frame`; the geom-frame vertex when that frame is not known).
    #[inline(always)]
    pub fn mujoco_point(&self, i: usize) -> Vector {
        self.mj_points[i]
    }

    /// Whether MuJoCo's mesh frame has the geom frame's axes (its rotation the identity).
    pub fn mesh_axes_identity(&self) -> bool {
        self.mj_axes_t.is_none()
    }

    /// The hull vertices in the mesh's vertex-list order (see the field).
    pub fn scan_order(&self) -> &[u32] {
        &self.scan_order
    }

    /// The index (in [`Self::points`]) of the vertex farthest along `dir` by MuJoCo's exhaustive
    /// scan (`mjc_meshSupport`, for meshes too small to climb): from `cached` (the previous answer
    /// of the same query sequence, −1 or out of range: none, the scan then starting below every
    /// vertex at `f32::MIN`), every vertex in [`Self::scan_order`], a later one taken only when
    /// strictly farther (ties keep the earlier best). Inlined: the solver calls it once per
    /// support point of a small mesh, and the call's register spills cost a third of the scan.
    #[inline(always)]
    pub fn support_index_scan(&self, dir: Vector, cached: i32) -> usize {
        let (mut imax, mut max) = (0usize, f32::MIN as f64);
        if let Some(c) = usize::try_from(cached).ok().filter(|&c| c < self.points.len()) {
            imax = c;
            max = dir.dot(self.points[c]);
        }
        // The position in the scan of the best vertex so far (MAX: the start still is).
        let mut kmax = usize::MAX;
        for (k, p) in self.scan_points.iter().enumerate() {
            let v = dir.dot(*p);
            if v > max {
                (max, kmax) = (v, k);
            }
        }
        match self.scan_order.get(kmax) {
            Some(&i) => i as usize,
            None => imax,
        }
    }

    /// The neighbours of vertex `v` along the hull's edges.
    pub fn neighbours(&self, v: usize) -> &[u32] {
        self.graph.neighbours(v)
    }

    /// The index (in [`Self::points`]) of the vertex farthest along `dir`, by hill climbing.
    pub fn support_index(&self, dir: Vector) -> usize {
        self.support_index_warm(dir, -1)
    }

    /// [`Self::support_index`] warm-started as MuJoCo's `mjc_hillclimbSupport`: from the better of
    /// the grid seed and `cached` (the previous answer of the same query sequence; −1: none).
    pub fn support_index_warm(&self, dir: Vector, cached: i32) -> usize {
        // MuJoCo climbs in its mesh frame, on the vertices as it stores them.
        let dir = match &self.mj_axes_t {
            Some(t) => {
                let v = t * crate::spatial::Vec3::new(dir.x, dir.y, dir.z);
                Vector::new(v.x, v.y, v.z)
            }
            None => dir,
        };
        let points = &self.mj_points;
        let cell = |a: f64| (a > 0.4) as usize + 1 - (a < -0.4) as usize;
        let seed = self.extrema[9 * cell(dir.x) + 3 * cell(dir.y) + cell(dir.z)] as usize;
        let mut best = seed;
        if let Some(c) = usize::try_from(cached).ok().filter(|&c| c < points.len()) {
            if points[seed].dot(dir) <= points[c].dot(dir) {
                best = c;
            }
        }
        if self.valid_graph {
            // SAFETY: `valid_graph` (checked in `new` on the graph this hull owns and never
            // changes) says every index read below is in bounds: `best` starts at a vertex
            // (`seed` from `scan` over the non-empty points, or `c` < len) and moves only to
            // entries of `adj`, all below the vertex count; `adj_start[v]`, `adj_start[v + 1]`
            // exist for every vertex v and delimit a range of `adj`.
            unsafe {
                let (adj_start, adj) = (&self.graph.adj_start, &self.graph.adj);
                let mut best_dot = points.get_unchecked(best).dot(dir);
                loop {
                    let current = best;
                    let (from, to) = (
                        *adj_start.get_unchecked(current) as usize,
                        *adj_start.get_unchecked(current + 1) as usize,
                    );
                    for &j in adj.get_unchecked(from..to) {
                        let dot = points.get_unchecked(j as usize).dot(dir);
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
        let mut best_dot = points[best].dot(dir);
        loop {
            let current = best;
            for &j in self.graph.neighbours(current) {
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

/// MuJoCo's grid seeds (`mesh_extrema`, user_model.cc): per direction (cx, cy, cz) of
/// {−1, 0, 1}³ (index 9(cx + 1) + 3(cy + 1) + cz + 1), the first vertex with the largest
/// x·cx + y·cy + z·cz, computed in `f32` on the stored vertices `points`.
fn grid_extrema(points: &[Vector]) -> [u32; 27] {
    let mut extrema = [0u32; 27];
    let mut max = [f32::MIN; 27];
    for (i, p) in points.iter().enumerate() {
        let (x, y, z) = (p.x as f32, p.y as f32, p.z as f32);
        for (k, (slot, m)) in extrema.iter_mut().zip(max.iter_mut()).enumerate() {
            let c = |j: usize| j as f32 - 1.0;
            let dot = x * c(k / 9) + y * c((k / 3) % 3) + z * c(k % 3);
            if dot > *m {
                *m = dot;
                *slot = i as u32;
            }
        }
    }
    extrema
}

impl SupportMap for HullSupport {
    fn local_support_point(&self, dir: Vector) -> Vector {
        self.points[self.support_index(dir)]
    }
}
