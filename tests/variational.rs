//! The variational integrator (`src/integrate/variational.rs`): its Lagrangian terms
//! against CRBA, RNEA and finite differences; momentum conservation (Noether) on a free body and
//! on a constrained loop; the equality constraints held to the solver tolerance; the error of a
//! Newton iteration that does not converge. Its order on ball and free joints is in
//! `tests/integrator_order.rs`, the long runs in `tests/stress.rs`.

mod common;

use common::{load_robot, random_q, random_v, rng};
use lagrange::dynamics::{crba, gravity_forces, kinetic_energy, spatial_momentum};
use lagrange::integrate::{IntegratorKind, LagrangianTerms, CONSTRAINT_TOL};
use lagrange::io::{load, LoadOptions};
use lagrange::kinematics::{forward_kinematics, forward_velocities};
use lagrange::model::integrate_configuration;
use lagrange::sim::{SimOptions, Simulation};
use lagrange::{Data, Model};
use std::path::Path;
use std::sync::Arc;

fn textbook(name: &str) -> Model {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("models/textbook").join(name);
    load(&path, &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

fn sim(model: Model, dt: f64, q0: &[f64], v0: &[f64]) -> Simulation {
    let options = SimOptions {
        integrator: Some(IntegratorKind::Variational),
        timestep: Some(dt),
        ..Default::default()
    };
    let mut sim = Simulation::new(Arc::new(model), &options);
    sim.set_state(q0, v0).unwrap();
    sim
}

/// M(q) ξ equals CRBA's M times ξ and g(q) RNEA's gravity (1e-12 relative); ∂T/∂q (right
/// trivialized, along q ⊕ ε e_k) equals the central difference of T(q ⊕ ε e_k, ξ) with ε = 1e-6
/// (1e-7 relative to the largest entry: the difference's truncation and round-off), on the mixed
/// tree (ball, hinge, slide, free) and a floating robot.
#[test]
fn lagrangian_terms_match_crba_rnea_and_finite_differences() {
    let models = [
        ("damped_mixed_tree", textbook("damped_mixed_tree.xml")),
        ("solo12 floating", load_robot("solo12", true)),
    ];
    let mut r = rng(15);
    for (name, model) in &models {
        let mut data = Data::new(model);
        let mut terms = LagrangianTerms::new(model);
        for _ in 0..3 {
            let q = random_q(model, &mut r);
            let xi = random_v(model, &mut r);
            terms.compute(model, &mut data, &q, &xi).unwrap();
            let m = crba(model, &mut data, &q).unwrap().clone();
            let m_xi = &m * nalgebra::DVector::from_vec(xi.clone());
            let scale = m_xi.amax().max(1.0);
            let e_m = (&terms.momentum_gen - &m_xi).amax() / scale;
            let g = gravity_forces(model, &mut data, &q).unwrap().clone();
            let e_g = (&terms.gravity_gen - &g).amax() / g.amax().max(1.0);
            let kinetic = |data: &mut Data, q: &[f64]| kinetic_energy(model, data, q, &xi).unwrap();
            let eps = 1e-6;
            let mut e_t: f64 = 0.0;
            let d_scale = terms.dkinetic_dq.amax().max(1e-3);
            for k in 0..model.nv {
                let mut e = vec![0.0; model.nv];
                e[k] = 1.0;
                let (mut qp, mut qm) = (q.clone(), q.clone());
                integrate_configuration(model, &mut qp, &e, eps).unwrap();
                integrate_configuration(model, &mut qm, &e, -eps).unwrap();
                let fd = (kinetic(&mut data, &qp) - kinetic(&mut data, &qm)) / (2.0 * eps);
                e_t = e_t.max((fd - terms.dkinetic_dq[k]).abs() / d_scale);
            }
            println!("{name}: M ξ rel {e_m:.1e}, g rel {e_g:.1e}, ∂T/∂q vs central difference rel {e_t:.1e}");
            assert!(e_m <= 1e-12 && e_g <= 1e-12, "{name}: M ξ {e_m}, g {e_g}");
            assert!(e_t <= 1e-7, "{name}: ∂T/∂q {e_t}");
        }
    }
}

/// A free asymmetric body tumbling without gravity (dt = 1 ms, 20 s): the spatial momentum (linear,
/// and angular about the world origin) is conserved at every step (the discrete
/// momentum maps of translations and rotations, discrete Noether theorem) to 1e-10 relative — the
/// round-off of p → v = M⁻¹p → p each step, a random walk of ~cond(M) ε per step; the energy error stays
/// below 1e-5 relative and shows no trend (second half's max no larger than 1.5× the first's).
#[test]
fn free_body_conserves_spatial_momentum_and_bounds_energy() {
    let model = textbook("free_asymmetric_body.xml");
    let half = 0.2f64;
    let q0 = [0.1, 0.0, 0.0, half.cos(), 0.0, half.sin(), 0.0];
    let v0 = [0.1, -0.2, 0.3, 3.0, 1.0, 2.0];
    let mut s = sim(model, 1e-3, &q0, &v0);
    let momentum = |s: &mut Simulation| {
        let (q, v) = (s.data.qpos.clone(), s.data.qvel.clone());
        forward_kinematics(&s.model, &mut s.data, q.as_slice()).unwrap();
        forward_velocities(&s.model, &mut s.data, v.as_slice()).unwrap();
        let h = spatial_momentum(&s.model, &s.data);
        [h.ang.x, h.ang.y, h.ang.z, h.lin.x, h.lin.y, h.lin.z]
    };
    let h0 = momentum(&mut s);
    let scale = h0.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let e0 = s.energies().0;
    let (mut worst_h, mut first_half, mut second_half) = (0.0f64, 0.0f64, 0.0f64);
    let n = 20_000;
    for i in 0..n {
        s.step().unwrap();
        let h = momentum(&mut s);
        worst_h = worst_h.max(h.iter().zip(&h0).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max) / scale);
        let de = ((s.energies().0 - e0) / e0).abs();
        if i < n / 2 {
            first_half = first_half.max(de);
        } else {
            second_half = second_half.max(de);
        }
    }
    println!("free body, variational dt 1 ms, 20 s: momentum rel {worst_h:.2e}, energy rel max {first_half:.2e} (first 10 s), {second_half:.2e} (last 10 s)");
    assert!(worst_h <= 1e-10, "momentum drift {worst_h}");
    assert!(first_half.max(second_half) <= 1e-5 && second_half <= 1.5 * first_half);
}

/// The pendulum on a cart as a loop (two slides and a hinge closed by a connect, dt = 1 ms, 10 s):
/// the connect is held to the solver tolerance (`CONSTRAINT_TOL`, 1e-12) and J v = 0 to 1e-12,
/// the horizontal momentum (the discrete momentum map of translating both slides, a symmetry the
/// constraint shares) is conserved to 1e-11 relative (round-off), and the energy error (second
/// order, bounded) stays within 3e-5 relative.
#[test]
fn constrained_loop_holds_the_constraint_and_conserves_momentum() {
    let model = textbook("pendulum_on_cart_loop.xml");
    let key = &model.keyframes[model.keyframe_id("push").unwrap()];
    let (q0, v0) = (key.qpos.clone().unwrap(), key.qvel.clone().unwrap());
    // The keyframe leaves the pivot at x = 0 with the cart: consistent with the connect.
    let mut s = sim(model, 1e-3, &q0, &v0);
    let momentum = |s: &mut Simulation| {
        let (q, v) = (s.data.qpos.clone(), s.data.qvel.clone());
        forward_kinematics(&s.model, &mut s.data, q.as_slice()).unwrap();
        forward_velocities(&s.model, &mut s.data, v.as_slice()).unwrap();
        spatial_momentum(&s.model, &s.data).lin.x
    };
    let p0 = momentum(&mut s);
    let (e0_t, e0_v) = s.energies();
    let e0 = e0_t + e0_v;
    let (mut worst_phi, mut worst_jv, mut worst_p, mut worst_e) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for _ in 0..10_000 {
        let report = s.step().unwrap();
        worst_phi = worst_phi.max(report.constraint_violation[0]);
        worst_jv = worst_jv.max(report.constraint_violation[1]);
        let check = s.constraint_violation();
        worst_phi = worst_phi.max(check[0]);
        worst_p = worst_p.max((momentum(&mut s) - p0).abs() / p0.abs());
        let (t, v) = s.energies();
        worst_e = worst_e.max(((t + v) - e0).abs() / e0_t.max(1.0));
    }
    println!("cart-pendulum loop, variational dt 1 ms, 10 s: |φ| {worst_phi:.1e}, |J v| {worst_jv:.1e}, momentum rel {worst_p:.1e}, energy rel {worst_e:.1e}");
    assert!(worst_phi <= CONSTRAINT_TOL, "φ {worst_phi}");
    assert!(worst_jv <= 1e-12, "J v {worst_jv}");
    assert!(worst_p <= 1e-11, "momentum {worst_p}");
    assert!(worst_e <= 3e-5, "energy {worst_e}");
}

/// The four-bar (a planar loop closed by a 3-row connect of rank 2: one redundant row) released
/// from a tilt: the connect stays within `CONSTRAINT_TOL` and the energy within 1e-5 relative
/// over 5 s at dt = 2 ms.
#[test]
fn four_bar_with_redundant_rows_holds_the_loop() {
    let model = textbook("four_bar.xml");
    let a = 0.5f64;
    // A parallelogram: crank and rocker at the same angle, the coupler turned back by it.
    let mut s = sim(model, 2e-3, &[a, -a, a], &[0.0, 0.0, 0.0]);
    let (t0, v0) = s.energies();
    let e0 = t0 + v0;
    let (mut worst_phi, mut worst_e) = (0.0f64, 0.0f64);
    for _ in 0..2_500 {
        s.step().unwrap();
        worst_phi = worst_phi.max(s.constraint_violation()[0]);
        let (t, v) = s.energies();
        worst_e = worst_e.max(((t + v) - e0).abs() / e0.abs());
    }
    println!("four-bar, variational dt 2 ms, 5 s: |φ| {worst_phi:.1e}, energy rel {worst_e:.1e}");
    assert!(worst_phi <= CONSTRAINT_TOL && worst_e <= 1e-5, "φ {worst_phi}, energy {worst_e}");
}

/// A step far too large for Newton (a heavy top spinning at 2000 rad/s, dt = 0.5 s): the step is
/// refused with a `SimError` naming the integrator, step, time, step size and residual, and the
/// state is left where it was.
#[test]
fn newton_failure_is_a_typed_error_naming_step_time_and_residual() {
    let half = 0.15f64;
    let q0 = [half.cos(), half.sin(), 0.0, 0.0];
    let mut s = sim(textbook("heavy_top.xml"), 0.5, &q0, &[300.0, -200.0, 2000.0]);
    let err = s.step().expect_err("Newton should not converge at dt = 0.5 s");
    let msg = err.to_string();
    println!("{msg}");
    for needle in [
        "the variational integrator's Newton iteration did not converge in step 1",
        "t = 0 s → 0.5 s, dt = 0.5 s",
        "residual ",
        "iterations",
        "reduce SimOptions::timestep",
    ] {
        assert!(msg.contains(needle), "missing '{needle}' in: {msg}");
    }
    assert_eq!(s.data.qpos.as_slice(), &q0);
    assert_eq!(s.steps, 0);
}

/// States at rest where the forces are zero or round-off: the double pendulum hanging straight
/// down (g = 0 exactly) stays there, and balanced upside down (gravity torques of 1e-16 from
/// sin π) the steps converge — Newton's tolerance has an absolute floor, the impulse of the forces
/// over the step — and the pendulum stays balanced to 1e-9 rad over 0.2 s at dt = 1 ms.
#[test]
fn states_at_rest_with_round_off_forces_converge() {
    for (q0, tol) in [([0.0, 0.0], 0.0), ([std::f64::consts::PI, 0.0], 1e-9)] {
        let mut s = sim(textbook("double_pendulum.xml"), 1e-3, &q0, &[0.0, 0.0]);
        for _ in 0..200 {
            s.step().unwrap_or_else(|e| panic!("from {q0:?}: {e}"));
        }
        let moved = (s.data.qpos[0] - q0[0]).abs().max(s.data.qpos[1].abs());
        println!("double pendulum at rest at {q0:?}: moved {moved:.1e} rad in 0.2 s");
        assert!(moved <= tol, "from {q0:?}: moved {moved}");
    }
}

/// `Variational::with_tolerance`: a looser Newton tolerance (1e-10 of the momentum scale) takes
/// fewer iterations on a fast-falling 30-link chain than the default (round-off) and stays
/// within 1e-6 rad of it over 0.2 s (dt = 1 ms).
#[test]
fn looser_newton_tolerance_takes_fewer_iterations() {
    use lagrange::integrate::{Stepper, Variational};
    let model = textbook("chain30.xml");
    let run = |mut stepper: Variational| {
        let mut data = Data::new(&model);
        data.qpos.add_scalar_mut(0.3);
        let mut iterations = 0;
        for _ in 0..200 {
            let report = stepper.step(&model, &mut data, 1e-3);
            assert!(report.accepted);
            iterations += report.solver_iterations;
        }
        (data.qpos, iterations)
    };
    let (tight, n_tight) = run(Variational::new(&model));
    let (loose, n_loose) = run(Variational::with_tolerance(&model, 1e-10));
    let diff = (&tight - &loose).amax();
    println!("chain30, 200 steps: {n_tight} iterations at round-off, {n_loose} at 1e-10; |Δq| {diff:.1e}");
    assert!(n_loose < n_tight && diff < 1e-6, "{n_loose} vs {n_tight}, Δq {diff}");
}
