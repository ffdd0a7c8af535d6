//! The actuation stage (MuJoCo's `mj_fwdActuation`) against hand-computed forces: position,
//! motor, velocity, affine general and tendon actuators, with control and force clamping and gear;
//! activation dynamics (act_dot of each dyntype, filterexact's exact step, actrange, actearly, an
//! intvelocity servo); site, ball and free transmissions (moments against finite differences).
//! The same forces against MuJoCo on corpus robots are `validation/crossval_actuators`.

mod common;

use common::ALGO_REL;
use lagrange::constraint::ConstraintMode;
use lagrange::forward::{forward, unsimulated_reason, Plan, Status};
use lagrange::io::{load, LoadOptions};
use lagrange::Data;
use std::path::Path;

#[test]
fn actuator_forces_follow_mujocos_formulas() {
    let model = load(Path::new("tests/data/mjcf/actuators/basic.xml"), &LoadOptions::default()).unwrap();
    let plan = Plan::new(&model, Some(ConstraintMode::Exact));
    let stage = plan.stages.iter().find(|s| s.name == "actuation").unwrap();
    println!("actuation stage: {:?} — {}", stage.status, stage.reason);
    assert_eq!(stage.status, Status::Runs);
    assert!(
        stage.reason.contains("6 actuators") && !stage.reason.contains("not simulated"),
        "{}",
        stage.reason
    );
    assert!(model.actuators.iter().all(|a| unsimulated_reason(&model, a).is_none()));
    assert_eq!(model.na(), 1);

    let mut data = Data::new(&model);
    let (q, v) = ([0.3, -0.2, 0.1, 0.4], [1.0, -2.0, 0.5, 0.8]);
    // Controls beyond the ranges of the position and motor actuators: clamped to 1 and 0.4. The
    // filter's activation is 0.2: its force is gain · act, whatever the control.
    data.ctrl.copy_from_slice(&[2.0, 0.9, 3.0, 1.5, -0.6, 5.0]);
    data.act[0] = 0.2;
    forward(&model, &plan, &mut data, &q, &v);
    let f = data.actuator_force.as_slice();
    let want = [
        50.0 * (1.0 - 0.3) - 3.0 * 1.0, // kp (ctrl − q) − kv q̇, ctrl clamped to 1
        0.4,                            // motor: ctrl clamped to 0.4
        (7.0 * 3.0 - 7.0 * 0.5f64).clamp(-1.0, 1.0), // velocity kv (ctrl − q̇), force clamped
        (2.0 + 0.5 * 0.4 + 0.25 * 0.8) * 1.5 + (1.0 - 3.0 * 0.4 - 0.5 * 0.8), // affine gain and bias
        -0.6,                           // tendon motor
        10.0 * 0.2,                     // filter: gain · act
    ];
    println!("actuator_force {f:?}\nwant           {want:?}");
    for (i, (a, b)) in f.iter().zip(want).enumerate() {
        assert!((a - b).abs() <= ALGO_REL * (1.0 + b.abs()), "actuator {i}: {a} vs {b}");
    }
    // Lengths through the transmissions: gear · q, and the tendon's gear · Σ coef q.
    let tendon_length = 1.5 * (2.0 * 0.3 - 0.5 * -0.2);
    assert!(
        (data.actuator_length[1] - 2.5 * -0.2).abs() < 1e-15
            && (data.actuator_length[4] - tendon_length).abs() < 1e-15
    );
    // qfrc_actuator = Σ momentᵀ force: gear on the joint, gear · coef through the tendon.
    let qfrc = data.qfrc_actuator.as_slice();
    let want_qfrc =
        [want[0] + 1.5 * 2.0 * want[4], 2.5 * want[1] + 1.5 * -0.5 * want[4], want[2], want[3] + want[5]];
    println!("qfrc_actuator {qfrc:?}\nwant          {want_qfrc:?}");
    for (a, b) in qfrc.iter().zip(want_qfrc) {
        assert!((a - b).abs() <= ALGO_REL * (1.0 + b.abs()));
    }
    // actuator_moment (MuJoCo's): the gear on the joint's dof, gear · coef on the tendon's dofs;
    // and qfrc_actuator = momentᵀ · actuator_force.
    let moment = &data.actuator_moment;
    assert_eq!((moment[(1, 1)], moment[(4, 0)], moment[(4, 1)]), (2.5, 1.5 * 2.0, 1.5 * -0.5));
    // The filter's act_dot = (ctrl − act) / τ (its control is not limited).
    assert!((data.act_dot[0] - (5.0 - 0.2) / 0.1).abs() < 1e-12);
    let from_moment = moment.transpose() * &data.actuator_force;
    assert!((from_moment - &data.qfrc_actuator).amax() <= ALGO_REL * data.qfrc_actuator.amax());
    // The accelerations include them (no gravity, no other force; diagonal M).
    assert!(data.qacc.iter().zip(qfrc).all(|(a, f)| a.signum() == f.signum() || f.abs() < 1e-12));
}

#[test]
fn actuation_switched_off_or_absent_costs_nothing() {
    let model = load(Path::new("models/textbook/drop.xml"), &LoadOptions::default()).unwrap();
    let plan = Plan::new(&model, None);
    let stage = plan.stages.iter().find(|s| s.name == "actuation").unwrap();
    assert_eq!((stage.status, stage.reason.as_str()), (Status::Skipped, "no actuators"));
    let options = LoadOptions { disabled_flags: vec!["actuation".into()], ..Default::default() };
    let model = load(Path::new("tests/data/mjcf/actuators/basic.xml"), &options).unwrap();
    let plan = Plan::new(&model, None);
    let stage = plan.stages.iter().find(|s| s.name == "actuation").unwrap();
    assert_eq!(stage.status, Status::Skipped);
    let mut data = Data::new(&model);
    data.ctrl.fill(1.0);
    forward(&model, &plan, &mut data, &[0.0; 4], &[0.0; 4]);
    assert_eq!(data.qfrc_actuator.amax(), 0.0);
}
