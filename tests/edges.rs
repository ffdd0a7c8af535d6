//! Solver and integrator edges (issue 27, item 6) and the stepping API's refusals (item 7).
//!
//! - `<option iterations="0">` as MuJoCo 4.0 (validation/mujoco_edges_golden.py): no solver
//!   iteration, so qacc is the warm start (the previous step's acceleration) or `qacc_smooth`,
//!   whichever costs less; a box dropped on a floor falls through it free of constraint forces.
//! - The soft solver counts the solves that stop at the iteration limit (go1, 1 iteration).
//! - The adaptive integrator on resting contact at tolerances below the solver's accuracy stops
//!   with an error that says why and what to use, instead of running for minutes.
//! - After a failed step, stepping is refused until the state is reset or set; step sizes of 0,
//!   negative or NaN are refused; every public kernel refuses slices too short and too long.

mod common;

use common::ALGO_REL;
use lagrange::integrate::IntegratorKind;
use lagrange::model::options::Solver;
use lagrange::prelude::*;
use serde_json::Value;

const BOX_ITER0: &str = "tests/data/mjcf/edges/box_iterations0.xml";

fn golden(name: &str) -> Value {
    serde_json::from_str(&std::fs::read_to_string(format!("tests/data/mujoco/{name}")).unwrap()).unwrap()
}

fn values(v: &Value) -> Vec<f64> {
    v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
}

/// max |a − b| / max(1, |b|) over the golden sample's qpos, qvel, qacc and first four efc_force.
fn sample_err(sample: &Value, data: &Data) -> f64 {
    let nefc = sample["nefc"].as_u64().unwrap() as usize;
    assert_eq!(data.nefc, nefc, "rows at {sample}");
    let force: Vec<f64> = (0..4).map(|i| if nefc > 0 { data.efc_force[i] } else { 0.0 }).collect();
    let ours = [data.qpos.as_slice(), data.qvel.as_slice(), data.qacc.as_slice(), &force];
    let mut worst = 0.0f64;
    for (key, ours) in ["qpos", "qvel", "qacc", "efc_force"].iter().zip(ours) {
        for (a, b) in ours.iter().zip(values(&sample[key])) {
            worst = worst.max((a - b).abs() / b.abs().max(1.0));
        }
    }
    worst
}

#[test]
fn iterations_zero_falls_free_as_mujoco() {
    let golden = golden("edges.json");
    let samples = golden["samples"].as_array().unwrap();
    let mut worst = 0.0f64;
    for (label, solver) in [("Newton", Solver::Newton), ("CG", Solver::Cg), ("PGS", Solver::Pgs)] {
        let mut model = Model::from_file(BOX_ITER0).unwrap();
        model.options.solver = solver;
        let mut data = Data::new(&model);
        let mut k = 0;
        for sample in samples.iter().filter(|s| s["solver"] == label) {
            let n = sample["step"].as_u64().unwrap();
            if n == 0 {
                // At rest 1 cm into the floor from a fresh data (zero warm start).
                let mut data = Data::new(&model);
                data.qpos[2] = 0.09;
                forward(&model, &mut data);
                worst = worst.max(sample_err(sample, &data));
                continue;
            }
            while k < n {
                step(&model, &mut data).unwrap();
                k += 1;
            }
            worst = worst.max(sample_err(sample, &data));
        }
        // Through the floor at the free-fall acceleration.
        assert!(data.qpos[2] < -4.0 && (data.qacc[2] + 9.81).abs() < 1e-12, "{label}: z {}", data.qpos[2]);
    }
    println!("iterations=0: worst relative difference to MuJoCo 4.0 {worst:.1e}");
    assert!(worst <= ALGO_REL, "{worst:e}");
}

const GO1: &str = "models/mjcf/unitree_go1/scene.xml";

/// Unconverged soft solves of 200 steps of go1 standing from its home keyframe with `iterations`
/// and `solver`: (count, worst residual, steps with rows).
fn go1_unconverged(iterations: u32, solver: Solver) -> (u64, f64, u32) {
    let mut model = Model::from_file(GO1).unwrap();
    model.options.iterations = iterations;
    model.options.solver = solver;
    let mut data = Data::new(&model);
    reset_keyframe(&model, &mut data, "home").unwrap();
    let mut with_rows = 0;
    for _ in 0..200 {
        step(&model, &mut data).unwrap();
        with_rows += u32::from(data.nefc > 0);
    }
    (data.efc_unconverged, data.efc_unconverged_residual, with_rows)
}

#[test]
fn soft_solver_counts_unconverged_solves() {
    for solver in [Solver::Newton, Solver::Cg, Solver::Pgs] {
        let (n1, r1, rows) = go1_unconverged(1, solver);
        let (n100, r100, _) = go1_unconverged(100, solver);
        println!("go1 {solver:?}: 1 iteration {n1} unconverged of {rows} solves (worst {r1:.2e}); 100 iterations {n100} (worst {r100:.2e})");
        assert!(rows > 100, "go1 stands on the floor");
        assert!(n1 > 0 && r1 > model_tolerance(), "{solver:?}: a 1-iteration solver must count");
        assert!(n100 < n1, "{solver:?}");
    }
}

fn model_tolerance() -> f64 {
    Model::from_file(GO1).unwrap().options.tolerance
}

/// A 0.2 m box resting on a floor (soft contacts).
const RESTING_BOX: &str = r#"<mujoco><worldbody><geom type="plane" size="5 5 .1"/>
<body pos="0 0 0.1"><freejoint/><geom type="box" size=".1 .1 .1"/></body></worldbody></mujoco>"#;

fn adaptive_box(tolerances: [f64; 2]) -> Simulation {
    let model = std::sync::Arc::new(Model::from_str(RESTING_BOX).unwrap());
    let options = SimOptions {
        integrator: Some(IntegratorKind::Adaptive),
        tolerances: Some(tolerances),
        ..Default::default()
    };
    Simulation::new(model, &options)
}

#[test]
fn adaptive_on_resting_contact_stops_with_a_reason_at_tight_tolerances() {
    // Default tolerances: 0.1 s (50 steps of the model's 2 ms) within the work budget.
    let mut sim = adaptive_box([lagrange::integrate::DEFAULT_RTOL, lagrange::integrate::DEFAULT_ATOL]);
    let mut attempts = 0;
    for _ in 0..50 {
        let r = sim.step().unwrap();
        attempts += r.substeps + r.rejected;
    }
    println!("default tolerances: {attempts} attempts ({} evaluations) for 0.1 s", 7 * attempts);
    assert!((sim.data.time - 0.1).abs() < 1e-12 && (sim.data.qpos[2] - 0.1).abs() < 1e-3);
    // rtol 1e-12, atol 1e-14: below what the soft solve resolves. It used to take minutes for
    // 0.1 s; now it stops within the budget with an error that says why and what to use.
    let mut sim = adaptive_box([1e-12, 1e-14]);
    let mut err = None;
    for _ in 0..50 {
        if let Err(e) = sim.step() {
            err = Some(e);
            break;
        }
    }
    let err = err.expect("the adaptive integrator must stop at these tolerances");
    let text = err.to_string();
    println!("{text}");
    assert!(matches!(err, SimError::AdaptiveStalled { .. }), "{err:?}");
    assert!(text.contains("contact") && text.contains("fixed-step integrator"), "{text}");
    assert!(sim.data.qpos.iter().all(|x| x.is_finite()));
}

/// A pendulum (hinge, nq = nv = 1) and a free body (nq = 7, nv = 6) in one model.
const TWO_JOINTS: &str = r#"<mujoco><option timestep="0.001"/><worldbody>
<body><joint name="hinge" type="hinge" axis="0 1 0"/><geom type="capsule" fromto="0 0 0 0 0 -1" size="0.05"/></body>
<body pos="0 2 0"><freejoint name="free"/><geom type="box" size=".1 .2 .3"/></body>
</worldbody></mujoco>"#;

#[test]
fn stepping_after_a_divergence_is_refused_until_the_state_is_reset_or_set() {
    let model = Model::from_str(TWO_JOINTS).unwrap();
    let mut data = Data::new(&model);
    data.qvel[0] = 1e300;
    assert!(matches!(step(&model, &mut data), Err(SimError::Diverged { .. })));
    for _ in 0..2 {
        let err = step(&model, &mut data).unwrap_err();
        let text = err.to_string();
        assert!(matches!(err, SimError::Refused { step: 1, .. }), "{err:?}");
        assert!(text.contains("non-finite") && text.contains("reset") && !text.contains("inertia"), "{text}");
    }
    assert_eq!(data.failed_step().map(|f| f.step), Some(1));
    // Setting the state (a wrong one is rejected and changes nothing) lets it go on.
    assert!(data.set_state(&model, &[0.0; 7], &[0.0; 7]).is_err());
    assert!(data.set_state(&model, &[0.3, 0.0, 2.0, 0.0, 1.0, 0.0, 0.0, 0.0], &[f64::NAN; 7]).is_err());
    assert!(data.failed_step().is_some());
    data.set_state(&model, &[0.3, 0.0, 2.0, 0.0, 1.0, 0.0, 0.0, 0.0], &[0.0; 7]).unwrap();
    step(&model, &mut data).unwrap();
    // So does a reset.
    data.qvel[0] = f64::INFINITY;
    assert!(step(&model, &mut data).is_err());
    assert!(matches!(step(&model, &mut data), Err(SimError::Refused { .. })));
    reset(&model, &mut data).unwrap();
    step(&model, &mut data).unwrap();

    // The same through Simulation.
    let mut sim = Simulation::new(std::sync::Arc::new(model), &SimOptions::default());
    sim.data.qvel[0] = 1e300;
    assert!(matches!(sim.step(), Err(SimError::Diverged { .. })));
    assert!(matches!(sim.step(), Err(SimError::Refused { .. })));
    sim.set_state(&[0.3, 0.0, 2.0, 0.0, 1.0, 0.0, 0.0, 0.0], &[0.0; 7]).unwrap();
    sim.step().unwrap();
    assert!(sim.data.qpos.iter().all(|x| x.is_finite()));
}

#[test]
fn timestep_setters_refuse_zero_negative_and_nan() {
    let model = std::sync::Arc::new(Model::from_str(TWO_JOINTS).unwrap());
    let mut sim = Simulation::new(model.clone(), &SimOptions::default());
    for bad in [0.0, -0.001, f64::NAN, f64::INFINITY] {
        let err = sim.set_timestep(bad).unwrap_err();
        assert!(matches!(err, SimError::Input(InputError::Value { .. })), "{bad}: {err:?}");
        assert_eq!(sim.timestep, 0.001, "unchanged");
        // The public field is checked when stepping; time never runs backwards.
        sim.timestep = bad;
        let err = sim.step().unwrap_err();
        assert!(matches!(err, SimError::Input(InputError::Value { .. })), "{bad}: {err:?}");
        assert_eq!(sim.data.time, 0.0);
        // A refused call is not a failed step: a valid timestep steps at once.
        sim.set_timestep(0.002).unwrap();
        sim.step().unwrap();
        sim.set_state(&model.qpos0, &[0.0; 7]).unwrap();
        sim.data.time = 0.0;
        sim.timestep = 0.001;
        let options = SimOptions { timestep: Some(bad), ..Default::default() };
        let mut bad_sim = Simulation::new(model.clone(), &options);
        assert!(matches!(bad_sim.step(), Err(SimError::Input(InputError::Value { .. }))), "{bad}");
        let mut m = (*model).clone();
        m.options.timestep = bad;
        let mut data = Data::new(&m);
        assert!(matches!(step(&m, &mut data), Err(SimError::Input(InputError::Value { .. }))), "{bad}");
        assert_eq!(data.time, 0.0);
    }
}

/// Every public kernel refuses a slice one too short and one too long (nothing is read past nq
/// or nv silently).
#[test]
fn kernels_refuse_slices_too_short_and_too_long() {
    use lagrange::dynamics::{
        aba, bias_forces, crba, crba_upper, gravity_forces, kinetic_energy, rnea, solve_with_factor,
    };
    use lagrange::kinematics::{bias_accelerations, forward_kinematics, forward_velocities};
    use lagrange::model::{dexp_inv_configuration, difference_configuration, integrate_configuration};
    let model = Model::from_str(TWO_JOINTS).unwrap();
    let mut d = Data::new(&model);
    let (nq, nv) = (model.nq, model.nv);
    let q0 = model.qpos0.clone();
    let z = vec![0.0; nv];
    let is_len = |r: Result<(), InputError>, what: &str| {
        assert!(matches!(r, Err(InputError::Length { .. })), "{what}: {r:?}");
    };
    for delta in [-1i64, 1] {
        let q = vec![0.0; (nq as i64 + delta) as usize];
        let v = vec![0.0; (nv as i64 + delta) as usize];
        let mut qm = q.clone();
        let mut vm = v.clone();
        is_len(aba(&model, &mut d, &q, &z, &z).map(|_| ()), "aba q");
        is_len(aba(&model, &mut d, &q0, &v, &z).map(|_| ()), "aba v");
        is_len(aba(&model, &mut d, &q0, &z, &v).map(|_| ()), "aba tau");
        is_len(rnea(&model, &mut d, &q, &z, &z).map(|_| ()), "rnea q");
        is_len(rnea(&model, &mut d, &q0, &v, &z).map(|_| ()), "rnea v");
        is_len(rnea(&model, &mut d, &q0, &z, &v).map(|_| ()), "rnea qacc");
        is_len(bias_forces(&model, &mut d, &q, &z).map(|_| ()), "bias q");
        is_len(bias_forces(&model, &mut d, &q0, &v).map(|_| ()), "bias v");
        is_len(gravity_forces(&model, &mut d, &q).map(|_| ()), "gravity q");
        is_len(crba(&model, &mut d, &q).map(|_| ()), "crba q");
        is_len(crba_upper(&model, &mut d, &q).map(|_| ()), "crba_upper q");
        is_len(kinetic_energy(&model, &mut d, &q, &z).map(|_| ()), "kinetic q");
        is_len(kinetic_energy(&model, &mut d, &q0, &v).map(|_| ()), "kinetic v");
        is_len(forward_kinematics(&model, &mut d, &q), "fk q");
        is_len(forward_velocities(&model, &mut d, &v), "fv v");
        is_len(bias_accelerations(&model, &mut d, &v), "bias_accelerations v");
        crba(&model, &mut d, &q0).unwrap();
        let factor = d.mass_factor.clone();
        is_len(solve_with_factor(&model, &factor, &mut vm), "solve_with_factor x");
        let mut x = nalgebra::DVector::from_vec(v.clone());
        is_len(lagrange::dynamics::solve_mass_matrix(&model, &d, &mut x), "solve_mass_matrix x");
        is_len(model.spring_energy(&q).map(|_| ()), "spring_energy q");
        is_len(integrate_configuration(&model, &mut qm, &z, 1.0), "integrate q");
        let mut q1 = q0.clone();
        is_len(integrate_configuration(&model, &mut q1, &v, 1.0), "integrate v");
        let mut out = z.clone();
        is_len(dexp_inv_configuration(&model, &v, &z, &mut out), "dexp_inv theta");
        is_len(dexp_inv_configuration(&model, &z, &v, &mut out), "dexp_inv v");
        is_len(dexp_inv_configuration(&model, &z, &z, &mut vm), "dexp_inv out");
        is_len(difference_configuration(&model, &q, &q0, &mut out), "difference q0");
        is_len(difference_configuration(&model, &q0, &q, &mut out), "difference q1");
        is_len(difference_configuration(&model, &q0, &q0, &mut vm), "difference v");
        is_len(d.set_state(&model, &q, &z), "Data::set_state q");
        is_len(d.set_state(&model, &q0, &v), "Data::set_state v");
        let mut jac = nalgebra::DMatrix::zeros(6, (nv as i64 + delta) as usize);
        is_len(
            lagrange::kinematics::frame_jacobian(
                &model,
                &d,
                1,
                lagrange::kinematics::ReferenceFrame::World,
                &mut jac,
            ),
            "frame_jacobian",
        );
        is_len(frames::jacobian(&model, &mut d, "body1", &mut jac), "frames::jacobian");
        let mut sim = Simulation::new(std::sync::Arc::new(model.clone()), &SimOptions::default());
        assert!(sim.set_state(&q, &z).is_err() && sim.set_state(&q0, &v).is_err());
    }
}

/// The closed-loop four-bar of models/textbook/four_bar.xml in exact mode at the model's 2 ms
/// step, revolving (v0 = 5.16 rad/s on the crank: the parallelogram passes its flat, singular
/// configurations twice per turn) for 100 s: the first-order steppers' energy stays within 1 % of
/// the energy scale max(|E₀|, max T) (as `simulate` reports it), and the state finite.
#[test]
fn first_order_steppers_hold_a_revolving_four_bar_for_100_s() {
    use lagrange::constraint::ConstraintMode;
    let model = std::sync::Arc::new(Model::from_file("models/textbook/four_bar.xml").unwrap());
    for integrator in [IntegratorKind::Euler, IntegratorKind::Implicit, IntegratorKind::ImplicitFast] {
        let options = SimOptions {
            integrator: Some(integrator),
            constraints: Some(ConstraintMode::Exact),
            ..Default::default()
        };
        let mut sim = Simulation::new(model.clone(), &options);
        assert_eq!(sim.timestep, 0.002);
        sim.set_state(&[0.0; 3], &[5.16, -5.16, 5.16]).unwrap();
        let (t0, v0) = sim.energies();
        let e0 = t0 + v0;
        let (mut max_dev, mut max_t) = (0.0f64, t0);
        for k in 1..=50_000 {
            sim.step().unwrap();
            if k % 50 == 0 {
                let (t, v) = sim.energies();
                max_dev = max_dev.max((t + v - e0).abs());
                max_t = max_t.max(t);
            }
        }
        let scale = e0.abs().max(max_t);
        println!(
            "{integrator:?}: E0 {e0:.4} J, max |E - E0| {max_dev:.3e} J = {:.2e} of {scale:.2} J",
            max_dev / scale
        );
        assert!(max_dev <= 0.01 * scale, "{integrator:?}");
    }
}
