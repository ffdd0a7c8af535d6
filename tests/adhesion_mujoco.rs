//! Adhesion (body transmissions, docs/physics.md) against MuJoCo 4.0 (reference data from
//! validation/mujoco_adhesion_golden.py, checked against the live MuJoCo in `.ci/run`): for each
//! scene of tests/data/mjcf/adhesion (adhesive spheres on a plane, one with rows and one in the
//! gap; a suction cup (sphere) on a box resting on a table, with a `<general body=...>` on the box; a box
//! within margin of a tilted plane with elliptic cones), `mj_forward` quantities at states near
//! the resting one (the dense `actuator_moment`, the actuators' length, velocity and force,
//! `qfrc_actuator` to 1e-9 relative; `qacc` to the soft solver's 1e-6), and a 200-step `mj_step`
//! trajectory at fixed controls compared after every step to 1e-6.

mod common;

use common::{follow_samples, rel_err_vec, state_rel_err, REF_REL, SOFT_REL};
use lagrange::forward::unsimulated_reason;
use lagrange::prelude::*;
use serde_json::Value;

fn floats(v: &Value) -> Vec<f64> {
    v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
}

fn golden() -> Value {
    serde_json::from_str(&std::fs::read_to_string("tests/data/mujoco/adhesion.json").unwrap()).unwrap()
}

/// Compares every forward quantity of every state of `scene` and its trajectory.
fn check_scene(name: &str) {
    let golden = golden();
    let scene = &golden["scenes"][name];
    let model = Model::from_file(scene["model"].as_str().unwrap()).unwrap();
    assert!(model.warnings.is_empty(), "{name}: {:?}", model.warnings);
    for a in &model.actuators {
        assert_eq!(unsimulated_reason(&model, a), None, "{name}: {}", a.name);
    }
    let mut data = Data::new(&model);
    let (mut worst_forward, mut worst_qacc) = (0.0f64, 0.0f64);
    for (s, state) in scene["states"].as_array().unwrap().iter().enumerate() {
        data.qpos.copy_from_slice(&floats(&state["qpos"]));
        data.qvel.copy_from_slice(&floats(&state["qvel"]));
        data.ctrl.copy_from_slice(&floats(&state["ctrl"]));
        forward(&model, &mut data);
        let ncon = data.contacts.iter().filter(|c| c.dist < c.includemargin + c.gap).count();
        assert_eq!(ncon as u64, state["ncon"].as_u64().unwrap(), "{name} state {s}: contact count");
        let moment: Vec<f64> = data.actuator_moment.transpose().as_slice().to_vec();
        let ours: [(&str, &[f64]); 5] = [
            ("actuator_moment", &moment),
            ("qfrc_actuator", data.qfrc_actuator.as_slice()),
            ("actuator_length", data.actuator_length.as_slice()),
            ("actuator_velocity", data.actuator_velocity.as_slice()),
            ("actuator_force", data.actuator_force.as_slice()),
        ];
        for (key, ours) in ours {
            let err = rel_err_vec(ours, &floats(&state[key]));
            assert!(err <= REF_REL, "{name} state {s}: {key} rel err {err:e}: {ours:?} vs {}", state[key]);
            worst_forward = worst_forward.max(err);
        }
        let err = rel_err_vec(data.qacc.as_slice(), &floats(&state["qacc"]));
        assert!(err <= SOFT_REL, "{name} state {s}: qacc rel err {err:e}");
        worst_qacc = worst_qacc.max(err);
    }
    reset(&model, &mut data).unwrap();
    data.ctrl.copy_from_slice(&floats(&scene["ctrl"]));
    let worst_run = follow_samples(&model, &mut data, &scene["run"], |sample, data, k| {
        let err = state_rel_err(sample, data);
        assert!(err <= SOFT_REL, "{name} step {k}: rel err {err:e}");
        err
    });
    println!(
        "{name}: moment/force worst rel err {worst_forward:.1e}, qacc {worst_qacc:.1e}, 200 steps {worst_run:.1e}"
    );
}

#[test]
fn adhesive_spheres_with_rows_and_in_the_gap_follow_mujoco() {
    check_scene("sphere_plane.xml");
}

#[test]
fn suction_cup_on_a_box_follows_mujoco() {
    check_scene("suction_box.xml");
}

#[test]
fn adhesive_box_with_elliptic_cones_follows_mujoco() {
    check_scene("box_elliptic.xml");
}
