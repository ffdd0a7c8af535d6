//! Convex hulls of mesh geoms that take part in collisions: MuJoCo collides a mesh by its convex
//! hull (MuJoCo documentation, "Modeling → Meshes": "the collision geometry of a mesh is its convex
//! hull"). The hull is computed once per compile with parry's quickhull (`mass::convex_hull`, MuJoCo's degeneracy checks), in the mesh file's frame
//! after scaling (the frame in which lagrange places a mesh geom); each file and scale is read once.

use super::{LinkWord, LoadError};
use crate::mass;
use crate::model::spec::{GeomSpec, Shape};
use crate::spatial::Vec3;
use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::Arc;

/// Hull vertices by (file, scale).
#[derive(Default)]
pub struct HullCache {
    entries: HashMap<(PathBuf, [u64; 3]), Arc<Vec<Vec3>>>,
}

/// The hull vertices of `g` if it is a colliding mesh geom (None for primitives and for meshes
/// with contype = conaffinity = 0). A mesh whose points span no volume (fewer than 4 points, all
/// coplanar or collinear) has no hull: a typed error naming the geom's file and line. A mesh file
/// that cannot be read (missing, or a format lagrange does not decode, such as COLLADA) is a
/// warning in `warnings` and None: the geom does not collide (a dynamics model stays loadable; the
/// warning says what is lost).
pub fn geom_hull(
    g: &GeomSpec,
    what: LinkWord,
    link: &str,
    cache: &mut HullCache,
    warnings: &mut Vec<String>,
) -> Result<Option<Arc<Vec<Vec3>>>, LoadError> {
    let Shape::Mesh { path, scale } = &g.shape else { return Ok(None) };
    if !g.collision {
        return Ok(None);
    }
    let key = (path.clone(), [scale.x.to_bits(), scale.y.to_bits(), scale.z.to_bits()]);
    if let Some(h) = cache.entries.get(&key) {
        return Ok(Some(h.clone()));
    }
    let err = |reason: String| LoadError::MeshHull {
        loc: g.loc.clone(),
        what,
        link: link.to_string(),
        path: path.display().to_string(),
        reason,
    };
    let mesh = match mass::read_mesh(path, scale) {
        Ok(m) => m,
        Err(e) => {
            warnings.push(format!(
                "{}: {what} '{link}': collision mesh '{}' cannot be read ({e}): the geom does not collide",
                g.loc,
                path.display()
            ));
            return Ok(None);
        }
    };
    let hull = mass::convex_hull(&mesh.vertices).map_err(|e| match e {
        mass::MeshError::Hull { detail } => err(detail),
        other => err(other.to_string()),
    })?;
    let vertices = Arc::new(hull.vertices);
    cache.entries.insert(key, vertices.clone());
    Ok(Some(vertices))
}
