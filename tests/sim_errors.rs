//! Bad states and diverging simulations give typed errors naming the joint and the fix, never a
//! panic and never a silently propagated NaN.

use lagrange::integrate::IntegratorKind;
use lagrange::io::{load_urdf_str, LoadOptions};
use lagrange::sim::{SimError, SimOptions, Simulation};
use std::path::Path;
use std::sync::Arc;

/// A pendulum whose second link is massless: M is singular (the wrist's pivot D = 0).
const MASSLESS_TIP: &str = r#"<robot name="r">
  <link name="base"/>
  <joint name="shoulder" type="continuous"><parent link="base"/><child link="arm"/><axis xyz="0 1 0"/></joint>
  <link name="arm"><inertial><origin xyz="0 0 -1"/><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="wrist" type="continuous"><parent link="arm"/><child link="tip"/><origin xyz="0 0 -1"/><axis xyz="0 1 0"/></joint>
  <link name="tip"/>
</robot>"#;

#[test]
fn massless_tip_is_named_at_load_and_regularized_in_steps() {
    // M is singular at every state (the wrist's pivot D = 0). The model loads (Pinocchio loads
    // it) with a warning naming the joint; a simulation runs with MuJoCo's regularized result
    // (the pivot raised to 1e-15, mjWARN_INERTIA) and a run-time warning naming the joint, the
    // arm swinging as a pendulum with nothing at its end.
    let model = load_urdf_str(MASSLESS_TIP, Path::new("massless_tip.urdf"), &LoadOptions::default()).unwrap();
    let w = model.warnings.iter().find(|w| w.contains("moves nothing")).expect("a warning");
    for needle in ["massless_tip.urdf:5", "joint 'wrist' moves nothing", "link 'tip'", "<inertial>"] {
        assert!(w.contains(needle), "missing '{needle}' in: {w}");
    }
    let options =
        SimOptions { integrator: Some(IntegratorKind::Euler), timestep: Some(1e-3), ..Default::default() };
    let mut sim = Simulation::new(Arc::new(model), &options);
    sim.set_state(&[0.3, 0.0], &[0.0, 0.0]).unwrap();
    for _ in 0..100 {
        sim.step().unwrap();
    }
    assert!(sim.data.qpos.iter().chain(sim.data.qvel.iter()).all(|x| x.is_finite()));
    assert!(sim.data.warnings.inertia.number > 0);
    let msg = sim.data.warnings.messages(&sim.model).join("\n");
    for needle in ["singular", "'wrist'", "mjWARN_INERTIA"] {
        assert!(msg.contains(needle), "missing '{needle}' in: {msg}");
    }
}

/// A stiff hinge spring (k = 1e6 N·m/rad on 1 kg at 1 m): semi-implicit Euler at dt = 0.01 s is
/// far beyond its stability limit 2/ω = 2 ms and blows up.
const STIFF_SPRING: &str = r#"<mujoco><worldbody><body><joint name="spring" type="hinge" axis="0 1 0" stiffness="1e6"/>
  <inertial pos="0 0 -1" mass="1" diaginertia="0.01 0.01 0.01"/></body></worldbody></mujoco>"#;

fn stiff_spring(integrator: IntegratorKind) -> Simulation {
    let spec =
        lagrange::io::mjcf::parse_str(STIFF_SPRING, Path::new("stiff.xml"), &LoadOptions::default()).unwrap();
    let model = lagrange::io::compile(&spec).unwrap();
    let options = SimOptions { integrator: Some(integrator), timestep: Some(1e-2), ..Default::default() };
    Simulation::new(Arc::new(model), &options)
}

fn diverge(sim: &mut Simulation) -> String {
    for _ in 0..100_000 {
        if let Err(e) = sim.step() {
            assert!(matches!(e, SimError::Diverged { .. }), "{e:?}");
            return e.to_string();
        }
    }
    panic!("no divergence");
}

#[test]
fn diverging_simulation_names_time_joint_and_fix() {
    let mut sim = stiff_spring(IntegratorKind::Euler);
    sim.set_state(&[0.1], &[0.0]).unwrap();
    let msg = diverge(&mut sim);
    for needle in [
        "diverged at t = ",
        "joint 'spring'",
        "reduce SimOptions::timestep (now 0.01 s)",
        "use SimOptions::integrator = rk4",
    ] {
        assert!(msg.contains(needle), "missing '{needle}' in: {msg}");
    }
    // The time is printed rounded (a sum of steps, not 6.800000000000003).
    let t = msg.split("t = ").nth(1).and_then(|r| r.split(' ').next()).unwrap();
    assert!(t.len() <= 8, "time printed as {t}");
    // With rk4 in use, the hint does not suggest rk4.
    let mut sim = stiff_spring(IntegratorKind::Rk4);
    sim.set_state(&[0.1], &[0.0]).unwrap();
    let msg = diverge(&mut sim);
    assert!(
        msg.contains("reduce SimOptions::timestep") && !msg.contains("use SimOptions::integrator = rk4"),
        "{msg}"
    );
}

#[test]
fn divergence_in_the_first_step_points_at_the_initial_state() {
    let mut sim = stiff_spring(IntegratorKind::Euler);
    sim.set_state(&[0.1], &[1e307]).unwrap();
    let msg = diverge(&mut sim);
    for needle in ["(step 1)", "first step", "initial state", "huge initial velocity"] {
        assert!(msg.contains(needle), "missing '{needle}' in: {msg}");
    }
    assert!(!msg.contains("use SimOptions::integrator"), "{msg}");
}

#[test]
fn non_finite_or_wrongly_sized_state_is_rejected() {
    let mut sim = stiff_spring(IntegratorKind::Rk4);
    let msg = sim.set_state(&[f64::NAN], &[0.0]).unwrap_err().to_string();
    assert!(msg.contains("invalid initial state") && msg.contains("not finite"), "{msg}");
    let msg = sim.set_state(&[0.0], &[0.0, 0.0]).unwrap_err().to_string();
    assert!(msg.contains("q has 1 values and v 2, the model needs nq = 1 and nv = 1"), "{msg}");
}
