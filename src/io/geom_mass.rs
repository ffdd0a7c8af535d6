//! Mass properties of a spec geom (MuJoCo `inertiafromgeom`): primitives in closed form, meshes
//! through [`crate::mass`], each mesh file read once per compile.

use super::{LinkWord, LoadError};
use crate::mass::{self, GeomMass, MeshInertia, Primitive};
use crate::model::spec::{GeomSpec, Shape};
use crate::spatial::{RigidInertia, Vec3};
use std::collections::HashMap;

/// Unit-density mesh mass properties by (file, scale, mode), so that a mesh used by several geoms
/// is read and integrated once.
#[derive(Default)]
pub struct MeshCache {
    entries: HashMap<(mass::MeshSource, [u64; 3], MeshInertia), (f64, RigidInertia)>,
}

/// The mass properties a geom contributes to its link, in the geom's frame.
/// `what` is "link" (URDF) or "body" (MJCF), for messages.
pub fn geom_inertia(
    g: &GeomSpec,
    what: LinkWord,
    link: &str,
    meshes: &mut MeshCache,
    warnings: &mut Vec<String>,
) -> Result<RigidInertia, LoadError> {
    // Massless geoms (visuals, `density="0"`, `mass="0"`) are never measured: a broken mesh used
    // only for drawing or collision is no error.
    if matches!(g.mass, GeomMass::None | GeomMass::Density(0.0) | GeomMass::Mass(0.0)) {
        return Ok(RigidInertia::zero());
    }
    let primitive = match &g.shape {
        Shape::Sphere { radius } => Primitive::Sphere { radius: *radius },
        Shape::Capsule { radius, length } => {
            Primitive::Capsule { radius: *radius, half_length: length / 2.0 }
        }
        Shape::Cylinder { radius, length } => {
            Primitive::Cylinder { radius: *radius, half_length: length / 2.0 }
        }
        Shape::Box { size } => Primitive::Box { half_extents: size / 2.0 },
        Shape::Ellipsoid { radii } => Primitive::Ellipsoid { radii: *radii },
        // Planes carry no mass; a height field weighs as MuJoCo's box of half-extents
        // size[0], size[1], size[2]/4 + size[3]/2 (its `geom_size`, mjCGeom::SetInertia).
        Shape::Plane { .. } => return Ok(RigidInertia::zero()),
        Shape::Hfield { field, .. } => Primitive::Box { half_extents: Vec3::from(field.mass_box()) },
        Shape::Mesh { source, scale } => {
            return mesh_geom_inertia(g, what, link, source, scale, meshes, warnings)
        }
    };
    let measure = mass::primitive_measure(&primitive, g.distribution);
    let m = mass::resolve_mass(g.mass, measure);
    Ok(mass::primitive_inertia(&primitive, g.distribution, m))
}

fn mesh_geom_inertia(
    g: &GeomSpec,
    what: LinkWord,
    link: &str,
    source: &mass::MeshSource,
    scale: &Vec3,
    meshes: &mut MeshCache,
    warnings: &mut Vec<String>,
) -> Result<RigidInertia, LoadError> {
    let key = (source.clone(), [scale.x.to_bits(), scale.y.to_bits(), scale.z.to_bits()], g.mesh_inertia);
    let (measure, unit) = match meshes.entries.get(&key) {
        Some(e) => *e,
        None => {
            let err = |e: mass::MeshError| LoadError::MeshMass {
                loc: g.loc.clone(),
                what,
                link: link.to_string(),
                path: source.to_string(),
                reason: e.to_string(),
            };
            let mesh = source.read(scale).map_err(err)?;
            let (e, open) = mass::mesh_inertia_as_mujoco(&mesh, g.mesh_inertia).map_err(err)?;
            if let Some(open) = open {
                // MuJoCo 4.0 integrates an open surface in these modes too: so do we, and say so.
                warnings.push(format!(
                    "{}: {what} '{link}': mesh '{}': {open}; its mass properties are MuJoCo's volume integrals over the open surface (inertia=\"{}\"), which depend on where the holes are",
                    g.loc,
                    source,
                    match g.mesh_inertia {
                        MeshInertia::Exact => "exact",
                        _ => "legacy",
                    }
                ));
            }
            meshes.entries.insert(key, e);
            e
        }
    };
    let m = mass::resolve_mass(g.mass, measure);
    Ok(mass::scaled_to_mass(&unit, m))
}
