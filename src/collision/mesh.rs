//! The geometry of a mesh geom that the geometric queries need beyond the collision hull: its
//! triangles (MuJoCo's `mj_ray` intersects a mesh's triangles, `mj_rayMesh` / `mju_rayTree` in
//! engine_ray.c, through a bounding-volume tree) and its convex hull as a support-map shape (what
//! `mj_geomDistance` measures a mesh by, as collision does). Visual meshes count: a ray hits them
//! and a distance sensor may name one.
//!
//! MuJoCo reads every mesh when it compiles a model; lagrange reads a mesh geom's file only when a
//! ray or a distance first needs it (loading a model with many visual meshes costs nothing for
//! them), once per file and scale, behind a [`OnceLock`] shared by the geoms that use the file.
//! The vertices stay in the mesh file's frame after scaling (the frame lagrange places a mesh geom
//! in) and in f64; MuJoCo moves them to the mesh's inertial frame and stores them as f32, so its
//! results differ from these by the f32 rounding of the vertices (a few 1e-8 of the mesh's size).

use super::convex::ConvexShape;
use crate::mass::{self, TriangleMesh};
use crate::spatial::Vec3;
use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::math::Vector;
use parry3d_f64::partitioning::{Bvh, BvhBuildStrategy};
use std::path::Path;
use std::sync::{Arc, OnceLock};

/// A mesh geom's file, with its triangles and hull read on first use (see the module
/// documentation).
#[derive(Debug)]
pub struct GeomMesh {
    source: mass::MeshSource,
    scale: Vec3,
    triangles: OnceLock<Result<MeshTriangles, String>>,
    hull: OnceLock<Result<MeshHull, String>>,
}

/// Two mesh geoms are equal when they read the same file (or inline asset) at the same scale.
impl PartialEq for GeomMesh {
    fn eq(&self, other: &Self) -> bool {
        self.source == other.source && self.scale == other.scale
    }
}

/// A mesh's triangles in the geom frame, with a bounding-volume tree over them for ray casting.
#[derive(Clone, Debug)]
pub struct MeshTriangles {
    /// Vertex positions in the geom frame (m).
    pub vertices: Vec<Vec3>,
    /// Triangles as indices into `vertices`, counter-clockwise seen from outside (the file's
    /// winding; a ray reports the normal of this winding, as MuJoCo does).
    pub triangles: Vec<[u32; 3]>,
    /// The tree over the triangles' bounding boxes (leaf i: triangle i), each box loosened by a
    /// small fraction of the mesh's size so that a flat triangle's box has volume.
    pub(crate) bvh: Bvh,
}

/// A mesh's convex hull: its vertices (what the plane closed form walks) and its support-map
/// shape (what GJK and EPA use).
#[derive(Clone, Debug)]
pub struct MeshHull {
    /// The hull's vertices in the geom frame (m).
    pub vertices: Vec<Vec3>,
    /// The hull as a support-map shape.
    pub shape: ConvexShape,
}

impl GeomMesh {
    /// The mesh from `source`, scaled by `scale` (nothing is read yet).
    pub fn new(source: mass::MeshSource, scale: Vec3) -> Self {
        Self { source, scale, triangles: OnceLock::new(), hull: OnceLock::new() }
    }

    /// The mesh file (None for an inline mesh).
    pub fn path(&self) -> Option<&Path> {
        self.source.path()
    }

    /// Where the mesh's triangles come from.
    pub fn source(&self) -> &mass::MeshSource {
        &self.source
    }

    /// The scale applied to the file's vertices.
    pub fn scale(&self) -> Vec3 {
        self.scale
    }

    /// The triangles, read from the file on the first call.
    ///
    /// # Errors
    /// Why the file cannot be read (missing, or a format lagrange does not decode), as text; every
    /// later call returns the same.
    pub fn triangles(&self) -> Result<&MeshTriangles, &str> {
        self.triangles
            .get_or_init(|| {
                let mesh = self.source.read(&self.scale).map_err(|e| e.to_string())?;
                Ok(MeshTriangles::new(mesh))
            })
            .as_ref()
            .map_err(String::as_str)
    }

    /// The convex hull, computed on the first call (qhull on the triangles' scaled vertices, with
    /// MuJoCo's degeneracy checks, [`super::mesh_graph::MeshGraph`]).
    ///
    /// # Errors
    /// Why the file cannot be read or its points span no volume, as text.
    pub fn hull(&self) -> Result<&MeshHull, &str> {
        self.hull
            .get_or_init(|| {
                let triangles = self.triangles().map_err(str::to_string)?;
                let (points, _) = super::mesh_graph::distinct_vertices(&triangles.vertices);
                let graph = super::mesh_graph::MeshGraph::new(&points, &points, &points, -1)
                    .map_err(|e| format!("its convex hull fails: {e}"))?;
                let vertices = graph.vertices.clone();
                let shape =
                    ConvexShape::Hull(Box::new(super::hull_support::HullSupport::new(Arc::new(graph))));
                Ok(MeshHull { vertices, shape })
            })
            .as_ref()
            .map_err(String::as_str)
    }
}

impl MeshTriangles {
    /// The triangles of `mesh` (indices out of range are dropped) and their tree.
    fn new(mesh: TriangleMesh) -> Self {
        let n = mesh.vertices.len();
        let triangles: Vec<[u32; 3]> =
            mesh.triangles.into_iter().filter(|t| t.iter().all(|&i| (i as usize) < n)).collect();
        let vertices = mesh.vertices;
        let size = vertices.iter().map(|v| v.amax()).fold(0.0, f64::max);
        let pad = 1e-9 * size.max(1e-300);
        let boxes: Vec<Aabb> = triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| vertices[i as usize]);
                let lo = a.inf(&b).inf(&c).add_scalar(-pad);
                let hi = a.sup(&b).sup(&c).add_scalar(pad);
                Aabb::new(Vector::new(lo.x, lo.y, lo.z), Vector::new(hi.x, hi.y, hi.z))
            })
            .collect();
        let bvh = Bvh::from_leaves(BvhBuildStrategy::Binned, &boxes);
        Self { vertices, triangles, bvh }
    }

    /// The corners of triangle `t`.
    #[inline]
    pub fn corners(&self, t: usize) -> [Vec3; 3] {
        self.triangles[t].map(|i| self.vertices[i as usize])
    }
}
