//! `lagrange.Data`: one simulation's state, inputs and outputs (MuJoCo's `mjData`), whose arrays
//! are NumPy views of the library's own buffers, without copies: writing `d.qpos[0]` changes what
//! the next `forward` or `step` reads, and a view read before a step shows the values after it.
//! Every view's base is the `Data` object, which therefore lives as long as any of its views.
//!
//! The per-body arrays `xpos`, `xquat`, `xmat` (MuJoCo's body order) are the one exception: the
//! library keeps poses as transforms of its own compiled bodies and frames, so these are buffers
//! of the `Data` object that reading the attribute refills (forward kinematics at `qpos`).

use crate::arrays;
use crate::contact::PyContact;
use crate::error;
use crate::model::PyModel;
use crate::view::view;
use lagrange::Data;
use numpy::PyArrayDyn;
use pyo3::prelude::*;
use std::sync::Mutex;

/// One simulation of a model: state (`time`, `qpos`, `qvel`, `act`), inputs (`ctrl`,
/// `qfrc_applied`, `xfrc_applied`, `mocap_pos`, `mocap_quat`) and outputs (`qacc`,
/// `qfrc_constraint`, `qfrc_bias`, `qfrc_actuator`, `qfrc_passive`, `sensordata`, contacts) as
/// MuJoCo names them. `Data(model)` starts at the model's `qpos0` at rest at time 0.
#[pyclass(name = "Data", module = "lagrange")]
pub struct PyData {
    /// The library's data. A Mutex only to make the class `Sync` (the steppers are `Send`); the
    /// bindings reach it through `&mut self` (`Mutex::get_mut`), never locking.
    inner: Mutex<Data>,
    /// The model this data was made for.
    pub model: Py<PyModel>,
    /// Copies of kernel arguments (q: nq, v/a/tau: nv) so that a view of this data may be passed.
    pub scratch_q: Vec<f64>,
    /// Scratch of length nv (velocities).
    pub scratch_v: Vec<f64>,
    /// Scratch of length nv (accelerations or torques).
    pub scratch_a: Vec<f64>,
    /// Body positions (nbody × 3), refilled when `xpos` is read.
    xpos: Vec<f64>,
    /// Body orientations w x y z (nbody × 4), refilled when `xquat` is read.
    xquat: Vec<f64>,
    /// Body rotation matrices, row-major (nbody × 9), refilled when `xmat` is read.
    xmat: Vec<f64>,
}

impl PyData {
    /// The library's data.
    pub fn data(&mut self) -> &mut Data {
        self.inner.get_mut().unwrap_or_else(|e| e.into_inner())
    }

    /// The library's data beside the scratch arguments q, v, a (disjoint borrows).
    pub fn split(&mut self) -> (&mut Data, &[f64], &[f64], &[f64]) {
        let data = self.inner.get_mut().unwrap_or_else(|e| e.into_inner());
        (data, &self.scratch_q, &self.scratch_v, &self.scratch_a)
    }

    /// Forward kinematics at `qpos`, then the MuJoCo bodies' poses into `xpos`, `xquat`, `xmat`.
    fn refresh_bodies(&mut self, py: Python<'_>) -> PyResult<()> {
        let model = self.model.bind(py).get().inner.clone();
        let q = &mut self.scratch_q;
        let data = self.inner.get_mut().unwrap_or_else(|e| e.into_inner());
        q.copy_from_slice(data.qpos.as_slice());
        lagrange::kinematics::forward_kinematics(&model, data, q).map_err(error::input)?;
        for (b, &f) in model.links.frame.iter().enumerate() {
            let x = &data.x_world_frame[f];
            self.xpos[3 * b..3 * b + 3].copy_from_slice(x.pos.as_slice());
            self.xquat[4 * b..4 * b + 4].copy_from_slice(&x.quat_wxyz());
            for r in 0..3 {
                for c in 0..3 {
                    self.xmat[9 * b + 3 * r + c] = x.rot[(r, c)];
                }
            }
        }
        Ok(())
    }
}

/// Where a buffer of the data is and its shape.
type Locate = fn(&mut Data) -> (*mut f64, Vec<usize>);

/// A zero-copy view of the buffer `locate` finds, its base the Data object.
fn buffer_view<'py>(slf: Bound<'py, PyData>, locate: Locate) -> Bound<'py, PyArrayDyn<f64>> {
    let (ptr, shape) = locate(slf.borrow_mut().data());
    // SAFETY: the buffer belongs to this Data, allocated by `Data::new` and never reallocated
    // (the library moves it out and back within a call); the view's base is the Data object,
    // which owns it.
    unsafe { view(slf.into_any(), ptr, &shape) }
}

/// Copies `value` (converted by NumPy, of the buffer's shape) into the buffer `locate` finds
/// (`d.qpos = x`, as MuJoCo's bindings allow).
fn buffer_set(slf: Bound<'_, PyData>, value: &Bound<'_, PyAny>, name: &str, locate: Locate) -> PyResult<()> {
    let (_, shape) = locate(slf.borrow_mut().data());
    let values = arrays::assign(value, name, &shape)?;
    let (ptr, _) = locate(slf.borrow_mut().data());
    // SAFETY: the buffer holds `values.len()` f64s (its shape was checked) and `values` is a
    // separate copy.
    unsafe { std::ptr::copy_nonoverlapping(values.as_ptr(), ptr, values.len()) };
    Ok(())
}

#[pymethods]
impl PyData {
    /// Allocates every buffer for `model` (MuJoCo's `mj_makeData`).
    #[new]
    fn new(py: Python<'_>, model: Py<PyModel>) -> Self {
        let m = model.bind(py).get().inner.clone();
        let nbody = m.links.len();
        PyData {
            inner: Mutex::new(Data::new(&m)),
            scratch_q: vec![0.0; m.nq],
            scratch_v: vec![0.0; m.nv],
            scratch_a: vec![0.0; m.nv],
            xpos: vec![0.0; 3 * nbody],
            xquat: vec![0.0; 4 * nbody],
            xmat: vec![0.0; 9 * nbody],
            model,
        }
    }

    /// The model this data was made for.
    #[getter]
    fn model(&self, py: Python<'_>) -> Py<PyModel> {
        self.model.clone_ref(py)
    }

    /// Simulation time (s).
    #[getter]
    fn get_time(&mut self) -> f64 {
        self.data().time
    }

    #[setter]
    fn set_time(&mut self, t: f64) {
        self.data().time = t;
    }

    /// Number of contacts of the last collision pass (MuJoCo's `ncon`).
    #[getter]
    fn ncon(&mut self) -> usize {
        self.data().contacts.len()
    }

    /// The contacts of the last collision pass (MuJoCo's `contact`): geoms, bodies, pos,
    /// frame (rows: normal from geom1 to geom2, tangent1, tangent2), dist, and the force
    /// (as `contact_force`).
    #[getter]
    fn contact(&mut self, py: Python<'_>) -> PyResult<Vec<PyContact>> {
        let model = self.model.bind(py).get().inner.clone();
        let data = self.data();
        (0..data.contacts.len()).map(|i| PyContact::of(&model, data, i)).collect()
    }

    /// Number of constraint rows of the last solve (MuJoCo's `nefc`).
    #[getter]
    fn nefc(&mut self) -> usize {
        self.data().nefc
    }

    /// Run-time warnings of the library since the last reset (MuJoCo's `warning`), as text.
    #[getter]
    fn warnings(&mut self) -> String {
        format!("{:?}", self.data().warnings)
    }

    /// Generalized coordinates (nq; MuJoCo's layout: free joint position then w x y z).
    #[getter]
    fn qpos<'py>(slf: Bound<'py, Self>) -> Bound<'py, PyArrayDyn<f64>> {
        buffer_view(slf, |d| (d.qpos.as_mut_ptr().cast::<f64>(), vec![d.qpos.len()]))
    }

    #[setter]
    fn set_qpos(slf: Bound<'_, Self>, value: &Bound<'_, PyAny>) -> PyResult<()> {
        buffer_set(slf, value, "qpos", |d| (d.qpos.as_mut_ptr().cast::<f64>(), vec![d.qpos.len()]))
    }
    /// Generalized velocities (nv).
    #[getter]
    fn qvel<'py>(slf: Bound<'py, Self>) -> Bound<'py, PyArrayDyn<f64>> {
        buffer_view(slf, |d| (d.qvel.as_mut_ptr().cast::<f64>(), vec![d.qvel.len()]))
    }

    #[setter]
    fn set_qvel(slf: Bound<'_, Self>, value: &Bound<'_, PyAny>) -> PyResult<()> {
        buffer_set(slf, value, "qvel", |d| (d.qvel.as_mut_ptr().cast::<f64>(), vec![d.qvel.len()]))
    }
    /// Actuator activations (na).
    #[getter]
    fn act<'py>(slf: Bound<'py, Self>) -> Bound<'py, PyArrayDyn<f64>> {
        buffer_view(slf, |d| (d.act.as_mut_ptr().cast::<f64>(), vec![d.act.len()]))
    }

    #[setter]
    fn set_act(slf: Bound<'_, Self>, value: &Bound<'_, PyAny>) -> PyResult<()> {
        buffer_set(slf, value, "act", |d| (d.act.as_mut_ptr().cast::<f64>(), vec![d.act.len()]))
    }
    /// The actuators' control histories (MuJoCo's `history`, nhistory values in its layout):
    /// part of the state with delayed actuators (`delay`, `nsample`).
    #[getter]
    fn history<'py>(slf: Bound<'py, Self>) -> Bound<'py, PyArrayDyn<f64>> {
        buffer_view(slf, |d| (d.history.as_mut_ptr().cast::<f64>(), vec![d.history.len()]))
    }

    #[setter]
    fn set_history(slf: Bound<'_, Self>, value: &Bound<'_, PyAny>) -> PyResult<()> {
        buffer_set(slf, value, "history", |d| (d.history.as_mut_ptr().cast::<f64>(), vec![d.history.len()]))
    }
    /// Controls (nu).
    #[getter]
    fn ctrl<'py>(slf: Bound<'py, Self>) -> Bound<'py, PyArrayDyn<f64>> {
        buffer_view(slf, |d| (d.ctrl.as_mut_ptr().cast::<f64>(), vec![d.ctrl.len()]))
    }

    #[setter]
    fn set_ctrl(slf: Bound<'_, Self>, value: &Bound<'_, PyAny>) -> PyResult<()> {
        buffer_set(slf, value, "ctrl", |d| (d.ctrl.as_mut_ptr().cast::<f64>(), vec![d.ctrl.len()]))
    }
    /// Generalized forces applied by the user (nv).
    #[getter]
    fn qfrc_applied<'py>(slf: Bound<'py, Self>) -> Bound<'py, PyArrayDyn<f64>> {
        buffer_view(slf, |d| (d.qfrc_applied.as_mut_ptr().cast::<f64>(), vec![d.qfrc_applied.len()]))
    }

    #[setter]
    fn set_qfrc_applied(slf: Bound<'_, Self>, value: &Bound<'_, PyAny>) -> PyResult<()> {
        buffer_set(slf, value, "qfrc_applied", |d| {
            (d.qfrc_applied.as_mut_ptr().cast::<f64>(), vec![d.qfrc_applied.len()])
        })
    }
    /// Cartesian wrenches applied to bodies (nbody × 6: force, torque; world frame, at the
    /// body's centre of mass), MuJoCo's body order.
    #[getter]
    fn xfrc_applied<'py>(slf: Bound<'py, Self>) -> Bound<'py, PyArrayDyn<f64>> {
        buffer_view(slf, |d| (d.xfrc_applied.as_mut_ptr().cast::<f64>(), vec![d.xfrc_applied.len(), 6]))
    }

    #[setter]
    fn set_xfrc_applied(slf: Bound<'_, Self>, value: &Bound<'_, PyAny>) -> PyResult<()> {
        buffer_set(slf, value, "xfrc_applied", |d| {
            (d.xfrc_applied.as_mut_ptr().cast::<f64>(), vec![d.xfrc_applied.len(), 6])
        })
    }
    /// Mocap body positions (nmocap × 3).
    #[getter]
    fn mocap_pos<'py>(slf: Bound<'py, Self>) -> Bound<'py, PyArrayDyn<f64>> {
        buffer_view(slf, |d| (d.mocap_pos.as_mut_ptr().cast::<f64>(), vec![d.mocap_pos.len(), 3]))
    }

    #[setter]
    fn set_mocap_pos(slf: Bound<'_, Self>, value: &Bound<'_, PyAny>) -> PyResult<()> {
        buffer_set(slf, value, "mocap_pos", |d| {
            (d.mocap_pos.as_mut_ptr().cast::<f64>(), vec![d.mocap_pos.len(), 3])
        })
    }
    /// Mocap body orientations (nmocap × 4, w x y z).
    #[getter]
    fn mocap_quat<'py>(slf: Bound<'py, Self>) -> Bound<'py, PyArrayDyn<f64>> {
        buffer_view(slf, |d| (d.mocap_quat.as_mut_ptr().cast::<f64>(), vec![d.mocap_quat.len(), 4]))
    }

    #[setter]
    fn set_mocap_quat(slf: Bound<'_, Self>, value: &Bound<'_, PyAny>) -> PyResult<()> {
        buffer_set(slf, value, "mocap_quat", |d| {
            (d.mocap_quat.as_mut_ptr().cast::<f64>(), vec![d.mocap_quat.len(), 4])
        })
    }
    /// Generalized accelerations of the last forward (nv).
    #[getter]
    fn qacc<'py>(slf: Bound<'py, Self>) -> Bound<'py, PyArrayDyn<f64>> {
        buffer_view(slf, |d| (d.qacc.as_mut_ptr().cast::<f64>(), vec![d.qacc.len()]))
    }

    #[setter]
    fn set_qacc(slf: Bound<'_, Self>, value: &Bound<'_, PyAny>) -> PyResult<()> {
        buffer_set(slf, value, "qacc", |d| (d.qacc.as_mut_ptr().cast::<f64>(), vec![d.qacc.len()]))
    }
    /// Constraint forces Jᵀλ of the last forward (nv).
    #[getter]
    fn qfrc_constraint<'py>(slf: Bound<'py, Self>) -> Bound<'py, PyArrayDyn<f64>> {
        buffer_view(slf, |d| (d.qfrc_constraint.as_mut_ptr().cast::<f64>(), vec![d.qfrc_constraint.len()]))
    }

    #[setter]
    fn set_qfrc_constraint(slf: Bound<'_, Self>, value: &Bound<'_, PyAny>) -> PyResult<()> {
        buffer_set(slf, value, "qfrc_constraint", |d| {
            (d.qfrc_constraint.as_mut_ptr().cast::<f64>(), vec![d.qfrc_constraint.len()])
        })
    }
    /// Bias forces c(q, v) (nv), filled by forward when the model has constraint rows.
    #[getter]
    fn qfrc_bias<'py>(slf: Bound<'py, Self>) -> Bound<'py, PyArrayDyn<f64>> {
        buffer_view(slf, |d| (d.qfrc_bias.as_mut_ptr().cast::<f64>(), vec![d.qfrc_bias.len()]))
    }

    #[setter]
    fn set_qfrc_bias(slf: Bound<'_, Self>, value: &Bound<'_, PyAny>) -> PyResult<()> {
        buffer_set(slf, value, "qfrc_bias", |d| {
            (d.qfrc_bias.as_mut_ptr().cast::<f64>(), vec![d.qfrc_bias.len()])
        })
    }
    /// Passive forces (springs, damping) (nv).
    #[getter]
    fn qfrc_passive<'py>(slf: Bound<'py, Self>) -> Bound<'py, PyArrayDyn<f64>> {
        buffer_view(slf, |d| (d.qfrc_passive.as_mut_ptr().cast::<f64>(), vec![d.qfrc_passive.len()]))
    }

    #[setter]
    fn set_qfrc_passive(slf: Bound<'_, Self>, value: &Bound<'_, PyAny>) -> PyResult<()> {
        buffer_set(slf, value, "qfrc_passive", |d| {
            (d.qfrc_passive.as_mut_ptr().cast::<f64>(), vec![d.qfrc_passive.len()])
        })
    }
    /// Actuator forces in joint space (nv).
    #[getter]
    fn qfrc_actuator<'py>(slf: Bound<'py, Self>) -> Bound<'py, PyArrayDyn<f64>> {
        buffer_view(slf, |d| (d.qfrc_actuator.as_mut_ptr().cast::<f64>(), vec![d.qfrc_actuator.len()]))
    }

    #[setter]
    fn set_qfrc_actuator(slf: Bound<'_, Self>, value: &Bound<'_, PyAny>) -> PyResult<()> {
        buffer_set(slf, value, "qfrc_actuator", |d| {
            (d.qfrc_actuator.as_mut_ptr().cast::<f64>(), vec![d.qfrc_actuator.len()])
        })
    }
    /// Actuator scalar forces (nu).
    #[getter]
    fn actuator_force<'py>(slf: Bound<'py, Self>) -> Bound<'py, PyArrayDyn<f64>> {
        buffer_view(slf, |d| (d.actuator_force.as_mut_ptr().cast::<f64>(), vec![d.actuator_force.len()]))
    }

    #[setter]
    fn set_actuator_force(slf: Bound<'_, Self>, value: &Bound<'_, PyAny>) -> PyResult<()> {
        buffer_set(slf, value, "actuator_force", |d| {
            (d.actuator_force.as_mut_ptr().cast::<f64>(), vec![d.actuator_force.len()])
        })
    }
    /// Sensor values of the last forward or step (nsensordata; a step leaves the sensors of
    /// the state it started from, as MuJoCo's mj_step).
    #[getter]
    fn sensordata<'py>(slf: Bound<'py, Self>) -> Bound<'py, PyArrayDyn<f64>> {
        buffer_view(slf, |d| (d.sensordata.as_mut_ptr().cast::<f64>(), vec![d.sensordata.len()]))
    }

    #[setter]
    fn set_sensordata(slf: Bound<'_, Self>, value: &Bound<'_, PyAny>) -> PyResult<()> {
        buffer_set(slf, value, "sensordata", |d| {
            (d.sensordata.as_mut_ptr().cast::<f64>(), vec![d.sensordata.len()])
        })
    }

    /// Body positions (nbody × 3, world frame, MuJoCo's body order): forward kinematics at
    /// `qpos` when read.
    #[getter]
    fn xpos<'py>(slf: Bound<'py, Self>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let (ptr, n) = {
            let mut this = slf.borrow_mut();
            this.refresh_bodies(slf.py())?;
            (this.xpos.as_ptr(), this.xpos.len() / 3)
        };
        // SAFETY: a buffer of this Data, allocated in `new` and never resized.
        Ok(unsafe { view(slf.into_any(), ptr, &[n, 3]) })
    }

    /// Body orientations (nbody × 4, w x y z, w ≥ 0): forward kinematics at `qpos` when read.
    #[getter]
    fn xquat<'py>(slf: Bound<'py, Self>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let (ptr, n) = {
            let mut this = slf.borrow_mut();
            this.refresh_bodies(slf.py())?;
            (this.xquat.as_ptr(), this.xquat.len() / 4)
        };
        // SAFETY: a buffer of this Data, allocated in `new` and never resized.
        Ok(unsafe { view(slf.into_any(), ptr, &[n, 4]) })
    }

    /// Body rotation matrices (nbody × 9, row-major as MuJoCo's `xmat`): forward kinematics
    /// at `qpos` when read.
    #[getter]
    fn xmat<'py>(slf: Bound<'py, Self>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let (ptr, n) = {
            let mut this = slf.borrow_mut();
            this.refresh_bodies(slf.py())?;
            (this.xmat.as_ptr(), this.xmat.len() / 9)
        };
        // SAFETY: a buffer of this Data, allocated in `new` and never resized.
        Ok(unsafe { view(slf.into_any(), ptr, &[n, 9]) })
    }

    fn __repr__(&mut self) -> String {
        let d = self.data();
        format!(
            "lagrange.Data(time={}, nq={}, nv={}, ncon={})",
            d.time,
            d.qpos.len(),
            d.qvel.len(),
            d.contacts.len()
        )
    }
}
