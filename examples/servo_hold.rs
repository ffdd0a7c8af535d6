//! Actuators with activation state: an `intvelocity` servo — MuJoCo's integrated-
//! velocity position servo, whose setpoint is the activation `act` — and a `position` servo with
//! a `timeconst` (a filterexact low-pass on its target) on a two-link arm under gravity.
//!
//! The controller commands the shoulder's velocity (0.5 rad/s for 1 s, then 0) and steps the
//! elbow's target to 0.8 rad at t = 0.5 s; the shoulder holds the 0.5 rad its activation
//! integrated, the elbow follows its filtered target. Prints the state and `act` as it goes.
//!
//! Run with `cargo run --release --example servo_hold`.

use lagrange::io::{mjcf, LoadOptions};
use lagrange::sim::{SimOptions, Simulation};
use std::path::Path;
use std::sync::Arc;

const ARM: &str = r#"<mujoco model="servo arm">
  <option timestep="0.002" integrator="implicitfast"/>
  <worldbody>
    <body name="upper">
      <joint name="shoulder" axis="0 1 0"/>
      <geom type="capsule" fromto="0 0 0 0.4 0 0" size="0.04" mass="2"/>
      <body name="lower" pos="0.4 0 0">
        <joint name="elbow" axis="0 1 0"/>
        <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03" mass="1"/>
      </body>
    </body>
  </worldbody>
  <actuator>
    <intvelocity name="shoulder" joint="shoulder" kp="400" dampratio="1" actrange="-1.5 1.5"/>
    <position name="elbow" joint="elbow" kp="100" dampratio="1" timeconst="0.1"/>
  </actuator>
</mujoco>"#;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let spec = mjcf::parse_str(ARM, Path::new("servo_arm.xml"), &LoadOptions::default())?;
    let model = Arc::new(lagrange::io::compile(&spec)?);
    println!("{} actuators, {} activation states (act)", model.actuators.len(), model.na());
    let mut sim = Simulation::new(model, &SimOptions::default());
    sim.set_act(&[0.0, 0.0])?;
    sim.set_controller(|t, _q, _v, ctrl| {
        ctrl[0] = if t < 1.0 - 1e-9 { 0.5 } else { 0.0 }; // shoulder velocity command, rad/s
        ctrl[1] = if t < 0.5 - 1e-9 { 0.0 } else { 0.8 }; // elbow target, rad
    });
    println!("{:>6} {:>10} {:>10} {:>10} {:>10}", "t", "shoulder", "act[0]", "elbow", "act[1]");
    for step in 1..=1500 {
        sim.step()?;
        if step % 125 == 0 {
            let (q, act) = (&sim.data.qpos, sim.act());
            println!(
                "{:>6.2} {:>10.5} {:>10.5} {:>10.5} {:>10.5}",
                sim.data.time, q[0], act[0], q[1], act[1]
            );
        }
    }
    let (q, act) = (&sim.data.qpos, sim.act());
    println!(
        "held after 3 s: shoulder {:.4} rad (setpoint {:.4}), elbow {:.4} rad (target 0.8); the gaps are gravity over kp",
        q[0], act[0], q[1]
    );
    Ok(())
}
