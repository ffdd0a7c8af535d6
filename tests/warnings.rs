//! Run-time warnings (issue 27 item 2): a mass matrix singular at the state gives MuJoCo 4.0's
//! regularized accelerations (its factor's pivots raised to mjMINVAL, mjWARN_INERTIA) and a bad
//! control zeroes every control (mjWARN_BADCTRL), each counted in `Data::warnings` and worded
//! naming the joints or the actuator; checked against validation/mujoco_warnings_golden.py.

mod common;

use common::*;
use lagrange::prelude::*;
use serde_json::Value;

fn numbers(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| match x {
            Value::String(s) => s.parse::<f64>().unwrap(),
            x => x.as_f64().unwrap(),
        })
        .collect()
}

/// Every golden case: lagrange's qacc and actuator forces equal MuJoCo's, and so do the warning
/// counts and the dof or actuator they name.
#[test]
fn singular_mass_matrix_and_bad_controls_as_mujoco() {
    let golden: Value =
        serde_json::from_str(&std::fs::read_to_string(repo_path("tests/data/mujoco/warnings.json")).unwrap())
            .unwrap();
    let mut worst = 0.0f64;
    let mut n = 0;
    for file in golden["models"].as_array().unwrap() {
        let name = file["file"].as_str().unwrap();
        let model = Model::from_file(repo_path(&format!("tests/data/mjcf/warnings/{name}"))).unwrap();
        for case in file["cases"].as_array().unwrap() {
            let mut data = Data::new(&model);
            data.qpos.copy_from_slice(&numbers(&case["qpos"]));
            data.qvel.copy_from_slice(&numbers(&case["qvel"]));
            data.qfrc_applied.copy_from_slice(&numbers(&case["qfrc_applied"]));
            data.ctrl.copy_from_slice(&numbers(&case["ctrl"]));
            forward(&model, &mut data);
            let want_qacc = numbers(&case["qacc"]);
            let err = rel_err_vec(data.qacc.as_slice(), &want_qacc);
            let err_f = rel_err_vec(data.actuator_force.as_slice(), &numbers(&case["actuator_force"]));
            println!("{name} ctrl {:?}: qacc {err:.1e}, actuator_force {err_f:.1e}", data.ctrl.as_slice());
            assert!(err <= SINGULAR_REL && err_f <= ALGO_REL, "{name} {case}: {:?}", data.qacc.as_slice());
            worst = worst.max(err);
            let w = &data.warnings;
            assert_eq!(w.inertia.number, case["inertia_warnings"].as_u64().unwrap(), "{name}");
            assert_eq!(w.bad_ctrl.number, case["badctrl_warnings"].as_u64().unwrap(), "{name}");
            if w.inertia.number > 0 {
                assert_eq!(w.inertia.last_info as u64, case["inertia_lastinfo"].as_u64().unwrap());
            }
            if w.bad_ctrl.number > 0 {
                assert_eq!(w.bad_ctrl.last_info as u64, case["badctrl_lastinfo"].as_u64().unwrap());
            }
            n += 1;
        }
    }
    println!("{n} cases, worst qacc {worst:.1e}");
    assert_eq!(n, 10);
}

/// The warnings name what they concern: the duplicated joints, the bad actuator.
#[test]
fn messages_name_the_joints_and_the_actuator() {
    let model = Model::from_file(repo_path("tests/data/mjcf/warnings/dup_hinges.xml")).unwrap();
    let mut data = Data::new(&model);
    forward(&model, &mut data);
    assert!(data.qacc.iter().all(|a| a.is_finite()));
    let text = data.warnings.messages(&model).join("\n");
    assert!(text.contains("'a'") && text.contains("'c'") && text.contains("'d'"), "{text}");
    assert!(!text.contains("'b'") && !text.contains("'e'"), "{text}");
    reset(&model, &mut data).unwrap();
    assert!(!data.warnings.any());

    let model = Model::from_file(repo_path("tests/data/mjcf/warnings/bad_ctrl.xml")).unwrap();
    let mut data = Data::new(&model);
    data.ctrl[1] = f64::NAN;
    forward(&model, &mut data);
    let text = data.warnings.messages(&model).join("\n");
    assert!(text.contains("'m_limited'"), "{text}");
    // The control as set is kept (MuJoCo zeroes a local copy).
    assert!(data.ctrl[1].is_nan());
    // Steps go on: the ball falls freely, the arm under gravity only.
    for _ in 0..10 {
        step(&model, &mut data).unwrap();
    }
    assert!(data.qpos.iter().all(|q| q.is_finite()));
}

/// A moving leaf without mass or inertia (loaded with a warning; MuJoCo refuses the file):
/// finite accelerations, the leaf's joint named, on the ABA path (no constraint) and after steps.
#[test]
fn massless_leaf_gives_finite_accelerations() {
    let model = Model::from_str(
        r#"<mujoco><compiler inertiafromgeom="false"/><worldbody>
        <body pos="0 0 1"><joint name="arm" axis="0 1 0"/>
          <inertial pos="0.1 0 0" mass="1" diaginertia=".01 .01 .01"/>
          <body pos="0.3 0 0"><joint name="leaf" axis="0 1 0"/>
            <inertial pos="0 0 0" mass="0" diaginertia="0 0 0"/></body></body>
        </worldbody></mujoco>"#,
    )
    .unwrap();
    let mut data = Data::new(&model);
    data.qpos[0] = 0.4;
    forward(&model, &mut data);
    println!("qacc {:?}", data.qacc.as_slice());
    assert!(data.qacc.iter().all(|a| a.is_finite()), "{:?}", data.qacc.as_slice());
    // The arm swings as a physical pendulum: m g r cos(θ) / (I + m r²) about its hinge (+y; the
    // weight at r = 0.1 m along the turned x axis); the leaf's dof stays at rest (no force on it).
    let want = 9.81 * 0.1 * 0.4f64.cos() / (0.01 + 0.01);
    assert_eq!(data.qacc[1], 0.0);
    assert!(rel_err(data.qacc[0], want) <= ALGO_REL, "{} vs {want}", data.qacc[0]);
    let text = data.warnings.messages(&model).join("\n");
    assert!(text.contains("'leaf'") && !text.contains("'arm'"), "{text}");
    for _ in 0..100 {
        step(&model, &mut data).unwrap();
    }
    assert!(data.qpos.iter().all(|q| q.is_finite()));
}
