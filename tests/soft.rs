//! The soft (MuJoCo-compatible) constraint mode against MuJoCo 4.0 (golden data of
//! `validation/mujoco_soft_golden.py`: `mj_forward` at keyframes, snapshots of MuJoCo's own
//! simulation and perturbations of them; the rolling cylinder of docs/physics.md §2.5 stepped by MuJoCo's
//! Euler), the impedance function of MuJoCo's documentation ("Computation → Soft constraints"),
//! and the three solvers against each other. The live, row-by-row comparison is
//! `validation/crossval_soft.py` (in `.ci/run`).

mod common;

use common::{rel_err, SOFT_CG_REL, SOFT_REL};
use lagrange::constraint::soft::impedance::impedance;
use lagrange::constraint::ConstraintMode;
use lagrange::forward::Plan;
use lagrange::io::{load, LoadOptions};
use lagrange::model::options::Solver;
use lagrange::sim::{SimOptions, Simulation};
use lagrange::{Data, Model};
use serde_json::Value;
use std::path::Path;
use std::sync::Arc;

/// The model with the golden data's tight solver options.
fn tight(path: &str) -> Model {
    common::tight_model(path)
}

fn golden(name: &str) -> Value {
    let text = std::fs::read_to_string(format!("tests/data/mujoco/soft/{name}.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

fn floats(v: &Value) -> Vec<f64> {
    v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
}

/// max |a − b| / max(|a|, |b|, floor).
fn rel_floor(a: &[f64], b: &[f64], floor: f64) -> f64 {
    let scale = a.iter().chain(b).fold(floor, |m, x| m.max(x.abs()));
    a.iter().zip(b).fold(0.0_f64, |m, (x, y)| m.max((x - y).abs())) / scale
}

/// Runs the golden states of `name` through `forward` in soft mode with `solver`; returns the
/// worst (qacc, qfrc_constraint) errors and checks the row counts.
fn against_golden(name: &str, solver: Solver) -> (f64, f64) {
    let g = golden(name);
    let mut model = tight(g["model"].as_str().unwrap());
    model.options.solver = solver;
    if solver == Solver::Pgs {
        // Gauss–Seidel converges linearly, slowly on go1's elliptic cones with impratio 100
        // (measured: 1e-6 after about 20000 sweeps, 1e-7 after 40000).
        model.options.iterations = 40_000;
    }
    let model = common::with_mode(model, ConstraintMode::Soft);
    let mut data = Data::new(&model);
    let (mut e_acc, mut e_frc) = (0.0_f64, 0.0_f64);
    for (i, s) in g["states"].as_array().unwrap().iter().enumerate() {
        let (q, v) = (floats(&s["q"]), floats(&s["v"]));
        common::forward_at(&model, &mut data, &q, &v);
        assert_eq!(data.nefc as u64, s["nefc"].as_u64().unwrap(), "{name} state {i}: rows");
        // qacc relative to the larger of itself and qacc_smooth: a body held at rest by its
        // contacts has qacc ≈ 0 as the difference of gravity-sized terms.
        let smooth = floats(&s["qacc_smooth"]).iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        e_acc = e_acc.max(rel_floor(data.qacc.as_slice(), &floats(&s["qacc"]), smooth));
        e_frc = e_frc.max(rel_floor(data.qfrc_constraint.as_slice(), &floats(&s["qfrc_constraint"]), 1e-6));
    }
    (e_acc, e_frc)
}

#[test]
fn newton_matches_mujoco_forward_on_contact_limit_and_equality_scenes() {
    for name in ["go1", "humanoid", "incline_box", "weld_bodies_torquescale", "tendon_limit"] {
        let (acc, frc) = against_golden(name, Solver::Newton);
        println!("{name}: qacc {acc:.1e}, qfrc_constraint {frc:.1e} (tolerance {SOFT_REL:e})");
        assert!(acc <= SOFT_REL && frc <= SOFT_REL, "{name}: qacc {acc:e}, qfrc_constraint {frc:e}");
    }
}

/// CG and PGS (given the iterations) reach the optimum Newton and MuJoCo reach.
#[test]
fn cg_and_pgs_reach_the_same_optimum() {
    for name in ["go1", "humanoid", "incline_box", "tendon_limit"] {
        for solver in [Solver::Cg, Solver::Pgs] {
            let (acc, frc) = against_golden(name, solver);
            let tol = if solver == Solver::Cg { SOFT_CG_REL } else { SOFT_REL };
            println!("{name} {solver:?}: qacc {acc:.1e}, qfrc_constraint {frc:.1e} (tolerance {tol:e})");
            assert!(acc <= tol && frc <= tol, "{name} {solver:?}: qacc {acc:e}, qfrc_constraint {frc:e}");
        }
    }
}

#[test]
fn rolling_cylinder_matches_mujocos_soft_error() {
    // Notes §2.5: a solid cylinder rolls down a 30° incline with ẍ = ⅔ g sin θ. The soft contact
    // lets it sink and creep by a little: measured here and in MuJoCo (500 Euler steps of 1 ms).
    let g = golden("incline_cylinder_roll");
    let model = Arc::new(tight("models/textbook/incline_cylinder.xml"));
    let options = SimOptions {
        integrator: Some(lagrange::integrate::IntegratorKind::Euler),
        constraints: Some(ConstraintMode::Soft),
        ..SimOptions::default()
    };
    let mut sim = Simulation::new(model, &options);
    let x0: Vec<f64> = sim.data.qpos.as_slice()[..3].to_vec();
    let steps = g["steps"].as_u64().unwrap();
    let mut report = None;
    for _ in 0..steps {
        report = Some(sim.step().unwrap());
    }
    // The step reports the soft solve: Newton's iterations and its final scaled improvement.
    let report = report.unwrap();
    assert!(report.solver_iterations > 0 && report.solver_improvement.is_finite(), "{report:?}");
    let theta = 30f64.to_radians();
    let downhill = [theta.cos(), 0.0, -theta.sin()];
    let travelled: f64 = (0..3).map(|k| (sim.data.qpos[k] - x0[k]) * downhill[k]).sum();
    let t = steps as f64 * g["timestep"].as_f64().unwrap();
    let ours = 2.0 * travelled / (t * t);
    let mujoco = g["acceleration"].as_f64().unwrap();
    let closed = 2.0 / 3.0 * 9.81 * theta.sin();
    println!(
        "rolling cylinder: lagrange {ours:.10} m/s², MuJoCo {mujoco:.10}, closed form {closed:.10}; soft error {:.3e} (MuJoCo {:.3e})",
        ours / closed - 1.0,
        mujoco / closed - 1.0
    );
    assert!(rel_err(ours, mujoco) <= SOFT_REL, "lagrange {ours} against MuJoCo {mujoco}");
    assert!((ours / closed - 1.0).abs() < 1e-2, "the soft error stays that of a soft contact");
}

#[test]
fn impedance_follows_mujocos_sigmoid() {
    // solimp = (dmin, dmax, width, midpoint, power) = MuJoCo's default (0.9, 0.95, 0.001, 0.5, 2):
    // d(0) = dmin, d(x ≥ width) = dmax; y = x/width: a·y² (a = 1/mid) below the midpoint, 1 − b(1 − y)²
    // above it (b = 1/(1 − mid)).
    let s = [0.9, 0.95, 0.001, 0.5, 2.0];
    let cases =
        [(0.0, 0.9), (0.001, 0.95), (0.5, 0.95), (-0.002, 0.95), (0.00025, 0.90625), (0.00075, 0.94375)];
    for (x, want) in cases {
        let (d, _) = impedance(&s, x);
        assert!((d - want).abs() < 1e-15, "d({x}) = {d}, want {want}");
    }
    // The derivative: central differences inside each half, with the sign of x.
    for x in [0.0002, 0.0007, -0.0003] {
        let (_, dd) = impedance(&s, x);
        let fd = (impedance(&s, x + 1e-9).0 - impedance(&s, x - 1e-9).0) / 2e-9;
        assert!((dd - fd).abs() < 1e-6 * dd.abs().max(1.0), "d'({x}) = {dd}, differences {fd}");
    }
    // Equal dmin and dmax: flat.
    assert_eq!(impedance(&[0.7, 0.7, 0.01, 0.5, 2.0], 0.003), (0.7, 0.0));
}

#[test]
fn mjcf_defaults_to_soft_and_urdf_to_exact() {
    let mjcf = load(Path::new("models/textbook/incline_box.xml"), &LoadOptions::default()).unwrap();
    let urdf = load(Path::new("models/ur5/ur5.urdf"), &LoadOptions::default()).unwrap();
    let (p, q) = (Plan::new(&mjcf, None), Plan::new(&urdf, None));
    assert_eq!((p.mode(), p.mode_reason.as_str()), (ConstraintMode::Soft, "soft is the default for MJCF"));
    assert_eq!((q.mode(), q.mode_reason.as_str()), (ConstraintMode::Exact, "exact is the default for URDF"));
    let r = Plan::new(&mjcf, Some(ConstraintMode::Exact));
    assert_eq!((r.mode(), r.mode_reason.as_str()), (ConstraintMode::Exact, "exact requested"));
}

/// The standing robot in soft mode: go1 from keyframe `home`, holding the keyframe's
/// position-servo controls, 5 s with the scene's own options (Euler, 2 ms, Newton). MuJoCo 4.0.0
/// (`mj_resetDataKeyframe`, 2500 × `mj_step`) ends with the base at 0.2648645591 m.
#[test]
fn go1_stands_on_its_servos_as_in_mujoco() {
    const MUJOCO_HEIGHT: f64 = 0.2648645591;
    let model =
        Arc::new(load(Path::new("models/mjcf/unitree_go1/scene.xml"), &LoadOptions::default()).unwrap());
    let key = &model.keyframes[model.keyframe_id("home").unwrap()];
    let (mut q, mut v, mut ctrl, mut act) =
        (model.qpos0.clone(), vec![0.0; model.nv], vec![0.0; model.actuators.len()], vec![0.0; model.na()]);
    key.apply(&mut q, &mut v, &mut ctrl, &mut act);
    let mut sim = Simulation::new(model.clone(), &SimOptions::default());
    assert_eq!(sim.model.plan.mode(), ConstraintMode::Soft, "MJCF defaults to soft");
    sim.set_state(&q, &v).unwrap();
    sim.ctrl_mut().copy_from_slice(&ctrl);
    for _ in 0..2500 {
        sim.step().unwrap();
    }
    let z = sim.data.qpos[2];
    println!(
        "go1 base after 5 s: {z:.10} m, MuJoCo {MUJOCO_HEIGHT} m, difference {:.2e} m",
        z - MUJOCO_HEIGHT
    );
    assert!((z - MUJOCO_HEIGHT).abs() < 0.01, "within 1 cm of MuJoCo's; got {z}");
    assert!(sim.data.qvel.amax() < 1e-2, "standing still: |v| = {}", sim.data.qvel.amax());
}

/// Fluid forces (`<option density viscosity wind>`) run in the passive stage: the plan lists the
/// medium (tests/fluid.rs compares the forces with MuJoCo's).
#[test]
fn fluid_options_are_listed_as_simulated() {
    let path = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("lagrange-fluid-{}.xml", std::process::id()));
    std::fs::write(
        &path,
        r#"<mujoco><option viscosity="0.1" wind="1 0 0"/><worldbody><body><freejoint/><geom size="0.1"/></body></worldbody></mujoco>"#,
    )
    .unwrap();
    let model = load(&path, &LoadOptions::default()).unwrap();
    let _ = std::fs::remove_file(&path);
    let plan = Plan::new(&model, None);
    let fluid = plan.stages.iter().find(|s| s.name == "fluid forces").expect("a fluid stage");
    assert_eq!(fluid.status, lagrange::forward::Status::Runs);
    assert!(
        fluid.reason.contains("viscosity=\"0.1\"") && fluid.reason.contains("wind=\"1 0 0\""),
        "{}",
        fluid.reason
    );
}

/// The variational integrator holds constraints exactly: on an MJCF model (soft by default) it
/// runs the exact mode and says why.
#[test]
fn variational_integrator_uses_the_exact_mode() {
    let model =
        Arc::new(load(Path::new("models/textbook/incline_box.xml"), &LoadOptions::default()).unwrap());
    let options = SimOptions {
        integrator: Some(lagrange::integrate::IntegratorKind::Variational),
        ..Default::default()
    };
    let sim = Simulation::new(model, &options);
    assert_eq!(sim.model.plan.mode(), ConstraintMode::Exact);
    assert!(
        sim.notes.iter().any(|n| n.contains("variational integrator holds constraints exactly")),
        "{:?}",
        sim.notes
    );
}

/// A fixed-tendon limit that is the model's only constraint is simulated in soft mode (the plan
/// once took such a model for unconstrained and dropped the limit), and listed as not simulated
/// in exact mode.
#[test]
fn a_tendon_limit_alone_constrains_the_model() {
    let model =
        load(Path::new("tests/data/mjcf/constraints/tendon_limit.xml"), &LoadOptions::default()).unwrap();
    let plan = Plan::new(&model, None);
    assert!(plan.has_constraints(), "soft mode has the tendon's limit rows");
    // Released horizontal, the chain falls (qa grows) until the tendon L = qa + 0.5 qb + 0.3 qc
    // reaches its upper bound 0.25; the soft limit holds it there within a small penetration.
    let highest = |model: &Model| {
        let mut sim = Simulation::new(Arc::new(model.clone()), &SimOptions::default());
        let mut highest = f64::NEG_INFINITY;
        for _ in 0..2000 {
            sim.step().unwrap();
            let q = &sim.data.qpos;
            highest = highest.max(q[0] + 0.5 * q[1] + 0.3 * q[2]);
        }
        highest
    };
    let mut free = model.clone();
    free.options.flags.limit = false;
    free.rebuild_plan();
    let (held, unheld) = (highest(&model), highest(&free));
    println!("highest tendon length {held:.4} with the limit, {unheld:.4} without (range −0.25..0.25)");
    assert!(unheld > 0.5, "without the limit the chain swings far past it: {unheld}");
    assert!(held < 0.25 + 0.02 && held > 0.2, "the limit is reached and holds: {held}");
    let exact = Plan::new(&model, Some(ConstraintMode::Exact));
    assert!(!exact.has_constraints());
    let listed = exact.stages.iter().find(|s| s.name == "joint limits").unwrap();
    assert!(
        listed
            .reason
            .contains("1 tendon length limits and friction losses kept, not simulated in exact mode"),
        "{}",
        listed.reason
    );
}

/// A step size given to the simulation is the model's timestep for the soft constraints too, as
/// MuJoCo's `opt.timestep`: `refsafe` raises a limit's time constant (solref 0.02 s) to 2 · 0.02 s
/// at a 0.02 s step, so the run with `SimOptions::timestep` = 0.02 (or `timestep` set after `new`)
/// is the run of the model whose `<option timestep>` is 0.02, bit for bit. (It once kept the
/// file's 0.005 s for `refsafe`, and the humanoid's work-precision rows left MuJoCo's at that
/// step: 0.147 against 0.129.)
#[test]
fn a_step_size_override_is_the_timestep_of_the_soft_constraints() {
    let model = load(Path::new("models/mjcf/humanoid/humanoid.xml"), &LoadOptions::default()).unwrap();
    assert!(model.options.timestep < 0.01 && model.options.flags.refsafe);
    let run = |model: Model, timestep: Option<f64>, set_after: Option<f64>| {
        let mut sim = Simulation::new(Arc::new(model), &SimOptions { timestep, ..Default::default() });
        if let Some(h) = set_after {
            sim.timestep = h;
        }
        for (k, v) in sim.data.qvel.iter_mut().enumerate().skip(6) {
            *v = if k % 2 == 0 { 1.0 } else { -1.0 };
        }
        for _ in 0..25 {
            sim.step().unwrap();
        }
        assert_eq!(sim.model.options.timestep, 0.02);
        sim.data.qpos.clone()
    };
    let mut at_h = model.clone();
    at_h.options.timestep = 0.02;
    let q_file = run(at_h.clone(), None, None);
    assert_eq!(run(model.clone(), Some(0.02), None), q_file, "SimOptions::timestep");
    assert_eq!(run(model, None, Some(0.02)), q_file, "timestep set after new");
    // And refsafe matters in this scene: without it the limits are twice as stiff.
    at_h.options.flags.refsafe = false;
    let diff = (run(at_h, None, None) - &q_file).amax();
    println!("refsafe off at 0.02 s moves q by {diff:.3e} after 0.5 s");
    assert!(diff > 1e-6, "the scene exercises refsafe: {diff:e}");
}
