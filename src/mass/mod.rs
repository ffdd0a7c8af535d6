//! Mass properties of primitives and triangle meshes (docs/architecture.md, "Layers").
//!
//! Every function returns a [`RigidInertia`] expressed in the shape's own frame (mass, first
//! moment, rotational inertia about the frame origin), so placing a shape in a body is
//! [`RigidInertia::transformed`] and composing shapes is `+=` or [`compose`] (docs/physics.md §3, eq. 56
//! and 81–83).
//!
//! - `primitive`: MuJoCo's closed forms for spheres, capsules, cylinders, boxes and ellipsoids,
//!   solid and shell (`mjCGeom::GetVolume`, `mjCGeom::SetInertia`).
//! - `mesh_io`: [`read_mesh`] for STL (binary, ASCII), OBJ and MuJoCo MSH files, scale applied.
//! - `mesh`: [`mesh_inertia`] in MuJoCo's four mesh modes ([`MeshInertia`]), exact polyhedral
//!   integrals, refusing meshes that do not bound the solid the mode needs ([`MeshError`]).
//! - `topology`: closedness and orientation of a mesh ([`Topology`]).
//! - `principal`: principal moments and axes, parallel-axis shift, tensor rotation,
//!   composition.
//! - `eig3`: principal axes oriented as MuJoCo's compiler orients them (bodies, mesh frames).
//! - `error`: [`MeshError`], whose messages name the defect and the fix.
//!
//! The convex hull (convex mode) is parry3d-f64's; every other integral is computed here, in
//! MuJoCo's order of operations (`mjCMesh::Process`), because MuJoCo's legacy mode (its default)
//! has no counterpart in parry and the other modes must agree with MuJoCo to round-off.

pub(crate) mod eig3;
mod error;
mod fast_hash;
mod mesh;
mod mesh_io;
mod mesh_source;
mod primitive;
mod principal;
mod topology;

pub use error::MeshError;
pub use mesh::{convex_hull, mesh_inertia, mesh_inertia_as_mujoco, TriangleMesh};
pub use mesh_io::{read_mesh, read_mesh_with, ObjObjects, ReadOptions};
pub use mesh_source::MeshSource;
pub use primitive::{primitive_inertia, primitive_measure, Primitive};
pub use principal::{
    compose, parallel_axis, principal, principal_angle_xy, principal_axes, rotate_tensor, Principal,
};
pub use topology::Topology;

use crate::spatial::RigidInertia;

/// How mass is spread over a shape: through its volume (a solid) or over its surface (a thin
/// shell, MJCF `shellinertia="true"` / mesh `inertia="shell"`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Distribution {
    /// A solid: mass through the volume.
    #[default]
    Volume,
    /// A thin shell: mass on the surface.
    Shell,
}

/// How a geometry's mass is given.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum GeomMass {
    /// The geometry carries no mass (URDF visuals, MJCF geoms outside the inertia groups).
    #[default]
    None,
    /// Mass = density × volume (kg/m³), or × area for shells (kg/m²).
    Density(f64),
    /// A total mass (kg); the density follows from the volume or area.
    Mass(f64),
}

/// The mass of `measure` (a volume or an area) under `mass`, MuJoCo's rule: an explicit mass wins,
/// else density × measure.
pub fn resolve_mass(mass: GeomMass, measure: f64) -> f64 {
    match mass {
        GeomMass::None => 0.0,
        GeomMass::Density(rho) => rho * measure,
        GeomMass::Mass(m) => m,
    }
}

/// Scales a unit-density inertia (as the mesh routines return) to the given total mass.
pub fn scaled_to_mass(unit: &RigidInertia, mass: f64) -> RigidInertia {
    if unit.mass <= 0.0 {
        return RigidInertia::zero();
    }
    // The mass is set exactly; first moment and inertia scale with it.
    RigidInertia { mass, ..unit.scaled(mass / unit.mass) }
}

/// MuJoCo's mesh inertia modes (`<mesh inertia="...">`; MuJoCo's default is `legacy`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum MeshInertia {
    /// The solid convex hull of the mesh.
    Convex,
    /// The solid the closed, consistently oriented mesh encloses.
    Exact,
    /// MuJoCo's historical rule: the mesh's tetrahedra about its centroid with their volumes
    /// taken as absolute values (tolerates misoriented faces, overcounts non-convex meshes).
    #[default]
    Legacy,
    /// A thin shell over the mesh surface.
    Shell,
}
