//! Dry joint friction (`frictionloss`) and ball-joint cone limits in exact mode: statics against
//! closed forms, Coulomb's law on a dof (stick below the bound, slide at it), J̇v of the cone row
//! against central differences, and simulations that never gain energy.

mod common;

use common::{rel_err, CONSTRAINT_REL, ENERGY_GAIN_REL, JDOTV_FD_REL, LIMIT_EXCURSION};
use lagrange::constraint::{ball_angle_axis, ConstraintMode, LimitRow};
use lagrange::io::{load, LoadOptions};
use lagrange::model::{integrate_configuration, EfcType};
use lagrange::sim::Simulation;
use lagrange::{Data, Model};
use std::path::Path;
use std::sync::Arc;

fn model(file: &str) -> Model {
    load(&Path::new("tests/data/mjcf/friction").join(file), &LoadOptions::default()).unwrap()
}

/// Friction loss on a slide joint (f = 2 N, m = 1 kg): a push below f sticks (q̈ = 0, λ = −τ);
/// above f the block accelerates at (τ − f)/m; while it moves, λ = −f sign(v) whatever the push.
#[test]
fn friction_loss_sticks_below_its_bound_and_slides_at_it() {
    let model = model("friction_loss.xml");
    let model = common::with_mode(model, ConstraintMode::Exact);
    let mut data = Data::new(&model);
    let slide = model.joint_id("slide").unwrap();
    let d = model.joints[slide].dof_adr;
    let q = model.qpos0.clone();
    let (f, m) = (2.0, 1.0);
    for (push, v, want_acc, want_force) in [
        (1.5, 0.0, 0.0, -1.5),
        (-1.9, 0.0, 0.0, 1.9),
        (3.0, 0.0, (3.0 - f) / m, -f),
        (-5.0, 0.0, (-5.0 + f) / m, f),
        (0.5, -0.3, (0.5 + f) / m, f),
        (0.0, 0.2, -f / m, -f),
    ] {
        data.qfrc_applied.fill(0.0);
        data.qfrc_applied[d] = push;
        let mut vel = vec![0.0; model.nv];
        vel[d] = v;
        common::forward_at(&model, &mut data, &q, &vel);
        let r = (0..data.nefc)
            .find(|&r| data.efc_type[r] == EfcType::FrictionDof && data.efc_id[r] == d)
            .unwrap();
        println!(
            "push {push:5.1} N, v {v:4.1}: q̈ {:+.15} (want {want_acc}), λ {:+.15}",
            data.qacc[d], data.efc_force[r]
        );
        assert!(
            (data.qacc[d] - want_acc).abs() <= CONSTRAINT_REL * (1.0 + want_acc.abs()),
            "q̈ = {}",
            data.qacc[d]
        );
        assert!(rel_err(data.efc_force[r], want_force) <= CONSTRAINT_REL, "λ = {}", data.efc_force[r]);
        assert!(data.efc_converged, "residual {:e}", data.efc_residual);
    }
}

/// A pendulum (m = 1 kg, centre of mass l = 0.5 m below a hinge with f = 0.5 N·m of friction loss)
/// is held at rest wherever m g l sin θ ≤ f; beyond, it accelerates with the torque reduced by f.
#[test]
fn friction_loss_holds_a_pendulum_below_the_breakaway_angle() {
    let model = model("friction_loss.xml");
    let model = common::with_mode(model, ConstraintMode::Exact);
    let mut data = Data::new(&model);
    let hinge = model.joint_id("hinge").unwrap();
    let (qa, d) = (model.joints[hinge].qpos_adr, model.joints[hinge].dof_adr);
    let (m, g, l, f): (f64, f64, f64, f64) = (1.0, 9.81, 0.5, 0.5);
    let breakaway = (f / (m * g * l)).asin();
    let v = vec![0.0; model.nv];
    for theta in [0.5 * breakaway, 0.99 * breakaway, -0.9 * breakaway] {
        let mut q = model.qpos0.clone();
        q[qa] = theta;
        common::forward_at(&model, &mut data, &q, &v);
        println!("θ = {theta:+.4} rad (breakaway {breakaway:.4}): q̈ = {:e}", data.qacc[d]);
        assert!(data.qacc[d].abs() <= 1e-12, "held at rest: q̈ = {}", data.qacc[d]);
    }
    let mut q = model.qpos0.clone();
    q[qa] = 2.0 * breakaway;
    common::forward_at(&model, &mut data, &q, &v);
    // Free acceleration reduced by f / I about the hinge.
    let inertia = data.qfrc_constraint[d] / (data.qacc[d] - data.qacc_smooth[d]);
    let want = data.qacc_smooth[d] + f / inertia * -data.qacc_smooth[d].signum();
    println!("θ = 2 × breakaway: q̈ {} vs {want}", data.qacc[d]);
    assert!(rel_err(data.qacc[d], want) <= CONSTRAINT_REL);
    assert!(rel_err(data.qfrc_constraint[d].abs(), f) <= CONSTRAINT_REL);
}

/// Released from 1 rad, the pendulum with dry friction loses energy at every step and comes to
/// rest inside the breakaway band; the energy never increases (RK4, 1 ms, projection).
#[test]
fn friction_loss_dissipates_and_brings_a_pendulum_to_rest() {
    let model = Arc::new(model("friction_loss.xml"));
    let hinge = model.joint_id("hinge").unwrap();
    let (qa, d) = (model.joints[hinge].qpos_adr, model.joints[hinge].dof_adr);
    let options = common::exact_rk4(1e-3);
    let mut sim = Simulation::new(model.clone(), &options);
    let mut q = model.qpos0.clone();
    q[qa] = 1.0;
    sim.set_state(&q, &vec![0.0; model.nv]).unwrap();
    let (t, v) = sim.energies();
    let mut e_prev = t + v;
    let mut rise = 0.0f64;
    for _ in 0..20000 {
        sim.step().unwrap();
        let (t, v) = sim.energies();
        rise = rise.max(t + v - e_prev);
        e_prev = t + v;
    }
    let breakaway = (0.5f64 / (9.81 * 0.5)).asin();
    println!(
        "after 20 s: θ = {:.5}, v = {:e}, largest energy rise in one step {rise:e} J",
        sim.data.qpos[qa], sim.data.qvel[d]
    );
    assert!(rise <= 1e-9, "energy rose by {rise:e} J in a step");
    assert!(sim.data.qvel[d].abs() <= 1e-9, "at rest: v = {}", sim.data.qvel[d]);
    assert!(sim.data.qpos[qa].abs() <= breakaway + 1e-9, "rests inside the band: θ = {}", sim.data.qpos[qa]);
}

/// Resting on its 30° cone, the inverted rod (m = 1 kg, centre of mass l = 0.5 m from the ball)
/// carries the gravity torque m g l sin 30° as the limit's multiplier and does not accelerate.
#[test]
fn ball_cone_limit_carries_the_gravity_torque() {
    let model = model("ball_cone.xml");
    let model = common::with_mode(model, ConstraintMode::Exact);
    let mut data = Data::new(&model);
    let max_angle = 30f64.to_radians();
    // Rotation by exactly the cone angle about x.
    let q = [(0.5 * max_angle).cos(), (0.5 * max_angle).sin(), 0.0, 0.0];
    common::forward_at(&model, &mut data, &q, &[0.0; 3]);
    assert_eq!((data.nefc, data.efc_type[0]), (1, EfcType::LimitJoint));
    let want = 1.0 * 9.81 * 0.5 * max_angle.sin();
    println!("cone multiplier {} vs m g l sin θ = {want}", data.efc_force[0]);
    assert!(rel_err(data.efc_force[0], want) <= CONSTRAINT_REL);
    assert!(data.qacc.amax() <= 1e-12, "q̈ = {}", data.qacc);
    // Inside the cone: no row.
    let inside = [(0.2f64).cos(), (0.2f64).sin(), 0.0, 0.0];
    common::forward_at(&model, &mut data, &inside, &[0.0; 3]);
    assert_eq!(data.nefc, 0);
}

/// J̇v of the cone row against central differences of J(q) v along v on the manifold.
#[test]
fn ball_cone_jdotv_matches_finite_differences() {
    let model = model("ball_cone.xml");
    let row = LimitRow::of_joint(&model, 0).unwrap();
    let axis = nalgebra::Vector3::new(0.3, -0.8, 0.2).normalize();
    let angle = 0.7; // beyond the 30° cone: active
    let s = (0.5f64 * angle).sin();
    let q = [(0.5f64 * angle).cos(), axis[0] * s, axis[1] * s, axis[2] * s];
    let v = [1.3, -0.4, 2.1];
    let jv = |q: &[f64]| {
        let (dir, _) = row.active(q).unwrap().unwrap();
        dir.dot(&nalgebra::Vector3::from_column_slice(&v))
    };
    let eps = 1e-6;
    let (mut qp, mut qm) = (q.to_vec(), q.to_vec());
    integrate_configuration(&model, &mut qp, &v, eps).unwrap();
    integrate_configuration(&model, &mut qm, &v, -eps).unwrap();
    let fd = (jv(&qp) - jv(&qm)) / (2.0 * eps);
    let exact = row.jdotv(&q, &v).unwrap();
    println!("cone J̇v {exact} vs central difference {fd}; angle check {}", ball_angle_axis(&q).unwrap().0);
    assert!(rel_err(exact, fd) <= JDOTV_FD_REL, "{exact} vs {fd}");
}

/// The inverted rod released with a sideways spin hits its cone and runs around it: it never
/// leaves the cone by more than the limit tolerance and gains no energy beyond RK4's own drift
/// (RK4, 1 ms); riding the cone, the row stays closed (the rod does not chatter on and off it).
#[test]
fn ball_cone_holds_a_spinning_rod_without_energy_gain() {
    let model = Arc::new(model("ball_cone.xml"));
    let options = common::exact_rk4(1e-3);
    let mut sim = Simulation::new(model, &options);
    let tilt = 0.1f64;
    sim.set_state(&[(0.5 * tilt).cos(), (0.5 * tilt).sin(), 0.0, 0.0], &[0.0, 2.0, 0.5]).unwrap();
    let (t, v) = sim.energies();
    let e0 = t + v;
    let max_angle = 30f64.to_radians();
    let (mut worst, mut rise, mut at_limit) = (0.0f64, f64::MIN, 0);
    for _ in 0..5000 {
        sim.step().unwrap();
        let angle = ball_angle_axis(sim.data.qpos.as_slice()).unwrap().0;
        worst = worst.max(angle - max_angle);
        at_limit += usize::from(angle >= max_angle - 1e-9);
        let (t, v) = sim.energies();
        rise = rise.max(t + v - e0);
    }
    println!("rod on its cone: max excursion {worst:e} rad, {at_limit} of 5000 steps at the cone, max E − E0 {rise:e} J");
    assert!(at_limit > 4500, "the rod should reach the cone and stay on it: {at_limit} steps");
    assert!(worst <= LIMIT_EXCURSION, "left the cone by {worst:e} rad");
    assert!(rise <= ENERGY_GAIN_REL * e0.abs(), "energy increased by {rise:e} J of {e0} J");
}
