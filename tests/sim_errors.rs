//! Bad states and diverging simulations give typed errors naming the joint and the fix, never a
//! panic and never a silently propagated NaN.

use lagrange::integrate::IntegratorKind;
use lagrange::io::{load_urdf_str, LoadOptions};
use lagrange::sim::{SimError, SimOptions, Simulation};
use std::path::Path;
use std::sync::Arc;

/// A pendulum whose second link is massless: its joint has no finite acceleration (D = 0).
const MASSLESS_TIP: &str = r#"<robot name="r">
  <link name="base"/>
  <joint name="shoulder" type="continuous"><parent link="base"/><child link="arm"/><axis xyz="0 1 0"/></joint>
  <link name="arm"><inertial><origin xyz="0 0 -1"/><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="wrist" type="continuous"><parent link="arm"/><child link="tip"/><origin xyz="0 0 -1"/><axis xyz="0 1 0"/></joint>
  <link name="tip"/>
</robot>"#;

#[test]
fn diverging_simulation_names_time_joint_and_fix() {
    let model = load_urdf_str(MASSLESS_TIP, Path::new("massless_tip.urdf"), &LoadOptions::default()).unwrap();
    let options =
        SimOptions { integrator: Some(IntegratorKind::Euler), timestep: Some(1e-3), ..Default::default() };
    let mut sim = Simulation::new(Arc::new(model), &options);
    sim.set_state(&[0.3, 0.0], &[0.0, 0.0]).unwrap();
    let err = sim.step().unwrap_err();
    assert!(matches!(err, SimError::Diverged { .. }), "{err:?}");
    let msg = err.to_string();
    for needle in ["diverged at t = 0.001 s (step 1)", "joint 'wrist'", "reduce --dt", "massless subtree"] {
        assert!(msg.contains(needle), "missing '{needle}' in: {msg}");
    }
}

#[test]
fn non_finite_or_wrongly_sized_state_is_rejected() {
    let model = load_urdf_str(MASSLESS_TIP, Path::new("massless_tip.urdf"), &LoadOptions::default()).unwrap();
    let options = SimOptions { integrator: Some(IntegratorKind::Rk4), ..Default::default() };
    let mut sim = Simulation::new(Arc::new(model), &options);
    let msg = sim.set_state(&[f64::NAN, 0.0], &[0.0, 0.0]).unwrap_err().to_string();
    assert!(msg.contains("invalid initial state") && msg.contains("not finite"), "{msg}");
    let msg = sim.set_state(&[0.0], &[0.0, 0.0]).unwrap_err().to_string();
    assert!(msg.contains("q has 1 values and v 2, the model needs nq = 2 and nv = 2"), "{msg}");
}
