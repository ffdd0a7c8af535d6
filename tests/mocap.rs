//! Mocap bodies (MJCF `mocap="true"`): their poses are inputs in `Data` (`mocap_pos`,
//! `mocap_quat`) that move their geoms, sites and the equality constraints anchored on them. A
//! site follows the mocap pose exactly; and the scene of tests/data/mjcf/applied/mocap.xml — a
//! mocap box pushing a free sphere on the floor, a turning, rising mocap hand holding a block by
//! a weld and a capsule by a connect — follows MuJoCo's `mj_step` over 300 steps with the same
//! mocap poses set before each step (soft contacts and equalities: whole trajectories at the
//! soft tolerance). Reference data from validation/mujoco_mocap_golden.py, checked against the
//! live MuJoCo in `.ci/run`.

mod common;

use common::{state_rel_err, SOFT_REL};
use lagrange::prelude::*;
use lagrange::spatial::Vec3;
use serde_json::Value;

const SCENE: &str = "tests/data/mjcf/applied/mocap.xml";

/// The poses of the two mocap bodies (pusher, hand) at time t, as validation/mujoco_mocap_golden.py.
fn set_mocap(data: &mut Data) {
    let t = data.time;
    data.mocap_pos[0] = Vec3::new(-0.3 + 0.6 * t, 0.0, 0.1);
    data.mocap_pos[1] = Vec3::new(1.0, 0.0, 0.8 + 0.2 * t);
    let angle = 20f64.to_radians() + 1.5 * t;
    data.mocap_quat[1] = [(angle / 2.0).cos(), 0.0, 0.0, (angle / 2.0).sin()];
}

#[test]
fn mocap_poses_move_their_sites_and_start_at_the_file_pose() {
    let model = Model::from_file(SCENE).unwrap();
    let mut data = Data::new(&model);
    assert_eq!((data.mocap_pos.len(), model.mocap_pose0.len()), (2, 2));
    assert_eq!(data.mocap_pos[0], Vec3::new(-0.3, 0.0, 0.1), "the pusher's pos in the file");
    let tip = frames::pose(&model, &mut data, "pusher_tip").unwrap();
    assert!((tip.pos - Vec3::new(-0.2, 0.0, 0.1)).amax() < 1e-15);
    data.mocap_pos[0] = Vec3::new(1.0, 2.0, 3.0);
    data.mocap_quat[0] = [0.0, 0.0, 0.0, 2.0]; // 180° about z, not normalized
    let tip = frames::pose(&model, &mut data, "pusher_tip").unwrap();
    assert!((tip.pos - Vec3::new(0.9, 2.0, 3.0)).amax() < 1e-15, "{:?}", tip.pos);
    reset(&model, &mut data).unwrap();
    assert_eq!(data.mocap_pos[0], Vec3::new(-0.3, 0.0, 0.1), "reset restores the file's pose");
}

#[test]
fn mocap_bodies_push_and_hold_as_in_mujoco() {
    let golden: Value =
        serde_json::from_str(&std::fs::read_to_string("tests/data/mujoco/mocap.json").unwrap()).unwrap();
    let model = Model::from_file(SCENE).unwrap();
    let mut data = Data::new(&model);
    let mut worst = 0.0f64;
    let mut k = 0;
    for sample in golden["samples"].as_array().unwrap() {
        while k < sample["step"].as_u64().unwrap() {
            set_mocap(&mut data);
            step(&model, &mut data).unwrap();
            k += 1;
        }
        worst = worst.max(state_rel_err(sample, &data));
        println!("step {k}: worst rel err so far {worst:.1e}, ball x {:.4}", data.qpos[0]);
    }
    // The pusher has pushed the ball (MuJoCo's ball is at x = 0.31 after 300 steps).
    assert!(data.qpos[0] > 0.3, "ball x {}", data.qpos[0]);
    assert!(worst <= SOFT_REL, "{worst:e}");
}

/// A keyframe's `mpos` and `mquat` set the mocap poses (MuJoCo's `mj_resetDataKeyframe`); a
/// wrong count is refused at load with the count the model needs.
#[test]
fn keyframes_set_mocap_poses() {
    let scene = |key: &str| {
        format!(
            r#"<mujoco><worldbody><body name="m" mocap="true" pos="1 2 3"><geom size="0.1"/></body>
               <body><freejoint/><geom size="0.1"/></body></worldbody><keyframe>{key}</keyframe></mujoco>"#
        )
    };
    let model = Model::from_str(&scene(r#"<key name="k" mpos="4 5 6" mquat="0 1 0 0"/>"#)).unwrap();
    let mut data = Data::new(&model);
    reset_keyframe(&model, &mut data, "k").unwrap();
    assert_eq!((data.mocap_pos[0], data.mocap_quat[0]), (Vec3::new(4.0, 5.0, 6.0), [0.0, 1.0, 0.0, 0.0]));
    let err = Model::from_str(&scene(r#"<key name="k" mpos="4 5"/>"#)).unwrap_err().to_string();
    assert!(err.contains("keyframe 'k': mpos has 2 values, the model needs 3"), "{err}");
}
