//! A mesh's convex hull as MuJoCo's compiler builds it: the mesh graph (`mesh_graph`: hull
//! vertices in qhull's order, each one's neighbours, the triangles) and the face polygons
//! (`mesh_polyvert`, `mesh_polynormal`, `mesh_polymap`), following `mjCMesh::MakeGraph`,
//! `MakePolygons` and `MakePolygonNormals` (src/user/user_mesh.cc of MuJoCo 4.0; read for their
//! semantics, written here anew).
//!
//! - **Graph.** qhull (the commit MuJoCo pins, crate `qhull-src`) runs with MuJoCo's options on
//!   the mesh's vertices as MuJoCo's compiler holds them at that point: the file's `f32`
//!   coordinates, repeated vertices removed (first occurrence kept), before scaling. Its vertex
//!   order is the hill climb's vertex order, its neighbour lists the climb's edge order.
//! - **Polygons.** Each triangle (qhull's facet order) is keyed by its normal's azimuth and polar
//!   angle rounded to 0.01 rad (`MeshPolygonKey`); triangles of one key are merged edge by edge
//!   into islands and each island traced into a polygon from its first remaining edge
//!   (`MeshPolygon::InsertFace`, `Paths`). The polygons come out in the iteration order of
//!   MuJoCo's `std::unordered_map` over the keys, which is reproduced here for the libc++ that
//!   MuJoCo 4.0's released library is built with (its `std::hash<double>` is the value's bits, the
//!   pair hash a boost-style combination of them, `pair_hash`; buckets grow 2, 5, 11, 23, … as
//!   prime or power-of-two counts; `LibcxxOrder`). Which polygon comes first decides MuJoCo's choice
//!   among equally good faces,
//!   and where a polygon starts decides which clipped points its multi-point contact keeps.
//! - **Normals.** Each polygon's normal is that of its first three vertices (`MakePolygonNormals`)
//!   from the scaled `f64` vertices.
//!
//! The golden file tests/data/mujoco/qhull.json (validation/mujoco_qhull_golden.py) holds MuJoCo's
//! graphs and polygons for the corpus meshes; tests/mesh_graph.rs compares them exactly.

use crate::spatial::{Mat3, Vec3};
use std::collections::HashMap;

/// A mesh's hull graph and face polygons in MuJoCo's orders (see the module documentation).
/// Indices are hull vertex indices (0..`vertices.len()`, qhull's order) unless named global.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshGraph {
    /// Hull vertex positions in the geom frame (m), qhull's order.
    pub vertices: Vec<Vec3>,
    /// Per hull vertex, its index among the mesh's vertices (MuJoCo's `vert_globalid`).
    pub globalid: Vec<u32>,
    /// The number of the mesh's vertices (MuJoCo's `mesh_vertnum`: hull vertices and the rest).
    pub nvert: usize,
    /// Vertex i's neighbours are `adj[adj_start[i]..adj_start[i + 1]]`, in MuJoCo's order.
    pub adj_start: Vec<u32>,
    /// The neighbour lists (see `adj_start`).
    pub adj: Vec<u32>,
    /// The hull's triangles (qhull's facet order, outward counter-clockwise).
    pub faces: Vec<[u32; 3]>,
    /// Polygon p's vertices, counter-clockwise about its outward normal and starting where
    /// MuJoCo's do, are `poly[poly_start[p]..poly_start[p + 1]]`.
    pub poly_start: Vec<u32>,
    /// The polygons' vertices (see `poly_start`).
    pub poly: Vec<u32>,
    /// Polygon p's outward unit normal in the geom frame (`mesh_polynormal`).
    pub poly_normal: Vec<Vec3>,
    /// Vertex i's polygons, ascending, are `vpolys[vpoly_start[i]..vpoly_start[i + 1]]`
    /// (`mesh_polymap`).
    pub vpoly_start: Vec<u32>,
    /// The vertex-to-polygon lists (see `vpoly_start`).
    pub vpolys: Vec<u32>,
    /// MuJoCo's frame of the mesh in the geom frame — its centre of mass and principal axes
    /// (`mjCMesh::Process`) — in which MuJoCo's bounding box of the geom (`geom_aabb`) is
    /// axis-aligned (`obb::LocalBox`); the geom frame itself (identity) when it is not known.
    pub box_frame: (Vec3, Mat3),
    /// The hull vertices as MuJoCo's compiler stores them (`mesh_vert`: `f32` coordinates in its
    /// mesh frame, `box_frame`), qhull's order: what MuJoCo's hill climb compares and its grid
    /// seeds (`mesh_extrema`) are found from. `vertices` when that frame is not known.
    pub mujoco_vertices: Vec<Vec3>,
}

/// Why a mesh has no hull graph.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum MeshGraphError {
    /// The vertex lists disagree in length, or fewer than 4 distinct vertices.
    BadInput(String),
    /// qhull failed (its message was printed on stderr).
    Qhull(qhull_src::QhullError),
}

impl std::fmt::Display for MeshGraphError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            MeshGraphError::BadInput(s) => write!(f, "{s}"),
            MeshGraphError::Qhull(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for MeshGraphError {}

impl MeshGraph {
    /// The graph and polygons of a mesh whose distinct vertices (first occurrence order, as
    /// MuJoCo keeps them) are `file` (the file's coordinates, unscaled), `scaled` (the same after
    /// scaling, f64: the polygon normals) and `placed` (where collision reads them, geom frame:
    /// the hull vertices' positions). `maxhullvert` is MJCF's limit (−1: none).
    ///
    /// # Errors
    /// [`MeshGraphError`] when the lists disagree or qhull finds no hull.
    pub fn new(
        file: &[Vec3],
        scaled: &[Vec3],
        placed: &[Vec3],
        maxhullvert: i32,
    ) -> Result<Self, MeshGraphError> {
        let n = file.len();
        if scaled.len() != n || placed.len() != n {
            return Err(MeshGraphError::BadInput("vertex lists of different lengths".to_string()));
        }
        if let Some(reason) = degenerate(file) {
            return Err(MeshGraphError::BadInput(reason));
        }
        let points: Vec<[f64; 3]> = file.iter().map(|v| [v.x, v.y, v.z]).collect();
        let g = qhull_src::hull_graph(&points, maxhullvert).map_err(MeshGraphError::Qhull)?;
        let nv = g.vert_globalid.len();
        let mut local = vec![u32::MAX; n];
        for (i, &gid) in g.vert_globalid.iter().enumerate() {
            local[gid as usize] = i as u32;
        }
        let mut adj_start = Vec::with_capacity(nv + 1);
        let mut adj = Vec::with_capacity(g.edge_localid.len());
        adj_start.push(0);
        for &e in &g.edge_localid {
            if e < 0 {
                adj_start.push(adj.len() as u32);
            } else {
                adj.push(e as u32);
            }
        }
        let global_faces: Vec<[u32; 3]> =
            g.face_globalid.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
        let faces = global_faces.iter().map(|f| f.map(|v| local[v as usize])).collect();
        let polygons = make_polygons(file, &global_faces);
        let mut poly_start = Vec::with_capacity(polygons.len() + 1);
        let mut poly = Vec::new();
        let mut poly_normal = Vec::with_capacity(polygons.len());
        poly_start.push(0);
        let mut per_vertex: Vec<Vec<u32>> = vec![Vec::new(); nv];
        for (p, path) in polygons.iter().enumerate() {
            poly_normal.push(polygon_normal(scaled, path));
            for &v in path {
                let l = local[v as usize];
                poly.push(l);
                per_vertex[l as usize].push(p as u32);
            }
            poly_start.push(poly.len() as u32);
        }
        let mut vpoly_start = Vec::with_capacity(nv + 1);
        let mut vpolys = Vec::new();
        vpoly_start.push(0);
        for l in per_vertex {
            vpolys.extend_from_slice(&l);
            vpoly_start.push(vpolys.len() as u32);
        }
        let vertices: Vec<Vec3> = g.vert_globalid.iter().map(|&gid| placed[gid as usize]).collect();
        Ok(Self {
            mujoco_vertices: vertices.clone(),
            vertices,
            globalid: g.vert_globalid,
            nvert: n,
            adj_start,
            adj,
            faces,
            poly_start,
            poly,
            poly_normal,
            vpoly_start,
            vpolys,
            box_frame: (Vec3::zeros(), Mat3::identity()),
        })
    }

    /// The number of polygons.
    pub fn npoly(&self) -> usize {
        self.poly_normal.len()
    }

    /// Polygon `p`'s vertices (hull vertex indices, MuJoCo's order).
    pub fn polygon(&self, p: usize) -> &[u32] {
        &self.poly[self.poly_start[p] as usize..self.poly_start[p + 1] as usize]
    }

    /// The polygons holding vertex `v`, ascending.
    pub fn vertex_polygons(&self, v: usize) -> &[u32] {
        &self.vpolys[self.vpoly_start[v] as usize..self.vpoly_start[v + 1] as usize]
    }

    /// Vertex `v`'s neighbours along the hull's edges, in MuJoCo's order.
    pub fn neighbours(&self, v: usize) -> &[u32] {
        &self.adj[self.adj_start[v] as usize..self.adj_start[v + 1] as usize]
    }
}

/// Why `points` span no volume, by MuJoCo's checks before it runs qhull (`MakeGraph`: a second
/// point apart from the first, a third off their line, a fourth off their plane, each beyond
/// `mjMINVAL` = 1e-15); None when they do. Fewer than 4 distinct points count as degenerate too
/// (MuJoCo builds no hull for fewer than 4 vertices).
fn degenerate(points: &[Vec3]) -> Option<String> {
    const MINVAL: f64 = 1e-15;
    let mut distinct: Vec<[u64; 3]> =
        points.iter().map(|v| [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()]).collect();
    distinct.sort_unstable();
    distinct.dedup();
    if distinct.len() < 4 {
        return Some(format!("it has {} distinct vertices, fewer than the 4 of a solid", distinct.len()));
    }
    if points.iter().any(|v| !v.iter().all(|x| x.is_finite())) {
        return Some("a vertex is not finite".to_string());
    }
    let p0 = points[0];
    let Some(i1) = (1..points.len()).find(|&i| (points[i] - p0).norm() > MINVAL) else {
        return Some("all vertices are at one point".to_string());
    };
    let edge1 = points[i1] - p0;
    let len1 = edge1.norm();
    let normal = (1..points.len()).filter(|&i| i != i1).find_map(|i| {
        let edge2 = points[i] - p0;
        let len2 = edge2.norm();
        if len2 < MINVAL {
            return None;
        }
        let n = edge1.cross(&edge2);
        let norm = n.norm();
        (norm > MINVAL * len1 * len2).then(|| n / norm)
    });
    let Some(normal) = normal else {
        return Some("all vertices are on one line".to_string());
    };
    let d = normal.dot(&p0);
    if !points.iter().any(|p| (normal.dot(p) - d).abs() > MINVAL * len1) {
        return Some("all vertices are in one plane".to_string());
    }
    None
}

/// A polygon's unit normal as MuJoCo 4.0.0 has it (`mesh_polynormal`): its vector area, the sum
/// of the fan triangles' cross products from its first vertex (equal to the sum over the hull
/// triangles merged into it), normalised. The live library's normals are not its first three
/// vertices' (its source snapshot's `MakePolygonNormals`): on a merged, slightly curved polygon
/// whose first vertices lie nearly on a line the two differ by degrees (a G1 palm mesh's
/// 10-vertex polygon: 0.77°), and the face clipped against another geom with them. (1, 0, 0) when degenerate.
fn polygon_normal(vertices: &[Vec3], path: &[u32]) -> Vec3 {
    let v0 = vertices[path[0] as usize];
    let mut n = Vec3::zeros();
    for w in path[1..].windows(2) {
        n += (vertices[w[0] as usize] - v0).cross(&(vertices[w[1] as usize] - v0));
    }
    let norm = n.dot(&n).sqrt();
    if norm < 1e-14 {
        return Vec3::x();
    }
    n / norm
}

/// MuJoCo's `MeshPolygonKey`: the triangle's normal's azimuth and polar angle rounded to
/// multiples of `tol` (None for a degenerate triangle).
fn polygon_key(v1: &Vec3, v2: &Vec3, v3: &Vec3, tol: f64) -> Option<(f64, f64)> {
    let n = (v2 - v1).cross(&(v3 - v1));
    let norm = n.dot(&n).sqrt();
    if norm < 1e-15 {
        return None;
    }
    // + 0.0 turns −0 into +0 (atan2 tells them apart)
    let n = Vec3::new(n.x / norm + 0.0, n.y / norm + 0.0, n.z / norm + 0.0);
    if n.z.abs() > 1.0 - 1e-7 {
        let phi = if n.z < 0.0 { (std::f64::consts::PI / tol).round() } else { 0.0 };
        return Some((0.0, phi));
    }
    Some(((n.y.atan2(n.x) / tol).round(), (n.z.acos() / tol).round()))
}

/// One key's triangles merged into islands (MuJoCo's `MeshPolygon`).
struct Polygon {
    edges: Vec<(u32, u32)>,
    islands: Vec<i32>,
    nisland: i32,
}

impl Polygon {
    fn new(v1: u32, v2: u32, v3: u32) -> Self {
        Self { edges: vec![(v1, v2), (v2, v3), (v3, v1)], islands: vec![0, 0, 0], nisland: 1 }
    }

    fn combine(&mut self, island1: &mut i32, island2: &mut i32) {
        if *island2 < *island1 {
            std::mem::swap(island1, island2);
        }
        for k in self.islands.iter_mut() {
            if *k == *island2 {
                *k = *island1;
            } else if *k > *island2 {
                *k -= 1;
            }
        }
    }

    /// Removes the edge (b, a) if present (the face attaches along (a, b)); its island.
    fn take_reverse(&mut self, a: u32, b: u32) -> Option<i32> {
        let i = self.edges.iter().position(|&(f, s)| f == b && s == a)?;
        self.edges.remove(i);
        Some(self.islands.remove(i))
    }

    fn insert_face(&mut self, v1: u32, v2: u32, v3: u32) {
        let mut island = -1;
        let add1 = match self.take_reverse(v1, v2) {
            Some(i) => {
                island = i;
                false
            }
            None => true,
        };
        let mut add = [add1, true, true];
        for (k, (a, b)) in [(v2, v3), (v3, v1)].into_iter().enumerate() {
            if let Some(mut other) = self.take_reverse(a, b) {
                if island == -1 {
                    island = other;
                } else if other != island {
                    self.nisland -= 1;
                    self.combine(&mut island, &mut other);
                }
                add[k + 1] = false;
            }
        }
        if island == -1 {
            island = self.nisland;
            self.nisland += 1;
        }
        for (k, e) in [(v1, v2), (v2, v3), (v3, v1)].into_iter().enumerate() {
            if add[k] {
                self.edges.push(e);
                self.islands.push(island);
            }
        }
    }

    /// The islands' boundary paths (MuJoCo's `MeshPolygon::Paths`, its scan included: the search
    /// for the next edge starts at the second edge). A polygon of three edges is traced too: the
    /// live MuJoCo 4.0.0 does (a fan of three triangles keeps its orientation), where its source
    /// snapshot read the three edges' first vertices in list order.
    fn paths(&self) -> Vec<Vec<u32>> {
        let mut paths = Vec::new();
        for i in 0..self.nisland {
            let mut path = Vec::new();
            if let Some(j) = self.islands.iter().position(|&k| k == i) {
                path.push(self.edges[j].0);
                path.push(self.edges[j].1);
            }
            if path.is_empty() {
                continue;
            }
            let mut next = *path.last().unwrap_or(&0);
            for _ in 0..self.edges.len() {
                let mut finished = false;
                for k in 1..self.edges.len() {
                    if self.islands[k] == i && self.edges[k].0 == next {
                        next = self.edges[k].1;
                        if next == path[0] {
                            paths.push(std::mem::take(&mut path));
                            finished = true;
                            break;
                        }
                        path.push(next);
                        break;
                    }
                }
                if finished {
                    break;
                }
            }
        }
        paths
    }
}

/// MuJoCo's `MakePolygons` on the graph's triangles `faces` (global vertex ids into `file`):
/// the polygons (global ids) in MuJoCo's order.
fn make_polygons(file: &[Vec3], faces: &[[u32; 3]]) -> Vec<Vec<u32>> {
    const ANGLE_TOL: f64 = 0.01;
    let mut index: HashMap<(u64, u64), usize> = HashMap::new();
    let mut polygons: Vec<Polygon> = Vec::new();
    let mut order = LibcxxOrder::default();
    for f in faces {
        let [a, b, c] = f.map(|v| file[v as usize]);
        let Some((theta, phi)) = polygon_key(&a, &b, &c, ANGLE_TOL) else { continue };
        // −0 and +0 are one key (and hash alike)
        let key = ((theta + 0.0).to_bits(), (phi + 0.0).to_bits());
        match index.get(&key) {
            Some(&p) => polygons[p].insert_face(f[0], f[1], f[2]),
            None => {
                index.insert(key, polygons.len());
                polygons.push(Polygon::new(f[0], f[1], f[2]));
                order.insert(pair_hash(theta, phi));
            }
        }
    }
    let mut out = Vec::new();
    for p in order.iter() {
        for path in polygons[p].paths() {
            if path.len() >= 3 {
                out.push(path);
            }
        }
    }
    out
}

/// MuJoCo 4.0's hash of a polygon key: libc++'s `std::hash<double>` of each angle (the value's
/// bits; 0 for ±0) combined as `h1 ^ (h2 + 0x9e3779b9 + (h1 << 6) + (h1 >> 2))` (found against
/// the live MuJoCo 4.0.0: its source snapshot's plain xor does not give its polygon order).
fn pair_hash(theta: f64, phi: f64) -> u64 {
    let h = |x: f64| if x == 0.0 { 0 } else { x.to_bits() };
    let (h1, h2) = (h(theta), h(phi));
    h1 ^ h2.wrapping_add(0x9e37_79b9).wrapping_add(h1 << 6).wrapping_add(h1 >> 2)
}

/// The iteration order of libc++'s `std::unordered_map` with unique keys, given each newly
/// inserted key's hash in insertion order (`__hash_table::__emplace_unique_key_args`, `__rehash`,
/// `__do_rehash`): a singly linked list whose buckets each point at the node before their first
/// node; a new node goes first in its bucket, or first in the list when its bucket is empty;
/// the table grows to the next prime (or power of two) above 2n + 1 buckets when full.
#[derive(Default)]
struct LibcxxOrder {
    /// Node i + 1's hash (node 0 is the list's head sentinel).
    hash: Vec<u64>,
    /// Per node (0: the sentinel), the next node; NIL at the end.
    next: Vec<usize>,
    /// Per bucket, the node before its first node (NIL: empty).
    buckets: Vec<usize>,
}

const NIL: usize = usize::MAX;

impl LibcxxOrder {
    fn constrain(h: u64, bc: usize) -> usize {
        let bc = bc as u64;
        (if bc & (bc - 1) == 0 {
            h & (bc - 1)
        } else if h < bc {
            h
        } else {
            h % bc
        }) as usize
    }

    fn insert(&mut self, h: u64) {
        if self.next.is_empty() {
            self.next.push(NIL);
            self.hash.push(0);
        }
        let size = self.next.len() - 1;
        let bc = self.buckets.len();
        if (size + 1) as f32 > bc as f32 || bc == 0 {
            let pow2 = bc > 2 && bc & (bc - 1) == 0;
            let mut n = (2 * bc + usize::from(!pow2)).max(((size + 1) as f32).ceil() as usize);
            if n == 1 {
                n = 2;
            } else if n & (n - 1) != 0 {
                n = next_prime(n);
            }
            if n > bc {
                self.rehash(n);
            }
        }
        let bc = self.buckets.len();
        let node = self.next.len();
        self.next.push(NIL);
        self.hash.push(h);
        let chash = Self::constrain(h, bc);
        let pn = self.buckets[chash];
        if pn == NIL {
            self.next[node] = self.next[0];
            self.next[0] = node;
            self.buckets[chash] = 0;
            let after = self.next[node];
            if after != NIL {
                self.buckets[Self::constrain(self.hash[after], bc)] = node;
            }
        } else {
            self.next[node] = self.next[pn];
            self.next[pn] = node;
        }
    }

    fn rehash(&mut self, nbc: usize) {
        self.buckets = vec![NIL; nbc];
        let mut pp = 0;
        let mut cp = self.next[0];
        if cp == NIL {
            return;
        }
        let mut phash = Self::constrain(self.hash[cp], nbc);
        self.buckets[phash] = pp;
        pp = cp;
        cp = self.next[cp];
        while cp != NIL {
            let chash = Self::constrain(self.hash[cp], nbc);
            if chash == phash {
                pp = cp;
            } else if self.buckets[chash] == NIL {
                self.buckets[chash] = pp;
                pp = cp;
                phash = chash;
            } else {
                let b = self.buckets[chash];
                self.next[pp] = self.next[cp];
                self.next[cp] = self.next[b];
                self.next[b] = cp;
            }
            cp = self.next[pp];
        }
    }

    /// The inserted keys (0-based insertion index) in iteration order.
    fn iter(&self) -> impl Iterator<Item = usize> + '_ {
        let mut at = if self.next.is_empty() { NIL } else { self.next[0] };
        std::iter::from_fn(move || {
            if at == NIL {
                return None;
            }
            let node = at;
            at = self.next[node];
            Some(node - 1)
        })
    }
}

/// The smallest prime ≥ n (libc++'s `__next_prime`).
fn next_prime(n: usize) -> usize {
    let is_prime = |m: usize| {
        if m < 2 {
            return false;
        }
        let mut d = 2;
        while d * d <= m {
            if m.is_multiple_of(d) {
                return false;
            }
            d += 1;
        }
        true
    };
    let mut m = n.max(2);
    while !is_prime(m) {
        m += 1;
    }
    m
}

/// The distinct vertices of `vertices` in first-occurrence order (MuJoCo's `ProcessVertices`
/// with repeated vertices removed: equal bit patterns are one vertex), and per input vertex its
/// index among them.
pub fn distinct_vertices(vertices: &[Vec3]) -> (Vec<Vec3>, Vec<u32>) {
    let mut seen: HashMap<[u64; 3], u32> = HashMap::with_capacity(vertices.len());
    let mut out = Vec::new();
    let mut map = Vec::with_capacity(vertices.len());
    for v in vertices {
        let key = [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()];
        let id = *seen.entry(key).or_insert_with(|| {
            out.push(*v);
            (out.len() - 1) as u32
        });
        map.push(id);
    }
    (out, map)
}
