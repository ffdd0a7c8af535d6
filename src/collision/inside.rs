//! Whether a point lies inside a primitive shape: MuJoCo's `mju_insideGeom` (engine_util_misc.c),
//! what the `insidesite` sensor and the contact sensor's site filter use. Strictly inside: a point
//! on the surface is outside.
//!
//! | shape | inside when (in the shape's frame) |
//! |---|---|
//! | sphere | ‖p‖² < r² (world frame, no rotation) |
//! | capsule | x² + y² + (z − clamp(z, −h, h))² < r² |
//! | ellipsoid | Σ pᵢ² / rᵢ² < 1 |
//! | cylinder | \|z\| < h and x² + y² < r² |
//! | box | \|pᵢ\| < sᵢ on every axis |

use crate::error::InputError;
use crate::mass::Primitive;
use crate::model::{Data, Model};
use crate::spatial::{Transform, Vec3};

/// Whether `point` (world) is strictly inside `shape` at pose `x` (MuJoCo's `mju_insideGeom`).
pub(crate) fn inside_primitive(x: &Transform, shape: &Primitive, point: &Vec3) -> bool {
    let d = point - x.pos;
    if let Primitive::Sphere { radius } = *shape {
        return d.dot(&d) < radius * radius;
    }
    let p = x.rot.tr_mul(&d);
    match *shape {
        Primitive::Sphere { .. } => unreachable!("handled above"),
        Primitive::Capsule { radius, half_length } => {
            let dz = p.z - p.z.clamp(-half_length, half_length);
            p.x * p.x + p.y * p.y + dz * dz < radius * radius
        }
        Primitive::Ellipsoid { radii: r } => {
            p.x * p.x / (r.x * r.x) + p.y * p.y / (r.y * r.y) + p.z * p.z / (r.z * r.z) < 1.0
        }
        Primitive::Cylinder { radius, half_length } => {
            p.z.abs() < half_length && p.x * p.x + p.y * p.y < radius * radius
        }
        Primitive::Box { half_extents: s } => p.x.abs() < s.x && p.y.abs() < s.y && p.z.abs() < s.z,
    }
}

/// Whether `point_world` is strictly inside the shape of site `site` (an index in `Model::frames`
/// of an MJCF site) at its pose in `data` (after forward kinematics): MuJoCo's `mju_insideGeom` on
/// the site's type and size, as the `insidesite` sensor evaluates it.
///
/// # Errors
/// [`InputError`] when `data` was not made for `model`, `site` is not a site with a primitive
/// shape, or a coordinate is not finite.
pub fn inside_site(model: &Model, data: &Data, site: usize, point_world: Vec3) -> Result<bool, InputError> {
    const F: &str = "collision::inside_site";
    crate::error::check::data(F, model, data)?;
    let shape = super::ray::site_shape(F, model, site)?;
    InputError::check_finite(F, "point_world", point_world.as_slice())?;
    Ok(inside_primitive(&data.x_world_frame[site], &shape, &point_world))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spatial::Mat3;

    #[test]
    fn surface_points_are_outside() {
        let x = Transform::new(Mat3::identity(), Vec3::new(1.0, 0.0, 0.0));
        let shapes = [
            Primitive::Sphere { radius: 0.5 },
            Primitive::Capsule { radius: 0.5, half_length: 0.25 },
            Primitive::Ellipsoid { radii: Vec3::new(0.5, 0.5, 0.5) },
            Primitive::Cylinder { radius: 0.5, half_length: 0.5 },
            Primitive::Box { half_extents: Vec3::repeat(0.5) },
        ];
        for s in &shapes {
            assert!(inside_primitive(&x, s, &Vec3::new(1.25, 0.0, 0.0)), "{s:?}");
            assert!(!inside_primitive(&x, s, &Vec3::new(1.5, 0.0, 0.0)), "{s:?} surface");
            assert!(!inside_primitive(&x, s, &Vec3::new(0.0, 0.0, 0.0)), "{s:?} outside");
        }
    }
}
