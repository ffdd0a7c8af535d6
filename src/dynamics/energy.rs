//! Energy, centre of mass and momentum of the moving bodies (docs/physics.md §2.1–2.2, §1.5). Bodies welded
//! to the world (body 0) are excluded, as in MuJoCo and Pinocchio.

use crate::error::{check, InputError};
#[cfg(doc)]
use crate::kinematics::{forward_kinematics, forward_velocities};
use crate::kinematics::{forward_kinematics_unchecked, forward_velocities_unchecked};
use crate::model::{Data, Model};
use crate::spatial::{Force, Vec3};

/// Kinetic energy T = Σ ½ vᵢ·Iᵢvᵢ + ½ Σ armature·v² (= ½ vᵀ M v, MuJoCo's definition). Runs forward
/// kinematics and velocities at (q, v).
///
/// # Errors
/// [`InputError::Length`] when q is not nq long, v not nv long, or `data` was made for another
/// model.
pub fn kinetic_energy(model: &Model, data: &mut Data, q: &[f64], v: &[f64]) -> Result<f64, InputError> {
    check::data("kinetic_energy", model, data)?;
    check::q("kinetic_energy", model, q)?;
    check::v("kinetic_energy", "v", model, v)?;
    data.poses_stamp.clear();
    data.velocity_stamp.clear();
    Ok(kinetic_energy_unchecked(model, data, q, v))
}

/// [`kinetic_energy`] without the argument checks.
pub(crate) fn kinetic_energy_unchecked(model: &Model, data: &mut Data, q: &[f64], v: &[f64]) -> f64 {
    forward_kinematics_unchecked(model, data, q);
    forward_velocities_unchecked(model, data, v);
    let bodies: f64 =
        (1..model.nbody()).map(|b| model.bodies[b].inertia.kinetic_energy(&data.v_body[b])).sum();
    let armature: f64 = model.dof_armature.iter().zip(v).map(|(a, vi)| 0.5 * a * vi * vi).sum();
    bodies + armature
}

/// Potential energy V = −Σ mᵢ g·cᵢ (zero at the world origin). Needs [`forward_kinematics`].
pub fn potential_energy(model: &Model, data: &Data) -> f64 {
    (1..model.nbody())
        .map(|b| {
            let inertia = &model.bodies[b].inertia;
            -inertia.mass * model.gravity.dot(&data.x_world_body[b].act_point(&inertia.com()))
        })
        .sum()
}

/// Centre of mass of the moving bodies in the world frame (docs/physics.md §2.1). Needs
/// [`forward_kinematics`]. The origin if they are massless.
pub fn center_of_mass(model: &Model, data: &Data) -> Vec3 {
    let mut first_moment = Vec3::zeros();
    let mut mass = 0.0;
    for b in 1..model.nbody() {
        let inertia = &model.bodies[b].inertia;
        first_moment += data.x_world_body[b].act_point(&inertia.com()) * inertia.mass;
        mass += inertia.mass;
    }
    if mass > 0.0 {
        first_moment / mass
    } else {
        Vec3::zeros()
    }
}

/// Spatial momentum in world coordinates: `lin` = linear momentum, `ang` = angular momentum about
/// the world origin. Needs [`forward_kinematics`] and [`forward_velocities`].
pub fn spatial_momentum(model: &Model, data: &Data) -> Force {
    let mut h = Force::zero();
    for b in 1..model.nbody() {
        let h_body = model.bodies[b].inertia.mul_motion(&data.v_body[b]);
        h += data.x_world_body[b].act_force(&h_body);
    }
    h
}
