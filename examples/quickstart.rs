//! Quick start: load the go1 quadruped on its floor, reset it to its `home` keyframe, hold the
//! keyframe's servo targets as controls, step half a second, and read each foot's contact force
//! and the trunk's pose; then read the dm_control humanoid's torso IMU (MuJoCo's `sensordata`).
//!
//!     cargo run --release --example quickstart

use lagrange::prelude::*;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let model = Model::from_file("models/mjcf/unitree_go1/scene.xml")?;
    let mut data = Data::new(&model);
    reset_keyframe(&model, &mut data, "home")?; // qpos, and ctrl = the servos' targets
    for _ in 0..250 {
        step(&model, &mut data)?; // the model's integrator and timestep (2 ms)
    }
    forward(&model, &mut data); // the contact forces at the final state
    for c in contacts(&model, &data).filter(|c| c.active) {
        let f = c.force_world();
        println!(
            "{:>5} on {:<5}: force [{:7.3} {:7.3} {:7.3}] N",
            c.geom_names[1], c.geom_names[0], f.x, f.y, f.z
        );
    }
    let trunk = frames::pose(&model, &mut data, "trunk")?;
    println!("t = {:.3} s, trunk at height {:.4} m", data.time, trunk.pos.z);

    // Sensors: computed by `forward` (and by each step, for the state it starts from).
    let humanoid = Model::from_file("models/mjcf/humanoid/humanoid.xml")?;
    let mut hdata = Data::new(&humanoid);
    while hdata.time < 1.5 {
        step(&humanoid, &mut hdata)?; // it falls (the accelerometer reads 0) and lands
    }
    let imu = hdata.sensor(&humanoid, "torso_accel")?;
    println!("humanoid torso accelerometer: [{:.3} {:.3} {:.3}] m/s²", imu[0], imu[1], imu[2]);
    Ok(())
}
