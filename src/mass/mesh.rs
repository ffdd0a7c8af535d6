//! Triangle meshes: reading and mass properties. (Placeholder until the mass-properties work lands:
//! every call reports that mesh inertia is not available, never a wrong number.)

use super::{Distribution, MeshInertia};
use crate::spatial::{RigidInertia, Vec3};
use std::path::Path;
use thiserror::Error;

/// A triangle mesh in its file's coordinates, scale applied.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriangleMesh {
    pub vertices: Vec<Vec3>,
    pub triangles: Vec<[u32; 3]>,
}

/// Why a mesh cannot be read or cannot give mass properties.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum MeshError {
    #[error("mesh inertia is not implemented yet; give the body an explicit <inertial>")]
    Unsupported,
}

/// Reads an STL or OBJ file and applies `scale`.
pub fn read_mesh(_path: &Path, _scale: &Vec3) -> Result<TriangleMesh, MeshError> {
    Err(MeshError::Unsupported)
}

/// Volume (or area for shells) and unit-density mass properties of a mesh, in the mesh frame.
pub fn mesh_inertia(_mesh: &TriangleMesh, _mode: MeshInertia) -> Result<(f64, RigidInertia), MeshError> {
    let _ = Distribution::Volume;
    Err(MeshError::Unsupported)
}
