//! Resetting a simulation's state: to the model's reference configuration at rest ([`reset`],
//! MuJoCo's `mj_resetData`) or to one of its keyframes ([`reset_keyframe`],
//! `mj_resetDataKeyframe`).

use super::{Data, Model};
use crate::error::InputError;

/// Resets `data` to `model`'s reference state: time 0, `qpos` = `qpos0`, and zero velocities,
/// activations, controls and applied forces (`qfrc_applied`, `xfrc_applied`), the control histories
/// as MuJoCo initialises them; the solvers' warm starts are cleared, so the next
/// step is the first of a new run, and the run-time warnings (`data.warnings`) are cleared
/// (MuJoCo's `mj_resetData`). Allocates nothing. The output
/// buffers keep their values until the next `forward`.
///
/// # Errors
/// [`InputError::Length`] when `data` was not made for `model`.
///
/// # Example
/// ```
/// use lagrange::prelude::*;
/// let model = Model::from_str(r#"<mujoco><worldbody><body><joint type="hinge"/>
///     <geom size="0.1"/></body></worldbody></mujoco>"#)?;
/// let mut data = Data::new(&model);
/// data.qpos[0] = 1.0;
/// data.time = 3.0;
/// reset(&model, &mut data)?;
/// assert_eq!((data.qpos[0], data.time), (0.0, 0.0));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn reset(model: &Model, data: &mut Data) -> Result<(), InputError> {
    data.check_sizes(model, "reset")?;
    data.time = 0.0;
    data.qpos.copy_from_slice(&model.qpos0);
    for buffer in
        [&mut data.qvel, &mut data.act, &mut data.ctrl, &mut data.qfrc_applied, &mut data.qacc_warmstart]
    {
        buffer.fill(0.0);
    }
    data.xfrc_applied.fill([0.0; 6]);
    crate::forward::reset_actuator_buffers(model, data.history.as_mut_slice());
    for (m, x) in model.mocap_pose0.iter().enumerate() {
        data.mocap_pos[m] = x.pos;
        data.mocap_quat[m] = x.quat_wxyz();
    }
    data.exact.warm_rows.clear();
    data.contacts.clear();
    data.nefc = 0;
    data.thaw_rows();
    data.stepper.steps = 0;
    data.stepper.failed = None;
    data.warnings.clear();
    data.sleep.reset(model);
    Ok(())
}

/// Resets `data` (as [`reset`]) and then sets what keyframe `name` of `model` gives: its time,
/// `qpos`, `qvel`, `ctrl`, `act` and the mocap poses `mpos`, `mquat` (each only when the
/// keyframe has it, as MuJoCo's `mj_resetDataKeyframe`).
///
/// # Errors
/// [`InputError::Name`] when the model has no keyframe `name` (the message lists those it has);
/// [`InputError::Length`] when `data` was not made for `model`.
///
/// # Example
/// ```
/// use lagrange::prelude::*;
/// let model = Model::from_str(r#"<mujoco><worldbody><body><joint type="hinge"/>
///     <geom size="0.1"/></body></worldbody>
///     <keyframe><key name="tilted" qpos="0.3" qvel="1"/></keyframe></mujoco>"#)?;
/// let mut data = Data::new(&model);
/// reset_keyframe(&model, &mut data, "tilted")?;
/// assert_eq!((data.qpos[0], data.qvel[0]), (0.3, 1.0));
/// assert!(reset_keyframe(&model, &mut data, "upright").is_err());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn reset_keyframe(model: &Model, data: &mut Data, name: &str) -> Result<(), InputError> {
    let key = model.keyframe_id(name).map(|k| &model.keyframes[k]).ok_or_else(|| {
        InputError::unknown_name(
            "reset_keyframe",
            "keyframe",
            name,
            model.keyframes.iter().map(|k| k.name.as_str()),
        )
    })?;
    reset(model, data)?;
    data.time = key.time;
    // The compiler checked the keyframe's lengths; a keyframe whose ctrl or act does not fit is
    // left out, as MuJoCo does.
    let parts = [
        (key.qpos.as_deref(), &mut data.qpos),
        (key.qvel.as_deref(), &mut data.qvel),
        (key.ctrl.as_deref(), &mut data.ctrl),
        (key.act.as_deref(), &mut data.act),
    ];
    for (values, buffer) in parts {
        if let Some(values) = values.filter(|v| v.len() == buffer.len()) {
            buffer.copy_from_slice(values);
        }
    }
    // Mocap poses (the compiler checked 3 and 4 values per mocap body).
    if let Some(p) = key.mpos.as_deref().filter(|p| p.len() == 3 * data.mocap_pos.len()) {
        for (pos, xyz) in data.mocap_pos.iter_mut().zip(p.chunks_exact(3)) {
            *pos = crate::spatial::Vec3::new(xyz[0], xyz[1], xyz[2]);
        }
    }
    if let Some(q) = key.mquat.as_deref().filter(|q| q.len() == 4 * data.mocap_quat.len()) {
        for (quat, wxyz) in data.mocap_quat.iter_mut().zip(q.chunks_exact(4)) {
            quat.copy_from_slice(wxyz);
        }
    }
    Ok(())
}
