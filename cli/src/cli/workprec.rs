//! `lagrange workprec`: work-precision of the integrators on one model. Every
//! integrator runs the model from the same initial state for the same duration at several step
//! sizes (fixed-step methods) or tolerances (the adaptive method); each run is compared with a
//! reference solution — the adaptive Dormand–Prince 5(4) method at rtol = atol = 1e-13 — by
//!
//! - `error`: the final-time error, the max-norm over q on the manifold (hinge and slide
//!   coordinates as differences, the rotation of a ball or free joint as the angle of
//!   q_ref⁻¹ q, a free joint's position as differences) together with v − v_ref;
//! - `error_l2`: the root mean square over the sample times (every coarsest step, t > 0) of the
//!   Euclidean norm of (q ⊖ q_ref, v − v_ref);
//! - `energy_error`: the largest |E(t) − E_ref(t)| over the sample times, relative to
//!   max(|E_ref(0)|, max T_ref) (for a conservative model: the relative energy drift |E − E0|);
//!
//! and the CPU time of its stepping loop alone (the thread's CPU time, minimum of `--repeats`
//! runs; the measured run that records the samples is not timed). Output: a table, the JSON of
//! docs/cli.md, a log-log plot ([`super::workprec_plot`]); `--dump-reference` writes the reference
//! trajectory and the run's settings for `validation/workprec_mujoco.py`.

use super::interrupt;
use super::output_file::OutputFile;
use super::stdout;
use super::workprec_plot;
use super::CliError;
use lagrange::constraint::ConstraintMode;
use lagrange::integrate::IntegratorKind;
use lagrange::io::{load, LoadOptions};
use lagrange::model::{difference_configuration, JointKind};
use lagrange::sim::{SimOptions, Simulation};
use lagrange::Model;
use nalgebra::DVector;
use serde::{Deserialize, Serialize};
use serde_json::json;
use std::fmt::Write as _;
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Tolerances of the reference solution (adaptive Dormand–Prince 5(4)).
pub const REFERENCE_RTOL: f64 = 1e-13;
pub const REFERENCE_ATOL: f64 = 1e-13;
/// The looser run whose distance to the reference estimates the reference's own error.
const CHECK_RTOL: f64 = 1e-12;
/// When the adaptive reference fails (contact events, stiffness), RK4 at the finest step divided
/// by this is the reference instead.
const FALLBACK_REFINEMENT: usize = 16;
/// A run may take at most this many times the internal steps (accepted and rejected) of the
/// finest fixed-step run (and at least `MIN_BUDGET`) before it is given up.
const BUDGET_FACTOR: u64 = 10;
const MIN_BUDGET: u64 = 10_000;
/// Default duration (s), rounded to a whole number of the coarsest step.
const DEFAULT_DURATION: f64 = 2.0;
/// Default step sizes as multiples of the model's `<option timestep>`.
const DEFAULT_DT_FACTORS: [f64; 6] = [4.0, 2.0, 1.0, 0.5, 0.25, 0.125];
const DEFAULT_RTOLS: [f64; 4] = [1e-4, 1e-6, 1e-8, 1e-10];
/// Integrators `--integrators` knows, in the default order.
const KNOWN: [(&str, IntegratorKind); 6] = [
    ("euler", IntegratorKind::Euler),
    ("rk4", IntegratorKind::Rk4),
    ("implicitfast", IntegratorKind::ImplicitFast),
    ("implicit", IntegratorKind::Implicit),
    ("variational", IntegratorKind::Variational),
    ("adaptive", IntegratorKind::Adaptive),
];

/// What `workprec` was asked for (the command line, parsed by the binary).
pub struct Request {
    pub model: Option<PathBuf>,
    pub from_json: Option<PathBuf>,
    pub integrators: Option<String>,
    pub dts: Option<String>,
    pub rtols: Option<String>,
    pub duration: Option<f64>,
    pub repeats: u32,
    pub json: bool,
    pub plot: Option<PathBuf>,
    pub keyframe: Option<String>,
    pub q0: Option<String>,
    pub v0: Option<String>,
    pub dump_reference: Option<PathBuf>,
    pub extra_rows: Vec<PathBuf>,
    pub constraints: Option<ConstraintMode>,
}

/// One row of the JSON: one integrator at one step size or tolerance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Row {
    pub integrator: String,
    /// Step size (s); None for the adaptive method.
    pub dt: Option<f64>,
    /// Relative tolerance; None for fixed-step methods.
    pub rtol: Option<f64>,
    /// Steps taken (accepted internal steps for the adaptive method).
    pub steps: u64,
    pub error: f64,
    pub error_l2: f64,
    pub energy_error: f64,
    pub cpu_s: f64,
}

/// The reference solution's method and tolerance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ReferenceSpec {
    pub integrator: String,
    /// None for the RK4 fallback reference.
    pub rtol: Option<f64>,
}

/// The `workprec --json` object (docs/cli.md, "workprec"): exactly these keys.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Report {
    pub model: String,
    pub duration: f64,
    pub reference: ReferenceSpec,
    pub rows: Vec<Row>,
}

/// The settings of a measurement: model, initial state, sample grid.
#[derive(Clone)]
struct Setup {
    model: Arc<Model>,
    model_label: String,
    mode: Option<ConstraintMode>,
    q0: Vec<f64>,
    v0: Vec<f64>,
    ctrl: Vec<f64>,
    /// Initial actuator activations (na; the keyframe's `act`, else zero).
    act: Vec<f64>,
    /// How the initial state was chosen, for the output.
    start: String,
    /// Spacing of the sample times (the coarsest step) and their number after t = 0.
    sample_dt: f64,
    samples: usize,
    /// Most internal steps (accepted and rejected) a run may take.
    budget: u64,
}

impl Setup {
    fn duration(&self) -> f64 {
        self.sample_dt * self.samples as f64
    }
}

/// One run to measure: a stepper, the interval passed to `Simulation::step`, and how many of
/// them make one sample interval.
#[derive(Clone, Copy)]
struct RunSpec {
    kind: IntegratorKind,
    step: f64,
    per_sample: usize,
    tolerances: Option<[f64; 2]>,
}

/// States and energies at the sample times t_k = k·sample_dt, k = 0..=samples.
struct Samples {
    q: Vec<DVector<f64>>,
    v: Vec<DVector<f64>>,
    energy: Vec<f64>,
    kinetic: Vec<f64>,
    /// Steps taken (accepted internal steps of the adaptive method) and rejected attempts.
    steps: u64,
    rejected: u64,
}

/// The thread's CPU time in seconds (wall-clock time where no CPU clock is available).
fn cpu_time() -> f64 {
    #[cfg(unix)]
    {
        let mut ts = libc::timespec { tv_sec: 0, tv_nsec: 0 };
        // SAFETY: clock_gettime writes one timespec through a valid pointer.
        let rc = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
        if rc == 0 {
            return ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9;
        }
    }
    use std::sync::OnceLock;
    static START: OnceLock<std::time::Instant> = OnceLock::new();
    START.get_or_init(std::time::Instant::now).elapsed().as_secs_f64()
}

fn usage(msg: String) -> CliError {
    CliError::Usage(msg)
}

/// A comma-separated list of positive finite numbers for `--flag`.
fn parse_positive_list(flag: &str, s: &str, what: &str) -> Result<Vec<f64>, CliError> {
    let mut out = Vec::new();
    for item in s.split(',').map(str::trim) {
        let x: f64 = item.parse().map_err(|_| {
            usage(format!("--{flag}: '{item}' is not a number; give {what}, e.g. --{flag} 1e-2,5e-3"))
        })?;
        if !(x > 0.0 && x.is_finite()) {
            return Err(usage(format!("--{flag}: {item} is not a positive finite {what}")));
        }
        out.push(x);
    }
    if out.is_empty() {
        return Err(usage(format!("--{flag}: give at least one {what}")));
    }
    Ok(out)
}

/// `--integrators euler,rk4,…` → the steppers, in the order given.
fn parse_integrators(s: &str) -> Result<Vec<IntegratorKind>, CliError> {
    let names: Vec<&str> = KNOWN.iter().map(|(n, _)| *n).collect();
    let mut out = Vec::new();
    for item in s.split(',').map(str::trim) {
        let Some((_, kind)) = KNOWN.iter().find(|(n, _)| n.eq_ignore_ascii_case(item)) else {
            return Err(usage(format!(
                "--integrators: unknown integrator '{item}'; known: {}",
                names.join(", ")
            )));
        };
        if !out.contains(kind) {
            out.push(*kind);
        }
    }
    Ok(out)
}

fn parse_state(flag: &str, s: &str, n: usize) -> Result<Vec<f64>, CliError> {
    let v: Result<Vec<f64>, _> = s.split(',').map(|x| x.trim().parse::<f64>()).collect();
    let v = v.map_err(|e| usage(format!("--{flag}: {e} in '{s}'; give {n} comma-separated numbers")))?;
    if v.len() != n {
        return Err(usage(format!("--{flag}: {} values given, the model needs {n}", v.len())));
    }
    Ok(v)
}

/// `n` with n·dt = span within round-off, if there is one.
fn whole_multiple(span: f64, dt: f64) -> Option<usize> {
    let n = (span / dt).round();
    (n >= 1.0 && (n * dt - span).abs() <= 1e-9 * span).then_some(n as usize)
}

/// The initial state and controls, and how they were chosen.
struct Start {
    q0: Vec<f64>,
    v0: Vec<f64>,
    ctrl: Vec<f64>,
    act: Vec<f64>,
    description: String,
}

/// The initial state: `--keyframe`, else the model's first keyframe, else qpos0 at rest;
/// `--q0`/`--v0` override their parts.
fn initial_state(model: &Model, request: &Request) -> Result<Start, CliError> {
    let (mut q0, mut v0) = (model.qpos0.clone(), vec![0.0; model.nv]);
    let mut ctrl = vec![0.0; model.actuators.len()];
    let mut act = vec![0.0; model.na()];
    let mut start = String::from("qpos0 at rest (the model has no keyframe; --q0/--v0 set a state)");
    let key = match &request.keyframe {
        Some(name) => {
            let Some(k) = model.keyframe_id(name) else {
                let known: Vec<&str> = model.keyframes.iter().map(|k| k.name.as_str()).collect();
                return Err(usage(format!(
                    "--keyframe {name}: the model has no such keyframe (it has: {})",
                    if known.is_empty() { "none".to_string() } else { known.join(", ") }
                )));
            };
            start = format!("keyframe '{name}'");
            Some(k)
        }
        None if !model.keyframes.is_empty() => {
            start = format!(
                "keyframe '{}' (the model's first; --keyframe NAME picks another)",
                model.keyframes[0].name
            );
            Some(0)
        }
        None => None,
    };
    if let Some(k) = key.map(|k| &model.keyframes[k]) {
        k.apply(&mut q0, &mut v0, &mut ctrl, &mut act);
    }
    if let Some(s) = &request.q0 {
        q0 = parse_state("q0", s, model.nq)?;
        start = "--q0".to_string() + if request.v0.is_some() { " and --v0" } else { "" };
    }
    if let Some(s) = &request.v0 {
        v0 = parse_state("v0", s, model.nv)?;
        if request.q0.is_none() {
            start += " with --v0";
        }
    }
    Ok(Start { q0, v0, ctrl, act, description: start })
}

impl Setup {
    fn simulation(&self, spec: RunSpec) -> Result<Simulation, CliError> {
        let mut sim = Simulation::new(
            self.model.clone(),
            &SimOptions {
                integrator: Some(spec.kind),
                timestep: Some(spec.step),
                constraints: self.mode,
                drift: None,
                tolerances: spec.tolerances,
            },
        );
        sim.set_state(&self.q0, &self.v0)?;
        sim.ctrl_mut().copy_from_slice(&self.ctrl);
        sim.set_act(&self.act)?;
        Ok(sim)
    }

    /// Runs `spec` for `samples` sample intervals of `spec.per_sample` steps each, recording the
    /// state at t = 0 and after each interval; Err(reason) if it diverges or the error control
    /// gives up.
    fn sample_run(&self, spec: RunSpec, samples: usize) -> Result<Samples, String> {
        let mut sim = self.simulation(spec).map_err(|e| e.to_string())?;
        let n = samples.saturating_add(1);
        let mut out = Samples {
            q: reserve(n)?,
            v: reserve(n)?,
            energy: reserve(n)?,
            kinetic: reserve(n)?,
            steps: 0,
            rejected: 0,
        };
        let record = |sim: &mut Simulation, out: &mut Samples| {
            let (kinetic, potential) = sim.energies();
            out.q.push(sim.data.qpos.clone());
            out.v.push(sim.data.qvel.clone());
            out.energy.push(kinetic + potential);
            out.kinetic.push(kinetic);
        };
        record(&mut sim, &mut out);
        for _ in 0..samples {
            if interrupt::requested() {
                return Err(INTERRUPTED.into());
            }
            for _ in 0..spec.per_sample {
                let report = sim.step().map_err(|e| e.to_string())?;
                if !report.accepted {
                    return Err(format!(
                        "the error control gave up at t = {:.6} s (step size below round-off)",
                        sim.data.time
                    ));
                }
                out.steps += u64::from(report.substeps);
                out.rejected += u64::from(report.rejected);
            }
            if out.steps + out.rejected > self.budget {
                return Err(format!(
                    "gave up at t = {:.6} s after {} internal steps ({} rejected), over the budget of {} ({BUDGET_FACTOR} × the finest fixed-step run): contact events or stiffness?",
                    sim.data.time, out.steps + out.rejected, out.rejected, self.budget
                ));
            }
            record(&mut sim, &mut out);
        }
        Ok(out)
    }

    /// CPU seconds of the stepping loop of `spec` over `samples` intervals, nothing else
    /// measured.
    fn timed_run(&self, spec: RunSpec, samples: usize) -> Result<f64, String> {
        let mut sim = self.simulation(spec).map_err(|e| e.to_string())?;
        let total = samples * spec.per_sample;
        let t0 = cpu_time();
        for _ in 0..total {
            sim.step().map_err(|e| e.to_string())?;
            if interrupt::requested() {
                return Err(INTERRUPTED.into());
            }
        }
        Ok(cpu_time() - t0)
    }
}

/// Err(Interrupted) if a signal asked the run to stop during `what`: nothing is written.
fn stop_if_interrupted(what: &str) -> Result<(), CliError> {
    if interrupt::requested() {
        return Err(CliError::Interrupted(format!(
            "interrupted during {what}: nothing was written (any earlier output files are untouched)"
        )));
    }
    Ok(())
}

/// The reason of a run a signal stopped.
const INTERRUPTED: &str = "interrupted";

/// An empty vector with room for `n` values, or the reason it cannot have it.
fn reserve<T>(n: usize) -> Result<Vec<T>, String> {
    let mut v = Vec::new();
    v.try_reserve_exact(n)
        .map_err(|_| format!("no memory for {n} samples ({} bytes each)", std::mem::size_of::<T>()))?;
    Ok(v)
}

/// Bytes of memory a measurement over `samples` sample times needs at most: the states (q, v)
/// and energies at every sample of the reference, its check and the run being measured, and
/// with `--dump-reference` the JSON written.
fn memory_needed(nq: usize, nv: usize, samples: usize, dump: bool) -> f64 {
    // Two DVectors (32-byte headers, heap blocks with ~16 bytes of allocator overhead), two f64.
    let per_sample = ((nq + nv) * 8 + 2 * (32 + 16) + 16) as f64;
    // JSON values (32 bytes each) and their text (~25 bytes) per number, plus row overheads.
    let per_dump = if dump { ((nq + nv + 2) * (32 + 25) + 3 * 48) as f64 } else { 0.0 };
    (samples as f64 + 1.0) * (3.0 * per_sample + per_dump)
}

/// Bytes of memory the system has available (Linux's MemAvailable), if it says.
fn memory_available() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024.0)
}

/// Refuses a measurement whose samples cannot fit in the memory available.
fn check_memory(model: &Model, samples: usize, sample_dt: f64, dump: bool) -> Result<(), CliError> {
    let needed = memory_needed(model.nq, model.nv, samples, dump);
    let available = memory_available();
    let limit = available.unwrap_or(f64::INFINITY).min(usize::MAX as f64 / 2.0);
    if needed > limit {
        let bytes = |x: f64| super::simulate::human_bytes(x.min(u64::MAX as f64) as u64);
        return Err(usage(format!(
            "{samples} sample times (every {sample_dt} s, the coarsest --dts step, over the duration) need about {} of memory (q, v and energy at each, for the reference, its check and each run{}), more than the {} available: shorten --duration or use a coarser largest --dts step",
            bytes(needed),
            if dump { ", and the --dump-reference JSON" } else { "" },
            available.map_or_else(|| "addressable".to_string(), bytes)
        )));
    }
    Ok(())
}

/// (max-norm, squared 2-norm) of the state error at one sample (see the module doc).
fn state_error(
    model: &Model,
    q_ref: &DVector<f64>,
    v_ref: &DVector<f64>,
    q: &DVector<f64>,
    v: &DVector<f64>,
    dq: &mut [f64],
) -> (f64, f64) {
    // The reference and the run are states of the same model: the lengths agree.
    if difference_configuration(model, q_ref.as_slice(), q.as_slice(), dq).is_err() {
        return (f64::NAN, f64::NAN);
    }
    let mut max: f64 = 0.0;
    for j in &model.joints {
        let d = &dq[j.dof_adr..j.dof_adr + j.kind.nv()];
        let angle = |r: &[f64]| (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt();
        match j.kind {
            JointKind::Ball => max = max.max(angle(d)),
            JointKind::Free => {
                max = d[..3].iter().fold(max, |m, x| m.max(x.abs())).max(angle(&d[3..6]));
            }
            _ => max = d.iter().fold(max, |m, x| m.max(x.abs())),
        }
    }
    let dv = v - v_ref;
    max = max.max(dv.amax());
    (max, dq.iter().map(|x| x * x).sum::<f64>() + dv.norm_squared())
}

/// The error measures of `run` against `reference`: (final, L2, energy).
fn errors(setup: &Setup, run: &Samples, reference: &Samples, energy_scale: f64) -> (f64, f64, f64) {
    let model = &setup.model;
    let mut dq = vec![0.0; model.nv];
    let mut sum_sq = 0.0;
    let mut last = 0.0;
    let mut energy: f64 = 0.0;
    for k in 1..=setup.samples {
        let (max, sq) = state_error(model, &reference.q[k], &reference.v[k], &run.q[k], &run.v[k], &mut dq);
        sum_sq += sq;
        last = max;
        energy = energy.max((run.energy[k] - reference.energy[k]).abs() / energy_scale);
    }
    (last, (sum_sq / setup.samples as f64).sqrt(), energy)
}

/// The final-time error (max-norm) of the last state of `run` against the reference's.
fn final_error(setup: &Setup, run: &Samples, reference: &Samples) -> f64 {
    let mut dq = vec![0.0; setup.model.nv];
    let (r, k) = (run.q.len() - 1, setup.samples);
    state_error(&setup.model, &reference.q[k], &reference.v[k], &run.q[r], &run.v[r], &mut dq).0
}

/// A run that did not finish.
struct Failure {
    integrator: &'static str,
    setting: String,
    reason: String,
}

/// What a measurement produced, beside the rows.
struct Measurement {
    rows: Vec<Row>,
    failures: Vec<Failure>,
    notes: Vec<String>,
    /// Distance of the rtol 1e-12 solution (or RK4 at twice the step) to the reference at the
    /// final time.
    reference_check: f64,
    /// The reference's method, for the output.
    reference: ReferenceSpec,
    reference_text: String,
    repeats: u32,
}

fn fmt_num(x: f64) -> String {
    format!("{x:e}")
}

/// Runs the measurement the request asks for.
fn measure(path: &Path, options: &LoadOptions, request: &Request) -> Result<(Setup, Measurement), CliError> {
    let model = load(path, options)?;
    let contacts = !model.collision_pairs.is_empty();
    let mut notes = Vec::new();
    let integrators = match &request.integrators {
        Some(s) => parse_integrators(s)?,
        None if contacts => {
            notes.push(
                "adaptive is left out by default on a model with contacts (its error control does not step through contact events; --integrators …,adaptive tries it)"
                    .to_string(),
            );
            KNOWN.iter().map(|(_, k)| *k).filter(|k| *k != IntegratorKind::Adaptive).collect()
        }
        None => KNOWN.iter().map(|(_, k)| *k).collect(),
    };
    let dts = match &request.dts {
        Some(s) => parse_positive_list("dts", s, "step size (s)")?,
        None => DEFAULT_DT_FACTORS.iter().map(|f| f * model.options.timestep).collect(),
    };
    let rtols = match &request.rtols {
        Some(s) => {
            let r = parse_positive_list("rtols", s, "relative tolerance")?;
            if let Some(bad) = r.iter().find(|&&x| x >= 1.0) {
                return Err(usage(format!("--rtols: {bad} is not a relative tolerance below 1, e.g. 1e-6")));
            }
            r
        }
        None => DEFAULT_RTOLS.to_vec(),
    };
    if request.repeats == 0 {
        return Err(usage("--repeats 0: give at least 1 timed repeat".into()));
    }
    // The sample grid: every coarsest step; each step size must divide it.
    let sample_dt = dts.iter().copied().fold(0.0, f64::max);
    let finest = dts.iter().copied().fold(f64::INFINITY, f64::min);
    for &dt in &dts {
        if whole_multiple(sample_dt, dt).is_none() {
            return Err(usage(format!(
                "--dts: {dt} does not divide the coarsest step {sample_dt}: the runs are compared at every coarsest step, so give step sizes that divide it (e.g. halvings)"
            )));
        }
    }
    let samples = match request.duration {
        Some(t) => {
            if !(t > 0.0 && t.is_finite()) {
                return Err(usage(format!("--duration {t}: give a positive finite duration in seconds")));
            }
            whole_multiple(t, sample_dt).ok_or_else(|| {
                usage(format!(
                    "--duration {t} is not a whole number of the coarsest step {sample_dt} (the sample interval): use e.g. --duration {}",
                    (t / sample_dt).round().max(1.0) * sample_dt
                ))
            })?
        }
        None => {
            let k = (DEFAULT_DURATION / sample_dt).round().max(1.0) as usize;
            if (k as f64 * sample_dt - DEFAULT_DURATION).abs() > 1e-9 {
                notes.push(format!(
                    "duration {} s: the default {DEFAULT_DURATION} s rounded to a whole number of the coarsest step",
                    k as f64 * sample_dt
                ));
            }
            k
        }
    };
    check_memory(&model, samples, sample_dt, request.dump_reference.is_some())?;
    interrupt::watch();
    let Start { q0, v0, ctrl, act, description: start } = initial_state(&model, request)?;
    let model_label = path.display().to_string();
    if !model.collision_pairs.is_empty() {
        notes.push(format!(
            "the model has {} candidate collision pairs: work-precision is measured with the engine's contact handling as it is (exact mode, drift projection after each step); contact events are not smooth, so the orders of the methods need not show",
            model.collision_pairs.len()
        ));
    }
    let setup = Setup {
        model: Arc::new(model),
        model_label,
        mode: request.constraints,
        q0,
        v0,
        ctrl,
        act,
        start,
        sample_dt,
        samples,
        budget: BUDGET_FACTOR
            .saturating_mul(
                (samples as u64).saturating_mul(whole_multiple(sample_dt, finest).expect("checked") as u64),
            )
            .max(MIN_BUDGET),
    };
    let probe = setup.simulation(RunSpec {
        kind: IntegratorKind::Euler,
        step: sample_dt,
        per_sample: 1,
        tolerances: None,
    })?;
    if probe.model.plan.has_constraints() && setup.model.collision_pairs.is_empty() {
        notes.push(format!(
            "the model has constraint rows: measured with the engine's constraint handling as it is ({}; drift projection after each step)",
            probe.model.plan.mode().name()
        ));
    }
    if integrators.contains(&IntegratorKind::ImplicitFast)
        && !setup.model.has_damping()
        && setup.model.actuators.is_empty()
    {
        notes.push(
            "implicitfast is implicit in joint damping and actuator derivatives only: without them (as here) it takes the same steps as euler".into(),
        );
    }

    // The reference, and a looser one to estimate its error.
    let adaptive = |rtol: f64, atol: f64| RunSpec {
        kind: IntegratorKind::Adaptive,
        step: sample_dt,
        per_sample: 1,
        tolerances: Some([rtol, atol]),
    };
    let adaptive_reference = if contacts {
        Err("contact events are not smooth".to_string())
    } else {
        setup.sample_run(adaptive(REFERENCE_RTOL, REFERENCE_ATOL), samples)
    };
    stop_if_interrupted("the reference solution")?;
    let (reference, check, reference_spec, reference_text, reference_per_sample) = match adaptive_reference {
        Ok(reference) => {
            let check = setup.sample_run(adaptive(CHECK_RTOL, CHECK_RTOL), samples).map_err(|e| {
                stop_if_interrupted("the reference check").err().unwrap_or_else(|| {
                    usage(format!("the reference check (adaptive, rtol {CHECK_RTOL:e}) failed: {e}"))
                })
            })?;
            let text = format!(
                "adaptive Dormand–Prince 5(4) at rtol {REFERENCE_RTOL:e}, atol {REFERENCE_ATOL:e} ({} steps); the rtol {CHECK_RTOL:e} solution ends {{check:.1e}} from it (the reference's own error is below that)",
                reference.steps
            );
            (
                reference,
                check,
                ReferenceSpec { integrator: "adaptive".into(), rtol: Some(REFERENCE_RTOL) },
                text,
                1,
            )
        }
        Err(why) => {
            // Not smooth enough for the error control: fine fixed-step RK4 instead.
            let n = whole_multiple(sample_dt, finest).expect("checked") * FALLBACK_REFINEMENT;
            let rk4 = |n: usize| RunSpec {
                kind: IntegratorKind::Rk4,
                step: sample_dt / n as f64,
                per_sample: n,
                tolerances: None,
            };
            let budget_free = Setup { budget: u64::MAX, ..setup.clone() };
            let reference = budget_free.sample_run(rk4(n), samples).map_err(|e| {
                stop_if_interrupted("the reference solution").err().unwrap_or_else(|| {
                    usage(format!(
                        "the reference solution failed: adaptive: {why}; RK4 at dt {:e}: {e}",
                        sample_dt / n as f64
                    ))
                })
            })?;
            let check = budget_free.sample_run(rk4(n / 2), samples).map_err(|e| {
                stop_if_interrupted("the reference check").err().unwrap_or_else(|| {
                    usage(format!(
                        "the reference check (RK4 at dt {:e}) failed: {e}",
                        2.0 * sample_dt / n as f64
                    ))
                })
            })?;
            notes.push(if contacts {
                "contacts: the reference is fine-step RK4, not the adaptive method (its error control does not step through contact events); through impacts every method converges at first order at best".to_string()
            } else {
                format!("the adaptive reference at rtol {REFERENCE_RTOL:e} failed ({why}): the reference is RK4 instead")
            });
            let text = format!(
                "RK4 at dt {:e} ({FALLBACK_REFINEMENT}× finer than the finest step); RK4 at twice that step ends {{check:.1e}} from it",
                sample_dt / n as f64
            );
            (reference, check, ReferenceSpec { integrator: "rk4".into(), rtol: None }, text, n)
        }
    };
    let energy_scale =
        reference.kinetic.iter().copied().fold(reference.energy[0].abs(), f64::max).max(f64::MIN_POSITIVE);
    let reference_check = errors(&setup, &check, &reference, energy_scale).0;
    if reference.kinetic.iter().all(|&t| t == 0.0) {
        notes.push(
            "the model stays at rest from this initial state, so every error is 0: give --keyframe NAME or --q0/--v0"
                .into(),
        );
    }

    let mut runs = Vec::new();
    for &kind in &integrators {
        if kind == IntegratorKind::Adaptive {
            for &rtol in &rtols {
                // atol scaled with rtol (the default pair is rtol 1e-8, atol 1e-10).
                runs.push((adaptive(rtol, rtol * 1e-2), None, Some(rtol)));
            }
        } else {
            for &dt in &dts {
                let per_sample = whole_multiple(sample_dt, dt).expect("checked above");
                runs.push((RunSpec { kind, step: dt, per_sample, tolerances: None }, Some(dt), None));
            }
        }
    }
    let mut rows = Vec::new();
    let mut failures = Vec::new();
    let progress = super::progress::bar(Some(runs.len() as u64), "runs");
    for (spec, dt, rtol) in runs {
        progress.inc(1);
        let setting = match (dt, rtol) {
            (Some(dt), _) => format!("dt {}", fmt_num(dt)),
            (_, Some(r)) => format!("rtol {}", fmt_num(r)),
            _ => String::new(),
        };
        // Fixed step: the sampled run gives every measure. Adaptive: the sampled run (stopping
        // at every sample time, which caps its step) gives error_l2 and the energy; error, steps
        // and CPU time come from one uninterrupted run over the whole duration.
        let whole = match spec.kind {
            IntegratorKind::Adaptive => Some(RunSpec { step: setup.duration(), ..spec }),
            _ => None,
        };
        let measured = setup.sample_run(spec, samples).and_then(|run| {
            let (timed, timed_samples) = match whole {
                Some(w) => (w, 1),
                None => (spec, samples),
            };
            let end = match whole {
                Some(w) => Some(setup.sample_run(w, 1)?),
                None => None,
            };
            let mut cpu = f64::INFINITY;
            for _ in 0..request.repeats {
                cpu = cpu.min(setup.timed_run(timed, timed_samples)?);
            }
            Ok((run, end, cpu))
        });
        stop_if_interrupted(&format!("{} at {setting}", spec.kind.name()))?;
        match measured {
            Ok((run, end, cpu_s)) => {
                let (mut error, error_l2, energy_error) = errors(&setup, &run, &reference, energy_scale);
                let mut steps = run.steps;
                if let Some(end) = &end {
                    error = final_error(&setup, end, &reference);
                    steps = end.steps;
                }
                // Every number printed is finite: a run whose measures are not failed.
                if let Some((name, x)) =
                    [("error", error), ("error_l2", error_l2), ("energy_error", energy_error)]
                        .into_iter()
                        .find(|(_, x)| !x.is_finite())
                {
                    let reason = format!("its {name} is {x} (the run left the reference's scale)");
                    failures.push(Failure { integrator: spec.kind.name(), setting, reason });
                    continue;
                }
                rows.push(Row {
                    integrator: spec.kind.name().to_string(),
                    dt,
                    rtol,
                    steps,
                    error,
                    error_l2,
                    energy_error,
                    cpu_s,
                });
            }
            Err(reason) => failures.push(Failure { integrator: spec.kind.name(), setting, reason }),
        }
    }
    if let Some(path) = &request.dump_reference {
        let meta = match reference_spec.rtol {
            Some(rtol) => {
                json!({"integrator": reference_spec.integrator, "rtol": rtol, "atol": REFERENCE_ATOL,
                                 "steps": reference.steps})
            }
            None => json!({"integrator": reference_spec.integrator, "rtol": null,
                           "dt": setup.sample_dt / reference_per_sample as f64, "steps": reference.steps}),
        };
        write_reference(path, &setup, &reference, energy_scale, meta, &dts, options)?;
    }
    progress.finish_and_clear();
    let measurement = Measurement {
        rows,
        failures,
        notes,
        reference_check,
        reference: reference_spec.clone(),
        reference_text,
        repeats: request.repeats,
    };
    Ok((setup, measurement))
}

/// The reference trajectory and the settings of the run, for `validation/workprec_mujoco.py`
/// (docs/cli.md, "workprec").
fn write_reference(
    path: &Path,
    setup: &Setup,
    reference: &Samples,
    energy_scale: f64,
    reference_meta: serde_json::Value,
    dts: &[f64],
    options: &LoadOptions,
) -> Result<(), CliError> {
    let model = &setup.model;
    let joints: Vec<serde_json::Value> = model
        .joints
        .iter()
        .map(|j| {
            let kind = match j.kind {
                JointKind::Revolute { .. } => "hinge",
                JointKind::Prismatic { .. } => "slide",
                JointKind::Free => "free",
                JointKind::Ball => "ball",
                JointKind::Planar { .. } => "planar",
            };
            json!({"name": j.name, "type": kind, "qposadr": j.qpos_adr, "dofadr": j.dof_adr})
        })
        .collect();
    let model_path =
        std::fs::canonicalize(&setup.model_label).unwrap_or_else(|_| PathBuf::from(&setup.model_label));
    let time: Vec<f64> = (0..=setup.samples).map(|k| k as f64 * setup.sample_dt).collect();
    let rows = |v: &[DVector<f64>]| -> Vec<Vec<f64>> { v.iter().map(|x| x.as_slice().to_vec()).collect() };
    let value = json!({
        "generator": "lagrange workprec --dump-reference (generated file)",
        "model": setup.model_label,
        "model_path": model_path.display().to_string(),
        "disabled_flags": options.disabled_flags,
        "duration": setup.duration(),
        "sample_dt": setup.sample_dt,
        "dts": dts,
        "reference": reference_meta,
        "start": setup.start,
        "q0": setup.q0,
        "v0": setup.v0,
        "ctrl": setup.ctrl,
        "nq": model.nq,
        "nv": model.nv,
        "joints": joints,
        "energy_scale": energy_scale,
        "samples": {"time": time, "q": rows(&reference.q), "v": rows(&reference.v), "energy": reference.energy},
    });
    let text = serde_json::to_string(&value).expect("serializable");
    let mut file = OutputFile::create(path)?;
    file.write_all((text + "\n").as_bytes())?;
    file.commit()
}

/// Reads a `workprec --json` file (the rows of another run or another engine).
fn read_report(path: &Path, flag: &str) -> Result<Report, CliError> {
    let text = std::fs::read_to_string(path)
        .map_err(|source| CliError::Io { file: path.display().to_string(), source })?;
    serde_json::from_str(&text).map_err(|e| CliError::Input {
        file: path.display().to_string(),
        detail: format!(
            "{flag}: not a `workprec --json` object {{\"model\", \"duration\", \"reference\", \"rows\"}}: {e}"
        ),
    })
}

fn opt(x: Option<f64>) -> String {
    x.map_or_else(|| "-".to_string(), |x| format!("{x:.3e}"))
}

/// The table of rows (one line each).
fn table(rows: &[Row]) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "{:<20} {:>10} {:>10} {:>9} {:>10} {:>10} {:>10} {:>10}",
        "integrator", "dt", "rtol", "steps", "error", "error_l2", "energy", "cpu_s"
    );
    for r in rows {
        let _ = writeln!(
            out,
            "{:<20} {:>10} {:>10} {:>9} {:>10.3e} {:>10.3e} {:>10.3e} {:>10.3e}",
            r.integrator,
            opt(r.dt),
            opt(r.rtol),
            r.steps,
            r.error,
            r.error_l2,
            r.energy_error,
            r.cpu_s
        );
    }
    out
}

/// What the columns measure; `samples` (number, interval) and `repeats` when known.
fn definitions(samples: Option<(usize, f64)>, repeats: Option<u32>, rows: &[Row]) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "error: at the final time, max-norm over q on the manifold (ball/free rotations: angle of q_ref⁻¹q) and v"
    );
    let grid = match samples {
        Some((n, dt)) => format!("the {n} sample times (every {dt} s, the coarsest dt)"),
        None => "the sample times (every coarsest dt)".to_string(),
    };
    let _ = writeln!(out, "error_l2: RMS over {grid} of |(q ⊖ q_ref, v − v_ref)|₂");
    let _ = writeln!(
        out,
        "energy: max over the sample times of |E − E_ref| / max(|E_ref(0)|, max T_ref) (conservative model: relative drift |E − E0|)"
    );
    let repeats = repeats.map_or_else(|| "the repeated runs".to_string(), |n| format!("{n} repeats"));
    let _ = writeln!(out, "cpu_s: thread CPU time of the stepping loop, min of {repeats}");
    if rows.iter().any(|r| r.integrator == "adaptive") {
        let _ = writeln!(
            out,
            "the adaptive rows (atol = rtol/100): error, steps (accepted) and cpu_s of one run over the whole duration; error_l2 and energy of a run stopping at every sample time"
        );
    }
    out
}

/// The text output of a measurement: how it was measured, then the table.
fn measurement_text(setup: &Setup, m: &Measurement, rows: &[Row], extra: usize) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "work-precision of {} ({} s from {}, nv = {})",
        setup.model_label,
        setup.duration(),
        setup.start,
        setup.model.nv
    );
    let _ = writeln!(
        out,
        "reference: {}",
        m.reference_text.replace("{check:.1e}", &format!("{:.1e}", m.reference_check))
    );
    out += &definitions(Some((setup.samples, setup.sample_dt)), Some(m.repeats), rows);
    for note in &m.notes {
        let _ = writeln!(out, "note: {note}");
    }
    if extra > 0 {
        let _ = writeln!(out, "(+{extra} rows from --extra-rows)");
    }
    out += &table(rows);
    for f in &m.failures {
        let _ = writeln!(out, "{:<20} {:>10}  failed: {}", f.integrator, f.setting, f.reason);
    }
    out
}

/// The title of the plot.
fn plot_title(report: &Report) -> String {
    let model = &report.model;
    let name =
        Path::new(model).file_name().map_or_else(|| model.to_string(), |n| n.to_string_lossy().into_owned());
    format!(
        "{name}, {} s: error vs CPU time (reference: {})",
        report.duration,
        reference_label(&report.reference)
    )
}

/// "adaptive at rtol 1e-13" or "rk4".
fn reference_label(r: &ReferenceSpec) -> String {
    match r.rtol {
        Some(rtol) => format!("{} at rtol {rtol:e}", r.integrator),
        None => r.integrator.clone(),
    }
}

/// Runs `workprec`.
pub fn run(options: &LoadOptions, request: &Request) -> Result<(), CliError> {
    if let Some(plot) = &request.plot {
        workprec_plot::check_path(plot)?;
    }
    let mut extra_rows = Vec::new();
    for path in &request.extra_rows {
        extra_rows.extend(read_report(path, "--extra-rows")?.rows);
    }
    let extra = extra_rows.len();
    let (mut report, text) = if let Some(path) = &request.from_json {
        let report = read_report(path, "--from-json")?;
        (report, None)
    } else {
        let Some(model_path) = &request.model else {
            return Err(usage("give a MODEL file (or --from-json FILE with the rows of a saved run)".into()));
        };
        let (setup, m) = measure(model_path, options, request)?;
        for f in &m.failures {
            // (A failing stderr has nowhere to report to: ignored.)
            let _ = writeln!(
                std::io::stderr(),
                "warning: {} at {} failed and is left out of the rows: {}",
                f.integrator,
                f.setting,
                f.reason
            );
        }
        let report = Report {
            model: setup.model_label.clone(),
            duration: setup.duration(),
            reference: m.reference.clone(),
            rows: m.rows.clone(),
        };
        let mut all = m.rows.clone();
        all.extend(extra_rows.iter().cloned());
        (report, Some(measurement_text(&setup, &m, &all, extra)))
    };
    report.rows.extend(extra_rows);
    let mut out = String::new();
    if request.json {
        out = serde_json::to_string(&report).expect("serializable") + "\n";
    } else {
        match text {
            Some(t) => out = t,
            None => {
                let _ = writeln!(
                    out,
                    "work-precision of {} ({} s; reference: {}), rows from {}{}",
                    report.model,
                    report.duration,
                    reference_label(&report.reference),
                    request.from_json.as_ref().map_or_else(String::new, |p| p.display().to_string()),
                    if extra > 0 { format!(" and --extra-rows ({extra} rows)") } else { String::new() }
                );
                out += &definitions(None, None, &report.rows);
                out += &table(&report.rows);
            }
        }
    }
    if let Some(plot) = &request.plot {
        workprec_plot::plot(plot, &plot_title(&report), &report.rows)?;
        if !request.json {
            let _ = writeln!(out, "plot written to {}", plot.display());
        }
    }
    stdout::print(&out)?;
    Ok(())
}
