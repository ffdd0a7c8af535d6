//! The actuation stage (MuJoCo's `mj_fwdActuation`) against hand-computed forces: position,
//! motor, velocity, affine general and tendon actuators, with control and force clamping and gear;
//! activation dynamics (act_dot of each dyntype, filterexact's exact step, actrange, actearly, an
//! intvelocity servo); site, ball and free transmissions (moments against finite differences).
//! The same forces against MuJoCo on corpus robots are `validation/crossval_actuators`.

mod common;

use common::{forward_at, with_mode, ALGO_REL, FD_REL, FD_STEP};
use lagrange::constraint::ConstraintMode;
use lagrange::forward::{actuation, unsimulated_reason, Plan, Status};
use lagrange::integrate::IntegratorKind;
use lagrange::io::{load, LoadOptions};
use lagrange::kinematics::forward_kinematics;
use lagrange::sim::{SimOptions, Simulation};
use lagrange::Data;
use std::path::Path;
use std::sync::Arc;

#[test]
fn actuator_forces_follow_mujocos_formulas() {
    let model = load(Path::new("tests/data/mjcf/actuators/basic.xml"), &LoadOptions::default()).unwrap();
    let model = with_mode(model, ConstraintMode::Exact);
    let plan = &model.plan;
    let stage = plan.stages.iter().find(|s| s.name == "actuation").unwrap();
    println!("actuation stage: {:?} — {}", stage.status, stage.reason);
    assert_eq!(stage.status, Status::Runs);
    assert!(
        stage.reason.contains("6 actuators") && !stage.reason.contains("not simulated"),
        "{}",
        stage.reason
    );
    assert!(model.actuators.iter().all(|a| unsimulated_reason(&model, a).is_none()));
    assert_eq!(model.na(), 1);

    let mut data = Data::new(&model);
    let (q, v) = ([0.3, -0.2, 0.1, 0.4], [1.0, -2.0, 0.5, 0.8]);
    // Controls beyond the ranges of the position and motor actuators: clamped to 1 and 0.4. The
    // filter's activation is 0.2: its force is gain · act, whatever the control.
    data.ctrl.copy_from_slice(&[2.0, 0.9, 3.0, 1.5, -0.6, 5.0]);
    data.act[0] = 0.2;
    forward_at(&model, &mut data, &q, &v);
    let f = data.actuator_force.as_slice();
    let want = [
        50.0 * (1.0 - 0.3) - 3.0 * 1.0, // kp (ctrl − q) − kv q̇, ctrl clamped to 1
        0.4,                            // motor: ctrl clamped to 0.4
        (7.0 * 3.0 - 7.0 * 0.5f64).clamp(-1.0, 1.0), // velocity kv (ctrl − q̇), force clamped
        (2.0 + 0.5 * 0.4 + 0.25 * 0.8) * 1.5 + (1.0 - 3.0 * 0.4 - 0.5 * 0.8), // affine gain and bias
        -0.6,                           // tendon motor
        10.0 * 0.2,                     // filter: gain · act
    ];
    println!("actuator_force {f:?}\nwant           {want:?}");
    for (i, (a, b)) in f.iter().zip(want).enumerate() {
        assert!((a - b).abs() <= ALGO_REL * (1.0 + b.abs()), "actuator {i}: {a} vs {b}");
    }
    // Lengths through the transmissions: gear · q, and the tendon's gear · Σ coef q.
    let tendon_length = 1.5 * (2.0 * 0.3 - 0.5 * -0.2);
    assert!(
        (data.actuator_length[1] - 2.5 * -0.2).abs() < 1e-15
            && (data.actuator_length[4] - tendon_length).abs() < 1e-15
    );
    // qfrc_actuator = Σ momentᵀ force: gear on the joint, gear · coef through the tendon.
    let qfrc = data.qfrc_actuator.as_slice();
    let want_qfrc =
        [want[0] + 1.5 * 2.0 * want[4], 2.5 * want[1] + 1.5 * -0.5 * want[4], want[2], want[3] + want[5]];
    println!("qfrc_actuator {qfrc:?}\nwant          {want_qfrc:?}");
    for (a, b) in qfrc.iter().zip(want_qfrc) {
        assert!((a - b).abs() <= ALGO_REL * (1.0 + b.abs()));
    }
    // actuator_moment (MuJoCo's): the gear on the joint's dof, gear · coef on the tendon's dofs;
    // and qfrc_actuator = momentᵀ · actuator_force.
    let moment = &data.actuator_moment;
    assert_eq!((moment[(1, 1)], moment[(4, 0)], moment[(4, 1)]), (2.5, 1.5 * 2.0, 1.5 * -0.5));
    // The filter's act_dot = (ctrl − act) / τ (its control is not limited).
    assert!((data.act_dot[0] - (5.0 - 0.2) / 0.1).abs() < 1e-12);
    let from_moment = moment.transpose() * &data.actuator_force;
    assert!((from_moment - &data.qfrc_actuator).amax() <= ALGO_REL * data.qfrc_actuator.amax());
    // The accelerations include them (no gravity, no other force; diagonal M).
    assert!(data.qacc.iter().zip(qfrc).all(|(a, f)| a.signum() == f.signum() || f.abs() < 1e-12));
}

#[test]
fn actuation_switched_off_or_absent_costs_nothing() {
    let model = load(Path::new("models/textbook/drop.xml"), &LoadOptions::default()).unwrap();
    let plan = Plan::new(&model, None);
    let stage = plan.stages.iter().find(|s| s.name == "actuation").unwrap();
    assert_eq!((stage.status, stage.reason.as_str()), (Status::Skipped, "no actuators"));
    let options = LoadOptions { disabled_flags: vec!["actuation".into()], ..Default::default() };
    let model = load(Path::new("tests/data/mjcf/actuators/basic.xml"), &options).unwrap();
    let plan = &model.plan;
    let stage = plan.stages.iter().find(|s| s.name == "actuation").unwrap();
    assert_eq!(stage.status, Status::Skipped);
    let mut data = Data::new(&model);
    data.ctrl.fill(1.0);
    forward_at(&model, &mut data, &[0.0; 4], &[0.0; 4]);
    assert_eq!(data.qfrc_actuator.amax(), 0.0);
}

const ACTIVATION: &str = "tests/data/mjcf/actuators/activation.xml";
const TRANSMISSIONS: &str = "tests/data/mjcf/actuators/transmissions.xml";

fn load_mjcf_str(text: &str) -> Result<lagrange::Model, lagrange::io::LoadError> {
    let spec = lagrange::io::mjcf::parse_str(text, Path::new("inline.xml"), &LoadOptions::default())?;
    lagrange::io::compile(&spec)
}

/// act_dot and actuator_force of every dyntype against MuJoCo's formulas (MuJoCo documentation,
/// "Actuation model → Activation dynamics"), by hand, at one state of `activation.xml`.
#[test]
fn activation_dynamics_follow_mujocos_formulas() {
    let model = load(Path::new(ACTIVATION), &LoadOptions::default()).unwrap();
    assert_eq!(model.na(), 9);
    let model = with_mode(model, ConstraintMode::Exact);
    let plan = &model.plan;
    let stage = plan.stages.iter().find(|s| s.name == "actuation").unwrap();
    assert!(stage.status == Status::Runs && !stage.reason.contains("not simulated"), "{}", stage.reason);
    let mut data = Data::new(&model);
    let (q, v) = ([0.1, -0.2, 0.05, 0.3], [0.4, -0.5, 0.6, -0.7]);
    let ctrl = [1.5, 1.0, -1.0, 2.0, 1.0, 0.3, 0.2, 1.0, 30.0];
    let act = [0.1, 0.2, -0.3, 0.35, 0.9, 0.1, 0.05, 0.4, 1.95];
    data.ctrl.copy_from_slice(&ctrl);
    data.act.copy_from_slice(&act);
    forward_at(&model, &mut data, &q, &v);
    let h = model.options.timestep;
    // filterexact's next activation: act + act_dot τ (1 − e^(−h/τ)).
    let exact_next = |a: f64, rate: f64, tau: f64| a + rate * tau * (1.0 - (-h / tau).exp());
    let want_act_dot = [
        1.0,                 // integrator: the control, clamped to ctrlrange [-1, 1]
        (1.0 - 0.2) / 0.05,  // filter: (ctrl − act) / τ
        (-1.0 + 0.3) / 0.02, // filterexact: the same rate
        2.0,                 // integrator with actrange: the rate is not clamped, act is
        (1.0 - 0.9) / 0.01,  // filterexact, actearly
        0.3,                 // intvelocity: integrator of the velocity command
        (0.2 - 0.05) / 0.03, // position with timeconst: filterexact
        (1.0 - 0.4) / 0.2,   // cylinder: filter
        (30.0 - 1.95) / 0.1, // filter, actearly
    ];
    // The position actuator's dampratio 0.7 on a sphere of mass 1, radius 0.1 (I = 0.004).
    let kv_lagged = 0.7 * 2.0 * (20.0f64 * 0.004).sqrt();
    let early_next = exact_next(0.9, want_act_dot[4], 0.01);
    let affine_next = (1.95 + h * want_act_dot[8]).clamp(-2.0, 2.0);
    let want_force = [
        2.0 * 0.1,
        3.0 * 0.2,
        4.0 * -0.3 + 0.5 - 1.0 * -0.2 - 0.2 * -0.5,
        5.0 * 0.35,
        (2.0 * early_next).clamp(-1.5, 1.5),
        30.0 * 0.1 - 30.0 * -0.2 - 2.0 * -0.5,
        20.0 * 0.05 - 20.0 * 0.3 - kv_lagged * -0.7,
        0.5 * 0.4 + 0.1 - 0.2 * 0.3 - 0.3 * -0.7,
        (1.0 + 0.5 * 0.3 - 0.25 * -0.7) * affine_next,
    ];
    println!("act_dot {:?}\nwant    {want_act_dot:?}", data.act_dot.as_slice());
    println!("force   {:?}\nwant    {want_force:?}", data.actuator_force.as_slice());
    assert_eq!(affine_next, 2.0, "actearly's next activation is clamped to actrange");
    assert!(early_next * 2.0 > 1.5, "and the force to forcerange");
    for i in 0..9 {
        let (a, b) = (data.act_dot[i], want_act_dot[i]);
        assert!((a - b).abs() <= ALGO_REL * (1.0 + b.abs()), "act_dot {i}: {a} vs {b}");
        let (a, b) = (data.actuator_force[i], want_force[i]);
        assert!((a - b).abs() <= ALGO_REL * (1.0 + b.abs()), "actuator_force {i}: {a} vs {b}");
    }
}

/// A simulation of `activation.xml` from its keyframe (act included) with `integrator`.
fn activation_sim(integrator: IntegratorKind) -> Simulation {
    let model = Arc::new(load(Path::new(ACTIVATION), &LoadOptions::default()).unwrap());
    let key = &model.keyframes[0];
    let (mut q, mut v, mut ctrl, mut act) =
        (model.qpos0.clone(), vec![0.0; model.nv], vec![0.0; model.actuators.len()], vec![0.0; model.na()]);
    key.apply(&mut q, &mut v, &mut ctrl, &mut act);
    assert_eq!(act, [0.1, 0.2, -0.3, 0.35, -0.5, 0.1, 0.05, 0.4, 1.5], "the keyframe's act");
    let mut sim = Simulation::new(model, &SimOptions { integrator: Some(integrator), ..Default::default() });
    sim.set_state(&q, &v).unwrap();
    sim.set_act(&act).unwrap();
    sim.ctrl_mut().copy_from_slice(&ctrl);
    sim
}

/// Euler steps: filterexact integrates the filter exactly (act → ctrl as e^(−t/τ) whatever the
/// step), filter by explicit Euler, the integrator exactly for a constant control, and actrange
/// clamps after the step.
#[test]
fn euler_steps_activations_as_mujoco() {
    let mut sim = activation_sim(IntegratorKind::Euler);
    let (h, n) = (sim.timestep, 25);
    assert_eq!(h, 0.002);
    for _ in 0..n {
        sim.step().unwrap();
    }
    let t = h * n as f64;
    let act = sim.act().to_vec();
    println!("act after {n} Euler steps: {act:?}");
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-13 * (1.0 + b.abs());
    // Integrator, ctrl 0.5: 0.1 + 0.5 t.
    assert!(close(act[0], 0.1 + 0.5 * t), "{}", act[0]);
    // Filter τ = 0.05, ctrl 1: explicit Euler, 1 + (0.2 − 1)(1 − h/τ)ⁿ.
    assert!(close(act[1], 1.0 + (0.2 - 1.0) * (1.0 - h / 0.05).powi(n)), "{}", act[1]);
    // Filterexact τ = 0.02, ctrl −1: exact, −1 + (−0.3 + 1) e^(−t/τ).
    assert!(close(act[2], -1.0 + 0.7 * (-t / 0.02).exp()), "{}", act[2]);
    // Integrator with actrange [−0.3, 0.4], ctrl 2: 0.35 + 2t passes 0.4 and stays there.
    assert_eq!(act[3], 0.4);
    // intvelocity with actrange [−0.8, 0.8], ctrl 0.3: 0.1 + 0.3 t.
    assert!(close(act[5], 0.1 + 0.3 * t), "{}", act[5]);
}

/// RK4 steps the activations with the stages of its tableau and applies the weighted mean rate
/// as MuJoCo's `mj_RungeKutta` does: classical RK4 for the filter; for filterexact the mean rate
/// through the exact factor τ (1 − e^(−h/τ)); clamping after the step. Every stepper keeps act
/// in actrange and integrates a constant-rate integrator exactly.
#[test]
fn every_stepper_integrates_activations() {
    let mut sim = activation_sim(IntegratorKind::Rk4);
    let h = sim.timestep;
    sim.step().unwrap();
    let rk4_mean = |a: f64, u: f64, tau: f64| {
        let k1 = (u - a) / tau;
        let k2 = (u - (a + 0.5 * h * k1)) / tau;
        let k3 = (u - (a + 0.5 * h * k2)) / tau;
        let k4 = (u - (a + h * k3)) / tau;
        (k1 + 2.0 * k2 + 2.0 * k3 + k4) / 6.0
    };
    let act = sim.act();
    let filter = 0.2 + h * rk4_mean(0.2, 1.0, 0.05);
    let exact = -0.3 + rk4_mean(-0.3, -1.0, 0.02) * 0.02 * (1.0 - (-h / 0.02f64).exp());
    println!("RK4 act {:?}; filter {filter}, filterexact {exact}", act);
    assert!((act[1] - filter).abs() < 1e-15 && (act[2] - exact).abs() < 1e-15);
    for kind in
        [IntegratorKind::Euler, IntegratorKind::Rk4, IntegratorKind::Adaptive, IntegratorKind::ImplicitFast]
    {
        let mut sim = activation_sim(kind);
        for _ in 0..50 {
            sim.step().unwrap();
            assert!((-0.3..=0.4).contains(&sim.act()[3]), "{kind:?}: {}", sim.act()[3]);
            assert!((-2.0..=2.0).contains(&sim.act()[8]), "{kind:?}: {}", sim.act()[8]);
        }
        let act = sim.act();
        println!("{kind:?}: act after 0.1 s {act:?}");
        assert_eq!(act[3], 0.4, "{kind:?}");
        assert!((act[0] - (0.1 + 0.5 * 0.1)).abs() < 1e-13, "{kind:?}: {}", act[0]);
        // The filterexact activation is near its exact value with every method (exact with the
        // first-order ones; RK4 blends its mean rate with the exact factor, as MuJoCo does).
        let exact = -1.0 + 0.7 * (-0.1f64 / 0.02).exp();
        let tol = if kind == IntegratorKind::Rk4 { 2e-3 } else { 1e-7 };
        assert!((act[2] - exact).abs() < tol, "{kind:?}: {} vs {exact}", act[2]);
    }
}

/// An `intvelocity` servo (MuJoCo's integrated-velocity position servo) drives a pendulum under
/// gravity to the integral of its velocity command and holds it there once the command is zero.
#[test]
fn intvelocity_servo_holds_a_position() {
    let model = load_mjcf_str(
        r#"<mujoco><option timestep="0.002"/><worldbody><body>
        <joint name="hinge" axis="0 1 0"/><geom type="capsule" fromto="0 0 0 0.4 0 0" size="0.03" mass="1"/>
        </body></worldbody><actuator>
        <intvelocity name="servo" joint="hinge" kp="100" dampratio="1" actrange="-1.5 1.5"/>
        </actuator></mujoco>"#,
    )
    .unwrap();
    assert_eq!(model.na(), 1);
    let mut sim = Simulation::new(Arc::new(model), &SimOptions::default());
    sim.set_controller(|t, _, _, ctrl| ctrl[0] = if t < 1.0 - 1e-9 { 0.5 } else { 0.0 });
    for _ in 0..2000 {
        sim.step().unwrap();
    }
    // The setpoint is ∫ ctrl dt = 0.5 rad, held once the command stops.
    let (q, v, act) = (sim.data.qpos[0], sim.data.qvel[0], sim.act()[0]);
    println!("after 4 s: q {q}, v {v}, act {act}, qacc {}", sim.data.qacc[0]);
    assert!((act - 0.5).abs() < 1e-12, "{act}");
    assert!(v.abs() < 1e-6 && sim.data.qacc[0].abs() < 1e-6, "at rest: v {v}");
    // Held where the servo's stiffness balances gravity: kp (q − act) = m g x_com cos q (a positive
    // angle about +y lowers the arm along +x, so gravity pulls q beyond the setpoint).
    let sag = 9.81 * 0.2 * q.cos() / 100.0;
    assert!((q - (0.5 + sag)).abs() < 1e-6, "q {q}, sag {sag}");
    let mut sim_free = activation_free_pendulum();
    for _ in 0..2000 {
        sim_free.step().unwrap();
    }
    assert!((sim_free.data.qpos[0] - q).abs() > 0.5, "without the servo the pendulum falls");
}

fn activation_free_pendulum() -> Simulation {
    let model = load_mjcf_str(
        r#"<mujoco><option timestep="0.002"/><worldbody><body>
        <joint name="hinge" axis="0 1 0" damping="0.5"/><geom type="capsule" fromto="0 0 0 0.4 0 0" size="0.03" mass="1"/>
        </body></worldbody></mujoco>"#,
    )
    .unwrap();
    Simulation::new(Arc::new(model), &SimOptions::default())
}

/// Richardson-extrapolated central difference of f along dof k on the configuration manifold.
fn fd(model: &lagrange::Model, q: &[f64], k: usize, mut f: impl FnMut(&[f64]) -> f64) -> f64 {
    let mut central = |h: f64| {
        let mut e = vec![0.0; model.nv];
        e[k] = 1.0;
        let (mut qp, mut qm) = (q.to_vec(), q.to_vec());
        lagrange::model::integrate_configuration(model, &mut qp, &e, h).unwrap();
        lagrange::model::integrate_configuration(model, &mut qm, &e, -h).unwrap();
        (f(&qp) - f(&qm)) / (2.0 * h)
    };
    (4.0 * central(FD_STEP / 2.0) - central(FD_STEP)) / 3.0
}

/// Site transmissions: with a reference site on an ancestor body and a translational gear, the
/// moment row is the gradient of the length (finite differences); without one (MuJoCo defines
/// no length), it is the gradient of the site position projected on the gear in the site frame.
/// Ball and free joint moments are the gear (rotated into the child frame for jointinparent).
#[test]
fn site_transmission_moments_are_length_gradients() {
    let model = load(Path::new(TRANSMISSIONS), &LoadOptions::default()).unwrap();
    let plan = &model.plan;
    let mut data = Data::new(&model);
    let mut q = model.qpos0.clone();
    let perturb = [
        0.1, -0.2, 0.05, 0.9, 0.2, -0.3, 0.1, 0.8, 0.3, 0.1, -0.4, 0.7, -0.5, 0.04, 0.95, 0.1, 0.2, -0.1,
        0.6, 0.05,
    ];
    q.copy_from_slice(&perturb[..model.nq]);
    for j in &model.joints {
        if j.kind.nq() >= 4 {
            let a = j.qpos_adr + j.kind.nq() - 4;
            let n = q[a..a + 4].iter().map(|x| x * x).sum::<f64>().sqrt();
            q[a..a + 4].iter_mut().for_each(|x| *x /= n);
        }
    }
    let v = vec![0.0; model.nv];
    let bias = plan.actuator_bias_velocity.clone();
    let id = |name: &str| model.actuators.iter().position(|a| a.name == name).unwrap();
    let mut data_fd = Data::new(&model);
    let mut length = |i: usize, q: &[f64]| {
        actuation(&model, &mut data_fd, q, &v, &bias).unwrap();
        data_fd.actuator_length[i]
    };
    let mut worst: f64 = 0.0;
    // Site with a reference site on an ancestor, translational gear; slider-cranks (one whose rod
    // reaches the crank pin, one on a single body whose length is constant).
    for name in ["ref_lin", "crank2", "crank"] {
        let a = id(name);
        for k in 0..model.nv {
            let d = fd(&model, &q, k, |q| length(a, q));
            actuation(&model, &mut data, &q, &v, &bias).unwrap();
            let m = data.actuator_moment[(a, k)];
            worst = worst.max((m - d).abs());
            assert!((m - d).abs() <= FD_REL * (1.0 + d.abs()), "{name} dof {k}: moment {m}, d length/dq {d}");
        }
    }
    actuation(&model, &mut data, &q, &v, &bias).unwrap();
    assert!(data.actuator_moment.row(id("crank2")).amax() > 0.1, "the rod reaches the pin here");
    // Without refsite: the gear [1, 2, −0.5] in the site frame, against the site's position.
    let site = model.site_id("hand").unwrap();
    let site_force = id("site_force");
    forward_kinematics(&model, &mut data, &q).unwrap();
    let wrench = data.x_world_frame[site].rot * lagrange::spatial::Vec3::new(1.0, 2.0, -0.5);
    let mut data2 = Data::new(&model);
    for k in 0..model.nv {
        let d = fd(&model, &q, k, |q| {
            forward_kinematics(&model, &mut data2, q).unwrap();
            data2.x_world_frame[site].pos.dot(&wrench)
        });
        actuation(&model, &mut data, &q, &v, &bias).unwrap();
        let m = data.actuator_moment[(site_force, k)];
        worst = worst.max((m - d).abs());
        assert!((m - d).abs() <= FD_REL * (1.0 + d.abs()), "site_force dof {k}: moment {m}, fd {d}");
    }
    println!("site transmissions: worst |moment − finite difference| {worst:.1e}");
    // Ball: the gear on the 3 dofs; jointinparent: Rᵀ gear. Free: (gear₀₋₂, gear₃₋₅).
    actuation(&model, &mut data, &q, &v, &bias).unwrap();
    let ball = model.joints.iter().find(|j| j.name == "shoulder").unwrap();
    let row =
        |i: usize, a: usize, n: usize| (a..a + n).map(|k| data.actuator_moment[(i, k)]).collect::<Vec<_>>();
    assert_eq!(row(id("ball"), ball.dof_adr, 3), [1.0, -2.0, 0.5]);
    let qa = ball.qpos_adr;
    let r = lagrange::spatial::quat_to_matrix(q[qa], q[qa + 1], q[qa + 2], q[qa + 3]);
    let g = r.transpose() * lagrange::spatial::Vec3::new(0.2, 1.0, -1.0);
    let got = row(id("ball_parent"), ball.dof_adr, 3);
    assert!((0..3).all(|k| (got[k] - g[k]).abs() < 1e-15), "{got:?} vs {g:?}");
    assert_eq!(row(id("free"), 0, 6), [1.0, 2.0, 3.0, -1.0, 0.5, 0.25]);
    assert_eq!(data.actuator_length[id("free")], 0.0);
}

#[test]
fn activation_input_errors_name_the_fix() {
    let base = |act: &str| {
        format!(
            r#"<mujoco><worldbody><body><joint name="j"/><geom size=".1"/></body></worldbody>
            <actuator>{act}</actuator><keyframe><key name="k" act="0.1 0.2"/></keyframe></mujoco>"#
        )
    };
    let err = load_mjcf_str(&base(r#"<general joint="j" dyntype="filter"/>"#)).unwrap_err().to_string();
    assert!(err.contains("keyframe 'k': act has 2 values, the model has 1 activation states"), "{err}");
    assert!(err.contains("inline.xml:2"), "{err}");
    let err = load_mjcf_str(&base(r#"<general joint="j" dyntype="integrator" actdim="0"/>"#))
        .unwrap_err()
        .to_string();
    assert!(err.contains("'actdim' is 0") && err.contains("give actdim=\"1\" or remove it"), "{err}");
    let err = load_mjcf_str(&base(r#"<motor joint="j" actdim="1"/>"#)).unwrap_err().to_string();
    assert!(err.contains("dyntype 'none' has no activation"), "{err}");
    let err = load_mjcf_str(
        &base(r#"<general joint="j" dyntype="filter"/><general joint="j" dyntype="filter"/>"#)
            .replace("0.1 0.2", "0.1 1e300"),
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("keyframe 'k': an activation (act) 1e300 is absurdly large"), "{err}");
    // A control delay is simulated (tests/delay_mujoco.rs): no warning, a history buffer.
    let model = load_mjcf_str(
        r#"<mujoco><worldbody><body><joint name="j"/><geom size=".1"/></body></worldbody>
        <actuator><motor joint="j" nsample="3" delay="0.004"/></actuator></mujoco>"#,
    )
    .unwrap();
    assert!(model.warnings.iter().all(|w| !w.contains("delay")), "{:?}", model.warnings);
    assert_eq!(model.nhistory(), 8);
    // The API refuses an act of the wrong length.
    let model = load(Path::new(ACTIVATION), &LoadOptions::default()).unwrap();
    let mut sim = Simulation::new(Arc::new(model), &SimOptions::default());
    let err = sim.set_act(&[0.0; 3]).unwrap_err().to_string();
    assert!(err.contains("act has 3 values, the model has na = 9"), "{err}");
}

/// Actuator `damping` and `armature` on a hinge transmission are the joint's gear² · damping and
/// gear² · armature (MuJoCo 4.0's `actuator_damping`, `actuator_armature`); on other
/// transmissions they are not simulated, with a warning.
#[test]
fn actuator_damping_and_armature_reflect_through_the_gear() {
    let model = load_mjcf_str(
        r#"<mujoco><worldbody><body><joint name="j" armature="0.1" damping="0.2"/><geom size=".1" mass="1"/>
        <site name="s"/></body></worldbody><actuator>
        <motor joint="j" gear="3" damping="0.5" armature="0.02"/>
        <motor name="on_site" site="s" damping="1"/>
        </actuator></mujoco>"#,
    )
    .unwrap();
    assert!((model.dof_damping[0] - (0.2 + 9.0 * 0.5)).abs() < 1e-15, "{}", model.dof_damping[0]);
    assert!((model.dof_armature[0] - (0.1 + 9.0 * 0.02)).abs() < 1e-15, "{}", model.dof_armature[0]);
    assert!(
        model.warnings.iter().any(|w| w.contains("inline.xml:4: <motor>: actuator damping and armature are simulated on hinge and slide joint transmissions only")),
        "{:?}",
        model.warnings
    );
    let err = load_mjcf_str(
        r#"<mujoco><worldbody><body><joint name="j"/><geom size=".1"/></body></worldbody>
        <actuator><motor joint="j" armature="-1"/></actuator></mujoco>"#,
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("'armature' is -1; it cannot be negative"), "{err}");
}

/// implicitfast is implicit in the actuators' velocity derivatives (MuJoCo's `mjd_actuator_vel`):
/// a velocity servo of gain kv on a free hinge of inertia I, commanded to 0, steps
/// v₁ = v₀ − h kv v₀ / (I + h kv), where explicit Euler gives v₀ − h kv v₀ / I.
#[test]
fn implicitfast_is_implicit_in_actuator_velocity_derivatives() {
    let text = r#"<mujoco><option gravity="0 0 0"/><worldbody><body><joint name="j"/>
        <geom size=".1" mass="1"/></body></worldbody><actuator><velocity joint="j" kv="10"/></actuator></mujoco>"#;
    let step = |kind| {
        let model = Arc::new(load_mjcf_str(text).unwrap());
        let mut sim = Simulation::new(model, &SimOptions { integrator: Some(kind), ..Default::default() });
        sim.set_state(&[0.0], &[2.0]).unwrap();
        sim.step().unwrap();
        sim.data.qvel[0]
    };
    let (h, kv, i) = (0.002, 10.0, 0.4 * 0.01);
    let implicit = step(IntegratorKind::ImplicitFast);
    let explicit = step(IntegratorKind::Euler);
    println!("implicitfast {implicit}, Euler {explicit}");
    assert!((implicit - (2.0 - h * kv * 2.0 / (i + h * kv))).abs() < 1e-13, "{implicit}");
    assert!((explicit - (2.0 - h * kv * 2.0 / i)).abs() < 1e-12, "{explicit}");
}

/// A tendon's `actuatorfrcrange` scales the forces of its actuators together into the range
/// (bound / total), before each actuator's own `forcerange` (MuJoCo 4.0.0's order: checked
/// against it by `validation/crossval_actuators`).
#[test]
fn tendon_actuator_force_range_scales_its_actuators() {
    let model =
        load(Path::new("tests/data/mjcf/actuators/tendon_force_range.xml"), &LoadOptions::default()).unwrap();
    assert_eq!(model.tendons[0].actuator_force_range, Some([-1.0, 1.0]));
    let mut data = Data::new(&model);
    data.ctrl.copy_from_slice(&[3.0, 1.0, 0.0, 7.0, 5.0]);
    forward_at(&model, &mut data, &[0.0, 0.0], &[0.0, 0.0]);
    // Total on t: 3 + 1 + 0 = 4 > 1: scaled by 1/4 (clamping m1 to its forcerange 2.5 first would
    // give 2.5/3.5 instead).
    let f = data.actuator_force.as_slice();
    println!("actuator_force {f:?}");
    assert_eq!(f, [0.75, 0.25, 0.0, 7.0, 5.0]);
    // Within the range: unchanged; a total of 0 is left alone.
    data.ctrl.copy_from_slice(&[0.5, -0.2, 0.0, 0.0, 0.0]);
    forward_at(&model, &mut data, &[0.0, 0.0], &[0.0, 0.0]);
    assert_eq!(&data.actuator_force.as_slice()[..3], [0.5, -0.2, 0.0]);
}

/// A step size given to the simulation is the timestep `actearly` looks ahead by, as MuJoCo's
/// `opt.timestep`: `activation.xml` (timestep 0.002) run at 0.005 s equals the file run with
/// `<option timestep="0.005">`, bit for bit, and differs from a stepper driven at 0.005 s on the
/// file's model (looking ahead by 0.002 s).
#[test]
fn a_step_size_override_is_the_timestep_of_actearly() {
    let file = load(Path::new(ACTIVATION), &LoadOptions::default()).unwrap();
    assert!(file.actuators.iter().any(|a| a.actearly) && file.options.timestep == 0.002);
    let start = |model: &lagrange::Model| {
        let key = &model.keyframes[0];
        let (mut q, mut v, mut ctrl, mut act) = (
            model.qpos0.clone(),
            vec![0.0; model.nv],
            vec![0.0; model.actuators.len()],
            vec![0.0; model.na()],
        );
        key.apply(&mut q, &mut v, &mut ctrl, &mut act);
        (q, v, ctrl, act)
    };
    let run = |model: lagrange::Model, timestep: Option<f64>| {
        let (q, v, ctrl, act) = start(&model);
        let mut sim = Simulation::new(Arc::new(model), &SimOptions { timestep, ..Default::default() });
        sim.set_state(&q, &v).unwrap();
        sim.set_act(&act).unwrap();
        sim.ctrl_mut().copy_from_slice(&ctrl);
        for _ in 0..40 {
            sim.step().unwrap();
        }
        sim.data.qvel.clone()
    };
    let mut at_h = file.clone();
    at_h.options.timestep = 0.005;
    let overridden = run(file.clone(), Some(0.005));
    assert_eq!(overridden, run(at_h, None), "the override runs the model at its own timestep");
    // The file's model stepped at 0.005 s by its stepper directly: actearly looks 0.002 s ahead.
    let (q, v, ctrl, act) = start(&file);
    let mut stepper = IntegratorKind::Euler.build(&file);
    let mut data = Data::new(&file);
    data.ctrl.as_mut_slice().copy_from_slice(&ctrl);
    data.qpos.as_mut_slice().copy_from_slice(&q);
    data.qvel.as_mut_slice().copy_from_slice(&v);
    data.act.as_mut_slice().copy_from_slice(&act);
    for _ in 0..40 {
        stepper.step(&file, &mut data, 0.005);
    }
    let diff = (&overridden - &data.qvel).amax();
    assert!(diff > 1e-9, "actearly's look-ahead step matters here: {diff:e}");
}
