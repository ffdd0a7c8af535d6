//! Batch rollouts: a batch over several threads equals the same rollouts run
//! one after the other, bit for bit, in input order; a bad item reports its error in its place.

use lagrange::batch::{rollout, rollout_models, BatchOptions, InitialState, Rollout};
use lagrange::io::{load, LoadOptions};
use lagrange::sim::{SimOptions, Simulation};
use lagrange::Model;
use rand::rngs::SmallRng;
use rand::{Rng, SeedableRng};
use std::path::Path;
use std::sync::Arc;

fn solo12() -> Arc<Model> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("models/solo12/solo12.urdf");
    Arc::new(load(&path, &LoadOptions { floating: true, ..Default::default() }).expect("solo12 loads"))
}

fn states(model: &Model, n: usize) -> Vec<InitialState> {
    let mut rng = SmallRng::seed_from_u64(14);
    (0..n)
        .map(|_| {
            let mut q = model.qpos0.clone();
            for x in q.iter_mut().skip(7) {
                *x += rng.random_range(-0.5..0.5);
            }
            let v = (0..model.nv).map(|_| rng.random_range(-1.0..1.0)).collect();
            InitialState { q, v }
        })
        .collect()
}

/// The same rollout on the calling thread, with a plain `Simulation`.
fn sequential(model: &Arc<Model>, state: &InitialState, options: &BatchOptions) -> Rollout {
    let mut sim = Simulation::new(Arc::clone(model), &options.sim);
    sim.set_state(&state.q, &state.v).unwrap();
    let mut trajectory = vec![];
    let every = options.record_every.unwrap_or(0);
    let sample = |sim: &Simulation| lagrange::batch::Sample {
        time: sim.data.time,
        q: sim.data.qpos.as_slice().to_vec(),
        v: sim.data.qvel.as_slice().to_vec(),
    };
    if every > 0 {
        trajectory.push(sample(&sim));
    }
    for k in 1..=options.steps {
        sim.step().unwrap();
        if every > 0 && k % every == 0 {
            trajectory.push(sample(&sim));
        }
    }
    Rollout { last: sample(&sim), steps: sim.steps, trajectory }
}

#[test]
fn batch_equals_sequential_bit_for_bit() {
    let model = solo12();
    let states = states(&model, 6);
    for (integrator, record_every) in
        [(None, None), (Some(lagrange::integrate::IntegratorKind::Rk4), Some(25))]
    {
        let options = BatchOptions {
            sim: SimOptions { integrator, timestep: Some(1e-3), ..Default::default() },
            steps: 200,
            record_every,
            threads: Some(2),
        };
        let batch = rollout(&model, &states, &options);
        assert_eq!(batch.len(), states.len());
        for (state, result) in states.iter().zip(&batch) {
            let got = result.as_ref().expect("rollout runs");
            let want = sequential(&model, state, &options);
            // Bit for bit: `==` on f64 vectors, no tolerance.
            assert_eq!(got, &want);
            assert_eq!(got.steps, 200);
            if record_every.is_some() {
                assert_eq!(got.trajectory.len(), 9);
            }
        }
        // The states differ, so must the rollouts (the batch did not run one state n times).
        let first = &batch[0].as_ref().unwrap().last.q;
        assert!(batch[1..].iter().all(|r| &r.as_ref().unwrap().last.q != first));
    }
}

#[test]
fn a_bad_item_reports_in_its_place() {
    let model = solo12();
    let mut states = states(&model, 3);
    states[1].v[0] = f64::NAN;
    let options = BatchOptions { steps: 10, threads: Some(2), ..Default::default() };
    let batch = rollout(&model, &states, &options);
    assert!(batch[0].is_ok() && batch[2].is_ok());
    assert!(batch[1].is_err());
}

#[test]
fn parameter_sets_run_in_order() {
    let base = solo12();
    // Three parameter sets: the trunk's mass scaled by 1, 2 and 3.
    let models: Vec<Arc<Model>> = (1..=3)
        .map(|s| {
            let mut m = (*base).clone();
            m.bodies[1].inertia = m.bodies[1].inertia.scaled(s as f64);
            m.rebuild_plan();
            Arc::new(m)
        })
        .collect();
    let options = BatchOptions { steps: 50, threads: Some(2), ..Default::default() };
    let batch = rollout_models(&models, &options);
    for (model, result) in models.iter().zip(&batch) {
        let mut sim = Simulation::new(Arc::clone(model), &options.sim);
        for _ in 0..50 {
            sim.step().unwrap();
        }
        assert_eq!(result.as_ref().unwrap().last.q, sim.data.qpos.as_slice());
        assert_eq!(result.as_ref().unwrap().last.v, sim.data.qvel.as_slice());
    }
}
