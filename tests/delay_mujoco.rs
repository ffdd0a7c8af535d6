//! Delayed controls (MuJoCo 4.0's actuator `delay`, `nsample`, `interp`; `forward::history`)
//! against MuJoCo 4.0.0 (reference data from validation/mujoco_delay_golden.py, checked against the
//! live MuJoCo in `.ci/run`): on each scene of tests/data/mjcf/delay (an arm, a slider and a wheel
//! driven by delayed actuators with each interpolation, a history kept without delay, a negative
//! delay, a delay below the timestep, a delayed servo and a delayed filter; Euler, RK4, implicit
//! and implicitfast), the model's history layout, the initial buffers, and 60 steps from the reset
//! state with controls that change every step: qpos, qvel, act, actuator_force and the history
//! buffers after every step, to 1e-9 relative (a smooth, non-chaotic trajectory: compared whole).

mod common;

use common::{rel_err_vec, REF_REL};
use lagrange::model::Interp;
use lagrange::prelude::*;
use serde_json::Value;

fn floats(v: &Value) -> Vec<f64> {
    v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
}

fn golden() -> Value {
    serde_json::from_str(&std::fs::read_to_string("tests/data/mujoco/delay.json").unwrap()).unwrap()
}

fn check_scene(name: &str) {
    let golden = golden();
    let scene = &golden["scenes"][name];
    let model = Model::from_file(format!("tests/data/mjcf/delay/{name}")).unwrap();
    assert!(model.warnings.is_empty(), "{name}: {:?}", model.warnings);
    // The layout: MuJoCo's nhistory, actuator_history (nsample, interp), historyadr and delay.
    assert_eq!(model.nhistory() as u64, scene["nhistory"].as_u64().unwrap(), "{name}: nhistory");
    let layout = floats(&scene["actuator_history"]);
    let adr = floats(&scene["actuator_historyadr"]);
    let delay = floats(&scene["actuator_delay"]);
    for (i, a) in model.actuators.iter().enumerate() {
        let (nsample, interp) = match &a.history {
            Some(h) => {
                assert_eq!(h.adr as f64, adr[i], "{name}: {} adr", a.name);
                assert_eq!(h.delay, delay[i], "{name}: {} delay", a.name);
                let interp = match h.interp {
                    Interp::ZeroOrderHold => 0.0,
                    Interp::Linear => 1.0,
                    Interp::Cubic => 2.0,
                };
                (h.nsample as f64, interp)
            }
            None => {
                assert_eq!(adr[i], -1.0, "{name}: {} has a history in MuJoCo", a.name);
                (0.0, 0.0)
            }
        };
        assert_eq!([nsample, interp], [layout[2 * i], layout[2 * i + 1]], "{name}: {}", a.name);
    }
    let mut data = Data::new(&model);
    assert_eq!(data.history.as_slice(), floats(&scene["initial"]["history"]).as_slice(), "{name}: initial");
    let mut worst = 0.0f64;
    for sample in scene["steps"].as_array().unwrap() {
        let k = sample["step"].as_u64().unwrap();
        data.ctrl.copy_from_slice(&floats(&sample["ctrl"]));
        lagrange::integrate::step(&model, &mut data).unwrap();
        let ours: [(&str, &[f64]); 5] = [
            ("qpos", data.qpos.as_slice()),
            ("qvel", data.qvel.as_slice()),
            ("act", data.act.as_slice()),
            ("actuator_force", data.actuator_force.as_slice()),
            ("history", data.history.as_slice()),
        ];
        for (key, ours) in ours {
            let err = rel_err_vec(ours, &floats(&sample[key]));
            assert!(err <= REF_REL, "{name} step {k}: {key} rel err {err:e}: {ours:?} vs {}", sample[key]);
            worst = worst.max(err);
        }
    }
    println!("{name}: 60 steps, worst relative difference from MuJoCo {worst:.1e}");
    // A reset restores MuJoCo's initial buffers.
    reset(&model, &mut data).unwrap();
    assert_eq!(data.history.as_slice(), floats(&scene["initial"]["history"]).as_slice(), "{name}: reset");
}

#[test]
fn delay_euler_matches_mujoco() {
    check_scene("arm_euler.xml");
}

#[test]
fn delay_rk4_reads_controls_at_stage_times() {
    check_scene("arm_rk4.xml");
}

#[test]
fn delay_implicit_matches_mujoco() {
    check_scene("arm_implicit.xml");
}

#[test]
fn delay_implicitfast_matches_mujoco() {
    check_scene("arm_implicitfast.xml");
}

#[test]
fn a_positive_delay_needs_samples() {
    let xml = r#"<mujoco><worldbody><body><joint name="j" type="slide"/><geom size=".1"/></body>
        </worldbody><actuator><motor joint="j" delay="0.02"/></actuator></mujoco>"#;
    let err = Model::from_str(xml).unwrap_err().to_string();
    assert!(err.contains("delay") && err.contains("nsample"), "{err}");
    let xml = xml.replace(r#"delay="0.02""#, r#"delay="0.02" nsample="2" interp="quadratic""#);
    let err = Model::from_str(&xml).unwrap_err().to_string();
    assert!(err.contains("interp") && err.contains("cubic"), "{err}");
}

#[test]
fn transition_jacobians_refuse_a_control_history() {
    let model = Model::from_file("tests/data/mjcf/delay/arm_euler.xml").unwrap();
    let mut data = Data::new(&model);
    let mut work = lagrange::derivatives::TransitionWork::new(&model);
    let options = lagrange::derivatives::TransitionOptions::default();
    let err =
        lagrange::derivatives::transition_jacobians(&model, &mut data, &mut work, &options).unwrap_err();
    assert!(err.to_string().contains("control history"), "{err}");
}

#[test]
fn histories_that_would_exhaust_memory_are_refused() {
    let motors: String =
        (0..20).map(|k| format!(r#"<motor name="m{k}" joint="j" nsample="1000000"/>"#)).collect();
    let xml = format!(
        r#"<mujoco><worldbody><body><joint name="j" type="slide"/><geom size=".1"/></body>
        </worldbody><actuator>{motors}</actuator></mujoco>"#
    );
    let err = Model::from_str(&xml).unwrap_err().to_string();
    assert!(err.contains("control histories") && err.contains("'m8'"), "{err}");
}
