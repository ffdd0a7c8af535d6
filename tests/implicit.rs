//! MuJoCo's `implicit` and `implicitfast` integrators on damped passive scenes. First
//! implicitfast on
//! `models/textbook/damped_double_pendulum.xml` (its `<option integrator="implicitfast">`
//! selects it): 100 steps of 0.01 s from q = (1, −0.5) at rest against MuJoCo 4.0.0's `mj_step`,
//! recorded with
//! `m = mujoco.MjModel.from_xml_path(...); d.qpos[:] = [1.0, -0.5]; 100 × mujoco.mj_step(m, d)`
//! (/work/venv, mujoco 4.0.0; the same values with MuJoCo's Euler, which is implicit in joint
//! damping too). Then implicit (with the Coriolis derivatives ∂c/∂v) on the same pendulum swung
//! hard and on `damped_mixed_tree.xml` (ball, hinge, slide and free joints), against `mj_step`
//! with integrator="implicit" (constants from `validation/implicit_golden.py`, below).
//! Tolerance: `common::REF_REL` (1e-9 relative).

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
    let eq = rel_err_vec(sim.data.qpos.as_slice(), &MUJOCO_QPOS);
    let ev = rel_err_vec(sim.data.qvel.as_slice(), &MUJOCO_QVEL);
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
        stable.data.qvel.amax() < 1e-3,
        "implicitfast after 100 s (decaying: 1.7e-4 measured): v = {}",
        stable.data.qvel
    );
}

// MuJoCo 4.0.0's `mj_step` with integrator="implicit", printed by
// `validation/.venv/bin/python validation/implicit_golden.py` (initial states there).
// damped_double_pendulum.xml: 100 steps of 0.01 s from q = (1, −0.5), v = (4, −6)
// (implicitfast differs from implicit by 2.4e-4 there).
const DOUBLE_PENDULUM_QPOS: [f64; 2] = [0.10340822788656898, -0.4983512274530619];
const DOUBLE_PENDULUM_QVEL: [f64; 2] = [-0.4191224015182769, 0.007635403902222103];
// damped_mixed_tree.xml (ball, hinge, slide, free): 200 steps of 0.005 s (implicitfast differs
// from implicit by 0.46 there).
const MIXED_TREE_QPOS: [f64; 13] = [
    0.3971459019709357,
    0.002339913479434012,
    -0.15850084529578531,
    -0.9039619125788005,
    0.05045192376231404,
    -1.820593507971336,
    1.651237379382813,
    0.02644782521300054,
    -2.96627654997089,
    -0.931996373714525,
    -0.11279154602587815,
    -0.34021685665916634,
    -0.053975151440497415,
];
const MIXED_TREE_QVEL: [f64; 11] = [
    0.7320936695266365,
    0.4226208056183461,
    -4.754329213683655,
    -1.3565164266897058,
    -2.6564433644030263,
    0.5852825528311797,
    -0.0761181047956936,
    -8.832031349732645,
    -0.39051817185875487,
    -0.5980206375199532,
    3.346913995922607,
];

/// Runs `file` with its own `<option>` (integrator="implicit" is asked for by the mixed tree;
/// the double pendulum's implicitfast is overridden) from (q0, v0) for `steps` steps and compares
/// with MuJoCo's final (qpos, qvel).
fn check_implicit(file: &str, q0: &[f64], v0: &[f64], steps: usize, qpos: &[f64], qvel: &[f64]) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("models/textbook").join(file);
    let model = Arc::new(load(&path, &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}")));
    let kind = match model.options.integrator {
        lagrange::model::options::Integrator::Implicit => None,
        _ => Some(IntegratorKind::Implicit),
    };
    let mut sim = Simulation::new(model, &SimOptions { integrator: kind, ..Default::default() });
    assert_eq!(sim.stepper.name(), "implicit", "notes: {:?}", sim.notes);
    assert!(sim.notes.is_empty(), "{:?}", sim.notes);
    let mut q = q0.to_vec();
    for joint in &sim.model.joints {
        // MuJoCo normalizes the quaternions of the initial state (mj_normalizeQuat) before stepping.
        let a = joint.qpos_adr;
        let quat = match joint.kind {
            lagrange::model::JointKind::Ball => a..a + 4,
            lagrange::model::JointKind::Free => a + 3..a + 7,
            _ => continue,
        };
        let n = q[quat.clone()].iter().map(|x| x * x).sum::<f64>().sqrt();
        q[quat].iter_mut().for_each(|x| *x /= n);
    }
    sim.set_state(&q, v0).unwrap();
    for _ in 0..steps {
        sim.step().unwrap();
    }
    let eq = rel_err_vec(sim.data.qpos.as_slice(), qpos);
    let ev = rel_err_vec(sim.data.qvel.as_slice(), qvel);
    println!("{file}: implicit vs MuJoCo after {steps} steps: q rel {eq:.2e}, v rel {ev:.2e}");
    assert!(eq <= REF_REL && ev <= REF_REL, "{file}: q {eq}, v {ev}");
}

#[test]
fn implicit_matches_mujoco_mj_step_on_fast_damped_double_pendulum() {
    check_implicit(
        "damped_double_pendulum.xml",
        &[1.0, -0.5],
        &[4.0, -6.0],
        100,
        &DOUBLE_PENDULUM_QPOS,
        &DOUBLE_PENDULUM_QVEL,
    );
}

#[test]
fn implicit_matches_mujoco_mj_step_on_damped_ball_hinge_slide_free_tree() {
    check_implicit(
        "damped_mixed_tree.xml",
        &[0.9, 0.3, 0.2, 0.1, 0.4, 0.05, 1.0, 0.0, 1.0, 0.98006657784, 0.0, 0.19866933080, 0.0],
        &[3.0, -2.0, 8.0, 5.0, 0.3, 0.5, -0.2, 1.0, 6.0, -4.0, 10.0],
        200,
        &MIXED_TREE_QPOS,
        &MIXED_TREE_QVEL,
    );
}
