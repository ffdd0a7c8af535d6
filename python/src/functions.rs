//! The module functions: MuJoCo's pipeline (`forward`, `step`, `reset`, `reset_keyframe`,
//! `contact_force`) and Pinocchio's kernels (`rnea`, `crba`, `aba`, `jacobian`,
//! `center_of_mass`, the energies) and the derivatives (`rnea_derivatives`, `aba_derivatives`,
//! `transition_jacobians`), each taking `(model, data, …)`.

use crate::arrays;
use crate::data::PyData;
use crate::error;
use crate::model::PyModel;
use lagrange::kinematics::ReferenceFrame;
use lagrange::{Data, Model};
use nalgebra::DMatrix;
use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::prelude::*;
use std::sync::Arc;

/// Adds the functions to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(forward, m)?)?;
    m.add_function(wrap_pyfunction!(step, m)?)?;
    m.add_function(wrap_pyfunction!(reset, m)?)?;
    m.add_function(wrap_pyfunction!(reset_keyframe, m)?)?;
    m.add_function(wrap_pyfunction!(contact_force, m)?)?;
    m.add_function(wrap_pyfunction!(rnea, m)?)?;
    m.add_function(wrap_pyfunction!(crba, m)?)?;
    m.add_function(wrap_pyfunction!(aba, m)?)?;
    m.add_function(wrap_pyfunction!(jacobian, m)?)?;
    m.add_function(wrap_pyfunction!(center_of_mass, m)?)?;
    m.add_function(wrap_pyfunction!(kinetic_energy, m)?)?;
    m.add_function(wrap_pyfunction!(potential_energy, m)?)?;
    m.add_function(wrap_pyfunction!(rnea_derivatives, m)?)?;
    m.add_function(wrap_pyfunction!(aba_derivatives, m)?)?;
    m.add_function(wrap_pyfunction!(transition_jacobians, m)?)?;
    Ok(())
}

/// The library model of `m`, after checking that `d` was made for a model of its sizes.
fn model_for(m: &Bound<'_, PyModel>, d: &PyData) -> PyResult<Arc<Model>> {
    let model = &m.get().inner;
    let own = &d.model.bind(m.py()).get().inner;
    if !Arc::ptr_eq(model, own)
        && (model.nq, model.nv, model.links.len(), model.actuators.len(), model.nsensordata)
            != (own.nq, own.nv, own.links.len(), own.actuators.len(), own.nsensordata)
    {
        return Err(error::bad(format!(
            "the data was made for another model ('{}': nq {}, nv {}), not '{}' (nq {}, nv {})",
            own.name, own.nq, own.nv, model.name, model.nq, model.nv
        )));
    }
    Ok(Arc::clone(model))
}

/// Raises `InputError` if a state buffer holds a non-finite value.
fn check_state(data: &Data, function: &str) -> PyResult<()> {
    for (name, values) in [
        ("qpos", data.qpos.as_slice()),
        ("qvel", data.qvel.as_slice()),
        ("act", data.act.as_slice()),
        ("ctrl", data.ctrl.as_slice()),
        ("qfrc_applied", data.qfrc_applied.as_slice()),
    ] {
        if let Some(i) = values.iter().position(|x| !x.is_finite()) {
            return Err(error::bad(format!(
                "{function}: d.{name}[{i}] is {}, not a finite number",
                values[i]
            )));
        }
    }
    Ok(())
}

/// Forward dynamics at the state in `d` (MuJoCo's `mj_forward`): qacc, constraint forces,
/// contacts, sensors. Raises `InputError` for a non-finite state.
#[pyfunction]
pub fn forward(m: &Bound<'_, PyModel>, mut d: PyRefMut<'_, PyData>) -> PyResult<()> {
    let model = model_for(m, &d)?;
    let data = d.data();
    check_state(data, "forward")?;
    lagrange::prelude::forward(&model, data);
    Ok(())
}

/// Advances `d` by `nstep` steps of the model's integrator (MuJoCo's `mj_step`); the GIL is
/// released when `nstep > 1`. Raises `SimulationError` when a step diverges or is refused.
#[pyfunction]
#[pyo3(signature = (m, d, nstep=1))]
pub fn step(
    py: Python<'_>,
    m: &Bound<'_, PyModel>,
    mut d: PyRefMut<'_, PyData>,
    nstep: usize,
) -> PyResult<()> {
    let model = model_for(m, &d)?;
    let data = d.data();
    if nstep == 1 {
        lagrange::prelude::step(&model, data).map_err(error::sim)?;
        return Ok(());
    }
    py.detach(|| {
        for _ in 0..nstep {
            lagrange::prelude::step(&model, data)?;
        }
        Ok(())
    })
    .map_err(error::sim)
}

/// Resets `d` to the model's `qpos0` at rest at time 0, zero controls and applied forces
/// (MuJoCo's `mj_resetData`).
#[pyfunction]
pub fn reset(m: &Bound<'_, PyModel>, mut d: PyRefMut<'_, PyData>) -> PyResult<()> {
    let model = model_for(m, &d)?;
    lagrange::prelude::reset(&model, d.data()).map_err(error::input)
}

/// Resets `d`, then sets what keyframe `key` (a name or an index) gives (MuJoCo's
/// `mj_resetDataKeyframe`).
#[pyfunction]
pub fn reset_keyframe(
    m: &Bound<'_, PyModel>,
    mut d: PyRefMut<'_, PyData>,
    key: &Bound<'_, PyAny>,
) -> PyResult<()> {
    let model = model_for(m, &d)?;
    let name = if let Ok(i) = key.extract::<usize>() {
        model.keyframes.get(i).map(|k| k.name.clone()).ok_or_else(|| {
            error::bad(format!(
                "reset_keyframe: keyframe {i} does not exist ({} keyframes)",
                model.keyframes.len()
            ))
        })?
    } else {
        key.extract::<String>()?
    };
    lagrange::prelude::reset_keyframe(&model, d.data(), &name).map_err(error::input)
}

/// The force of contact `i` in its contact frame: normal, tangent1, tangent2, then the
/// torsional and rolling torques (MuJoCo's `mj_contactForce`, 6 numbers); after `forward`.
#[pyfunction]
pub fn contact_force<'py>(
    py: Python<'py>,
    m: &Bound<'py, PyModel>,
    mut d: PyRefMut<'py, PyData>,
    i: usize,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let model = model_for(m, &d)?;
    let force = lagrange::prelude::contact_force(&model, d.data(), i).map_err(error::input)?;
    Ok(PyArray1::from_slice(py, &force))
}

/// Copies `q` (nq), and `v`, `a` (nv each, when given) into the data's scratch, strictly.
fn read_args(
    d: &mut PyData,
    q: &Bound<'_, PyAny>,
    v: Option<(&Bound<'_, PyAny>, &str)>,
    a: Option<(&Bound<'_, PyAny>, &str)>,
) -> PyResult<()> {
    let (nq, nv) = (d.scratch_q.len(), d.scratch_v.len());
    arrays::read_strict(q, "q", &[nq], &mut d.scratch_q)?;
    if let Some((v, name)) = v {
        arrays::read_strict(v, name, &[nv], &mut d.scratch_v)?;
    }
    if let Some((a, name)) = a {
        arrays::read_strict(a, name, &[nv], &mut d.scratch_a)?;
    }
    Ok(())
}

/// Inverse dynamics τ = M(q) a + c(q, v) (RNEA; Pinocchio's `rnea`), without actuators,
/// passive forces or constraints. Returns a new array of nv values.
#[pyfunction]
pub fn rnea<'py>(
    py: Python<'py>,
    m: &Bound<'py, PyModel>,
    mut d: PyRefMut<'py, PyData>,
    q: &Bound<'py, PyAny>,
    v: &Bound<'py, PyAny>,
    a: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let model = model_for(m, &d)?;
    read_args(&mut d, q, Some((v, "v")), Some((a, "a")))?;
    let (data, q, v, a) = d.split();
    let tau = lagrange::dynamics::rnea(&model, data, q, v, a).map_err(error::input)?;
    Ok(PyArray1::from_slice(py, tau.as_slice()))
}

/// The joint-space inertia matrix M(q) (CRBA; Pinocchio's `crba`), the full symmetric nv × nv
/// matrix, armature included.
#[pyfunction]
pub fn crba<'py>(
    py: Python<'py>,
    m: &Bound<'py, PyModel>,
    mut d: PyRefMut<'py, PyData>,
    q: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let model = model_for(m, &d)?;
    read_args(&mut d, q, None, None)?;
    let (data, q, _, _) = d.split();
    let mass = lagrange::dynamics::crba(&model, data, q).map_err(error::input)?;
    Ok(matrix(py, mass))
}

/// Forward dynamics without constraints a = M⁻¹(τ − c(q, v)) (ABA; Pinocchio's `aba`).
#[pyfunction]
pub fn aba<'py>(
    py: Python<'py>,
    m: &Bound<'py, PyModel>,
    mut d: PyRefMut<'py, PyData>,
    q: &Bound<'py, PyAny>,
    v: &Bound<'py, PyAny>,
    tau: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let model = model_for(m, &d)?;
    read_args(&mut d, q, Some((v, "v")), Some((tau, "tau")))?;
    let (data, q, v, tau) = d.split();
    let qacc = lagrange::dynamics::aba(&model, data, q, v, tau).map_err(error::input)?;
    Ok(PyArray1::from_slice(py, qacc.as_slice()))
}

/// A row-major NumPy copy of `m`.
fn matrix<'py>(py: Python<'py>, m: &DMatrix<f64>) -> Bound<'py, PyArray2<f64>> {
    let (rows, cols) = m.shape();
    let out = PyArray2::<f64>::zeros(py, [rows, cols], false);
    {
        let mut w = out.readwrite();
        let mut view = w.as_array_mut();
        for r in 0..rows {
            for c in 0..cols {
                view[[r, c]] = m[(r, c)];
            }
        }
    }
    out
}

/// The 6 × nv Jacobian of the frame (a body, URDF link or site) named `frame` at `d.qpos`:
/// rows 0–2 linear, 3–5 angular velocity (Pinocchio's `getFrameJacobian` row order), in
/// `reference` axes: 'local_world_aligned' (world axes at the frame's origin; MuJoCo's
/// `mj_jacSite`), 'local' (the frame's axes) or 'world' (world axes, the point at the world
/// origin).
#[pyfunction]
#[pyo3(signature = (m, d, frame, reference="local_world_aligned"))]
pub fn jacobian<'py>(
    py: Python<'py>,
    m: &Bound<'py, PyModel>,
    mut d: PyRefMut<'py, PyData>,
    frame: &str,
    reference: &str,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let model = model_for(m, &d)?;
    let reference = match reference {
        "world" | "WORLD" => ReferenceFrame::World,
        "local" | "LOCAL" => ReferenceFrame::Local,
        "local_world_aligned" | "LOCAL_WORLD_ALIGNED" => ReferenceFrame::LocalWorldAligned,
        other => {
            return Err(error::bad(format!(
                "jacobian: reference '{other}' is none of 'world', 'local', 'local_world_aligned'"
            )))
        }
    };
    let f = model.frame_id(frame).ok_or_else(|| {
        error::bad(format!("jacobian: the model has no body, link or site named '{frame}'"))
    })?;
    kinematics_at_state(&model, &mut d)?;
    let mut jac = DMatrix::zeros(6, model.nv);
    lagrange::kinematics::frame_jacobian(&model, d.data(), f, reference, &mut jac).map_err(error::input)?;
    Ok(matrix(py, &jac))
}

/// Forward kinematics at `d.qpos`.
fn kinematics_at_state(model: &Model, d: &mut PyData) -> PyResult<()> {
    let q = d.data().qpos.as_slice().to_vec();
    lagrange::kinematics::forward_kinematics(model, d.data(), &q).map_err(error::input)
}

/// The centre of mass of the moving bodies at `d.qpos` (world frame; MuJoCo's `subtree_com[0]`
/// of an MJCF model, Pinocchio's `centerOfMass`).
#[pyfunction]
pub fn center_of_mass<'py>(
    py: Python<'py>,
    m: &Bound<'py, PyModel>,
    mut d: PyRefMut<'py, PyData>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let model = model_for(m, &d)?;
    kinematics_at_state(&model, &mut d)?;
    let com = lagrange::dynamics::center_of_mass(&model, d.data());
    Ok(PyArray1::from_slice(py, com.as_slice()))
}

/// Kinetic energy ½ vᵀ M(q) v (Pinocchio's `computeKineticEnergy`).
#[pyfunction]
pub fn kinetic_energy(
    m: &Bound<'_, PyModel>,
    mut d: PyRefMut<'_, PyData>,
    q: &Bound<'_, PyAny>,
    v: &Bound<'_, PyAny>,
) -> PyResult<f64> {
    let model = model_for(m, &d)?;
    read_args(&mut d, q, Some((v, "v")), None)?;
    let (data, q, v, _) = d.split();
    lagrange::dynamics::kinetic_energy(&model, data, q, v).map_err(error::input)
}

/// Gravitational potential energy at `q` (Pinocchio's `computePotentialEnergy`; springs are
/// not included).
#[pyfunction]
pub fn potential_energy(
    m: &Bound<'_, PyModel>,
    mut d: PyRefMut<'_, PyData>,
    q: &Bound<'_, PyAny>,
) -> PyResult<f64> {
    let model = model_for(m, &d)?;
    read_args(&mut d, q, None, None)?;
    let (data, q, _, _) = d.split();
    lagrange::kinematics::forward_kinematics(&model, data, q).map_err(error::input)?;
    Ok(lagrange::dynamics::potential_energy(&model, data))
}

/// A NumPy matrix returned to Python.
type Matrix<'py> = Bound<'py, PyArray2<f64>>;

/// Analytic derivatives of inverse dynamics at (q, v, a) (Pinocchio's
/// `computeRNEADerivatives`): `(dtau_dq, dtau_dv)`, nv × nv each, rows are τ. q columns are in
/// each joint's tangent space; velocities in lagrange's (MuJoCo's) coordinates — a free joint's
/// linear velocity in world axes (docs/derivatives.md). ∂τ/∂a is `crba`.
#[pyfunction]
pub fn rnea_derivatives<'py>(
    py: Python<'py>,
    m: &Bound<'py, PyModel>,
    mut d: PyRefMut<'py, PyData>,
    q: &Bound<'py, PyAny>,
    v: &Bound<'py, PyAny>,
    a: &Bound<'py, PyAny>,
) -> PyResult<(Matrix<'py>, Matrix<'py>)> {
    let model = model_for(m, &d)?;
    read_args(&mut d, q, Some((v, "v")), Some((a, "a")))?;
    let mut work = lagrange::derivatives::DerivativesWork::new(&model);
    let (data, q, v, a) = d.split();
    lagrange::derivatives::rnea_derivatives(&model, data, &mut work, q, v, a).map_err(error::input)?;
    Ok((matrix(py, &work.dtau_dq), matrix(py, &work.dtau_dv)))
}

/// Analytic derivatives of unconstrained forward dynamics q̈ = ABA(q, v, τ) (Pinocchio's
/// `computeABADerivatives`): `(dqacc_dq, dqacc_dv, dqacc_dtau)`, nv × nv each; the conventions of
/// `rnea_derivatives`; `dqacc_dtau` = M⁻¹.
#[pyfunction]
pub fn aba_derivatives<'py>(
    py: Python<'py>,
    m: &Bound<'py, PyModel>,
    mut d: PyRefMut<'py, PyData>,
    q: &Bound<'py, PyAny>,
    v: &Bound<'py, PyAny>,
    tau: &Bound<'py, PyAny>,
) -> PyResult<(Matrix<'py>, Matrix<'py>, Matrix<'py>)> {
    let model = model_for(m, &d)?;
    read_args(&mut d, q, Some((v, "v")), Some((tau, "tau")))?;
    let mut work = lagrange::derivatives::DerivativesWork::new(&model);
    let (data, q, v, tau) = d.split();
    lagrange::derivatives::aba_derivatives(&model, data, &mut work, q, v, tau).map_err(error::input)?;
    Ok((matrix(py, &work.dqacc_dq), matrix(py, &work.dqacc_dv), matrix(py, &work.dqacc_dtau)))
}

/// Transition Jacobians of one step of the model's integrator from the state in `d`, with
/// constraints and contacts (MuJoCo's `mjd_transitionFD`): `(A, B)`, A of size
/// (2 nv + na) × (2 nv + na) for x = (q in the tangent space, v, act), B (2 nv + na) × nu for
/// u = ctrl; finite differences with nudge `eps`, centred by default, with MuJoCo's stage
/// skipping; `method="hybrid"` computes the velocity and control columns analytically
/// (docs/derivatives.md). `d`'s state is restored. The GIL is released while it runs.
#[pyfunction]
#[pyo3(signature = (m, d, eps=1e-6, centered=true, method="fd"))]
pub fn transition_jacobians<'py>(
    py: Python<'py>,
    m: &Bound<'py, PyModel>,
    mut d: PyRefMut<'py, PyData>,
    eps: f64,
    centered: bool,
    method: &str,
) -> PyResult<(Matrix<'py>, Matrix<'py>)> {
    use lagrange::derivatives::TransitionMethod;
    let model = model_for(m, &d)?;
    check_state(d.data(), "transition_jacobians")?;
    let method = match method {
        "fd" => TransitionMethod::FiniteDifference,
        "hybrid" => TransitionMethod::Hybrid,
        other => {
            return Err(pyo3::exceptions::PyValueError::new_err(format!(
                "transition_jacobians: method is {other:?}; use \"fd\" or \"hybrid\""
            )))
        }
    };
    let mut work = lagrange::derivatives::TransitionWork::new(&model);
    let options = lagrange::derivatives::TransitionOptions { eps, centered, method, ..Default::default() };
    let data = d.data();
    py.detach(|| lagrange::derivatives::transition_jacobians(&model, data, &mut work, &options))
        .map_err(error::sim)?;
    Ok((matrix(py, &work.a), matrix(py, &work.b)))
}
