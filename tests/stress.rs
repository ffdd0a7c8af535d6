//! The stress suite: the rigid bodies of `docs/physics.md` §3.3–3.7 and the integrators' stability: long runs, chaos and
//! stiffness on the scenes of `models/textbook/`. Each test names its integrator, step and
//! tolerance; each prints what it measured (run with `--nocapture` for the tables).

mod common;

use lagrange::dynamics::spatial_momentum;
use lagrange::integrate::IntegratorKind;
use lagrange::io::{load, LoadOptions};
use lagrange::kinematics::{forward_kinematics, forward_velocities};
use lagrange::sim::{SimOptions, Simulation};
use lagrange::spatial::Vec3;
use lagrange::Model;
use std::f64::consts::PI;
use std::path::Path;
use std::sync::Arc;

fn textbook(name: &str) -> Model {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("models/textbook").join(name);
    load(&path, &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

fn sim(model: &Model, kind: IntegratorKind, dt: f64, q0: &[f64], v0: &[f64]) -> Simulation {
    let options = SimOptions { integrator: Some(kind), timestep: Some(dt), ..Default::default() };
    let mut sim = Simulation::new(Arc::new(model.clone()), &options);
    sim.set_state(q0, v0).unwrap();
    sim
}

/// World angular momentum about the world origin (the pivot or the body origin at 0).
fn angular_momentum(s: &mut Simulation) -> Vec3 {
    let (q, v) = (s.data.qpos.clone(), s.data.qvel.clone());
    forward_kinematics(&s.model, &mut s.data, q.as_slice()).unwrap();
    forward_velocities(&s.model, &mut s.data, v.as_slice()).unwrap();
    let h = spatial_momentum(&s.model, &s.data);
    // About the centre of mass for a free body: L_com = L_o − c × p (c = body origin + offset).
    h.ang
}

/// The body's z axis in the world, R e_z, from a w-first unit quaternion.
fn body_z_axis(quat: &[f64]) -> Vec3 {
    let (w, x, y, z) = (quat[0], quat[1], quat[2], quat[3]);
    Vec3::new(2.0 * (x * z + w * y), 2.0 * (y * z - w * x), 1.0 - 2.0 * (x * x + y * y))
}

fn total_energy(s: &mut Simulation) -> f64 {
    let (t, v) = s.energies();
    t + v
}

/// Complete elliptic integral of the first kind K(k) by the arithmetic–geometric mean:
/// K = π / (2 AGM(1, √(1 − k²))).
fn elliptic_k(k2: f64) -> f64 {
    let (mut a, mut b) = (1.0f64, (1.0 - k2).sqrt());
    while (a - b).abs() > 1e-15 * a {
        (a, b) = (0.5 * (a + b), (a * b).sqrt());
    }
    PI / (2.0 * a)
}

/// Notes eq. 90–92: a free symmetric top (I = 0.004, I_s = 0.006 kg m², no gravity) spinning at
/// ω₃ = 10 rad/s with a transverse ω₀ = 1 rad/s: in the body frame ω₃ stays constant and
/// (ω₁, ω₂) turns at Ω = ω₃ (I_s − I)/I = 5 rad/s (eq. 91). RK4, dt = 1 ms, 10 s: the measured
/// rate (unwrapped phase of (ω₁, ω₂) over time) within 1e-8 relative of Ω, ω₃ within 1e-10.
/// The variational integrator at the same step: within 1e-4 (its second-order phase error).
#[test]
fn free_symmetric_top_precesses_at_eq_91_rate() {
    let model = textbook("free_symmetric_top.xml");
    let (i1, is, w3) = (0.004, 0.006, 10.0);
    let omega = w3 * (is - i1) / i1;
    let q0 = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0];
    let v0 = [0.0, 0.0, 0.0, 1.0, 0.0, w3];
    for (kind, tol) in [(IntegratorKind::Rk4, 1e-8), (IntegratorKind::Variational, 1e-4)] {
        let mut s = sim(&model, kind, 1e-3, &q0, &v0);
        let (mut phase, mut last, mut w3_err) = (0.0, 0.0f64, 0.0f64);
        for _ in 0..10_000 {
            s.step().unwrap();
            let angle = s.data.qvel[4].atan2(s.data.qvel[3]);
            let mut d = angle - last;
            d -= 2.0 * PI * (d / (2.0 * PI)).round();
            phase += d;
            last = angle;
            w3_err = w3_err.max((s.data.qvel[5] - w3).abs() / w3);
        }
        let rate = phase / s.data.time;
        let err = (rate - omega).abs() / omega;
        println!("free symmetric top, {} dt 1 ms: precession {rate:.10} rad/s vs eq. 91 Ω = {omega}, rel {err:.2e}; ω₃ rel {w3_err:.1e}", kind.name());
        assert!(err <= tol && w3_err <= 1e-10, "{}: Ω rel {err}, ω₃ {w3_err}", kind.name());
    }
}

/// Notes eq. 87–89: the free asymmetric body (I = 0.01, 0.02, 0.03 kg m², no gravity) tumbling
/// for 20 s at dt = 1 ms: |L| (eq. 88) and E (eq. 89) conserved — RK4 to 1e-9 relative;
/// variational: the angular momentum *vector* to 1e-10 relative (a discrete momentum map,
/// round-off only) and E within 1e-5 relative, bounded (second half no worse than 1.5× the first).
#[test]
fn euler_equations_asymmetric_body_conserves_l_and_e() {
    let model = textbook("free_asymmetric_body.xml");
    let half = 0.2f64;
    let q0 = [0.0, 0.0, 0.0, half.cos(), 0.0, half.sin(), 0.0];
    let v0 = [0.0, 0.0, 0.0, 3.0, 1.0, 2.0];
    for (kind, tol_l, tol_e) in
        [(IntegratorKind::Rk4, 1e-9, 1e-9), (IntegratorKind::Variational, 1e-10, 1e-5)]
    {
        let mut s = sim(&model, kind, 1e-3, &q0, &v0);
        let l0 = angular_momentum(&mut s);
        let e0 = total_energy(&mut s);
        let (mut l_err, mut l_norm_err, mut e_first, mut e_second) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        for i in 0..20_000 {
            s.step().unwrap();
            let l = angular_momentum(&mut s);
            l_err = l_err.max((l - l0).amax() / l0.norm());
            l_norm_err = l_norm_err.max((l.norm() - l0.norm()).abs() / l0.norm());
            let de = ((total_energy(&mut s) - e0) / e0).abs();
            if i < 10_000 {
                e_first = e_first.max(de);
            } else {
                e_second = e_second.max(de);
            }
        }
        println!("asymmetric body, {} dt 1 ms, 20 s: |L| rel {l_norm_err:.1e}, L vector rel {l_err:.1e}, E rel {e_first:.1e} (0–10 s), {e_second:.1e} (10–20 s)", kind.name());
        assert!(l_norm_err <= tol_l && l_err <= tol_l.max(1e-10), "{}: L {l_err}", kind.name());
        assert!(e_first.max(e_second) <= tol_e, "{}: E {e_first} {e_second}", kind.name());
        if kind == IntegratorKind::Variational {
            assert!(e_second <= 1.5 * e_first, "energy error grows: {e_first} → {e_second}");
        }
    }
}

/// Notes §3.4 (Fig. 8b): rotation near the intermediate axis of the asymmetric body
/// (ω = (0.05, 5, 0.05) rad/s) flips: ω₂ changes sign periodically. The period against the
/// closed form of the Euler equations' elliptic-function solution (Landau & Lifshitz, Mechanics
/// §37, for I₁ < I₂ < I₃ and L² > 2E I₂): T = 4 K(k)/λ with
/// λ² = (I₃ − I₂)(L² − 2E I₁)/(I₁ I₂ I₃), k² = (I₂ − I₁)(2E I₃ − L²)/((I₃ − I₂)(L² − 2E I₁)).
/// RK4 and variational, dt = 1 ms, 30 s: the mean time between upward zero crossings of ω₂ within
/// 1% of T.
#[test]
fn intermediate_axis_flip_period_matches_elliptic_integral() {
    let model = textbook("free_asymmetric_body.xml");
    let (i1, i2, i3) = (0.01f64, 0.02, 0.03);
    let w = [0.05, 5.0, 0.05];
    let two_e = i1 * w[0] * w[0] + i2 * w[1] * w[1] + i3 * w[2] * w[2];
    let l2 = (i1 * w[0]).powi(2) + (i2 * w[1]).powi(2) + (i3 * w[2]).powi(2);
    assert!(l2 > two_e * i2, "the closed form below is for L² > 2E I₂");
    let lambda = ((i3 - i2) * (l2 - two_e * i1) / (i1 * i2 * i3)).sqrt();
    let k2 = (i2 - i1) * (two_e * i3 - l2) / ((i3 - i2) * (l2 - two_e * i1));
    let period = 4.0 * elliptic_k(k2) / lambda;
    let q0 = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0];
    let v0 = [0.0, 0.0, 0.0, w[0], w[1], w[2]];
    for kind in [IntegratorKind::Rk4, IntegratorKind::Variational] {
        let mut s = sim(&model, kind, 1e-3, &q0, &v0);
        let mut crossings = Vec::new();
        let (mut t_prev, mut w_prev) = (0.0, w[1]);
        while s.data.time < 30.0 {
            s.step().unwrap();
            let (t, w2) = (s.data.time, s.data.qvel[4]);
            if w_prev < 0.0 && w2 >= 0.0 {
                crossings.push(t_prev + (t - t_prev) * (-w_prev) / (w2 - w_prev));
            }
            (t_prev, w_prev) = (t, w2);
        }
        assert!(crossings.len() >= 2, "{}: ω₂ did not flip twice: {crossings:?}", kind.name());
        let measured = (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f64;
        let err = (measured - period).abs() / period;
        println!("intermediate axis, {} dt 1 ms: flip period {measured:.6} s vs 4K(k)/λ = {period:.6} s (k² = {k2:.6}), rel {err:.2e}, {} flips", kind.name(), crossings.len());
        assert!(err <= 0.01, "{}: period {measured} vs {period}", kind.name());
    }
}

/// The heavy symmetric top (`heavy_top.xml`: m = 1 kg, l = 0.1 m, I = 0.004 + m l² = 0.014 about
/// the pivot, I_s = 0.008 kg m²) on its ball joint.
struct Top;

impl Top {
    const MGL: f64 = 9.81 * 0.1;
    const I: f64 = 0.014;
    const IS: f64 = 0.008;

    /// The state tilted by θ about x (Euler angles φ = ψ = 0) with θ̇ = 0, precession rate φ̇ and
    /// spin S = φ̇ cos θ + ψ̇ (docs/physics.md (94): body ω = (θ̇, φ̇ sin θ, S)).
    fn state(theta: f64, phi_dot: f64, spin: f64) -> ([f64; 4], [f64; 3]) {
        let h = 0.5 * theta;
        ([h.cos(), h.sin(), 0.0, 0.0], [0.0, phi_dot * theta.sin(), spin])
    }

    /// The critical spin of the sleeping top, docs/physics.md (109): S = 2 √(m g l I) / I_s.
    fn sleeping_threshold() -> f64 {
        2.0 * (Self::MGL * Self::I).sqrt() / Self::IS
    }
}

/// Notes eq. 104–106: with the variational integrator (dt = 1 ms, 100 s = 1e5 steps) the discrete
/// momentum maps of the top's two symmetries — L_z (rotation about the vertical) and L_z′
/// (rotation about the figure axis; L_z′ = I_s ω₃) — are conserved to 1e-10 relative (round-off),
/// and the energy error stays bounded (below 1e-4 relative, the last 50 s no worse than 1.5× the
/// first 50 s).
#[test]
fn heavy_top_variational_conserves_discrete_momenta_over_100_s() {
    let model = textbook("heavy_top.xml");
    let (q0, v0) = Top::state(0.3, 0.0, 20.0);
    let v0 = [1.0, v0[1] + 0.5, v0[2]];
    let mut s = sim(&model, IntegratorKind::Variational, 1e-3, &q0, &v0);
    let lz_and_lzp = |s: &mut Simulation| {
        let l = angular_momentum(s);
        (l.z, l.dot(&body_z_axis(s.data.qpos.as_slice())))
    };
    let (lz0, lzp0) = lz_and_lzp(&mut s);
    let e0 = total_energy(&mut s);
    let scale = lz0.abs().max(lzp0.abs());
    let (mut e_lz, mut e_lzp, mut e_first, mut e_second) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let n = 100_000;
    for i in 0..n {
        s.step().unwrap();
        if i % 10 == 9 {
            let (lz, lzp) = lz_and_lzp(&mut s);
            e_lz = e_lz.max((lz - lz0).abs() / scale);
            e_lzp = e_lzp.max((lzp - lzp0).abs() / scale);
            let de = (total_energy(&mut s) - e0).abs() / e0.abs();
            if i < n / 2 {
                e_first = e_first.max(de);
            } else {
                e_second = e_second.max(de);
            }
        }
    }
    println!("heavy top, variational dt 1 ms, 100 s: L_z rel {e_lz:.2e}, L_z' rel {e_lzp:.2e}, energy rel {e_first:.2e} (0–50 s), {e_second:.2e} (50–100 s)");
    assert!(e_lz <= 1e-10 && e_lzp <= 1e-10, "L_z {e_lz}, L_z' {e_lzp}");
    assert!(e_first.max(e_second) <= 1e-4 && e_second <= 1.5 * e_first, "energy {e_first} → {e_second}");
}

/// Notes eq. 107: steady precession. At θ = 0.5 rad and spin S = 60 rad/s the slow root
/// φ̇ = [I_s S − √(I_s² S² − 4 I cos θ m g l)] / (2 I cos θ) of eq. 107, set as the initial
/// precession with θ̇ = 0, keeps θ constant (within 1e-4 rad over 10 s) and the figure axis
/// precesses at φ̇ (within 1e-4 relative). Variational, dt = 1 ms.
#[test]
fn heavy_top_steady_precession_matches_eq_107() {
    let model = textbook("heavy_top.xml");
    let (theta, spin) = (0.5f64, 60.0);
    let c = theta.cos();
    let disc = (Top::IS * spin).powi(2) - 4.0 * Top::I * c * Top::MGL;
    assert!(disc > 0.0, "eq. 108 must hold");
    let phi_dot = (Top::IS * spin - disc.sqrt()) / (2.0 * Top::I * c);
    let (q0, v0) = Top::state(theta, phi_dot, spin);
    let mut s = sim(&model, IntegratorKind::Variational, 1e-3, &q0, &v0);
    let azimuth = |a: &Vec3| a.x.atan2(-a.y);
    let (mut phase, mut last, mut theta_err) = (0.0, 0.0f64, 0.0f64);
    while s.data.time < 10.0 - 1e-9 {
        s.step().unwrap();
        let a = body_z_axis(s.data.qpos.as_slice());
        theta_err = theta_err.max((a.z.acos() - theta).abs());
        let phi = azimuth(&a);
        let mut d = phi - last;
        d -= 2.0 * PI * (d / (2.0 * PI)).round();
        phase += d;
        last = phi;
    }
    let rate = phase / s.data.time;
    let err = (rate - phi_dot).abs() / phi_dot;
    println!("steady precession, variational dt 1 ms, 10 s: φ̇ {rate:.8} vs eq. 107 {phi_dot:.8} rad/s (rel {err:.1e}), max |θ − θ₀| {theta_err:.1e} rad");
    assert!(err <= 1e-4 && theta_err <= 1e-4, "φ̇ rel {err}, θ {theta_err}");
}

/// Notes eq. 109: the sleeping top. Released 0.01 rad from upright with spin S: at 1.2× the
/// threshold 2√(m g l I)/I_s (= 29.3 rad/s) it stays upright (tilt below 0.05 rad over 10 s); at
/// 0.8× it falls (tilt beyond 1 rad). Variational, dt = 1 ms.
#[test]
fn sleeping_top_threshold_eq_109() {
    let model = textbook("heavy_top.xml");
    let critical = Top::sleeping_threshold();
    for (factor, stays) in [(1.2, true), (0.8, false)] {
        let (q0, v0) = Top::state(0.01, 0.0, factor * critical);
        let mut s = sim(&model, IntegratorKind::Variational, 1e-3, &q0, &v0);
        let mut max_tilt: f64 = 0.0;
        for _ in 0..10_000 {
            s.step().unwrap();
            max_tilt = max_tilt.max(body_z_axis(s.data.qpos.as_slice()).z.clamp(-1.0, 1.0).acos());
        }
        println!("sleeping top, variational dt 1 ms: S = {factor} × {critical:.3} rad/s → max tilt {max_tilt:.4} rad over 10 s");
        if stays {
            assert!(max_tilt < 0.05, "above the threshold the top should stay upright: {max_tilt}");
        } else {
            assert!(max_tilt > 1.0, "below the threshold the top should fall: {max_tilt}");
        }
    }
}

/// The chaotic double pendulum (`double_pendulum.xml`, released at rest from q = (2.0, 2.5) rad):
/// the time at which each integrator's trajectory leaves a reference (RK4 at dt = 1/32 ms) by
/// more than 0.1 rad (max over the two angles, checked every 4 ms, up to 20 s), for steps of 4, 2,
/// 1 and 0.5 ms. The table is printed; for every integrator the divergence time does not decrease
/// as the step is halved, and grows from the coarsest to the finest step.
#[test]
fn chaotic_double_pendulum_divergence_time_grows_as_step_shrinks() {
    let model = textbook("double_pendulum.xml");
    let (q0, v0) = ([2.0, 2.5], [0.0, 0.0]);
    let horizon = 20.0f64;
    let sample = 4e-3;
    let n_samples = (horizon / sample).round() as usize;
    let h_ref = sample / 128.0;
    let mut reference = sim(&model, IntegratorKind::Rk4, h_ref, &q0, &v0);
    let mut ref_q = Vec::with_capacity(n_samples);
    for _ in 0..n_samples {
        for _ in 0..128 {
            reference.step().unwrap();
        }
        ref_q.push([reference.data.qpos[0], reference.data.qpos[1]]);
    }
    let dts = [4e-3, 2e-3, 1e-3, 5e-4];
    println!("divergence time (s) of the double pendulum from q = (2.0, 2.5): |Δq| > 0.1 rad against RK4 at {h_ref:.2e} s");
    println!("{:<12} {}", "integrator", dts.map(|h| format!("{:>9}", format!("{}ms", h * 1e3))).join(""));
    for kind in
        [IntegratorKind::Euler, IntegratorKind::Implicit, IntegratorKind::Variational, IntegratorKind::Rk4]
    {
        let times: Vec<f64> = dts
            .iter()
            .map(|&h| {
                let per = (sample / h).round() as usize;
                let mut s = sim(&model, kind, h, &q0, &v0);
                for (i, r) in ref_q.iter().enumerate() {
                    for _ in 0..per {
                        if s.step().is_err() {
                            return i as f64 * sample;
                        }
                    }
                    let d = (s.data.qpos[0] - r[0]).abs().max((s.data.qpos[1] - r[1]).abs());
                    if d > 0.1 {
                        return (i + 1) as f64 * sample;
                    }
                }
                horizon
            })
            .collect();
        println!("{:<12} {}", kind.name(), times.iter().map(|t| format!("{t:>9.3}")).collect::<String>());
        for w in times.windows(2) {
            assert!(
                w[1] >= w[0],
                "{}: divergence time fell from {} to {} s when the step was halved: {times:?}",
                kind.name(),
                w[0],
                w[1]
            );
        }
        assert!(times[3] > times[0], "{}: no gain from 4 ms to 0.5 ms: {times:?}", kind.name());
    }
}

/// A simple pendulum (`simple_pendulum.urdf`, l = 1 m, released at 2 rad) for 1e6 steps of
/// 0.01 s (1e4 s, about 4000 periods). The energy error relative to m g l, max over the first and
/// last 10% of the run and at the end, is printed for each integrator. Variational: bounded
/// (below 1e-3) with no secular trend (last 10% no worse than 1.2× the first 10%). RK4: its
/// error grows linearly in time (measured 9.8e-7 → 9.7e-6; asserted: the last 10% at least 5×
/// the first). Semi-implicit Euler is symplectic too on
/// this separable system: its error is bounded, shown in the table, not asserted.
#[test]
fn pendulum_million_steps_variational_energy_bounded() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("models/textbook/simple_pendulum.urdf");
    let model = load(&path, &LoadOptions::default()).unwrap();
    let n = 1_000_000usize;
    let scale = 9.81;
    println!("pendulum, dt 0.01 s, 1e6 steps: energy error / (m g l)");
    println!("{:<12} {:>12} {:>12} {:>12}", "integrator", "first 10%", "last 10%", "at end");
    for kind in [IntegratorKind::Variational, IntegratorKind::Rk4, IntegratorKind::Euler] {
        let mut s = sim(&model, kind, 0.01, &[2.0], &[0.0]);
        let e0 = total_energy(&mut s);
        let (mut first, mut last) = (0.0f64, 0.0f64);
        for i in 0..n {
            s.step().unwrap();
            if i < n / 10 || i >= n - n / 10 {
                let de = (total_energy(&mut s) - e0).abs() / scale;
                if i < n / 10 {
                    first = first.max(de);
                } else {
                    last = last.max(de);
                }
            }
        }
        let end = (total_energy(&mut s) - e0).abs() / scale;
        println!("{:<12} {first:>12.3e} {last:>12.3e} {end:>12.3e}", kind.name());
        match kind {
            IntegratorKind::Variational => {
                assert!(last <= 1e-3 && last <= 1.2 * first, "variational: {first} → {last}")
            }
            IntegratorKind::Rk4 => assert!(last >= 5.0 * first, "rk4 should drift: {first} → {last}"),
            _ => {}
        }
    }
}

/// A stiff spring–damper joint (`stiff_spring_damper.xml`: k = 100 N m/rad, b = 10 N m s/rad,
/// I = 0.01 kg m²) released 1 rad from rest at h = 0.01 s (h b / I = 10): semi-implicit Euler
/// explicit in the damping (`<flag eulerdamp="disable">`; MuJoCo's Euler is implicit in joint
/// damping by default, and stable here) diverges and the error names the joint, the step, the
/// time and the step size; implicit (the file's own integrator) decays to rest (|q|, |v| below
/// 1e-6 after 10 s).
#[test]
fn stiff_spring_damper_implicit_stable_where_euler_diverges() {
    let model = textbook("stiff_spring_damper.xml");
    let mut explicit = model.clone();
    explicit.options.flags.eulerdamp = false;
    let mut euler = sim(&explicit, IntegratorKind::Euler, 0.01, &[1.0], &[0.0]);
    let err = (0..1000).find_map(|_| euler.step().err()).expect("semi-implicit Euler should diverge");
    let msg = err.to_string();
    println!("euler: {msg}");
    for needle in ["diverged at t = ", "(step ", "joint 'stiff'", "reduce SimOptions::timestep (now 0.01 s)"]
    {
        assert!(msg.contains(needle), "missing '{needle}' in: {msg}");
    }
    let mut implicit = Simulation::new(Arc::new(model), &SimOptions::default());
    assert_eq!(implicit.integrator(), "implicit");
    implicit.set_state(&[1.0], &[0.0]).unwrap();
    for _ in 0..1000 {
        implicit.step().unwrap_or_else(|e| panic!("implicit: {e}"));
    }
    let (q, v) = (implicit.data.qpos[0], implicit.data.qvel[0]);
    println!("implicit dt 0.01 s after 10 s: q = {q:.2e}, v = {v:.2e}");
    assert!(q.abs() < 1e-6 && v.abs() < 1e-6);
}
