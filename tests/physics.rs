//! Physics from the lecture notes (`shared/reference/classical-mechanics-notes.md`): closed-form
//! results checked against the engine on the textbook models of `models/textbook/`.

mod common;

use common::{run, ALGO_REL, INTEGRATOR_ORDER_BAND, PERIOD_SMALL_AMPLITUDE_REL, RK4_CONSERVATION_REL};
use lagrange::dynamics::{aba, crba, gravity_forces};
use lagrange::integrate::{IntegratorKind, State};
use lagrange::io::{load, LoadOptions};
use lagrange::sim::{SimOptions, Simulation};
use lagrange::{Data, Model};
use std::f64::consts::PI;
use std::path::Path;
use std::sync::Arc;

const G: f64 = 9.81;

fn textbook(name: &str) -> Model {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("models/textbook").join(name);
    load(&path, &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

/// Deterministic pseudo-random numbers in [-1, 1) (no test depends on a particular stream).
fn uniform(seed: &mut u64) -> f64 {
    *seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
    ((*seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
}

/// Notes eq. 14: θ̈ = −(g/l) sin θ for the simple pendulum, at many (θ, θ̇).
#[test]
fn simple_pendulum_equation_of_motion_eq14() {
    let model = textbook("simple_pendulum.urdf");
    let mut data = Data::new(&model);
    let mut seed = 14;
    let mut worst = 0.0f64;
    for _ in 0..200 {
        let theta = PI * uniform(&mut seed);
        let omega = 5.0 * uniform(&mut seed);
        let qacc = aba(&model, &mut data, &[theta], &[omega], &[0.0]).unwrap()[0];
        let expected = -(G / 1.0) * theta.sin();
        worst = worst.max((qacc - expected).abs() / G);
    }
    println!("simple pendulum eq. 14: max |θ̈ − (−g/l sin θ)| / (g/l) = {worst:.2e}");
    assert!(worst <= ALGO_REL, "{worst}");
}

/// Notes §1.4, the two equations of motion of the pendulum on a movable support, at random states:
/// (m+M) Ẍ = m l (θ̇² sin θ − θ̈ cos θ)  and  θ̈ + (Ẍ/l) cos θ + (g/l) sin θ = 0.
#[test]
fn pendulum_on_movable_support_equations_of_motion() {
    let (cart, m, l) = (2.0, 0.5, 0.8);
    let model = textbook("pendulum_on_cart.urdf");
    assert_eq!(model.joints[0].name, "slider");
    let mut data = Data::new(&model);
    let mut seed = 1;
    let (mut worst_x, mut worst_theta) = (0.0f64, 0.0f64);
    for _ in 0..200 {
        let q = [3.0 * uniform(&mut seed), PI * uniform(&mut seed)];
        let v = [2.0 * uniform(&mut seed), 4.0 * uniform(&mut seed)];
        let acc = aba(&model, &mut data, &q, &v, &[0.0, 0.0]).unwrap().clone();
        let (th, thd, xdd, thdd) = (q[1], v[1], acc[0], acc[1]);
        let r_x = (m + cart) * xdd - m * l * (thd * thd * th.sin() - thdd * th.cos());
        let scale_x = (m + cart) * xdd.abs() + m * l * (thd * thd + thdd.abs());
        let r_theta = thdd + xdd / l * th.cos() + G / l * th.sin();
        let scale_theta = thdd.abs() + xdd.abs() / l + G / l;
        worst_x = worst_x.max(r_x.abs() / scale_x);
        worst_theta = worst_theta.max(r_theta.abs() / scale_theta);
    }
    println!("pendulum on support: X equation residual {worst_x:.2e}, θ equation residual {worst_theta:.2e}");
    assert!(worst_x <= ALGO_REL && worst_theta <= ALGO_REL);
}

/// Notes §1.4: X is cyclic, so ∂L/∂Ẋ = (m+M)Ẋ + m l θ̇ cos θ is conserved. Along an RK4 trajectory
/// it drifts only by the integrator's error, which shrinks ~16× per halving of dt.
#[test]
fn pendulum_on_movable_support_conserves_x_momentum() {
    let (cart, m, l) = (2.0, 0.5, 0.8);
    let model = textbook("pendulum_on_cart.urdf");
    let p_x = |s: &State| (m + cart) * s.v[0] + m * l * s.v[1] * s.q[1].cos();
    let drift = |dt: f64| {
        let mut sim = Simulation::new(
            Arc::new(model.clone()),
            &SimOptions { integrator: Some(IntegratorKind::Rk4), timestep: Some(dt), ..Default::default() },
        );
        sim.set_state(&[0.0, 1.2], &[0.3, -0.5]).unwrap();
        let p0 = p_x(&State::of(&sim.data));
        let mut worst = 0.0f64;
        while sim.data.time < 5.0 - 1e-12 {
            sim.step().unwrap();
            worst = worst.max((p_x(&State::of(&sim.data)) - p0).abs());
        }
        worst
    };
    let (coarse, fine) = (drift(2e-3), drift(1e-3));
    let scale = (m + cart) * 0.3 + m * l * 4.0;
    println!(
        "∂L/∂Ẋ drift over 5 s (RK4): dt 2e-3 → {:.2e}, dt 1e-3 → {:.2e} (ratio {:.1})",
        coarse / scale,
        fine / scale,
        coarse / fine
    );
    assert!(fine / scale <= RK4_CONSERVATION_REL, "{}", fine / scale);
    let ratio = coarse / fine;
    assert!(ratio >= 16.0 / INTEGRATOR_ORDER_BAND, "drift ratio {ratio}");
}

/// Notes eq. 56: the mass matrix of the physical pendulum is I_y = I_CM,y + m l_CM², at any angle.
#[test]
fn physical_pendulum_parallel_axis_eq56() {
    let (m, l_cm, i_cm_y) = (2.0, 0.3, 2.0 * (0.1f64.powi(2) + 1.0) / 12.0);
    let model = textbook("physical_pendulum.urdf");
    let mut data = Data::new(&model);
    for theta in [-2.0, -0.3, 0.0, 0.7, 3.0] {
        let i_y = crba(&model, &mut data, &[theta]).unwrap()[(0, 0)];
        let expected = i_cm_y + m * l_cm * l_cm;
        assert!((i_y - expected).abs() <= ALGO_REL * expected, "{i_y} vs {expected}");
        // Eq. 57: the gravity torque is m g l_CM sin θ.
        let g = gravity_forces(&model, &mut data, &[theta]).unwrap()[0];
        let expected_g = m * G * l_cm * f64::sin(theta);
        assert!((g - expected_g).abs() <= ALGO_REL * m * G * l_cm, "{g} vs {expected_g}");
    }
}

/// Notes eq. 59: small-amplitude period T = 2π √(I_CM,y/(m g l_CM) + l_CM/g). Simulated over one
/// predicted period; the measured period comes from the phase left over at its end.
#[test]
fn physical_pendulum_small_amplitude_period_eq59() {
    let (m, l_cm, i_cm_y) = (2.0, 0.3, 2.0 * (0.1f64.powi(2) + 1.0) / 12.0);
    let period_59 = 2.0 * PI * (i_cm_y / (m * G * l_cm) + l_cm / G).sqrt();
    let model = textbook("physical_pendulum.urdf");
    let theta0 = 1e-5; // amplitude correction θ0²/16 ≈ 6e-12, below the tolerance
    let n = 4000;
    let s = run(&model, IntegratorKind::Rk4, &[theta0], &[0.0], period_59 / n as f64, n);
    let omega = 2.0 * PI / period_59;
    let phase = f64::atan2(-s.v[0] / omega, s.q[0]);
    let period_measured = period_59 * 2.0 * PI / (2.0 * PI + phase);
    let rel = (period_measured - period_59).abs() / period_59;
    println!("physical pendulum: eq. 59 period {period_59:.12} s, simulated {period_measured:.12} s, rel. error {rel:.2e}");
    assert!(rel <= PERIOD_SMALL_AMPLITUDE_REL, "{rel}");
}

/// Complete elliptic integral of the first kind K(k) by the arithmetic–geometric mean.
fn elliptic_k(k: f64) -> f64 {
    let (mut a, mut b) = (1.0f64, (1.0 - k * k).sqrt());
    while (a - b).abs() > 1e-16 * a {
        let (an, bn) = ((a + b) / 2.0, (a * b).sqrt());
        a = an;
        b = bn;
    }
    PI / (2.0 * a)
}

/// Period of a simulated pendulum released at rest from θ0: the time of the first turning point
/// after a full swing (θ̇ crossing from + to − near t = T), located by the root of the cubic Hermite
/// interpolant of θ̇ between the two steps that bracket it (θ̈ from ABA), so the location error is
/// O(dt⁴) — below the integrators' period error.
fn simulated_period(model: &Model, kind: IntegratorKind, theta0: f64, dt: f64, t_guess: f64) -> f64 {
    let mut data = Data::new(model);
    let mut sim = Simulation::new(
        Arc::new(model.clone()),
        &SimOptions { integrator: Some(kind), timestep: Some(dt), ..Default::default() },
    );
    sim.set_state(&[theta0], &[0.0]).unwrap();
    let mut prev = (sim.data.time, sim.data.qpos[0], sim.data.qvel[0]);
    loop {
        sim.step().unwrap();
        let now = (sim.data.time, sim.data.qpos[0], sim.data.qvel[0]);
        if now.0 > 0.75 * t_guess && prev.2 > 0.0 && now.2 <= 0.0 {
            let mut acc =
                |theta: f64, omega: f64| aba(model, &mut data, &[theta], &[omega], &[0.0]).unwrap()[0];
            let (a0, a1) = (acc(prev.1, prev.2), acc(now.1, now.2));
            // Hermite basis on s ∈ [0, 1]; bisection on the bracketed sign change.
            let h = now.0 - prev.0;
            let omega_at = |s: f64| {
                let (s2, s3) = (s * s, s * s * s);
                (2.0 * s3 - 3.0 * s2 + 1.0) * prev.2
                    + (s3 - 2.0 * s2 + s) * h * a0
                    + (-2.0 * s3 + 3.0 * s2) * now.2
                    + (s3 - s2) * h * a1
            };
            let (mut lo, mut hi) = (0.0, 1.0);
            for _ in 0..200 {
                let mid = 0.5 * (lo + hi);
                if omega_at(mid) > 0.0 {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            return prev.0 + 0.5 * (lo + hi) * h;
        }
        prev = now;
    }
}

/// Large-amplitude pendulum (θ0 = 2 rad): the exact period is T = 4 √(l/g) K(sin(θ0/2)) with K the
/// complete elliptic integral of the first kind. The simulated period converges to it as dt
/// halves at RK4's order 4, and at order 2 for semi-implicit Euler: its *periods* are those of the
/// Störmer–Verlet method it is conjugate to (Hairer, Lubich & Wanner, *Geometric Numerical
/// Integration*, §VI.8: "effective order 2"), although its trajectories are first order.
#[test]
fn large_amplitude_pendulum_period_converges_at_integrator_order() {
    let model = textbook("simple_pendulum.urdf");
    let theta0: f64 = 2.0;
    let period = 4.0 * (1.0 / G).sqrt() * elliptic_k((theta0 / 2.0).sin());
    for (kind, order, n0) in [(IntegratorKind::Euler, 2, 500usize), (IntegratorKind::Rk4, 4, 200)] {
        let errors: Vec<f64> = (0..4)
            .map(|k| {
                let dt = period / (n0 << k) as f64;
                (simulated_period(&model, kind, theta0, dt, period) - period).abs() / period
            })
            .collect();
        let expected_ratio = 2f64.powi(order);
        println!("{kind:?}: exact period {period:.12} s; relative period errors at dt = T/{n0}, /2, /4, /8: {errors:?}");
        for w in errors.windows(2) {
            let ratio = w[0] / w[1];
            println!("  ratio {ratio:.3} (expected {expected_ratio})");
            assert!(
                ratio >= expected_ratio / INTEGRATOR_ORDER_BAND
                    && ratio <= expected_ratio * INTEGRATOR_ORDER_BAND,
                "{kind:?}: error ratio {ratio} not ~{expected_ratio}"
            );
        }
    }
}

/// Double pendulum: M(q) and g(q) against the closed-form Lagrangian of two point masses
/// (docs/physics.md §1.3: T and V in generalized coordinates), q = [θ1, φ2] with φ2 relative.
#[test]
fn double_pendulum_mass_matrix_and_gravity_closed_form() {
    let (m1, m2, l1, l2) = (1.0, 0.5, 1.0, 0.7);
    let model = textbook("double_pendulum.urdf");
    let mut data = Data::new(&model);
    let mut seed = 7;
    for _ in 0..50 {
        let q = [PI * uniform(&mut seed), PI * uniform(&mut seed)];
        let c2 = q[1].cos();
        let m = crba(&model, &mut data, &q).unwrap().clone();
        let expected = [
            [m1 * l1 * l1 + m2 * (l1 * l1 + l2 * l2 + 2.0 * l1 * l2 * c2), m2 * (l2 * l2 + l1 * l2 * c2)],
            [m2 * (l2 * l2 + l1 * l2 * c2), m2 * l2 * l2],
        ];
        for r in 0..2 {
            for c in 0..2 {
                assert!((m[(r, c)] - expected[r][c]).abs() <= ALGO_REL * expected[0][0], "M[{r},{c}]");
            }
        }
        let g = gravity_forces(&model, &mut data, &q).unwrap().clone();
        let s12 = (q[0] + q[1]).sin();
        let expected_g =
            [m1 * G * l1 * q[0].sin() + m2 * G * (l1 * q[0].sin() + l2 * s12), m2 * G * l2 * s12];
        for k in 0..2 {
            assert!((g[k] - expected_g[k]).abs() <= ALGO_REL * (m1 + m2) * G * l1, "g[{k}]");
        }
    }
}

/// Trajectory error at a generic time (t = 1 s, θ0 = 2 rad) against a reference from RK4 at
/// dt = 1e-5: it shrinks at each integrator's order as dt halves — first order for semi-implicit
/// Euler, fourth for RK4.
#[test]
fn pendulum_trajectory_error_converges_at_integrator_order() {
    let model = textbook("simple_pendulum.urdf");
    let reference = run(&model, IntegratorKind::Rk4, &[2.0], &[0.0], 1e-5, 100_000);
    for (kind, order, n0) in [(IntegratorKind::Euler, 1, 1000usize), (IntegratorKind::Rk4, 4, 50)] {
        let errors: Vec<f64> = (0..3)
            .map(|k| {
                let n = n0 << k;
                let s = run(&model, kind, &[2.0], &[0.0], 1.0 / n as f64, n);
                ((s.q[0] - reference.q[0]).powi(2) + ((s.v[0] - reference.v[0]) / G.sqrt()).powi(2)).sqrt()
            })
            .collect();
        let expected_ratio = 2f64.powi(order);
        println!("{kind:?}: state error at t = 1 s for dt = 1/{n0}, /2, /4: {errors:?}");
        for w in errors.windows(2) {
            let ratio = w[0] / w[1];
            assert!(
                ratio >= expected_ratio / INTEGRATOR_ORDER_BAND
                    && ratio <= expected_ratio * INTEGRATOR_ORDER_BAND,
                "{kind:?}: error ratio {ratio} not ~{expected_ratio}"
            );
        }
    }
}
