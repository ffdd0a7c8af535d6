//! MuJoCo's `implicitfast` integrator (issue 15) on a damped passive scene,
//! `models/textbook/damped_double_pendulum.xml` (its `<option integrator="implicitfast">`
//! selects it): 100 steps of 0.01 s from q = (1, −0.5) at rest against MuJoCo 4.0.0's `mj_step`,
//! recorded with
//! `m = mujoco.MjModel.from_xml_path(...); d.qpos[:] = [1.0, -0.5]; 100 × mujoco.mj_step(m, d)`
//! (/work/venv, mujoco 4.0.0; the same values with MuJoCo's Euler, which is implicit in joint
//! damping too). Tolerance: `common::REF_REL` (1e-9 relative).

mod common;

use common::{rel_err_vec, REF_REL};
use lagrange::integrate::IntegratorKind;
use lagrange::io::{load, LoadOptions};
use lagrange::sim::{SimOptions, Simulation};
use std::path::Path;
use std::sync::Arc;

const MUJOCO_QPOS: [f64; 2] = [0.06620957738097963, -0.49725546233466694];
const MUJOCO_QVEL: [f64; 2] = [-0.14331466887977284, 0.011152003337331715];

fn damped_double_pendulum(kind: Option<IntegratorKind>) -> Simulation {
    damped_double_pendulum_with(kind, true)
}

/// The scene with `<flag eulerdamp>` on (MuJoCo's default) or off.
fn damped_double_pendulum_with(kind: Option<IntegratorKind>, eulerdamp: bool) -> Simulation {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("models/textbook/damped_double_pendulum.xml");
    let mut model = load(&path, &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    model.options.flags.eulerdamp = eulerdamp;
    let mut sim = Simulation::new(Arc::new(model), &SimOptions { integrator: kind, ..Default::default() });
    sim.set_state(&[1.0, -0.5], &[0.0, 0.0]).unwrap();
    sim
}

/// 100 steps of `sim`, then q and v against MuJoCo's golden values.
fn assert_matches_mujoco(mut sim: Simulation, label: &str) {
    for _ in 0..100 {
        sim.step().unwrap();
    }
    let eq = rel_err_vec(sim.state.q.as_slice(), &MUJOCO_QPOS);
    let ev = rel_err_vec(sim.state.v.as_slice(), &MUJOCO_QVEL);
    println!("{label} vs MuJoCo after 100 steps: q rel {eq:.2e}, v rel {ev:.2e}");
    assert!(eq <= REF_REL && ev <= REF_REL, "{label}: q {eq}, v {ev}");
}

#[test]
fn implicitfast_matches_mujoco_mj_step_on_damped_double_pendulum() {
    let sim = damped_double_pendulum(None);
    assert_eq!(sim.stepper.name(), "implicitfast", "notes: {:?}", sim.notes);
    assert_eq!(sim.timestep, 0.01);
    assert_matches_mujoco(sim, "implicitfast");
}

/// MuJoCo's Euler integrates joint damping implicitly (`<flag eulerdamp>`, on by default): on this
/// scene (damping its only velocity-dependent force) it takes the same steps as implicitfast, so
/// `mj_step` with `integrator="Euler"` gives the same golden values.
#[test]
fn euler_with_eulerdamp_matches_mujoco_mj_step_on_damped_double_pendulum() {
    assert_matches_mujoco(damped_double_pendulum(Some(IntegratorKind::Euler)), "Euler (eulerdamp)");
}

/// The same scene and step with semi-implicit Euler explicit in the damping (`eulerdamp` off):
/// the lower damper (40 N m s/rad) at h = 0.01 s is beyond explicit Euler's stability limit, and
/// the simulation stops with the divergence error naming the step, time and joint.
#[test]
fn explicit_euler_diverges_where_implicitfast_is_stable() {
    let mut sim = damped_double_pendulum_with(Some(IntegratorKind::Euler), false);
    let err =
        (0..10_000).find_map(|_| sim.step().err()).expect("explicit Euler should diverge at h = 0.01 s");
    let msg = err.to_string();
    println!("{msg}");
    assert!(msg.contains("diverged at t = ") && msg.contains("(step ") && msg.contains("joint 'j"), "{msg}");
    let mut stable = damped_double_pendulum(None);
    for _ in 0..10_000 {
        stable.step().unwrap_or_else(|e| panic!("implicitfast: {e}"));
    }
    assert!(
        stable.state.v.amax() < 1e-3,
        "implicitfast after 100 s (decaying: 1.7e-4 measured): v = {}",
        stable.state.v
    );
}
