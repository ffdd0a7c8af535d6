//! Inline `<mesh vertex="…" face="…">` assets as MuJoCo 4.0 reads them (`mjCMesh`, user_mesh.cc:
//! `CheckInitialMesh`, and `Compile` building the convex hull's faces when `face` is omitted):
//! `vertex` is 3n coordinates (at least 4 vertices; rounded to `f32` as MuJoCo stores them), `face` 3m vertex indices in range; `normal`
//! and `texcoord` are accepted and do not affect the dynamics. Without `face` the mesh's triangles
//! are those of its vertices' convex hull, which is then what its inertia integrates (MuJoCo copies
//! the hull graph into the faces, `CopyGraph`). MuJoCo's errors for bad counts and out-of-range
//! indices are typed load errors naming the element's line.

use super::attrs::Attrs;
use super::xml::Element;
use crate::io::LoadError;
use crate::mass::{self, TriangleMesh};
use crate::spatial::Vec3;
use std::sync::Arc;

/// The name and triangles (mesh frame, before scale) of an inline mesh element `e` (attributes
/// `a`, its default class applied).
pub(crate) fn inline_mesh(e: &Element, a: &Attrs) -> Result<(String, Arc<TriangleMesh>), LoadError> {
    let invalid = |detail: String| LoadError::Invalid { loc: e.loc.clone(), element: "mesh".into(), detail };
    let Some(coords) = a.numbers("vertex")? else {
        return Err(invalid(
            "a mesh without 'file' or 'builtin' needs 'vertex'; give 'file', 'builtin', or 'vertex' (and 'face')".into(),
        ));
    };
    let Some(name) = a.text("name") else {
        return Err(invalid("an inline mesh (no 'file') needs a 'name' for geoms to refer to it".into()));
    };
    if coords.len() % 3 != 0 {
        return Err(
            a.error("vertex", format!("has {} numbers: vertex data must be a multiple of 3", coords.len()))
        );
    }
    if coords.len() < 12 {
        return Err(
            a.error("vertex", format!("has {} vertices: at least 4 vertices required", coords.len() / 3))
        );
    }
    // MuJoCo keeps user vertices as `f32` (`mjsMesh.uservert`): so do we, before any sum.
    let f32_of = |x: f64| x as f32 as f64;
    let vertices: Vec<Vec3> =
        coords.chunks_exact(3).map(|c| Vec3::new(f32_of(c[0]), f32_of(c[1]), f32_of(c[2]))).collect();
    let mesh = match a.numbers("face")? {
        Some(face) if !face.is_empty() => {
            if face.len() % 3 != 0 {
                return Err(a.error(
                    "face",
                    format!("has {} numbers: face data must be a multiple of 3", face.len()),
                ));
            }
            let n = vertices.len();
            let mut triangles = Vec::with_capacity(face.len() / 3);
            for (t, f) in face.chunks_exact(3).enumerate() {
                let mut tri = [0u32; 3];
                for (k, &i) in f.iter().enumerate() {
                    if i.fract() != 0.0 || i < 0.0 || i >= n as f64 {
                        return Err(a.error(
                            "face",
                            format!(
                                "in face {t}, vertex index {i} does not exist (the mesh has {n} vertices)"
                            ),
                        ));
                    }
                    tri[k] = i as u32;
                }
                triangles.push(tri);
            }
            TriangleMesh { vertices, triangles }
        }
        _ => mass::convex_hull(&vertices).map_err(|err| {
            invalid(format!(
                "mesh '{name}' has no 'face', so its faces are its vertices' convex hull, which fails: {err}"
            ))
        })?,
    };
    Ok((name.to_string(), Arc::new(mesh)))
}
