//! Convergence order of every integrator on quaternion joints: a heavy symmetric top on
//! a ball joint and a free tumbling asymmetric body (`models/textbook/`). Each integrator runs to
//! the same final time at three step sizes h, h/2, h/4; the error against a fine RK4 reference
//! (h_ref = 0.004 s / 32, whose own error is ≥ 32⁴ ≈ 1e6 times below RK4's smallest) is the max-norm
//! of the manifold difference q ⊖ q_ref and of v − v_ref; the observed order log₂(e(h)/e(h/2))
//! must lie in the band of `common::INTEGRATOR_ORDER_BAND` around the method's order (euler,
//! implicitfast: 1 — without damping implicitfast is explicit Euler; implicit: 1; variational: 2; rk4: 4). The adaptive method
//! is checked against its tolerance instead (its step size is not the caller's).

mod common;

use common::{run, ADAPTIVE_TOL_FACTOR, INTEGRATOR_ORDER_BAND};
use lagrange::integrate::{DormandPrince54, IntegratorKind, State, Stepper};
use lagrange::io::{load, LoadOptions};
use lagrange::model::difference_configuration;
use lagrange::Data;
use lagrange::Model;
use std::path::Path;

fn textbook(name: &str) -> Model {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("models/textbook").join(name);
    load(&path, &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

/// max |q ⊖ q_ref| and |v − v_ref|.
fn state_error(model: &Model, s: &State, reference: &State) -> f64 {
    let mut dq = vec![0.0; model.nv];
    difference_configuration(model, reference.q.as_slice(), s.q.as_slice(), &mut dq).unwrap();
    let dv = (&s.v - &reference.v).amax();
    dq.iter().fold(dv, |m, x| m.max(x.abs()))
}

/// A model, its initial state and the final time of the runs.
struct Case<'a> {
    name: &'a str,
    model: Model,
    q0: &'a [f64],
    v0: &'a [f64],
    t: f64,
}

/// Checks the observed orders of `kind` (step sizes h, h/2, h/4 to time `t`) against `order`.
fn check_order(case: &Case, kind: IntegratorKind, order: i32, h: f64) {
    let Case { name, model, q0, v0, t } = case;
    let t = *t;
    let n_ref = (t / (0.004 / 32.0)).round() as usize;
    let reference = run(model, IntegratorKind::Rk4, q0, v0, t / n_ref as f64, n_ref);
    let errors: Vec<f64> = (0..3)
        .map(|k| {
            let n = (t / h).round() as usize * (1 << k);
            state_error(model, &run(model, kind, q0, v0, t / n as f64, n), &reference)
        })
        .collect();
    let expected = 2f64.powi(order);
    for w in errors.windows(2) {
        let ratio = w[0] / w[1];
        println!(
            "{name} {}: errors {:.3e} → {:.3e}, ratio {ratio:.2} (order {:.2})",
            kind.name(),
            w[0],
            w[1],
            ratio.log2()
        );
        assert!(
            ratio >= expected / INTEGRATOR_ORDER_BAND && ratio <= expected * INTEGRATOR_ORDER_BAND,
            "{name}, {}: error ratio {ratio} per halving of the step (errors {errors:?}), expected {expected} (order {order})",
            kind.name()
        );
    }
}

/// Heavy symmetric top on a ball joint: tilted 0.3 rad about x, spin ω₃ = 20 rad/s plus a
/// transverse body rate, 0.5 s.
#[test]
fn ball_joint_heavy_top_converges_at_integrator_order() {
    let half = 0.15f64;
    let q0 = [half.cos(), half.sin(), 0.0, 0.0];
    let case = Case {
        name: "heavy top (ball)",
        model: textbook("heavy_top.xml"),
        q0: &q0,
        v0: &[1.0, 0.5, 20.0],
        t: 0.5,
    };
    check_order(&case, IntegratorKind::Euler, 1, 1e-3);
    check_order(&case, IntegratorKind::ImplicitFast, 1, 1e-3);
    check_order(&case, IntegratorKind::Implicit, 1, 1e-3);
    check_order(&case, IntegratorKind::Variational, 2, 4e-3);
    check_order(&case, IntegratorKind::Rk4, 4, 4e-3);
}

/// Free asymmetric body tumbling without gravity, centre of mass off the body origin, 0.5 s.
#[test]
fn free_joint_tumbling_body_converges_at_integrator_order() {
    let half = 0.2f64;
    let q0 = [0.0, 0.0, 0.0, half.cos(), 0.0, half.sin(), 0.0];
    let v0 = [0.1, -0.2, 0.3, 3.0, 1.0, 2.0];
    let model = textbook("free_asymmetric_body.xml");
    let case = Case { name: "tumbling body (free)", model, q0: &q0, v0: &v0, t: 0.5 };
    check_order(&case, IntegratorKind::Euler, 1, 1e-3);
    check_order(&case, IntegratorKind::ImplicitFast, 1, 1e-3);
    check_order(&case, IntegratorKind::Implicit, 1, 1e-3);
    check_order(&case, IntegratorKind::Variational, 2, 4e-3);
    check_order(&case, IntegratorKind::Rk4, 4, 1e-2);
}

/// Adaptive Dormand–Prince 5(4) on both quaternion cases: the error against the fine RK4
/// reference after 0.5 s (reporting interval 0.1 s) follows the requested tolerance — it shrinks
/// as rtol does and stays within `ADAPTIVE_TOL_FACTOR`·rtol.
#[test]
fn adaptive_error_follows_tolerance_on_ball_and_free_joints() {
    let half = 0.15f64;
    let q_top = [half.cos(), half.sin(), 0.0, 0.0];
    let q_free = [0.0, 0.0, 0.0, 0.2f64.cos(), 0.0, 0.2f64.sin(), 0.0];
    let cases = [
        Case {
            name: "heavy top (ball)",
            model: textbook("heavy_top.xml"),
            q0: &q_top,
            v0: &[1.0, 0.5, 20.0],
            t: 0.5,
        },
        Case {
            name: "tumbling body (free)",
            model: textbook("free_asymmetric_body.xml"),
            q0: &q_free,
            v0: &[0.1, -0.2, 0.3, 15.0, 5.0, 10.0],
            t: 0.5,
        },
    ];
    for case in &cases {
        let model = &case.model;
        let n_ref = (case.t / (0.004 / 32.0)).round() as usize;
        let reference = run(model, IntegratorKind::Rk4, case.q0, case.v0, case.t / n_ref as f64, n_ref);
        let mut previous = f64::INFINITY;
        for rtol in [1e-5, 1e-7, 1e-9] {
            let mut data = Data::new(model);
            let mut stepper = DormandPrince54::new(model, rtol, rtol * 1e-2);
            data.qpos.copy_from_slice(case.q0);
            data.qvel.copy_from_slice(case.v0);
            let mut worst_estimate: f64 = 0.0;
            for _ in 0..5 {
                let report = stepper.step(model, &mut data, case.t / 5.0);
                assert!(report.accepted, "{}: rejected interval at t = {}", case.name, data.time);
                worst_estimate = worst_estimate.max(report.error_estimate.unwrap());
            }
            let error = state_error(model, &State::of(&data), &reference);
            println!("{} adaptive rtol {rtol:.0e}: error {error:.3e}, worst scaled local estimate {worst_estimate:.2}", case.name);
            assert!(error <= ADAPTIVE_TOL_FACTOR * rtol, "{}: error {error} at rtol {rtol}", case.name);
            assert!(error < previous, "{}: error {error} did not shrink with rtol {rtol}", case.name);
            assert!(worst_estimate <= 1.0);
            previous = error;
        }
    }
}
