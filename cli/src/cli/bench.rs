//! `lagrange bench MODEL [--json]`: median wall time of loading the model (parse + compile) and of
//! the dynamics kernels and the staged `forward` on it, for side-by-side comparisons with MuJoCo and Pinocchio run by
//! `validation/bench_load.py` in the same session (docs/architecture.md, "Truth": speed is quoted as ratios).

use super::CliError;
use lagrange::constraint::ConstraintMode;
use lagrange::dynamics::{aba, crba, rnea};
use lagrange::forward::forward;
use lagrange::integrate::IntegratorKind;
use lagrange::io::{load, LoadOptions};
use lagrange::kinematics::forward_kinematics;
use lagrange::model::Data;
use lagrange::sim::{SimOptions, Simulation};
use lagrange::Model;
use serde_json::json;
use std::path::Path;
use std::time::{Duration, Instant};

/// Median of `f`'s run time in microseconds over batches of `inner` calls, repeated until
/// `budget` has passed (at least 5 batches).
fn median_us(budget: Duration, inner: u32, mut f: impl FnMut()) -> f64 {
    let start = Instant::now();
    let mut samples = Vec::new();
    while samples.len() < 5 || (start.elapsed() < budget && samples.len() < 10_000) {
        let t = Instant::now();
        for _ in 0..inner {
            f();
        }
        samples.push(t.elapsed().as_secs_f64() * 1e6 / f64::from(inner));
    }
    samples.sort_by(f64::total_cmp);
    samples[samples.len() / 2]
}

/// A deterministic, non-trivial state: qpos0 moved by a fixed tangent, a fixed velocity.
fn test_state(model: &Model) -> Result<[Vec<f64>; 3], CliError> {
    let dq: Vec<f64> = (0..model.nv).map(|i| 0.3 * ((i as f64) * 1.3).sin()).collect();
    let mut q = model.qpos0.clone();
    lagrange::model::integrate_configuration(model, &mut q, &dq, 1.0)?;
    let v: Vec<f64> = (0..model.nv).map(|i| ((i as f64) * 0.7).cos()).collect();
    let tau: Vec<f64> = (0..model.nv).map(|i| ((i as f64) * 0.4).sin()).collect();
    Ok([q, v, tau])
}

/// Runs `bench`: load time, then FK, RNEA, CRBA and ABA medians.
pub fn run(path: &Path, options: &LoadOptions, json: bool) -> Result<(), CliError> {
    let model = load(path, options)?;
    let load_us = median_us(Duration::from_secs(2), 1, || {
        let m = load(path, options).expect("the model loaded once already");
        std::hint::black_box(m);
    });
    let mut data = Data::new(&model);
    let [q, v, tau] = test_state(&model)?;
    let budget = Duration::from_millis(500);
    let fk_us = median_us(budget, 100, || {
        std::hint::black_box(forward_kinematics(&model, &mut data, &q)).ok();
    });
    let rnea_us = median_us(budget, 100, || {
        std::hint::black_box(rnea(&model, &mut data, &q, &v, &tau)).ok();
    });
    let crba_us = median_us(budget, 100, || {
        std::hint::black_box(crba(&model, &mut data, &q)).ok();
    });
    let aba_us = median_us(budget, 100, || {
        std::hint::black_box(aba(&model, &mut data, &q, &v, &tau)).ok();
    });
    // The whole staged pipeline at the same state (with the model's constraint rows, if any).
    let mut model = model;
    model.set_constraint_mode(ConstraintMode::Exact);
    let plan = &model.plan;
    let mut data = Data::new(&model);
    data.qfrc_applied.copy_from_slice(&tau);
    data.qpos.copy_from_slice(&q);
    data.qvel.copy_from_slice(&v);
    let forward_us = median_us(budget, 100, || {
        forward(&model, &mut data);
        std::hint::black_box(&data.qacc);
    });
    let nefc = data.nefc;
    // The collision pass alone (no candidate pairs: no work), at the same state.
    let collide_us = median_us(budget, 100, || {
        std::hint::black_box(plan.constraints.collide(&model, &mut data, &q)).ok();
    });
    // Whole steps (RK4, exact mode, drift projection included) from the first keyframe, or qpos0,
    // at rest: a scene on its floor settles into contact.
    let start = model.keyframes.first().and_then(|k| k.qpos.clone()).unwrap_or_else(|| model.qpos0.clone());
    let options = SimOptions {
        integrator: Some(IntegratorKind::Rk4),
        constraints: Some(ConstraintMode::Exact),
        ..Default::default()
    };
    let mut sim = Simulation::new(std::sync::Arc::new(model.clone()), &options);
    let (mut step_us, mut contacts) = (f64::NAN, 0);
    if sim.set_state(&start, &vec![0.0; model.nv]).is_ok() {
        let steps = 500;
        let t0 = std::time::Instant::now();
        let mut ok = true;
        for _ in 0..steps {
            ok &= sim.step().is_ok();
        }
        if ok {
            step_us = t0.elapsed().as_secs_f64() * 1e6 / steps as f64;
            contacts = (0..sim.data.nefc).filter(|&i| sim.data.efc_is_normal(i)).count();
        }
    }
    let (soft_step_us, soft_rows) = soft_step(&model);
    let pairs = model.collision_pairs.len();
    if json {
        let out = json!({"model": path.display().to_string(), "nq": model.nq, "nv": model.nv,
            "load_us": load_us, "fk_us": fk_us, "rnea_us": rnea_us, "crba_us": crba_us, "aba_us": aba_us,
            "forward_us": forward_us, "nefc": nefc, "collide_us": collide_us, "collision_pairs": pairs,
            "step_us": step_us, "step_contacts": contacts, "step_dt": sim.timestep,
            "soft_step_us": soft_step_us, "soft_step_rows": soft_rows,
            "soft_steps": SOFT_STEPS, "soft_integrator": model.options.integrator.mjcf_name()});
        super::stdout::print(&format!("{out}\n"))?;
    } else {
        use std::fmt::Write as _;
        let mut text = String::new();
        let _ = writeln!(text, "{} (nq {}, nv {}), median µs per call:", path.display(), model.nq, model.nv);
        let _ = writeln!(text, "  load (parse + compile) {load_us:>12.1}");
        let _ = writeln!(text, "  forward kinematics     {fk_us:>12.3}");
        let _ = writeln!(text, "  RNEA                   {rnea_us:>12.3}");
        let _ = writeln!(text, "  CRBA                   {crba_us:>12.3}");
        let _ = writeln!(text, "  ABA                    {aba_us:>12.3}");
        let _ = writeln!(text, "  forward ({nefc:>2} rows)      {forward_us:>12.3}");
        let _ = writeln!(text, "  collision ({pairs} pairs)  {collide_us:>12.3}");
        let _ = writeln!(
            text,
            "  RK4 step, exact, at rest from {} (dt {}, {contacts} contacts at the end) {step_us:>9.3} (mean of 500)",
            model.keyframes.first().map_or("qpos0", |k| k.name.as_str()),
            sim.timestep
        );
        let _ = writeln!(
            text,
            "  step, soft mode, the model's <option> ({}, dt {}), from {} with its ctrl, {soft_rows} rows at the end {soft_step_us:>9.3} (mean of {SOFT_STEPS})",
            model.options.integrator.mjcf_name(),
            model.options.timestep,
            model.keyframes.first().map_or("qpos0", |k| k.name.as_str()),
        );
        super::stdout::print(&text)?;
    }
    Ok(())
}

/// Steps of the soft-mode timing (`validation/bench_soft_step.py` times as many `mj_step`).
const SOFT_STEPS: u32 = 1000;

/// Mean µs of one step in soft mode with the model's own `<option>` (integrator, timestep,
/// solver), from the first keyframe with its ctrl (as MuJoCo's `mj_resetDataKeyframe`), and the
/// rows at the end; NaN if the simulation stops with an error.
fn soft_step(model: &Model) -> (f64, usize) {
    let (mut q, mut v, mut ctrl) =
        (model.qpos0.clone(), vec![0.0; model.nv], vec![0.0; model.actuators.len()]);
    let mut act = vec![0.0; model.na()];
    if let Some(k) = model.keyframes.first() {
        k.apply(&mut q, &mut v, &mut ctrl, &mut act);
    }
    let options = SimOptions { constraints: Some(ConstraintMode::Soft), ..Default::default() };
    let mut sim = Simulation::new(std::sync::Arc::new(model.clone()), &options);
    if sim.set_state(&q, &v).is_err() {
        return (f64::NAN, 0);
    }
    sim.ctrl_mut().copy_from_slice(&ctrl);
    if sim.set_act(&act).is_err() {
        return (f64::NAN, 0);
    }
    let t0 = Instant::now();
    for _ in 0..SOFT_STEPS {
        if sim.step().is_err() {
            return (f64::NAN, 0);
        }
    }
    (t0.elapsed().as_secs_f64() * 1e6 / f64::from(SOFT_STEPS), sim.data.nefc)
}
