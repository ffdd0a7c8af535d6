//! PD tracking through the controller callback of [`Simulation`].
//!
//! 1. An MJCF two-link arm with motor actuators: `set_controller` writes the controls (motor
//!    torques, clamped by MuJoCo's `ctrlrange`) from a PD law tracking a sinusoid on each joint.
//! 2. The UR5 URDF, which has no actuators: `set_torque_controller` writes joint torques from a PD
//!    law holding a pose, bounded by the URDF `<limit effort>` because it is loaded with
//!    `clamp_effort` (the CLI's `--clamp-effort`).
//!
//! Run with `cargo run --release --example pd_tracking`.

#![allow(clippy::needless_range_loop)] // the PD laws index q, v and the outputs by joint

use lagrange::integrate::IntegratorKind;
use lagrange::io::{load, mjcf, LoadOptions};
use lagrange::sim::{SimOptions, Simulation};
use std::path::Path;
use std::sync::Arc;

const ARM: &str = r#"<mujoco model="two-link arm">
  <option timestep="0.001"/>
  <worldbody>
    <body name="upper">
      <joint name="shoulder" axis="0 1 0" damping="0.1"/>
      <geom type="capsule" fromto="0 0 0 0 0 -0.5" size="0.04" mass="2"/>
      <body name="lower" pos="0 0 -0.5">
        <joint name="elbow" axis="0 1 0" damping="0.1"/>
        <geom type="capsule" fromto="0 0 0 0 0 -0.4" size="0.03" mass="1"/>
      </body>
    </body>
  </worldbody>
  <actuator>
    <motor name="shoulder_motor" joint="shoulder" ctrlrange="-80 80"/>
    <motor name="elbow_motor" joint="elbow" ctrlrange="-40 40"/>
  </actuator>
</mujoco>"#;

/// The reference: each joint follows a sinusoid of amplitude 0.5 rad at 1 Hz (the elbow lags by
/// a quarter period).
fn reference(t: f64) -> ([f64; 2], [f64; 2]) {
    let w = 2.0 * std::f64::consts::PI;
    ([0.5 * (w * t).sin(), 0.5 * (w * t).cos() - 0.5], [0.5 * w * (w * t).cos(), -0.5 * w * (w * t).sin()])
}

fn main() {
    // 1. Controls from a PD law.
    let spec = mjcf::parse_str(ARM, Path::new("two_link_arm.xml"), &LoadOptions::default()).expect("arm");
    let model = Arc::new(lagrange::io::compile(&spec).expect("arm compiles"));
    let options = SimOptions { integrator: Some(IntegratorKind::Rk4), ..Default::default() };
    let mut sim = Simulation::new(model, &options);
    let (kp, kd) = (800.0, 60.0);
    sim.set_controller(move |t, q, v, ctrl| {
        let (q_ref, v_ref) = reference(t);
        for k in 0..2 {
            ctrl[k] = kp * (q_ref[k] - q[k]) + kd * (v_ref[k] - v[k]);
        }
    });
    let mut worst = 0.0f64;
    while sim.data.time < 3.0 {
        sim.step().expect("the arm simulates");
        if sim.data.time > 1.0 {
            let (q_ref, _) = reference(sim.data.time);
            for (q, r) in sim.data.qpos.iter().zip(q_ref) {
                worst = worst.max((q - r).abs());
            }
        }
    }
    println!("two-link arm, PD on motor controls (kp {kp}, kd {kd}), RK4 at 1 ms:");
    println!("  worst tracking error over t in [1, 3] s: {worst:.4} rad");
    println!("  final actuator forces: {:?} N·m", sim.data.actuator_force.as_slice());

    // 2. Joint torques from a PD law on a URDF robot, bounded by its effort limits.
    let ur5 = Path::new(env!("CARGO_MANIFEST_DIR")).join("models/ur5/ur5.urdf");
    let load_options = LoadOptions { clamp_effort: true, ..Default::default() };
    let model = Arc::new(load(&ur5, &load_options).expect("ur5"));
    let hold = [0.0, -1.2, 1.5, -0.3, 1.57, 0.0];
    let mut sim = Simulation::new(model, &SimOptions { timestep: Some(1e-3), ..options });
    sim.set_state(&hold, &[0.0; 6]).expect("state");
    sim.set_torque_controller(move |_, q, v, tau| {
        for k in 0..6 {
            tau[k] = 2000.0 * (hold[k] - q[k]) - 80.0 * v[k];
        }
    });
    while sim.data.time < 2.0 {
        sim.step().expect("the ur5 simulates");
    }
    let error = sim.data.qpos.iter().zip(hold).map(|(q, h)| (q - h).abs()).fold(0.0, f64::max);
    println!("UR5 holding a pose with PD joint torques, efforts clamped to <limit effort>, 2 s:");
    println!("  largest joint error (the sag PD needs to hold the arm against gravity): {error:.4} rad");
}
