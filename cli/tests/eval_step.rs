//! `lagrange eval --step N` (the stepping interface of `validation/crossval_scenes.py`): N steps of
//! the model's integrator from each given state, against MuJoCo 4.0's `mj_step` (the committed
//! `tests/data/mujoco/edges.json`, validation/mujoco_edges_golden.py) and against the library's
//! own `step`; bad `--step` values and states are refused with a message.

#[path = "../../tests/common/mod.rs"]
mod common;
mod run;

use common::{rel_err_vec, ALGO_REL};
use lagrange::prelude::*;
use run::{lagrange, root};
use serde_json::{json, Value};

const BOX: &str = "tests/data/mjcf/edges/box_iterations0.xml";
const DROP: &str = "models/textbook/drop.xml";

fn states_file(name: &str, states: &Value) -> std::path::PathBuf {
    let path = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("lagrange-eval-step-{}-{name}.json", std::process::id()));
    std::fs::write(&path, json!({ "states": states }).to_string()).unwrap();
    path
}

fn eval_step(model: &str, name: &str, states: &Value, n: &str) -> Vec<Value> {
    let file = states_file(name, states);
    let (ok, out, err) = lagrange(&["eval", model, "--states", file.to_str().unwrap(), "--step", n]);
    std::fs::remove_file(&file).ok();
    assert!(ok, "{err}");
    let v: Value = serde_json::from_str(&out).unwrap();
    v["results"].as_array().unwrap().clone()
}

fn floats(v: &Value) -> Vec<f64> {
    v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
}

/// The Newton box of edges.json: 100 steps from rest, then 100 more from MuJoCo's step-100 state
/// (its qacc as the warm start, as `mj_step` leaves it), against MuJoCo's steps 100 and 200.
#[test]
fn eval_step_follows_mj_step() {
    let golden: Value =
        serde_json::from_str(&std::fs::read_to_string(root().join("tests/data/mujoco/edges.json")).unwrap())
            .unwrap();
    let sample = |k: u64| {
        golden["samples"]
            .as_array()
            .unwrap()
            .iter()
            .find(|s| s["solver"] == "Newton" && s["step"] == k)
            .unwrap()
            .clone()
    };
    let (s100, s200) = (sample(100), sample(200));
    let q0 = [0.0, 0.0, 0.2, 1.0, 0.0, 0.0, 0.0];
    let states = json!([
        {"q": q0},
        {"q": s100["qpos"], "v": s100["qvel"], "qacc_warmstart": s100["qacc"], "time": 0.2},
    ]);
    let results = eval_step(BOX, "box", &states, "100");
    let mut worst = 0.0f64;
    for (r, s) in results.iter().zip([&s100, &s200]) {
        let (eq, ev) = (
            rel_err_vec(&floats(&r["qpos"]), &floats(&s["qpos"])),
            rel_err_vec(&floats(&r["qvel"]), &floats(&s["qvel"])),
        );
        println!(
            "step {}: qpos {eq:.1e}, qvel {ev:.1e}, {} contacts, nefc {}",
            s["step"],
            r["contacts"].as_array().unwrap().len(),
            r["nefc"]
        );
        worst = worst.max(eq).max(ev);
        // The last step's collision pass: the box's four corners on the floor (16 pyramidal rows).
        assert_eq!(r["nefc"], s["nefc"]);
        assert_eq!(r["contacts"].as_array().unwrap().len(), 4);
        assert!(r["step_us"].as_f64().unwrap() > 0.0 && r["collide_us"].as_f64().unwrap() > 0.0);
    }
    assert!((results[1]["time"].as_f64().unwrap() - 0.4).abs() < 1e-12, "{}", results[1]["time"]);
    assert!(worst <= ALGO_REL, "{worst:e}");
}

/// One `--step 1` equals the library's `step` continuing a run from the same state to round-off
/// (the run's `Data` carries more than the state between steps: the last rows' bookkeeping), and
/// its contacts are those of the given state.
#[test]
fn eval_step_equals_the_library_step() {
    let model = Model::from_file(root().join(DROP)).unwrap();
    let mut data = Data::new(&model);
    for _ in 0..600 {
        step(&model, &mut data).unwrap();
    }
    let state = json!({"q": data.qpos.as_slice(), "v": data.qvel.as_slice(), "time": data.time,
                       "qacc_warmstart": data.qacc_warmstart.as_slice()});
    step(&model, &mut data).unwrap();
    let r = &eval_step(DROP, "drop", &json!([state]), "1")[0];
    let (eq, ev) = (
        rel_err_vec(&floats(&r["qpos"]), data.qpos.as_slice()),
        rel_err_vec(&floats(&r["qvel"]), data.qvel.as_slice()),
    );
    println!("drop, one step from step 600: qpos {eq:.1e}, qvel {ev:.1e}");
    assert!(eq <= ALGO_REL && ev <= ALGO_REL, "{eq:e} {ev:e}");
    let contacts = r["contacts"].as_array().unwrap();
    assert!(!contacts.is_empty());
    assert_eq!(contacts.len(), data.contacts.len());
    for (c, d) in contacts.iter().zip(&data.contacts) {
        assert!(rel_err_vec(&floats(&c["pos"]), d.pos.as_slice()) <= ALGO_REL, "{c} {:?}", d.pos);
        assert_eq!(c["geom_ids"], json!(d.geom));
    }
}

/// `--step 0` and a warm start of the wrong length are refused with a message.
#[test]
fn eval_step_refuses_bad_input() {
    let file =
        states_file("bad", &json!([{"q": [0.0, 0.0, 0.2, 1.0, 0.0, 0.0, 0.0], "qacc_warmstart": [0.0]}]));
    let path = file.to_str().unwrap();
    let (ok, _, err) = lagrange(&["eval", BOX, "--states", path, "--step", "0"]);
    assert!(!ok && err.contains("--step 0"), "{err}");
    let (ok, _, err) = lagrange(&["eval", BOX, "--states", path, "--step", "1"]);
    std::fs::remove_file(&file).ok();
    assert!(!ok && err.contains("'qacc_warmstart' has 1 values, the model needs 6"), "{err}");
}

/// `--dump-contact-problem`: the exact mode's problem at the state after the steps, one per state
/// — the box of edges.json resting on the floor: four contacts of three rows, a symmetric G, the
/// forward's and the cold solves' λ solving it (their residual ≤ 1e-8), best-of times; without
/// `--step` or in soft mode the flag is refused.
#[test]
fn eval_step_dumps_the_exact_contact_problem() {
    let states = json!([{"q": [0.0, 0.0, 0.1, 1.0, 0.0, 0.0, 0.0]}]);
    let file = states_file("dump", &states);
    let out = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("lagrange-eval-step-{}-problem.json", std::process::id()));
    let (states_arg, out_arg) = (file.to_str().unwrap(), out.to_str().unwrap());
    let base = ["eval", BOX, "--states", states_arg];
    let (ok, _, err) = lagrange(
        &[&base[..], &["--step", "50", "--constraints", "exact", "--dump-contact-problem", out_arg]].concat(),
    );
    assert!(ok, "{err}");
    let v: Value = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    let p = &v["problems"][0];
    assert_eq!(p["step"], 50);
    let n = p["nefc"].as_u64().unwrap() as usize;
    assert_eq!(n, 12, "four contacts of three rows");
    let g: Vec<Vec<f64>> = p["G"].as_array().unwrap().iter().map(floats).collect();
    for (i, row) in g.iter().enumerate() {
        assert_eq!(row.len(), n);
        for (j, x) in row.iter().enumerate() {
            assert_eq!(*x, g[j][i], "G[{i}][{j}]");
        }
    }
    assert!(p["blocks"].as_array().unwrap().iter().all(|b| b["law"] == "cone" && b["len"] == 3));
    for solve in ["forward", "pgs", "admm"] {
        let r = p[solve]["ccp_residual"]["relative"].as_f64().unwrap();
        assert!(r <= 1e-8, "{solve}: residual {r:e}");
        assert_eq!(floats(&p[solve]["lambda"]).len(), n);
    }
    for solve in ["pgs", "admm"] {
        assert!(p[solve]["solve_us"].as_f64().unwrap() > 0.0);
        assert_eq!(p[solve]["converged"], true);
    }
    std::fs::remove_file(&out).ok();
    let (ok, _, err) =
        lagrange(&[&base[..], &["--constraints", "exact", "--dump-contact-problem", out_arg]].concat());
    assert!(!ok && err.contains("--step"), "{err}");
    let (ok, _, err) = lagrange(
        &[&base[..], &["--step", "1", "--constraints", "soft", "--dump-contact-problem", out_arg]].concat(),
    );
    assert!(!ok && err.contains("--constraints exact"), "{err}");
    std::fs::remove_file(&file).ok();
}
