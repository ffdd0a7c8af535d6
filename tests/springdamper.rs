//! MJCF `springdamper` (timeconst, dampratio): the stiffness and damping MuJoCo's compiler
//! derives from each joint's inertia at `qpos0` (`mjCModel::AutoSpringDamper`; src/io/compile.rs)
//! against MuJoCo 4.0's `jnt_stiffness` and `dof_damping`, the resulting `qfrc_passive` after
//! `mj_forward`, and 300 steps of `mj_step` (Euler; a damped, smooth chain: whole trajectory) —
//! reference data from validation/mujoco_springdamper_golden.py, checked against the live
//! MuJoCo in `.ci/run`.

mod common;

use common::{rel_err, rel_err_vec, ALGO_REL, REF_REL};
use lagrange::prelude::*;
use serde_json::Value;

fn vec(v: &Value) -> Vec<f64> {
    v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
}

#[test]
fn springdamper_matches_mujoco() {
    let golden: Value =
        serde_json::from_str(&std::fs::read_to_string("tests/data/mujoco/springdamper.json").unwrap())
            .unwrap();
    let model = Model::from_file(golden["model"].as_str().unwrap()).unwrap();
    // The joints' own stiffness and damping (MuJoCo keeps an actuator's damping apart, in
    // actuator_damping; lagrange adds gear² · damping to the dof's).
    let (stiffness, damping) = (vec(&golden["jnt_stiffness"]), vec(&golden["dof_damping"]));
    for (j, joint) in model.joints.iter().enumerate() {
        let (es, ed) = (rel_err(joint.stiffness, stiffness[j]), rel_err(joint.damping, damping[j]));
        println!(
            "{}: stiffness {:.6} (err {es:.1e}), damping {:.6} (err {ed:.1e})",
            joint.name, joint.stiffness, joint.damping
        );
        assert!(es <= ALGO_REL && ed <= ALGO_REL, "joint {}: {es:e} {ed:e}", joint.name);
    }
    let mut data = Data::new(&model);
    for (i, s) in golden["states"].as_array().unwrap().iter().enumerate() {
        data.qpos.copy_from_slice(&vec(&s["q"]));
        data.qvel.copy_from_slice(&vec(&s["v"]));
        data.ctrl.copy_from_slice(&vec(&s["ctrl"]));
        forward(&model, &mut data);
        let err = rel_err_vec(data.qfrc_passive.as_slice(), &vec(&s["qfrc_passive"]));
        println!("state {i}: qfrc_passive rel err {err:.1e}");
        assert!(err <= REF_REL, "state {i}: {err:e}");
    }
    let s = &golden["states"][0];
    reset(&model, &mut data).unwrap();
    data.qpos.copy_from_slice(&vec(&s["q"]));
    data.qvel.copy_from_slice(&vec(&s["v"]));
    data.ctrl.copy_from_slice(&vec(&s["ctrl"]));
    let mut k = 0;
    for sample in golden["steps"].as_array().unwrap() {
        while k < sample["step"].as_u64().unwrap() {
            step(&model, &mut data).unwrap();
            k += 1;
        }
        let err = rel_err_vec(data.qpos.as_slice(), &vec(&sample["qpos"]))
            .max(rel_err_vec(data.qvel.as_slice(), &vec(&sample["qvel"])));
        println!("step {k}: state rel err {err:.1e}");
        assert!(err <= REF_REL, "step {k}: {err:e}");
    }
}

#[test]
fn non_positive_springdamper_is_refused() {
    let xml = r#"<mujoco><worldbody><body><joint springdamper="0.1 -1"/><geom size="0.1"/></body></worldbody></mujoco>"#;
    let path = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("springdamper_bad.xml");
    let err = lagrange::io::load_str(xml, &path, &Default::default()).unwrap_err().to_string();
    assert!(err.contains("springdamper") && err.contains("positive"), "{err}");
}
