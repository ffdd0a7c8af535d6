//! Times `transition_jacobians` (centred, ε = 1e-6) at the states of
//! `tests/data/mujoco/transition/SCENE.json`, with the model's own solver options; prints one JSON
//! line `{"scene", "nv", "us": [median per state]}`. Driven by validation/bench_transition.py,
//! which times MuJoCo's `mjd_transitionFD` on the same states in the same run.
//!
//!     cargo run --release --example transition_cost -- go1_standing [REPS] [plain|hybrid]
//!
//! `plain` times the differences without stage skipping (`TransitionOptions::skip` = false),
//! `hybrid` the analytic velocity and control columns (`TransitionMethod::Hybrid`).

use lagrange::derivatives::{transition_jacobians, TransitionMethod, TransitionOptions, TransitionWork};
use lagrange::io::{load, LoadOptions};
use lagrange::Data;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let scene = args.next().ok_or("usage: transition_cost SCENE [REPS]")?;
    let reps: usize = args.next().map_or(Ok(20), |s| s.parse())?;
    let mode = args.next();
    let options = TransitionOptions {
        skip: mode.as_deref() != Some("plain"),
        method: if mode.as_deref() == Some("hybrid") { TransitionMethod::Hybrid } else { Default::default() },
        ..Default::default()
    };
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(root.join(format!("tests/data/mujoco/transition/{scene}.json")))?;
    let golden: serde_json::Value = serde_json::from_str(&text)?;
    let model = load(&root.join(golden["model"].as_str().ok_or("no model")?), &LoadOptions::default())?;
    let mut data = Data::new(&model);
    let mut work = TransitionWork::new(&model);
    let vec = |v: &serde_json::Value| -> Vec<f64> {
        v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
    };
    let mut medians = Vec::new();
    for st in golden["states"].as_array().ok_or("no states")? {
        data.qpos.copy_from_slice(&vec(&st["qpos"]));
        data.qvel.copy_from_slice(&vec(&st["qvel"]));
        data.act.copy_from_slice(&vec(&st["act"]));
        data.ctrl.copy_from_slice(&vec(&st["ctrl"]));
        data.qacc_warmstart.copy_from_slice(&vec(&st["qacc_warmstart"]));
        transition_jacobians(&model, &mut data, &mut work, &options)?;
        let mut us: Vec<f64> = (0..reps)
            .map(|_| {
                let t0 = Instant::now();
                let _ = transition_jacobians(&model, &mut data, &mut work, &options);
                t0.elapsed().as_secs_f64() * 1e6
            })
            .collect();
        us.sort_by(f64::total_cmp);
        medians.push(us[us.len() / 2]);
    }
    println!("{}", serde_json::json!({"scene": scene, "nv": model.nv, "us": medians}));
    Ok(())
}
