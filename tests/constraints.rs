//! Exact (rigid) equality constraints: physics from the notes, algebraic cross-checks of the KKT
//! solution, drift correction, and mimic joints against the reduced dynamics.

mod common;

use common::{rel_err, rel_err_vec, CONSTRAINT_REL, JDOTV_FD_REL, PROJECTED_DRIFT};
use lagrange::constraint::ConstraintMode;
use lagrange::dynamics::{crba, spatial_momentum};
use lagrange::forward::DriftCorrection;
use lagrange::integrate::IntegratorKind;
use lagrange::io::{load, LoadOptions};
use lagrange::kinematics::{forward_kinematics, forward_velocities};
use lagrange::model::{integrate_configuration, EqualityKind};
use lagrange::sim::{SimOptions, Simulation};
use lagrange::{Data, Model};
use nalgebra::{DMatrix, DVector};
use rand::{rngs::SmallRng, Rng, SeedableRng};
use std::path::Path;
use std::sync::Arc;

/// The model with its joint limits switched off (`<flag limit="disable">`): these tests isolate the
/// equality rows, at random states that may lie beyond a limit (tests/limits.rs has the limits).
fn model(path: &str) -> Model {
    let mut model = load(Path::new(path), &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    model.options.flags.limit = false;
    model.rebuild_plan();
    model
}

/// docs/physics.md §1.6: the point mass in polar coordinates (θ hinge, r slide) held at r = l by the
/// equality r − l = 0. Its multiplier is the rod tension λ = −m r θ̇² − m g cos θ (the sign of
/// docs/physics.md: negative = the rod pulls the mass inwards), at 20 states.
#[test]
fn rod_tension_is_the_lagrange_multiplier_notes_1_6() {
    let model = model("models/textbook/rod_pendulum.xml");
    let model = common::with_mode(model, ConstraintMode::Exact);
    let mut data = Data::new(&model);
    let (m, g, l) = (1.5, 9.81, 1.0);
    let mut rng = SmallRng::seed_from_u64(16);
    let mut worst = 0.0f64;
    for _ in 0..20 {
        let (theta, theta_dot): (f64, f64) = (rng.random_range(-3.0..3.0), rng.random_range(-5.0..5.0));
        common::forward_at(&model, &mut data, &[theta, l], &[theta_dot, 0.0]);
        assert_eq!(data.nefc, 1);
        let lambda = data.efc_force[0];
        let tension = -m * l * theta_dot * theta_dot - m * g * theta.cos();
        let err = rel_err(lambda, tension);
        assert!(
            err <= CONSTRAINT_REL,
            "θ = {theta}, θ̇ = {theta_dot}: λ = {lambda}, notes {tension}, rel {err:e}"
        );
        // The rod holds: no radial acceleration.
        assert!(data.qacc[1].abs() <= CONSTRAINT_REL * (tension.abs() / m), "r̈ = {}", data.qacc[1]);
        worst = worst.max(err);
    }
    println!("rod tension vs docs/physics.md §1.6 at 20 states: max rel err {worst:.2e}");
}

/// Notes §1.4: the pendulum on a movable support, built as cart and pendulum on their own slides
/// joined by a connect: no horizontal force acts from outside, so P_x is conserved (RK4 with
/// projection; the connect's rows are rank 1 of 3 here).
#[test]
fn pendulum_on_movable_support_conserves_horizontal_momentum_notes_1_4() {
    let model = Arc::new(model("models/textbook/pendulum_on_cart_loop.xml"));
    let key = &model.keyframes[0];
    let mut sim = Simulation::new(
        model.clone(),
        &SimOptions {
            integrator: Some(IntegratorKind::Rk4),
            constraints: Some(ConstraintMode::Exact),
            ..Default::default()
        },
    );
    sim.set_state(key.qpos.as_ref().unwrap(), key.qvel.as_ref().unwrap()).unwrap();
    let momentum = |sim: &mut Simulation| {
        let (q, v) = (sim.data.qpos.clone(), sim.data.qvel.clone());
        forward_kinematics(&sim.model, &mut sim.data, q.as_slice()).unwrap();
        forward_velocities(&sim.model, &mut sim.data, v.as_slice()).unwrap();
        spatial_momentum(&sim.model, &sim.data).lin.x
    };
    let p0 = momentum(&mut sim);
    let mut worst = 0.0f64;
    for _ in 0..2000 {
        sim.step().unwrap();
        worst = worst.max((momentum(&mut sim) - p0).abs());
    }
    println!("pendulum on a movable support (connect): P_x = {p0:.6}, max |ΔP_x| {worst:.2e} over 2 s");
    assert!(worst <= 1e-9 * p0.abs().max(1.0), "P_x drifted by {worst:e}");
    assert_eq!(sim.data.efc_rank, 1, "the connect's y and z rows are redundant here");
}

/// At random states (v projected onto J v = 0) of every constraint model: the KKT equations hold
/// (M q̈ − (τ + passive − c) = Jᵀλ, J q̈ + J̇v = 0), and J̇v equals central differences of J(q)v
/// along v.
#[test]
fn kkt_solution_satisfies_dynamics_and_constraints() {
    let files = [
        "models/textbook/rod_pendulum.xml",
        "models/textbook/four_bar.xml",
        "models/textbook/pendulum_on_cart_loop.xml",
        "tests/data/mjcf/constraints/ball_chain_connect.xml",
        "tests/data/mjcf/constraints/connect_free_sites.xml",
        "tests/data/mjcf/constraints/fourbar_connect.xml",
        "tests/data/mjcf/constraints/joint_poly.xml",
        "tests/data/mjcf/constraints/tendon_fixed.xml",
        "tests/data/mjcf/constraints/weld_bodies_torquescale.xml",
        "tests/data/mjcf/constraints/weld_sites.xml",
        "tests/data/mjcf/constraints/weld_world_relpose.xml",
        "tests/data/urdf/constraints/mimic.urdf",
        "tests/data/urdf/constraints/mimic_chain.urdf",
        "models/panda/panda.urdf",
    ];
    let mut rng = SmallRng::seed_from_u64(7);
    for file in files {
        let model = model(file);
        assert!(!model.equalities.is_empty(), "{file}: no equality constraints loaded");
        let model = common::with_mode(model, ConstraintMode::Exact);
        let plan = &model.plan;
        let mut data = Data::new(&model);
        let nv = model.nv;
        let (mut e_dyn, mut e_acc, mut e_fd) = (0.0f64, 0.0f64, 0.0f64);
        for _ in 0..5 {
            let mut q = model.qpos0.clone();
            let dq: Vec<f64> = (0..nv).map(|_| rng.random_range(-0.5..0.5)).collect();
            integrate_configuration(&model, &mut q, &dq, 1.0).unwrap();
            let mut v: Vec<f64> = (0..nv).map(|_| rng.random_range(-1.0..1.0)).collect();
            let tau: Vec<f64> = (0..nv).map(|_| rng.random_range(-1.0..1.0)).collect();
            // v onto J v = 0 (the projection of the steppers).
            plan.constraints.evaluate(&model, &mut data, &q, &v).unwrap();
            crba(&model, &mut data, &q).unwrap();
            lagrange::dynamics::factorize_mass_matrix(&model, &mut data);
            lagrange::constraint::project_velocities(&model, &mut data, &mut v, 0.0, Default::default())
                .unwrap();
            data.qfrc_applied.copy_from_slice(&tau);
            common::forward_at(&model, &mut data, &q, &v);
            let n = data.nefc;
            let m = crba(&model, &mut data, &q).unwrap().clone();
            let qacc = data.qacc.clone();
            let lhs = &m * &qacc - (DVector::from_vec(tau.clone()) + &data.qfrc_passive - &data.qfrc_bias);
            let j = data.efc_j.rows(0, n).into_owned();
            let lambda = data.efc_force.rows(0, n).into_owned();
            e_dyn = e_dyn.max(rel_err_vec(lhs.as_slice(), (j.transpose() * &lambda).as_slice()));
            let scale = 1.0 + qacc.amax() * j.amax();
            e_acc = e_acc.max((&j * &qacc + data.efc_jdotv.rows(0, n)).amax() / scale);
            // J̇v by central differences of J(q ⊕ ±εv) v.
            let jdotv = data.efc_jdotv.rows(0, n).into_owned();
            let eps = 1e-6;
            let mut jv = |sign: f64| {
                let mut qe = q.clone();
                integrate_configuration(&model, &mut qe, &v, sign * eps).unwrap();
                forward_kinematics(&model, &mut data, &qe).unwrap();
                plan.constraints.positions(&model, &mut data, &qe, true).unwrap();
                data.efc_j.rows(0, n).into_owned() * DVector::from_vec(v.clone())
            };
            let fd: DVector<f64> = (jv(1.0) - jv(-1.0)) / (2.0 * eps);
            e_fd = e_fd.max((fd - &jdotv).amax() / (1.0 + jdotv.amax()));
        }
        println!("{file}: dynamics {e_dyn:.1e}, J q̈ + J̇v {e_acc:.1e}, J̇v vs FD {e_fd:.1e}");
        assert!(e_dyn <= CONSTRAINT_REL, "{file}: M q̈ − f ≠ Jᵀλ: {e_dyn:e}");
        assert!(e_acc <= CONSTRAINT_REL, "{file}: J q̈ + J̇v = {e_acc:e}");
        assert!(e_fd <= JDOTV_FD_REL, "{file}: J̇v vs central differences {e_fd:e}");
    }
}

/// The four-bar simulated 100 s at its timestep (RK4, 2 ms) stays closed to ≤ 1e-9 m with the
/// projection; without it the loop opens (the drift is printed and must be far larger).
#[test]
fn four_bar_stays_closed_with_projection() {
    let model = Arc::new(model("models/textbook/four_bar.xml"));
    let run = |drift: DriftCorrection| {
        let mut sim = Simulation::new(
            model.clone(),
            &SimOptions {
                drift: Some(drift),
                constraints: Some(ConstraintMode::Exact),
                ..Default::default()
            },
        );
        assert_eq!(sim.integrator(), "rk4", "the file's <option integrator>");
        let key = &model.keyframes[0];
        sim.set_state(key.qpos.as_ref().unwrap(), key.qvel.as_ref().unwrap()).unwrap();
        let mut worst = 0.0f64;
        for _ in 0..50_000 {
            let report = sim.step().unwrap();
            worst = worst.max(report.constraint_violation[0]);
        }
        (worst, sim.data.efc_rank, sim.data.efc_force.rows(0, sim.data.nefc).amax())
    };
    let (closed, rank, lambda) = run(DriftCorrection::default());
    let (open, _, _) = run(DriftCorrection { projection: false, ..DriftCorrection::default() });
    let (baumgarte, _, _) = run(DriftCorrection {
        projection: false,
        baumgarte: Some([20.0, 100.0]),
        ..DriftCorrection::default()
    });
    println!("four-bar, 100 s: max |φ| {closed:.2e} m projected, {open:.2e} m without, {baumgarte:.2e} m Baumgarte (20, 100)");
    assert!(closed <= PROJECTED_DRIFT, "projected drift {closed:e}");
    assert!(open > 100.0 * closed.max(1e-15), "without projection the loop should drift: {open:e}");
    assert!(baumgarte < open, "Baumgarte should reduce the drift: {baumgarte:e} vs {open:e}");
    assert_eq!(rank, 2, "a planar loop closed by a 3-row connect has rank 2");
    assert!(lambda.is_finite(), "minimum-norm multipliers are finite");
}

/// Mimic joints: the full-coordinate KKT solution equals the reduced dynamics in independent
/// coordinates, q = G q_r + o: q̈ = G (Gᵀ M G)⁻¹ Gᵀ (τ − c) (the mimic map is linear, so no Ġ term).
#[test]
fn mimic_full_coordinates_equal_reduced_dynamics() {
    for file in [
        "models/panda/panda.urdf",
        "tests/data/urdf/constraints/mimic.urdf",
        "tests/data/urdf/constraints/mimic_chain.urdf",
    ] {
        let model = model(file);
        let model = common::with_mode(model, ConstraintMode::Exact);
        let mut data = Data::new(&model);
        let nv = model.nv;
        // G: one column per independent dof; a mimic dof is multiplier × its leader's column.
        let mimics: Vec<(usize, usize, f64, f64)> = model
            .equalities
            .iter()
            .filter_map(|e| match e.kind {
                EqualityKind::Mimic { joint, leader, multiplier, offset } => {
                    Some((model.joints[joint].dof_adr, model.joints[leader].dof_adr, multiplier, offset))
                }
                _ => None,
            })
            .collect();
        assert!(!mimics.is_empty(), "{file}: no mimic loaded");
        let independent: Vec<usize> = (0..nv).filter(|d| !mimics.iter().any(|m| m.0 == *d)).collect();
        let mut g = DMatrix::<f64>::zeros(nv, independent.len());
        for (c, &d) in independent.iter().enumerate() {
            g[(d, c)] = 1.0;
        }
        // Mimics in dependency order (a mimic of a mimic follows its leader's row).
        for _ in 0..mimics.len() {
            for &(d, leader, mult, _) in &mimics {
                let row = g.row(leader) * mult;
                g.set_row(d, &row);
            }
        }
        let mut rng = SmallRng::seed_from_u64(3);
        let mut worst = 0.0f64;
        for _ in 0..10 {
            let mut q: Vec<f64> = (0..model.nq).map(|_| rng.random_range(-0.5..0.5)).collect();
            let vr: Vec<f64> = (0..independent.len()).map(|_| rng.random_range(-1.0..1.0)).collect();
            let v = &g * DVector::from_vec(vr);
            for _ in 0..mimics.len() {
                for &(d, leader, mult, off) in &mimics {
                    q[d] = mult * q[leader] + off; // hinge/slide: qpos address = dof address here
                }
            }
            let tau: Vec<f64> = (0..nv).map(|_| rng.random_range(-1.0..1.0)).collect();
            data.qfrc_applied.copy_from_slice(&tau);
            common::forward_at(&model, &mut data, &q, v.as_slice());
            let full = data.qacc.clone();
            let m = crba(&model, &mut data, &q).unwrap().clone();
            let f = DVector::from_vec(tau) + &data.qfrc_passive - &data.qfrc_bias;
            let mr = g.transpose() * &m * &g;
            let reduced = &g * mr.cholesky().unwrap().solve(&(g.transpose() * f));
            worst = worst.max(rel_err_vec(full.as_slice(), reduced.as_slice()));
        }
        println!("{file}: mimic full vs reduced, max rel err {worst:.2e}");
        assert!(worst <= CONSTRAINT_REL, "{file}: {worst:e}");
    }
}
