//! MuJoCo's fluid forces (`dynamics::fluid`, docs/fluid.md): the inertia-box model
//! (tests/data/mjcf/fluid/inertia_box.xml: a plate falling through water in a side wind, a
//! tumbling two-geom body, a pendulum with a sliding paddle) and the ellipsoid model
//! (tests/data/mjcf/fluid/ellipsoid.xml: a falling plate in a wind, a spinning ball's Magnus lift,
//! a capsule and a cylinder with their own `fluidcoef`, a geom without a fluid shape) against
//! MuJoCo's `mj_forward` (`qfrc_fluid`, `qfrc_passive`, `qacc`) and 200-step `mj_step`
//! trajectories (Euler and RK4; smooth, non-chaotic scenes: whole trajectories compared) —
//! reference data from validation/mujoco_fluid_golden.py, checked against the live MuJoCo in
//! `.ci/run`.

mod common;

use common::{follow_samples, rel_err_vec, state_rel_err, REF_REL};
use lagrange::model::options::Integrator;
use lagrange::prelude::*;
use serde_json::Value;

fn golden() -> Value {
    serde_json::from_str(&std::fs::read_to_string("tests/data/mujoco/fluid.json").unwrap()).unwrap()
}

fn vec(v: &Value) -> Vec<f64> {
    v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
}

#[test]
fn forward_fluid_forces_match_mujoco() {
    let golden = golden();
    for (scene, reference) in golden["scenes"].as_object().unwrap() {
        let model = Model::from_file(scene).unwrap();
        let mut data = Data::new(&model);
        for (i, sample) in reference["forward"].as_array().unwrap().iter().enumerate() {
            data.qpos.copy_from_slice(&vec(&sample["qpos"]));
            data.qvel.copy_from_slice(&vec(&sample["qvel"]));
            forward(&model, &mut data);
            for (key, got) in [
                ("qfrc_fluid", data.qfrc_fluid.as_slice()),
                ("qfrc_passive", data.qfrc_passive.as_slice()),
                ("qacc", data.qacc.as_slice()),
            ] {
                let err = rel_err_vec(got, &vec(&sample[key]));
                println!("{scene} state {i}: {key} rel err {err:.1e}");
                assert!(err <= REF_REL, "{scene} state {i} {key}: {err:e}\n{got:?}\n{}", sample[key]);
            }
        }
    }
}

#[test]
fn fluid_trajectories_match_mujoco() {
    let golden = golden();
    for (scene, reference) in golden["scenes"].as_object().unwrap() {
        for (name, integrator) in [("euler", Integrator::Euler), ("rk4", Integrator::Rk4)] {
            let mut model = Model::from_file(scene).unwrap();
            model.options.integrator = integrator;
            let mut data = Data::new(&model);
            reset_keyframe(&model, &mut data, "moving").unwrap();
            let worst = follow_samples(&model, &mut data, &reference["runs"][name], |sample, data, _| {
                state_rel_err(sample, data)
            });
            println!("{scene} {name}: 200 steps, worst rel err {worst:.1e}");
            assert!(worst <= REF_REL, "{scene} {name}: {worst:e}");
        }
    }
}

#[test]
fn info_lists_the_fluid_stage_as_running() {
    let model = Model::from_file("tests/data/mjcf/fluid/ellipsoid.xml").unwrap();
    let stage = model.plan.stages.iter().find(|s| s.name == "fluid forces").expect("a fluid stage");
    assert_eq!(stage.status, lagrange::forward::Status::Runs, "{}", stage.reason);
    assert!(stage.reason.contains("ellipsoid model on 4 geoms"), "{}", stage.reason);
    let model = Model::from_file("tests/data/mjcf/fluid/inertia_box.xml").unwrap();
    let stage = model.plan.stages.iter().find(|s| s.name == "fluid forces").unwrap();
    assert!(stage.reason.contains("inertia-box model on 4 bodies"), "{}", stage.reason);
}
