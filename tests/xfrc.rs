//! Cartesian wrenches on bodies (`Data::xfrc_applied`, MuJoCo's `xfrc_applied`): a force at a
//! free body's centre of mass accelerates it by f/m exactly; and the free box, arm and welded
//! hand of tests/data/mjcf/applied/xfrc.xml follow MuJoCo's `mj_step` (Euler and RK4, 200 steps,
//! a smooth non-chaotic scene: whole trajectories compared) — reference data from
//! validation/mujoco_xfrc_golden.py, checked against the live MuJoCo in `.ci/run`.

mod common;

use common::{follow_samples, state_rel_err, REF_REL};
use lagrange::model::FrameKind;
use lagrange::prelude::*;
use serde_json::Value;

/// The index in `xfrc_applied` of MuJoCo body `name` (the frames of kind Link, world first).
fn body_index(model: &Model, name: &str) -> usize {
    model.frames.iter().filter(|f| f.kind == FrameKind::Link).position(|f| f.name == name).unwrap()
}

#[test]
fn a_force_at_the_centre_of_mass_accelerates_by_f_over_m() {
    let model = Model::from_str(
        r#"<mujoco><option gravity="0 0 0"/><worldbody><body name="b" euler="30 40 50"><freejoint/>
           <geom type="box" size="0.1 0.2 0.3" mass="3" pos="0.1 -0.2 0.05"/></body></worldbody></mujoco>"#,
    )
    .unwrap();
    let mut data = Data::new(&model);
    assert_eq!(data.xfrc_applied.len(), 2, "world and b");
    data.xfrc_applied[body_index(&model, "b")] = [3.0, -6.0, 1.5, 0.0, 0.0, 0.0];
    forward(&model, &mut data);
    // Free joint: qacc[0..3] is the acceleration of the body origin, which moves with the centre
    // of mass while the body does not turn (a force through the centre of mass turns nothing).
    let want = [1.0, -2.0, 0.5];
    for (a, w) in data.qacc.iter().zip(want) {
        assert!((a - w).abs() < 1e-14, "{:?}", data.qacc.as_slice());
    }
    assert!(data.qacc.as_slice()[3..].iter().all(|a| a.abs() < 1e-14), "{:?}", data.qacc.as_slice());
    reset(&model, &mut data).unwrap();
    assert!(data.xfrc_applied.iter().all(|w| *w == [0.0; 6]), "reset clears the wrenches");
}

#[test]
fn wrenches_on_bodies_follow_mujoco() {
    let golden: Value =
        serde_json::from_str(&std::fs::read_to_string("tests/data/mujoco/xfrc.json").unwrap()).unwrap();
    for (name, integrator) in [("euler", "euler"), ("rk4", "rk4")] {
        let mut model = Model::from_file(golden["model"].as_str().unwrap()).unwrap();
        if integrator == "rk4" {
            model.options.integrator = lagrange::model::options::Integrator::Rk4;
        }
        let mut data = Data::new(&model);
        for (body, w) in golden["wrenches"].as_object().unwrap() {
            let w: Vec<f64> = w.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect();
            data.xfrc_applied[body_index(&model, body)].copy_from_slice(&w);
        }
        let worst = follow_samples(&model, &mut data, &golden["runs"][name], |sample, data, _| {
            state_rel_err(sample, data)
        });
        println!(
            "{name}: 200 steps with wrenches on box, forearm and welded hand, worst rel err {worst:.1e}"
        );
        assert!(worst <= REF_REL, "{name}: {worst:e}");
    }
}
