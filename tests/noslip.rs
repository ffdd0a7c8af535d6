//! MuJoCo's no-slip post-process (`constraint::soft::noslip`, `<option noslip_iterations>`):
//! tests/data/mjcf/noslip/ (a box on a 20° incline, pyramidal and elliptic cones, condim 3 and 6;
//! a two-finger squeeze of a box on slide joints with friction loss) against MuJoCo's
//! `mj_forward` (`efc_force`, `qacc`, `qfrc_constraint` after 20 steps) and 200-step `mj_step`
//! trajectories, for noslip_iterations 0, 10 and 100 — reference data from
//! validation/mujoco_noslip_golden.py, checked against the live MuJoCo in `.ci/run`. Elliptic
//! cones are not post-processed yet: their scenes are compared with no-slip off only.

mod common;

use common::{follow_samples, rel_err_vec, state_rel_err, REF_REL, SOFT_REL};
use lagrange::prelude::*;
use serde_json::Value;

fn golden() -> Value {
    serde_json::from_str(&std::fs::read_to_string("tests/data/mujoco/noslip.json").unwrap()).unwrap()
}

fn vec(v: &Value) -> Vec<f64> {
    v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
}

/// The cases this engine post-processes like MuJoCo: every pyramidal scene, elliptic ones with
/// no-slip off (`elliptic`: instead the elliptic scenes with no-slip on, not post-processed yet:
/// [`elliptic_noslip_matches_mujoco`] is ignored and says why).
fn cases_of(golden: &Value, elliptic: bool) -> Vec<(String, u32, Value)> {
    let mut out = Vec::new();
    for (scene, by_n) in golden["scenes"].as_object().unwrap() {
        for (n, case) in by_n.as_object().unwrap() {
            let n: u32 = n.parse().unwrap();
            if (n > 0 && scene.contains("elliptic")) != elliptic {
                continue;
            }
            out.push((scene.clone(), n, case.clone()));
        }
    }
    out
}

fn cases(golden: &Value) -> Vec<(String, u32, Value)> {
    cases_of(golden, false)
}

fn load(scene: &str, n: u32, ctrl: f64) -> (Model, Data) {
    let mut model = Model::from_file(scene).unwrap();
    model.options.noslip_iterations = n;
    let mut data = Data::new(&model);
    data.ctrl.fill(ctrl);
    (model, data)
}

#[test]
fn forward_noslip_forces_match_mujoco() {
    let golden = golden();
    let ctrl = golden["ctrl"].as_f64().unwrap();
    for (scene, n, case) in cases(&golden) {
        let (model, mut data) = load(&scene, n, ctrl);
        let sample = &case["forward"];
        data.qpos.copy_from_slice(&vec(&sample["qpos"]));
        data.qvel.copy_from_slice(&vec(&sample["qvel"]));
        forward(&model, &mut data);
        let nefc = data.nefc;
        for (key, got) in [
            ("efc_force", &data.efc_force.as_slice()[..nefc]),
            ("qacc", data.qacc.as_slice()),
            ("qfrc_constraint", data.qfrc_constraint.as_slice()),
        ] {
            let err = rel_err_vec(got, &vec(&sample[key]));
            println!("{scene} noslip {n}: {key} rel err {err:.1e}");
            assert!(err <= REF_REL, "{scene} noslip {n} {key}: {err:e}\n{got:?}\n{}", sample[key]);
        }
    }
}

#[test]
fn noslip_trajectories_match_mujoco() {
    let golden = golden();
    let ctrl = golden["ctrl"].as_f64().unwrap();
    for (scene, n, case) in cases(&golden) {
        let (model, mut data) = load(&scene, n, ctrl);
        let worst =
            follow_samples(&model, &mut data, &case["run"], |sample, data, _| state_rel_err(sample, data));
        println!("{scene} noslip {n}: 200 steps, worst rel err {worst:.1e}");
        assert!(worst <= SOFT_REL, "{scene} noslip {n}: {worst:e}");
    }
}

#[test]
#[ignore = "issue 30: no-slip on elliptic cones (MuJoCo's QCQP on the cone of the fixed normal force) is not written; src/constraint/soft/noslip.rs leaves elliptic contact rows as the main solver set them"]
fn elliptic_noslip_matches_mujoco() {
    let golden = golden();
    let ctrl = golden["ctrl"].as_f64().unwrap();
    for (scene, n, case) in cases_of(&golden, true) {
        let (model, mut data) = load(&scene, n, ctrl);
        let sample = &case["forward"];
        data.qpos.copy_from_slice(&vec(&sample["qpos"]));
        data.qvel.copy_from_slice(&vec(&sample["qvel"]));
        forward(&model, &mut data);
        let err = rel_err_vec(&data.efc_force.as_slice()[..data.nefc], &vec(&sample["efc_force"]));
        assert!(err <= REF_REL, "{scene} noslip {n} efc_force: {err:e}");
    }
}
