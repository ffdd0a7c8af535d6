//! `<flag override>` against MuJoCo 4.0 (reference data from validation/mujoco_override_golden.py,
//! checked against the live MuJoCo in `.ci/run`): for each scene of tests/data/mjcf/override, the
//! contacts' parameters (dist, includemargin = `o_margin`, friction = `o_friction`, solref and
//! solreffriction = `o_solref`, solimp = `o_solimp`; contacts in the gap without rows),
//! `efc_force` and `qacc` at a few states to 1e-9 relative, and a 200-step `mj_step` trajectory
//! (qpos, qvel) to 1e-9.

mod common;

use common::{follow_samples, rel_err_vec, state_rel_err, REF_REL};
use lagrange::prelude::*;
use serde_json::Value;

fn floats(v: &Value) -> Vec<f64> {
    v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
}

fn golden() -> Value {
    serde_json::from_str(&std::fs::read_to_string("tests/data/mujoco/override.json").unwrap()).unwrap()
}

/// Compares every contact, `efc_force` and `qacc` of every state of `scene`, and its trajectory;
/// returns the worst forward and trajectory errors.
fn check_scene(name: &str, scene: &Value) -> (f64, f64) {
    let model = Model::from_file(scene["model"].as_str().unwrap()).unwrap();
    assert!(model.warnings.is_empty(), "{name}: {:?}", model.warnings);
    let mut data = Data::new(&model);
    let mut worst_forward = 0.0f64;
    for (s, state) in scene["states"].as_array().unwrap().iter().enumerate() {
        data.qpos.copy_from_slice(&floats(&state["qpos"]));
        data.qvel.copy_from_slice(&floats(&state["qvel"]));
        forward(&model, &mut data);
        let theirs = state["contacts"].as_array().unwrap();
        assert_eq!(data.contacts.len(), theirs.len(), "{name} state {s}: contact count");
        for (c, (ours, theirs)) in data.contacts.iter().zip(theirs).enumerate() {
            let fields: [(&str, &[f64]); 6] = [
                ("dist", std::slice::from_ref(&ours.dist)),
                ("includemargin", std::slice::from_ref(&ours.includemargin)),
                ("friction", &ours.friction),
                ("solref", &ours.solref),
                ("solreffriction", &ours.solreffriction),
                ("solimp", &ours.solimp),
            ];
            for (key, ours) in fields {
                let err = rel_err_vec(ours, &floats(&theirs[key]));
                assert!(
                    err <= REF_REL,
                    "{name} state {s} contact {c}: {key} rel err {err:e}: {ours:?} vs {}",
                    theirs[key]
                );
                worst_forward = worst_forward.max(err);
            }
        }
        for (key, ours) in
            [("efc_force", &data.efc_force.as_slice()[..data.nefc]), ("qacc", data.qacc.as_slice())]
        {
            let theirs = floats(&state[key]);
            assert_eq!(ours.len(), theirs.len(), "{name} state {s}: {key} length");
            let err = rel_err_vec(ours, &theirs);
            assert!(err <= REF_REL, "{name} state {s}: {key} rel err {err:e}: {ours:?} vs {theirs:?}");
            worst_forward = worst_forward.max(err);
        }
    }
    reset(&model, &mut data).unwrap();
    data.qvel.copy_from_slice(&floats(&scene["qvel0"]));
    let worst_run = follow_samples(&model, &mut data, &scene["run"], |sample, data, k| {
        let err = state_rel_err(sample, data);
        assert!(err <= REF_REL, "{name} step {k}: rel err {err:e}");
        err
    });
    println!("{name}: forward worst rel err {worst_forward:.1e}, 200 steps worst rel err {worst_run:.1e}");
    (worst_forward, worst_run)
}

#[test]
fn override_replaces_the_contact_parameters_as_mujoco_does() {
    let golden = golden();
    check_scene("box_on_plane.xml", &golden["scenes"]["box_on_plane.xml"]);
}
