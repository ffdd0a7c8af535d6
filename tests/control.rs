//! Controls in the API: the controller callbacks of `Simulation` (a
//! zero-order hold, called once per step) and the URDF effort limits of `--clamp-effort`.

use lagrange::integrate::IntegratorKind;
use lagrange::io::{load, load_urdf_str, mjcf, LoadOptions};
use lagrange::sim::{SimOptions, Simulation};
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

const MOTOR_PENDULUM: &str = r#"<mujoco><option gravity="0 0 0"/><worldbody><body>
  <joint name="hinge" axis="0 1 0"/><geom type="capsule" fromto="0 0 0 0 0 -0.5" size="0.05" mass="1"/>
</body></worldbody><actuator><motor joint="hinge" gear="2" ctrlrange="-1 1"/></actuator></mujoco>"#;

#[test]
fn controller_sets_the_controls_once_per_step() {
    let spec = mjcf::parse_str(MOTOR_PENDULUM, Path::new("motor.xml"), &LoadOptions::default()).unwrap();
    let model = Arc::new(lagrange::io::compile(&spec).unwrap());
    let options =
        SimOptions { integrator: Some(IntegratorKind::Rk4), timestep: Some(1e-3), ..Default::default() };
    let mut sim = Simulation::new(model, &options);
    let calls = Arc::new(AtomicUsize::new(0));
    let seen = calls.clone();
    // ctrl = 3 (beyond ctrlrange: clamped to 1) for t < 5 ms, then 0.25.
    sim.set_controller(move |t, q, v, ctrl| {
        assert_eq!((q.len(), v.len(), ctrl.len()), (1, 1, 1));
        seen.fetch_add(1, Ordering::Relaxed);
        ctrl[0] = if t < 5e-3 - 1e-12 { 3.0 } else { 0.25 };
    });
    for _ in 0..5 {
        sim.step().unwrap();
    }
    // Held for the whole step (every RK4 stage): the actuator force is clamp(ctrl) = 1 (MuJoCo's
    // actuator_force, before the gear), the joint torque gear · 1 = 2 N·m.
    assert_eq!(sim.data.actuator_force[0], 1.0);
    assert_eq!(sim.data.qfrc_actuator[0], 2.0);
    // The moment arm (MuJoCo's actuator_moment) is the gear: qfrc_actuator = momentᵀ force.
    assert_eq!(sim.data.actuator_moment[(0, 0)], 2.0);
    let after_5 = sim.data.qvel[0];
    for _ in 0..5 {
        sim.step().unwrap();
    }
    assert_eq!(calls.load(Ordering::Relaxed), 10, "one call per step");
    assert_eq!(sim.data.actuator_force[0], 0.25);
    // Without gravity the hinge accelerates at τ/I: the velocity after 5 ms of 2 N·m, then 5 ms
    // of 0.5 N·m, is (2 + 0.5)·5e-3 / I.
    let i = sim.model.bodies[1].inertia.i_origin[(1, 1)];
    assert!((after_5 - 2.0 * 5e-3 / i).abs() < 1e-12 * after_5.abs(), "{after_5}");
    assert!((sim.data.qvel[0] - 2.5 * 5e-3 / i).abs() < 1e-12 * sim.data.qvel[0].abs());
}

/// A horizontal pendulum (no gravity torque at rest) whose joint allows 1.5 N·m of effort.
const EFFORT_PENDULUM: &str = r#"<robot name="effort"><link name="base"/>
  <link name="arm"><inertial><origin xyz="0.5 0 0"/><mass value="2"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="hinge" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1.5" velocity="10"/></joint></robot>"#;

fn torque_driven(clamp_effort: bool) -> f64 {
    let options = LoadOptions { clamp_effort, ..Default::default() };
    let model = Arc::new(load_urdf_str(EFFORT_PENDULUM, Path::new("effort.urdf"), &options).unwrap());
    let sim_options =
        SimOptions { integrator: Some(IntegratorKind::Euler), timestep: Some(1e-3), ..Default::default() };
    let mut sim = Simulation::new(model, &sim_options);
    sim.set_torque_controller(|_, _, _, tau| tau[0] = 10.0);
    sim.step().unwrap();
    sim.data.qvel[0]
}

#[test]
fn clamp_effort_bounds_applied_joint_torques() {
    let i = 0.01 + 2.0 * 0.25; // about the hinge
                               // Unclamped: 10 N·m; clamped to the URDF effort 1.5 N·m (one Euler step of 1 ms).
    assert!((torque_driven(false) - 10.0 / i * 1e-3).abs() < 1e-12);
    assert!((torque_driven(true) - 1.5 / i * 1e-3).abs() < 1e-12);
    // MJCF: the option does not apply, and says so.
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("models/textbook/heavy_top.xml");
    let m = load(&path, &LoadOptions { clamp_effort: true, ..Default::default() }).unwrap();
    assert!(
        m.warnings.iter().any(|w| w.contains("LoadOptions::clamp_effort applies to URDF")),
        "{:?}",
        m.warnings
    );
}
