//! Where a mesh geom's triangles come from: a file on disk (read when first needed) or an inline
//! asset whose vertices and faces the model itself gives (MJCF `<mesh vertex=… face=…>`, MuJoCo's
//! `mjCMesh` with `uservert`/`userface`). Inline triangles are kept once, in the mesh frame before
//! scale, and shared (one `Arc`) by every geom naming the asset.

use super::{MeshError, TriangleMesh};
use crate::spatial::Vec3;
use std::fmt;
use std::hash::{Hash, Hasher};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The source of a mesh's triangles.
#[derive(Clone, Debug)]
pub enum MeshSource {
    /// A mesh file (STL, OBJ, MSH), read lazily.
    File(PathBuf),
    /// Triangles given in the model (mesh frame, before scale).
    Inline {
        /// The asset's name (for messages).
        name: String,
        /// The vertices and triangles, shared by every geom naming the asset.
        mesh: Arc<TriangleMesh>,
    },
}

impl MeshSource {
    /// The file, if the mesh comes from one.
    pub fn path(&self) -> Option<&Path> {
        match self {
            MeshSource::File(p) => Some(p),
            MeshSource::Inline { .. } => None,
        }
    }

    /// The triangles with `scale` applied (a file is read now; an inline mesh is copied).
    ///
    /// # Errors
    /// A scale that is not finite, or why the file cannot be read.
    pub fn read(&self, scale: &Vec3) -> Result<TriangleMesh, MeshError> {
        match self {
            MeshSource::File(p) => super::read_mesh(p, scale),
            MeshSource::Inline { mesh, .. } => {
                if !(scale.x.is_finite() && scale.y.is_finite() && scale.z.is_finite()) {
                    return Err(MeshError::BadScale { x: scale.x, y: scale.y, z: scale.z });
                }
                let mut m = TriangleMesh::clone(mesh);
                m.apply_scale(scale);
                Ok(m)
            }
        }
    }
}

/// Two sources are equal when they name the same file or share the same inline asset.
impl PartialEq for MeshSource {
    fn eq(&self, other: &Self) -> bool {
        match (self, other) {
            (MeshSource::File(a), MeshSource::File(b)) => a == b,
            (MeshSource::Inline { mesh: a, .. }, MeshSource::Inline { mesh: b, .. }) => Arc::ptr_eq(a, b),
            _ => false,
        }
    }
}

impl Eq for MeshSource {}

impl Hash for MeshSource {
    fn hash<H: Hasher>(&self, state: &mut H) {
        match self {
            MeshSource::File(p) => p.hash(state),
            MeshSource::Inline { mesh, .. } => (Arc::as_ptr(mesh) as usize).hash(state),
        }
    }
}

/// The file's path, or `inline mesh 'NAME'`.
impl fmt::Display for MeshSource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MeshSource::File(p) => write!(f, "{}", p.display()),
            MeshSource::Inline { name, .. } => write!(f, "inline mesh '{name}'"),
        }
    }
}
