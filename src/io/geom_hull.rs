//! Convex hulls of mesh geoms that take part in collisions: MuJoCo collides a mesh by its convex
//! hull (MuJoCo documentation, "Modeling → Meshes": "the collision geometry of a mesh is its convex
//! hull"). The hull is computed once per compile with qhull as MuJoCo's compiler runs it, on the
//! file's unscaled vertices ([`crate::collision::mesh_graph`]: MuJoCo's vertex, edge and polygon
//! orders), and placed in the mesh file's frame after scaling (the frame in which lagrange places
//! a mesh geom); each file, scale and inertia mode is read once.
//!
//! The hull's vertices are placed where MuJoCo's collision reads them (`mjCMesh::Process`,
//! user_mesh.cc): MuJoCo moves a mesh to its inertial frame — the centre of mass `c` of the mesh's
//! `inertia` mode, axes the principal axes `R` of its compiler's eigen-solver — and stores each
//! vertex `Rᵀ (v − c)` as an `f32` (`mesh_vert`); its geom frame is the file frame moved by
//! (c, R). Each hull vertex here is that `f32` vertex mapped back to the file frame,
//! `c + R f32(Rᵀ (v − c))`, so that world points agree with MuJoCo's to f64 round-off (the `f32`
//! rounding moved them by up to ~6e-8 of the mesh's size). Which way each coordinate rounds
//! depends on c and R to ~1e-13 m, so they are computed here with MuJoCo's own sums
//! (`ComputeFaceCentroid`, `ComputeVolume`, `ComputeInertia`) and its compiler's Jacobi
//! eigen-solver (`mjuu_eig3` as MuJoCo 4.0 runs it: tangent half-angles, stopping when the largest
//! off-diagonal entry is below 1e-12 of its diagonal or the rotation's cosine above 1 − 1e-12),
//! not with lagrange's mass module (which converges further: its axes differ by up to ~1e-8).

use super::{LinkWord, LoadError};
use crate::collision::mesh_graph::{distinct_vertices, MeshGraph};
use crate::mass;
use crate::model::spec::{GeomSpec, Shape};
use crate::spatial::{quat_to_matrix, Mat3, Vec3};
use std::collections::HashMap;
use std::sync::Arc;

/// A colliding mesh's hull: MuJoCo's graph and polygons of it, its vertices in qhull's order
/// where collision reads them.
pub type GeomHull = Arc<MeshGraph>;

/// Hull vertices and graphs by (file, scale, inertia mode).
#[derive(Default)]
pub struct HullCache {
    entries: HashMap<(mass::MeshSource, [u64; 3], mass::MeshInertia), GeomHull>,
}

/// The hull of `g` if it is a colliding mesh geom (None for primitives and for meshes with
/// contype = conaffinity = 0): its vertices (qhull's order, where MuJoCo's collision reads them)
/// and MuJoCo's graph and polygons of it. A mesh whose points span no volume (fewer than 4 points,
/// all coplanar or collinear) or that qhull cannot hull has no hull: a typed error naming the
/// geom's file and line. A mesh file that cannot be read (missing, or a format lagrange does not
/// decode, such as COLLADA) is a warning in `warnings` and None: the geom does not collide (a
/// dynamics model stays loadable; the warning says what is lost).
pub fn geom_hull(
    g: &GeomSpec,
    what: LinkWord,
    link: &str,
    cache: &mut HullCache,
    warnings: &mut Vec<String>,
) -> Result<Option<GeomHull>, LoadError> {
    let Shape::Mesh { source, scale } = &g.shape else { return Ok(None) };
    if !g.collision {
        return Ok(None);
    }
    let key = (source.clone(), [scale.x.to_bits(), scale.y.to_bits(), scale.z.to_bits()], g.mesh_inertia);
    if let Some(h) = cache.entries.get(&key) {
        return Ok(Some(h.clone()));
    }
    let err = |reason: String| LoadError::MeshHull {
        loc: g.loc.clone(),
        what,
        link: link.to_string(),
        path: source.to_string(),
        reason,
    };
    // The file's vertices as read (qhull runs on them unscaled, as MuJoCo's compiler does), then
    // scaled.
    let read = if scale.iter().all(|s| s.is_finite()) {
        source.read(&Vec3::repeat(1.0))
    } else {
        Err(mass::MeshError::BadScale { x: scale.x, y: scale.y, z: scale.z })
    };
    let file = match read {
        Ok(m) => m,
        Err(e) => {
            warnings.push(format!(
                "{}: {what} '{link}': collision mesh '{}' cannot be read ({e}): the geom does not collide",
                g.loc, source
            ));
            return Ok(None);
        }
    };
    let mut mesh = file.clone();
    mesh.apply_scale(scale);
    // MuJoCo removes repeated vertices of STL files (its OBJ and MSH readers and inline vertices
    // keep them): the vertex list qhull numbers.
    let stl = source.path().and_then(|p| p.extension()).is_some_and(|e| e.eq_ignore_ascii_case("stl"));
    let (unscaled, scaled): (Vec<Vec3>, Vec<Vec3>) = if stl {
        let (distinct, map) = distinct_vertices(&file.vertices);
        let mut scaled = vec![Vec3::zeros(); distinct.len()];
        for (i, &d) in map.iter().enumerate().rev() {
            scaled[d as usize] = mesh.vertices[i];
        }
        (distinct, scaled)
    } else {
        (file.vertices.clone(), mesh.vertices.clone())
    };
    let mut placed = scaled.clone();
    let frame = mujoco_mesh_frame(&mesh, g.mesh_inertia);
    if let Some((com, r)) = frame {
        round_as_mujoco(&mut placed, &com, &r);
    }
    let mut graph = MeshGraph::new(&unscaled, &scaled, &placed, -1).map_err(|e| err(e.to_string()))?;
    if let Some(frame) = frame {
        graph.box_frame = frame;
        let (com, r) = frame;
        graph.mujoco_vertices =
            graph.globalid.iter().map(|&gid| mujoco_stored(&scaled[gid as usize], &com, &r)).collect();
    }
    let entry = Arc::new(graph);
    cache.entries.insert(key, entry.clone());
    Ok(Some(entry))
}

/// Moves `vertices` (file frame) to where MuJoCo's `f32` copies of them lie (see the module
/// documentation): `c + R f32(Rᵀ (v − c))`, `c` the mesh's centre of mass and `R` its principal
/// axes as MuJoCo's compiler finds them ([`mujoco_mesh_frame`]).
pub(crate) fn round_as_mujoco(vertices: &mut [Vec3], com: &Vec3, r: &Mat3) {
    for v in vertices {
        *v = com + r * mujoco_stored(v, com, r);
    }
}

/// Where MuJoCo's compiler stores vertex `v` (file frame): `f32(Rᵀ (v − c))`, in its mesh frame.
fn mujoco_stored(v: &Vec3, com: &Vec3, r: &Mat3) -> Vec3 {
    (r.transpose() * (v - com)).map(|a| f64::from(a as f32))
}

/// Area (0 below 1e-15 of twice it, as MuJoCo ignores such faces), unit normal and centre of a
/// triangle (`triangle` in user_mesh.cc).
fn triangle(a: &Vec3, b: &Vec3, c: &Vec3) -> (f64, Vec3, Vec3) {
    let center = (a + b + c) / 3.0;
    let n = (b - a).cross(&(c - a));
    let len = n.dot(&n).sqrt();
    if len < 1e-15 {
        return (0.0, n, center);
    }
    (0.5 * len, n / len, center)
}

/// MuJoCo's inertial frame of a mesh (`mjCMesh::Process`): the centre of mass of its `mode`
/// (legacy or exact; None for convex and shell meshes, and for a mesh without volume, whose
/// vertices are then kept as read) and the principal axes of its inertia about it, summed in
/// MuJoCo's order.
fn mujoco_mesh_frame(mesh: &mass::TriangleMesh, mode: mass::MeshInertia) -> Option<(Vec3, Mat3)> {
    let legacy = match mode {
        mass::MeshInertia::Legacy => true,
        mass::MeshInertia::Exact => false,
        mass::MeshInertia::Convex | mass::MeshInertia::Shell => return None,
    };
    let corners = |t: &[u32; 3]| t.map(|i| mesh.vertices[i as usize]);
    let (mut facecen, mut total_area) = (Vec3::zeros(), 0.0);
    for t in &mesh.triangles {
        let [a, b, c] = corners(t);
        let (area, _, center) = triangle(&a, &b, &c);
        facecen += center * area;
        total_area += area;
    }
    if total_area.is_nan() || total_area < 1e-15 {
        return None;
    }
    facecen /= total_area;
    let (mut com, mut total_volume) = (Vec3::zeros(), 0.0);
    for t in &mesh.triangles {
        let [a, b, c] = corners(t);
        let (area, normal, center) = triangle(&a, &b, &c);
        let mut volume = (center - facecen).dot(&normal) * area / 3.0;
        if legacy {
            volume = volume.abs();
        }
        total_volume += volume;
        com += (center * 3.0 / 4.0 + facecen / 4.0) * volume;
    }
    if total_volume.is_nan() || total_volume < 1e-15 {
        return None;
    }
    com /= total_volume;
    // Products of inertia about the centre of mass (`ComputeInertia`).
    const K: [(usize, usize); 6] = [(0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)];
    let mut p = [0.0; 6];
    for t in &mesh.triangles {
        let [d, e, f] = corners(t).map(|v| v - com);
        let (area, normal, center) = triangle(&d, &e, &f);
        let mut volume = center.dot(&normal) * area / 3.0;
        if legacy {
            volume = volume.abs();
        }
        for (j, &(k0, k1)) in K.iter().enumerate() {
            p[j] += volume / 20.0
                * (2.0 * (d[k0] * d[k1] + e[k0] * e[k1] + f[k0] * f[k1])
                    + d[k0] * e[k1]
                    + d[k1] * e[k0]
                    + d[k0] * f[k1]
                    + d[k1] * f[k0]
                    + e[k0] * f[k1]
                    + e[k1] * f[k0]);
        }
    }
    let inert = Mat3::new(p[1] + p[2], -p[3], -p[4], -p[3], p[0] + p[2], -p[5], -p[4], -p[5], p[0] + p[1]);
    let [w, x, y, z] = crate::mass::eig3::principal_quat(&inert, &crate::mass::eig3::MESH);
    Some((com, quat_to_matrix(w, x, y, z)))
}
