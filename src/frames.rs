//! Poses, velocities and Jacobians of named frames — bodies (URDF links, MJCF bodies, fused or
//! not) and MJCF sites — at the state in `Data`. Each call computes the kinematics it needs at
//! `data.qpos` (and `data.qvel`) first, so the answer is never stale: `forward` on its ABA path
//! does not form world poses (a scene pays only for what it reads).
//!
//! Frames are looked up by name: a body or link of that name first, else a site (MuJoCo keeps
//! bodies and sites in separate namespaces). Velocities and Jacobians are in world axes at the
//! frame's origin (MuJoCo's `mj_jac`, Pinocchio's `LOCAL_WORLD_ALIGNED`); rows 0–2 linear, 3–5
//! angular.

use crate::error::InputError;
use crate::kinematics::{forward_kinematics_unchecked, forward_velocities_unchecked, ReferenceFrame};
use crate::model::{Data, Model};
use crate::spatial::{Transform, Vec3};
use nalgebra::DMatrix;

/// The frame's index, or the typed error listing some of the model's frame names.
fn frame_index(model: &Model, function: &'static str, name: &str) -> Result<usize, InputError> {
    model.frame_id(name).ok_or_else(|| {
        InputError::unknown_name(
            function,
            "body, link or site",
            name,
            model.frames.iter().map(|f| f.name.as_str()),
        )
    })
}

/// Forward kinematics at the state's configuration (the state moved out and back, no copy).
fn kinematics_at_state(model: &Model, data: &mut Data, velocities: bool) {
    let q = std::mem::take(&mut data.qpos);
    data.poses_stamp.clear();
    data.velocity_stamp.clear();
    forward_kinematics_unchecked(model, data, q.as_slice());
    data.qpos = q;
    if velocities {
        let v = std::mem::take(&mut data.qvel);
        forward_velocities_unchecked(model, data, v.as_slice());
        data.qvel = v;
    }
}

/// The world pose of frame `name` at `data.qpos`.
///
/// # Errors
/// [`InputError::Name`] when the model has no such body, link or site; [`InputError::Length`]
/// when `data` was not made for `model`.
///
/// # Example
/// ```
/// use lagrange::prelude::*;
/// let model = Model::from_file("models/ur5/ur5.urdf")?;
/// let mut data = Data::new(&model);
/// let tool = frames::pose(&model, &mut data, "tool0")?;
/// println!("tool at {:?}", tool.pos.as_slice());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn pose(model: &Model, data: &mut Data, name: &str) -> Result<Transform, InputError> {
    let f = frame_index(model, "frames::pose", name)?;
    data.check_sizes(model, "frames::pose")?;
    kinematics_at_state(model, data, false);
    Ok(data.x_world_frame[f])
}

/// The velocity (linear, angular) of frame `name`'s origin at (`data.qpos`, `data.qvel`), world
/// axes.
///
/// # Errors
/// As [`pose`].
///
/// # Example
/// ```
/// use lagrange::prelude::*;
/// let model = Model::from_file("models/ur5/ur5.urdf")?;
/// let mut data = Data::new(&model);
/// data.qvel[0] = 1.0; // the base joint turns about z at 1 rad/s
/// let (_, angular) = frames::velocity(&model, &mut data, "tool0")?;
/// assert!((angular[2] - 1.0).abs() < 1e-12);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn velocity(model: &Model, data: &mut Data, name: &str) -> Result<(Vec3, Vec3), InputError> {
    let f = frame_index(model, "frames::velocity", name)?;
    data.check_sizes(model, "frames::velocity")?;
    kinematics_at_state(model, data, true);
    Ok(crate::kinematics::frame_velocity_unchecked(model, data, f, ReferenceFrame::LocalWorldAligned))
}

/// The Jacobian of frame `name`'s origin at `data.qpos` into `jac` (6 × nv; rows 0–2 linear,
/// 3–5 angular, world axes): its velocity is `jac · qvel`.
///
/// # Errors
/// As [`pose`], and [`InputError::Length`] when `jac` is not 6 × nv.
///
/// # Example
/// ```
/// use lagrange::prelude::*;
/// let model = Model::from_file("models/ur5/ur5.urdf")?;
/// let mut data = Data::new(&model);
/// let mut jac = nalgebra::DMatrix::zeros(6, model.nv);
/// frames::jacobian(&model, &mut data, "tool0", &mut jac)?;
/// assert_eq!(jac[(5, 0)], 1.0); // the base joint turns the tool about world z
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn jacobian(
    model: &Model,
    data: &mut Data,
    name: &str,
    jac: &mut DMatrix<f64>,
) -> Result<(), InputError> {
    let f = frame_index(model, "frames::jacobian", name)?;
    data.check_sizes(model, "frames::jacobian")?;
    InputError::check_len("frames::jacobian", "jac (rows)", jac.nrows(), 6, "6")?;
    InputError::check_len("frames::jacobian", "jac (columns)", jac.ncols(), model.nv, "nv")?;
    kinematics_at_state(model, data, false);
    crate::kinematics::frame_jacobian_unchecked(model, data, f, ReferenceFrame::LocalWorldAligned, jac);
    Ok(())
}
