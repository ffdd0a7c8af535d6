//! `lagrange.rollout`: many rollouts of one model from given initial states under given
//! per-step controls, spread over threads with rayon and the GIL released (the pattern of
//! `lagrange::batch`, with controls per step, activations and sensors recorded).
//!
//! Each rollout steps a `Data` reset to the state `Data(m)` starts from (a worker's, reused:
//! `Data::new` costs milliseconds with contacts), exactly as setting the state, then per step
//! `d.ctrl[:] = controls[k]` and `step(m, d)` would from Python, and nothing is shared mutably
//! between rollouts: the result is bit for bit the same for any thread count
//! (python/tests/test_rollout.py).

use crate::arrays;
use crate::error;
use crate::model::PyModel;
use lagrange::{Data, Model};
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;

/// The outputs of one rollout: rows of qpos, qvel, act, time and sensordata (nstep + 1 each).
struct Out<'a> {
    qpos: &'a mut [f64],
    qvel: &'a mut [f64],
    act: &'a mut [f64],
    time: &'a mut [f64],
    sensordata: &'a mut [f64],
}

/// `count` consecutive chunks of `n` values of `s` (`n` may be 0).
fn chunks(mut s: &mut [f64], n: usize, count: usize) -> Vec<&mut [f64]> {
    (0..count)
        .map(|_| {
            let (head, tail) = std::mem::take(&mut s).split_at_mut(n);
            s = tail;
            head
        })
        .collect()
}

/// Copies the state of `data` into row `k` of `out`.
fn record(data: &Data, out: &mut Out<'_>, k: usize) {
    let (nq, nv, na) = (data.qpos.len(), data.qvel.len(), data.act.len());
    out.qpos[k * nq..(k + 1) * nq].copy_from_slice(data.qpos.as_slice());
    out.qvel[k * nv..(k + 1) * nv].copy_from_slice(data.qvel.as_slice());
    out.act[k * na..(k + 1) * na].copy_from_slice(data.act.as_slice());
    out.time[k] = data.time;
}

/// One rollout from `state` ([qpos, qvel, act]) under `controls` (nstep × nu) into `out`, in
/// `data` (a worker's, reset here: `reset` leaves a `Data` as `Data::new` made it, warm starts,
/// contacts, stepper and failure state included, and `Data::new` costs milliseconds for a model
/// with contacts); on a failed step, the rows after it are NaN and the error is returned.
fn run_one(
    model: &Model,
    data: &mut Data,
    state: &[f64],
    controls: &[f64],
    nstep: usize,
    out: &mut Out<'_>,
) -> Result<(), String> {
    let (nq, nv, nu) = (model.nq, model.nv, model.actuators.len());
    let ns = model.nsensordata;
    lagrange::prelude::reset(model, data).map_err(|e| e.to_string())?;
    data.qpos.copy_from_slice(&state[..nq]);
    data.qvel.copy_from_slice(&state[nq..nq + nv]);
    data.act.copy_from_slice(&state[nq + nv..]);
    record(data, out, 0);
    for k in 0..nstep {
        data.ctrl.copy_from_slice(&controls[k * nu..(k + 1) * nu]);
        if let Err(e) = lagrange::prelude::step(model, data) {
            for buffer in [&mut *out.qpos, &mut *out.qvel, &mut *out.act, &mut *out.sensordata] {
                let n = buffer.len() / (nstep + 1);
                buffer[(k + 1) * n..].fill(f64::NAN);
            }
            out.sensordata[k * ns..(k + 1) * ns].fill(f64::NAN);
            out.time[k + 1..].fill(f64::NAN);
            return Err(e.to_string());
        }
        // A step leaves the sensors of the state it started from (MuJoCo's mj_step).
        out.sensordata[k * ns..(k + 1) * ns].copy_from_slice(data.sensordata.as_slice());
        record(data, out, k + 1);
    }
    // The sensors of the last state, under the last controls.
    lagrange::prelude::forward(model, data);
    out.sensordata[nstep * ns..].copy_from_slice(data.sensordata.as_slice());
    Ok(())
}

/// Rolls `model` out from each row of `initial_states` (nbatch × (nq + nv + na): qpos, qvel,
/// act) for `nstep` steps under `controls` (nbatch × nstep × nu; None: zero controls), on
/// `threads` threads (None: all cores) without the GIL.
///
/// Returns a dict of arrays `qpos` (nbatch × (nstep + 1) × nq), `qvel`, `act`, `time`
/// (nbatch × (nstep + 1)) and `sensordata`, the initial state first; `sensordata[:, k]` holds
/// the sensors at state k under the controls of step k (MuJoCo's rollout sensordata for
/// k < nstep). `error` lists, per rollout, None or the message of the step that failed (its
/// later rows are NaN). The result equals stepping each rollout one by one from a fresh
/// `Data`, bit for bit, whatever the thread count.
#[pyfunction]
#[pyo3(signature = (model, initial_states, controls=None, nstep=None, *, threads=None))]
pub fn rollout<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyModel>,
    initial_states: &Bound<'py, PyAny>,
    controls: Option<&Bound<'py, PyAny>>,
    nstep: Option<usize>,
    threads: Option<usize>,
) -> PyResult<Bound<'py, PyDict>> {
    let model = model.get().inner.clone();
    let (nq, nv, na, nu, ns) = (model.nq, model.nv, model.na(), model.actuators.len(), model.nsensordata);
    let nstate = nq + nv + na;
    let shape: Vec<usize> = initial_states.getattr("shape").and_then(|s| s.extract()).map_err(|_| {
        pyo3::exceptions::PyTypeError::new_err(
            "initial_states: expected a float64 NumPy array (nbatch, nq + nv + na)",
        )
    })?;
    let nbatch = match shape.as_slice() {
        [n, _] => *n,
        _ => {
            return Err(error::bad(format!(
                "initial_states: expected shape (nbatch, {nstate}), got {shape:?}"
            )))
        }
    };
    let states = arrays::strict(initial_states, "initial_states", &[nbatch, nstate])?;
    let nstep = match (nstep, controls) {
        (Some(n), _) => n,
        (None, Some(c)) => {
            let shape: Vec<usize> = c.getattr("shape").and_then(|s| s.extract()).unwrap_or_default();
            *shape.get(1).ok_or_else(|| error::bad("controls: expected shape (nbatch, nstep, nu)".into()))?
        }
        (None, None) => return Err(error::bad("rollout: give nstep or controls".into())),
    };
    let controls = match controls {
        Some(c) if !c.is_none() => arrays::strict(c, "controls", &[nbatch, nstep, nu])?,
        _ => vec![0.0; nbatch * nstep * nu],
    };
    if threads == Some(0) {
        return Err(error::bad("rollout: threads must be at least 1 (None: all cores)".into()));
    }
    let rows = nstep + 1;
    let mut qpos = vec![0.0; nbatch * rows * nq];
    let mut qvel = vec![0.0; nbatch * rows * nv];
    let mut act = vec![0.0; nbatch * rows * na];
    let mut time = vec![0.0; nbatch * rows];
    let mut sensordata = vec![0.0; nbatch * rows * ns];
    let errors: Vec<Option<String>> = py.detach(|| {
        let outs: Vec<Out<'_>> = chunks(&mut qpos, rows * nq, nbatch)
            .into_iter()
            .zip(chunks(&mut qvel, rows * nv, nbatch))
            .zip(chunks(&mut act, rows * na, nbatch))
            .zip(chunks(&mut time, rows, nbatch))
            .zip(chunks(&mut sensordata, rows * ns, nbatch))
            .map(|((((qpos, qvel), act), time), sensordata)| Out { qpos, qvel, act, time, sensordata })
            .collect();
        let work = |data: &mut Data, (i, mut out): (usize, Out<'_>)| {
            let state = &states[i * nstate..(i + 1) * nstate];
            let controls = &controls[i * nstep * nu..(i + 1) * nstep * nu];
            run_one(&model, data, state, controls, nstep, &mut out).err()
        };
        // One Data per rayon job (not per rollout), reset before each rollout.
        let run =
            || outs.into_par_iter().enumerate().map_init(|| Data::new(&model), work).collect::<Vec<_>>();
        match threads {
            Some(n) => match rayon::ThreadPoolBuilder::new().num_threads(n).build() {
                Ok(pool) => pool.install(run),
                Err(_) => run(),
            },
            None => run(),
        }
    });
    let out = PyDict::new(py);
    out.set_item("qpos", PyArray1::from_vec(py, qpos).reshape([nbatch, rows, nq])?)?;
    out.set_item("qvel", PyArray1::from_vec(py, qvel).reshape([nbatch, rows, nv])?)?;
    out.set_item("act", PyArray1::from_vec(py, act).reshape([nbatch, rows, na])?)?;
    out.set_item("time", PyArray1::from_vec(py, time).reshape([nbatch, rows])?)?;
    out.set_item("sensordata", PyArray1::from_vec(py, sensordata).reshape([nbatch, rows, ns])?)?;
    out.set_item("error", errors)?;
    Ok(out)
}
