//! Batch rollouts: many independent simulations of one model from different initial states, or of
//! different models (parameter sets), spread over the cores with rayon.
//!
//! Each rollout builds its own [`Simulation`] (its own `Data`, plan and stepper) on the worker
//! thread that runs it and shares only the immutable `Arc<Model>`; nothing is shared mutably, so
//! a rollout's result does not depend on the thread that ran it or on the others: a batch equals
//! the same rollouts run one after the other, bit for bit (`tests/batch.rs`). Results come back
//! in input order, one `Result` per rollout: a diverging rollout reports its [`SimError`] and the
//! others go on.

use crate::model::Model;
use crate::sim::{SimError, SimOptions, Simulation};
use rayon::prelude::*;
use std::sync::Arc;

/// An initial state: configuration `q` (nq values) and velocity `v` (nv values), at time 0.
#[derive(Clone, Debug, PartialEq)]
pub struct InitialState {
    /// Configuration, `nq` values in MuJoCo's qpos layout.
    pub q: Vec<f64>,
    /// Velocity, `nv` values in MuJoCo's qvel layout.
    pub v: Vec<f64>,
}

/// How each rollout of a batch runs.
#[derive(Clone, Debug, Default)]
pub struct BatchOptions {
    /// Integrator, step size, constraint mode of every simulation (the model's own by default).
    pub sim: SimOptions,
    /// Steps per rollout.
    pub steps: u64,
    /// Keep the state every `record_every` steps (and the initial state) in
    /// [`Rollout::trajectory`]; `None` keeps only the final state.
    pub record_every: Option<u64>,
    /// Worker threads; `None` uses rayon's global pool (one thread per core).
    pub threads: Option<usize>,
}

/// One recorded state of a rollout.
#[derive(Clone, Debug, PartialEq)]
pub struct Sample {
    /// Simulation time (s).
    pub time: f64,
    /// Configuration (`qpos`).
    pub q: Vec<f64>,
    /// Velocity (`qvel`).
    pub v: Vec<f64>,
}

/// The outcome of one rollout: its final state and, if asked, the recorded trajectory.
#[derive(Clone, Debug, PartialEq)]
pub struct Rollout {
    /// The state after the last step.
    pub last: Sample,
    /// Steps taken.
    pub steps: u64,
    /// States every `record_every` steps, the initial one first (empty without `record_every`).
    pub trajectory: Vec<Sample>,
}

/// Rolls `model` out from each of `states` for `options.steps` steps, in parallel; results in the
/// order of `states`.
///
/// ```
/// use lagrange::batch::{rollout, BatchOptions, InitialState};
/// use lagrange::prelude::*;
/// use std::sync::Arc;
/// let model = Arc::new(Model::from_file("models/textbook/double_pendulum.xml")?);
/// let states: Vec<InitialState> =
///     (0..4).map(|i| InitialState { q: vec![0.1 * i as f64, 0.0], v: vec![0.0; 2] }).collect();
/// let options = BatchOptions { steps: 100, ..BatchOptions::default() };
/// let results = rollout(&model, &states, &options);
/// assert_eq!(results.len(), 4);
/// assert_eq!(results[0].as_ref().unwrap().steps, 100);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn rollout(
    model: &Arc<Model>,
    states: &[InitialState],
    options: &BatchOptions,
) -> Vec<Result<Rollout, SimError>> {
    rollout_with(states, options, |state| {
        let mut sim = Simulation::new(Arc::clone(model), &options.sim);
        sim.set_state(&state.q, &state.v)?;
        Ok(sim)
    })
}

/// Rolls each of `models` (e.g. one model with different masses, gains or damping) out from its
/// own reference configuration at rest, in parallel; results in the order of `models`.
pub fn rollout_models(models: &[Arc<Model>], options: &BatchOptions) -> Vec<Result<Rollout, SimError>> {
    rollout_with(models, options, |model| Ok(Simulation::new(Arc::clone(model), &options.sim)))
}

/// The general form: `setup` builds the simulation of one item (initial state, controller, …) on
/// the worker thread; each is then stepped `options.steps` times. Results in the order of `items`.
pub fn rollout_with<T: Sync>(
    items: &[T],
    options: &BatchOptions,
    setup: impl Fn(&T) -> Result<Simulation, SimError> + Sync,
) -> Vec<Result<Rollout, SimError>> {
    let run = || items.par_iter().map(|item| run_one(setup(item)?, options)).collect();
    match options.threads {
        Some(n) => match rayon::ThreadPoolBuilder::new().num_threads(n).build() {
            Ok(pool) => pool.install(run),
            // The pool could not be made (no threads left): run the batch on the caller's thread.
            Err(_) => items.iter().map(|item| run_one(setup(item)?, options)).collect(),
        },
        None => run(),
    }
}

/// Steps one simulation, recording as asked.
fn run_one(mut sim: Simulation, options: &BatchOptions) -> Result<Rollout, SimError> {
    let sample = |sim: &Simulation| Sample {
        time: sim.data.time,
        q: sim.data.qpos.as_slice().to_vec(),
        v: sim.data.qvel.as_slice().to_vec(),
    };
    let mut trajectory = Vec::new();
    let every = options.record_every.filter(|&n| n > 0);
    if let Some(n) = every {
        trajectory.reserve((options.steps / n + 1) as usize);
        trajectory.push(sample(&sim));
    }
    for k in 1..=options.steps {
        sim.step()?;
        if every.is_some_and(|n| k % n == 0) {
            trajectory.push(sample(&sim));
        }
    }
    Ok(Rollout { last: sample(&sim), steps: sim.steps, trajectory })
}
