//! Solver and integrator edges (issue 27, item 6) and the stepping API's refusals (item 7).
//!
//! - `<option iterations="0">` as MuJoCo 4.0 (validation/mujoco_edges_golden.py): no solver
//!   iteration, so qacc is the warm start (the previous step's acceleration) or `qacc_smooth`,
//!   whichever costs less; a box dropped on a floor falls through it free of constraint forces.

mod common;

use common::ALGO_REL;
use lagrange::model::options::Solver;
use lagrange::prelude::*;
use serde_json::Value;

const BOX_ITER0: &str = "tests/data/mjcf/edges/box_iterations0.xml";

fn golden(name: &str) -> Value {
    serde_json::from_str(&std::fs::read_to_string(format!("tests/data/mujoco/{name}")).unwrap()).unwrap()
}

fn values(v: &Value) -> Vec<f64> {
    v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
}

/// max |a − b| / max(1, |b|) over the golden sample's qpos, qvel, qacc and first four efc_force.
fn sample_err(sample: &Value, data: &Data) -> f64 {
    let nefc = sample["nefc"].as_u64().unwrap() as usize;
    assert_eq!(data.nefc, nefc, "rows at {sample}");
    let force: Vec<f64> = (0..4).map(|i| if nefc > 0 { data.efc_force[i] } else { 0.0 }).collect();
    let ours = [data.qpos.as_slice(), data.qvel.as_slice(), data.qacc.as_slice(), &force];
    let mut worst = 0.0f64;
    for (key, ours) in ["qpos", "qvel", "qacc", "efc_force"].iter().zip(ours) {
        for (a, b) in ours.iter().zip(values(&sample[key])) {
            worst = worst.max((a - b).abs() / b.abs().max(1.0));
        }
    }
    worst
}

#[test]
fn iterations_zero_falls_free_as_mujoco() {
    let golden = golden("edges.json");
    let samples = golden["samples"].as_array().unwrap();
    let mut worst = 0.0f64;
    for (label, solver) in [("Newton", Solver::Newton), ("CG", Solver::Cg), ("PGS", Solver::Pgs)] {
        let mut model = Model::from_file(BOX_ITER0).unwrap();
        model.options.solver = solver;
        let mut data = Data::new(&model);
        let mut k = 0;
        for sample in samples.iter().filter(|s| s["solver"] == label) {
            let n = sample["step"].as_u64().unwrap();
            if n == 0 {
                // At rest 1 cm into the floor from a fresh data (zero warm start).
                let mut data = Data::new(&model);
                data.qpos[2] = 0.09;
                forward(&model, &mut data);
                worst = worst.max(sample_err(sample, &data));
                continue;
            }
            while k < n {
                step(&model, &mut data).unwrap();
                k += 1;
            }
            worst = worst.max(sample_err(sample, &data));
        }
        // Through the floor at the free-fall acceleration.
        assert!(data.qpos[2] < -4.0 && (data.qacc[2] + 9.81).abs() < 1e-12, "{label}: z {}", data.qpos[2]);
    }
    println!("iterations=0: worst relative difference to MuJoCo 4.0 {worst:.1e}");
    assert!(worst <= ALGO_REL, "{worst:e}");
}

const GO1: &str = "models/mjcf/unitree_go1/scene.xml";

/// Unconverged soft solves of 200 steps of go1 standing from its home keyframe with `iterations`
/// and `solver`: (count, worst residual, steps with rows).
fn go1_unconverged(iterations: u32, solver: Solver) -> (u64, f64, u32) {
    let mut model = Model::from_file(GO1).unwrap();
    model.options.iterations = iterations;
    model.options.solver = solver;
    let mut data = Data::new(&model);
    reset_keyframe(&model, &mut data, "home").unwrap();
    let mut with_rows = 0;
    for _ in 0..200 {
        step(&model, &mut data).unwrap();
        with_rows += u32::from(data.nefc > 0);
    }
    (data.efc_unconverged, data.efc_unconverged_residual, with_rows)
}

#[test]
fn soft_solver_counts_unconverged_solves() {
    for solver in [Solver::Newton, Solver::Cg, Solver::Pgs] {
        let (n1, r1, rows) = go1_unconverged(1, solver);
        let (n100, r100, _) = go1_unconverged(100, solver);
        println!("go1 {solver:?}: 1 iteration {n1} unconverged of {rows} solves (worst {r1:.2e}); 100 iterations {n100} (worst {r100:.2e})");
        assert!(rows > 100, "go1 stands on the floor");
        assert!(n1 > 0 && r1 > model_tolerance(), "{solver:?}: a 1-iteration solver must count");
        assert!(n100 < n1, "{solver:?}");
    }
}

fn model_tolerance() -> f64 {
    Model::from_file(GO1).unwrap().options.tolerance
}
