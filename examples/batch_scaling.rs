//! Scaling of batch rollouts (`lagrange::batch`) with the number of worker threads: solo12 (free
//! flyer, 18 dofs, no contacts) from 64 random initial states, 2000 steps of 1 ms each, on 1, 2, …
//! threads up to the number of cores; wall-clock time of the whole batch, best of 3, and the
//! process's CPU time in that run. A wall-clock timing on a shared machine is only as good as the
//! machine's idleness; the CPU time tells whether the work itself grows with the threads (cache or
//! memory contention) — if it does not, the speed-up on an idle machine is the thread count.
//!
//! Run with `cargo run --release --example batch_scaling [ROLLOUTS] [STEPS]`.

use lagrange::batch::{rollout, BatchOptions, InitialState};
use lagrange::io::{load, LoadOptions};
use lagrange::sim::SimOptions;
use rand::rngs::SmallRng;
use rand::{Rng, SeedableRng};
use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

fn main() {
    let args: Vec<usize> = std::env::args().skip(1).filter_map(|a| a.parse().ok()).collect();
    let (n, steps) = (args.first().copied().unwrap_or(64), args.get(1).copied().unwrap_or(2000) as u64);
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("models/solo12/solo12.urdf");
    let model =
        Arc::new(load(&path, &LoadOptions { floating: true, ..Default::default() }).expect("solo12 loads"));
    let mut rng = SmallRng::seed_from_u64(14);
    let states: Vec<InitialState> = (0..n)
        .map(|_| {
            let mut q = model.qpos0.clone();
            for x in q.iter_mut().skip(7) {
                *x += rng.random_range(-0.5..0.5);
            }
            InitialState { q, v: (0..model.nv).map(|_| rng.random_range(-1.0..1.0)).collect() }
        })
        .collect();
    let cores = std::thread::available_parallelism().map_or(1, |c| c.get());
    println!("solo12: {n} rollouts × {steps} steps, {cores} core(s)");
    let mut t1 = None;
    for threads in 1..=cores {
        let options = BatchOptions {
            sim: SimOptions { timestep: Some(1e-3), ..Default::default() },
            steps,
            record_every: None,
            threads: Some(threads),
        };
        let (best, cpu) = (0..3)
            .map(|_| {
                let (start, cpu0) = (Instant::now(), cpu_seconds());
                let results = rollout(&model, &states, &options);
                let dt = start.elapsed().as_secs_f64();
                assert!(results.iter().all(|r| r.is_ok()));
                (dt, cpu_seconds() - cpu0)
            })
            .fold((f64::INFINITY, 0.0), |a, b| if b.0 < a.0 { b } else { a });
        let t1 = *t1.get_or_insert(best);
        let steps_per_s = (n as f64) * (steps as f64) / best;
        println!(
            "{threads} thread(s): {best:.3} s wall, {cpu:.3} s CPU, {:.0} steps/s, speed-up {:.2}× (efficiency {:.0}%)",
            steps_per_s,
            t1 / best,
            100.0 * t1 / best / threads as f64
        );
    }
}

/// CPU time of the whole process (all threads), seconds (NaN where not read).
#[cfg(unix)]
fn cpu_seconds() -> f64 {
    let mut ts = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: clock_gettime writes one timespec into the valid pointer it is given.
    unsafe { libc::clock_gettime(libc::CLOCK_PROCESS_CPUTIME_ID, &mut ts) };
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}

#[cfg(not(unix))]
fn cpu_seconds() -> f64 {
    f64::NAN
}
