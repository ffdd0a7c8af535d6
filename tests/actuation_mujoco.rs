//! Actuation features of issue 30 against MuJoCo 4.0 (reference data from
//! validation/mujoco_actuation_golden.py, checked against the live MuJoCo in `.ci/run`): for each
//! scene of tests/data/mjcf/actuation, `mj_forward` quantities at random states (gravity
//! compensation `qfrc_gravcomp`, `qfrc_passive`, `qfrc_actuator`, the actuators' length,
//! velocity, force and `act_dot`, `qacc`) to 1e-9 relative, and a 200-step `mj_step` trajectory at
//! fixed controls (qpos, qvel, act) to 1e-9.

mod common;

use common::{follow_samples, rel_err_vec, state_rel_err, REF_REL};
use lagrange::forward::unsimulated_reason;
use lagrange::prelude::*;
use serde_json::Value;

fn floats(v: &Value) -> Vec<f64> {
    v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
}

fn golden() -> Value {
    serde_json::from_str(&std::fs::read_to_string("tests/data/mujoco/actuation.json").unwrap()).unwrap()
}

/// Compares every forward quantity of every state of `scene` and its trajectory; returns the
/// worst forward and trajectory errors.
fn check_scene(name: &str, scene: &Value) -> (f64, f64) {
    let model = Model::from_file(scene["model"].as_str().unwrap()).unwrap();
    assert!(model.warnings.is_empty(), "{name}: {:?}", model.warnings);
    let mut data = Data::new(&model);
    let mut worst_forward = 0.0f64;
    for (s, state) in scene["states"].as_array().unwrap().iter().enumerate() {
        data.qpos.copy_from_slice(&floats(&state["qpos"]));
        data.qvel.copy_from_slice(&floats(&state["qvel"]));
        data.act.copy_from_slice(&floats(&state["act"]));
        data.ctrl.copy_from_slice(&floats(&state["ctrl"]));
        forward(&model, &mut data);
        let ours: [(&str, &[f64]); 8] = [
            ("qfrc_gravcomp", data.qfrc_gravcomp.as_slice()),
            ("qfrc_passive", data.qfrc_passive.as_slice()),
            ("qfrc_actuator", data.qfrc_actuator.as_slice()),
            ("actuator_length", data.actuator_length.as_slice()),
            ("actuator_velocity", data.actuator_velocity.as_slice()),
            ("actuator_force", data.actuator_force.as_slice()),
            ("act_dot", data.act_dot.as_slice()),
            ("qacc", data.qacc.as_slice()),
        ];
        for (key, ours) in ours {
            let err = rel_err_vec(ours, &floats(&state[key]));
            assert!(err <= REF_REL, "{name} state {s}: {key} rel err {err:e}: {ours:?} vs {}", state[key]);
            worst_forward = worst_forward.max(err);
        }
    }
    reset(&model, &mut data).unwrap();
    data.ctrl.copy_from_slice(&floats(&scene["ctrl"]));
    let worst_run = follow_samples(&model, &mut data, &scene["run"], |sample, data, k| {
        let err = state_rel_err(sample, data).max(rel_err_vec(data.act.as_slice(), &floats(&sample["act"])));
        assert!(err <= REF_REL, "{name} step {k}: rel err {err:e}");
        err
    });
    println!("{name}: forward worst rel err {worst_forward:.1e}, 200 steps worst rel err {worst_run:.1e}");
    (worst_forward, worst_run)
}

#[test]
fn gravity_compensation_follows_mujoco() {
    let golden = golden();
    check_scene("gravcomp.xml", &golden["scenes"]["gravcomp.xml"]);
}

/// A joint's and a tendon's `actuatorfrcrange` reached under implicitfast: the clamped actuators
/// are left out of the velocity derivative, as MuJoCo 4.0 does (before, 8.5e-5 rad apart after one
/// step).
#[test]
fn actuator_force_ranges_reached_under_implicitfast_follow_mujoco() {
    let golden = golden();
    check_scene("actfrcrange_implicitfast.xml", &golden["scenes"]["actfrcrange_implicitfast.xml"]);
}

/// The compile-time muscle constants of `scene`: `actuator_lengthrange` (exact: copied from the
/// file or a joint's or tendon's range) and `actuator_acc0` (to 1e-9 relative).
fn check_muscle_constants(name: &str, scene: &Value) {
    let model = Model::from_file(scene["model"].as_str().unwrap()).unwrap();
    let lengthrange: Vec<f64> = model.actuators.iter().flat_map(|a| a.lengthrange).collect();
    assert_eq!(lengthrange, floats(&scene["actuator_lengthrange"]), "{name}: actuator_lengthrange");
    let acc0: Vec<f64> = model.actuators.iter().map(|a| a.acc0).collect();
    let err = rel_err_vec(&acc0, &floats(&scene["actuator_acc0"]));
    assert!(err <= REF_REL, "{name}: actuator_acc0 rel err {err:e}: {acc0:?}");
    for a in &model.actuators {
        assert_eq!(unsimulated_reason(&model, a), None, "{name}: {}", a.name);
    }
}

#[test]
fn muscles_with_lengthrange_from_limits_follow_mujoco() {
    let golden = golden();
    let scene = &golden["scenes"]["muscle_limits.xml"];
    check_muscle_constants("muscle_limits.xml", scene);
    check_scene("muscle_limits.xml", scene);
}

#[test]
fn muscles_with_written_lengthrange_and_smooth_switching_follow_mujoco() {
    let golden = golden();
    let scene = &golden["scenes"]["muscle_written.xml"];
    check_muscle_constants("muscle_written.xml", scene);
    check_scene("muscle_written.xml", scene);
}

#[test]
fn a_muscle_without_lengthrange_is_simulated_for_one_and_listed_with_mode_none() {
    let text = |compiler: &str| {
        format!(
            r#"<mujoco>{compiler}<worldbody><body><joint name="j" range="-1 1"/><geom size="0.1"/></body></worldbody>
               <actuator><muscle joint="j"/></actuator></mujoco>"#
        )
    };
    // The compiler's simulation pushes the hinge to its limits, ±1° (MuJoCo 4.0.0: ±0.0180232309
    // rad, the soft limit's overshoot included; tests/lengthrange_mujoco.rs checks other scenes).
    let model = Model::from_str(&text("")).unwrap();
    let [lo, hi] = model.actuators[0].lengthrange;
    assert!(
        (lo + 0.018023230873313652).abs() < 1e-12 && (hi - 0.018023230873313652).abs() < 1e-12,
        "{lo} {hi}"
    );
    assert!(unsimulated_reason(&model, &model.actuators[0]).is_none());
    // mode="none": no range, and the muscle is listed as not simulated.
    let model = Model::from_str(&text(r#"<compiler><lengthrange mode="none"/></compiler>"#)).unwrap();
    assert_eq!(model.actuators[0].lengthrange, [0.0, 0.0]);
    assert!(unsimulated_reason(&model, &model.actuators[0]).unwrap().contains("lengthrange"));
}
