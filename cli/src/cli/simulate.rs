//! `lagrange simulate` and the default run of `lagrange` with no arguments.
//!
//! The trajectory CSV (`--out`) is written as [`super::output_file`] guarantees: the previous
//! file is replaced only when the run completes; a run that diverges, hits the size bound
//! (`--max-output-bytes`), fails to write or is interrupted (SIGINT/SIGTERM, [`super::interrupt`])
//! keeps its whole rows — every number finite — in `NAME.partial.csv`.

use super::finite_json::{describe, first_null};
use super::input_schedule::{self, Interp, Schedule};
use super::interrupt;
use super::output_file::{RowError, RowFile};
use super::sensor_columns;
use super::stdout;
use super::trajectory_csv::{self, RowFailure, RowProbe, TrajectoryCsv};
use super::CliError;
use super::{run_plot, view};
use indicatif::ProgressBar;
use lagrange::constraint::ConstraintMode;
use lagrange::forward::DriftCorrection;
use lagrange::integrate::{IntegratorKind, State};
use lagrange::io::{load, LoadOptions};
use lagrange::sim::{display_time, SimOptions, Simulation};
use lagrange::Model;
use serde_json::json;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// The scene `lagrange` simulates when run without arguments: the Unitree Go1 of
/// `models/mjcf/unitree_go1` on its floor (`scene.xml` includes `go1.xml`).
pub const DEFAULT_SCENE_XML: &str = include_str!("../../../models/mjcf/unitree_go1/scene.xml");
pub const DEFAULT_ROBOT_XML: &str = include_str!("../../../models/mjcf/unitree_go1/go1.xml");
/// go1's base height after 5 s from keyframe `home` in MuJoCo 4.0.0 (`mj_resetDataKeyframe`, then
/// 2500 × `mj_step` with the scene's own options), measured for comparison in the default run.
pub const DEFAULT_MUJOCO_HEIGHT: f64 = 0.2648645591;

/// What to simulate.
pub struct Request {
    pub duration: f64,
    /// Step size; None: the model's `<option timestep>`.
    pub dt: Option<f64>,
    /// None: the model's `<option integrator>`.
    pub integrator: Option<IntegratorKind>,
    /// (rtol, atol) of the adaptive integrator; None: its defaults.
    pub tolerances: Option<[f64; 2]>,
    /// None: the format's default mode.
    pub constraints: Option<ConstraintMode>,
    /// Drift correction of constrained models.
    pub drift: DriftCorrection,
    /// Print one JSON object instead of the text summary.
    pub json: bool,
    /// A keyframe of the model to start from.
    pub keyframe: Option<String>,
    pub q0: Option<String>,
    pub v0: Option<String>,
    /// Constant controls (comma-separated, one per actuator).
    pub ctrl: Option<String>,
    /// Controls over time (`--ctrl-file`, [`input_schedule`]).
    pub ctrl_file: Option<PathBuf>,
    /// Applied joint forces over time (`--tau-file`).
    pub tau_file: Option<PathBuf>,
    /// Interpolation of the input files between their rows.
    pub input_interp: Interp,
    pub out: Option<PathBuf>,
    /// Most bytes the CSV may take (`--max-output-bytes`; 0: no bound).
    pub max_output_bytes: u64,
    /// Write the viewer page of the run here (`--view`).
    pub view: Option<PathBuf>,
    /// Frames per second of simulated time the viewer keeps (`--view-fps`).
    pub view_fps: f64,
    /// Write the plot of the run here (`--plot`, .svg or .png).
    pub plot: Option<PathBuf>,
}

/// The default of `--view-fps`.
pub const DEFAULT_VIEW_FPS: f64 = 60.0;

impl Request {
    /// One second from `qpos0` at rest with the model's options, no output files (the fields
    /// `lagrange view` does not set).
    pub fn at_rest() -> Self {
        Request {
            duration: 1.0,
            dt: None,
            integrator: None,
            tolerances: None,
            constraints: None,
            drift: DriftCorrection::default(),
            json: false,
            keyframe: None,
            q0: None,
            v0: None,
            ctrl: None,
            ctrl_file: None,
            tau_file: None,
            input_interp: Interp::Linear,
            out: None,
            max_output_bytes: DEFAULT_MAX_OUTPUT_BYTES,
            view: None,
            view_fps: DEFAULT_VIEW_FPS,
            plot: None,
        }
    }
}

/// The default of `--max-output-bytes`: 2 GB.
pub const DEFAULT_MAX_OUTPUT_BYTES: u64 = 2_000_000_000;
/// Bytes per CSV value assumed by the size estimate made before a run (a double's shortest
/// round-trip form, sign and comma).
pub const CSV_BYTES_PER_VALUE: u64 = 20;

/// Where an interrupted run stopped.
pub struct Interruption {
    /// Steps the run was asked for.
    pub planned_steps: u64,
    /// The partial trajectory kept (`--out`), if any.
    pub partial: Option<PathBuf>,
    /// The note on the `--out` file (kept as partial, previous one untouched).
    pub note: String,
}

/// What a run measured.
pub struct Summary {
    pub integrator: &'static str,
    /// The computed sensors at the final state (`{"NAME": [values]}`).
    pub sensors: serde_json::Value,
    /// MuJoCo's run-time warnings raised during the run (a singular mass matrix regularized, bad
    /// controls zeroed), worded with the joints and actuators.
    pub warnings: Vec<String>,
    /// Nothing adds or removes energy (no damping, friction loss, actuators, joint limits or
    /// contacts): the energy drift measures the integration error alone.
    pub passive: bool,
    /// Contacts dropped because a collision pass found more than the model's contact budget.
    pub contacts_dropped: u64,
    /// With `<flag sleep>`: trees asleep at the end, trees, and how many fell asleep and woke
    /// during the run.
    pub sleep: Option<[u64; 4]>,
    /// Whether the model has constraint rows (equalities, mimics, joint limits).
    pub constrained: bool,
    pub dt: f64,
    /// Choices made for the user (integrator fallback, constraint mode).
    pub notes: Vec<String>,
    /// Largest max |φ| and max |J v| after any step.
    pub max_violation: [f64; 2],
    /// Deepest contact penetration (m) and most touching contacts after any step.
    pub max_penetration: f64,
    pub max_contacts: usize,
    /// Most iterations of one constraint solve at a step's end (Gauss–Seidel sweeps, or active-set
    /// changes), and the iterative solves that
    /// stopped at the iteration limit with the largest residual they left.
    pub max_solver_iterations: u32,
    /// Whether the soft (MuJoCo-compatible) constraint model ran (nothing is projected then).
    pub soft: bool,
    pub unconverged: (u64, f64),
    /// Smallest rank deficiency seen: (rank, rows) of J M⁻¹ Jᵀ when rows were redundant.
    pub redundant: Option<(usize, usize)>,
    pub steps: u64,
    pub wall: Duration,
    pub energy_start: f64,
    pub energy_end: f64,
    /// Largest |E(t) − E(0)| seen.
    pub energy_max_dev: f64,
    /// The energy scale the drift is quoted against: max(|E(0)|, max T).
    pub energy_scale: f64,
    /// The state at the end of the run.
    pub final_state: State,
    /// Joints that went outside their limits (a soft limit gives way, a rigid one by drift), with
    /// the farthest excursion.
    pub limit_excursions: Vec<(String, f64)>,
    /// Set when a signal stopped the run before its end (`steps` then counts the steps taken).
    pub interrupted: Option<Interruption>,
    /// What the run wrote besides the CSV (the viewer page, the plot), one line each.
    pub outputs: Vec<String>,
}

/// `--baumgarte α,β` → gains (both finite and ≥ 0).
pub fn parse_baumgarte(s: Option<&str>) -> Result<Option<[f64; 2]>, CliError> {
    let Some(s) = s else { return Ok(None) };
    let v = parse_list("baumgarte", s, 2)?;
    if v.iter().any(|x| !x.is_finite() || *x < 0.0) {
        return Err(CliError::Usage(format!("--baumgarte {s}: give two finite gains α,β ≥ 0")));
    }
    Ok(Some([v[0], v[1]]))
}

fn parse_list(name: &str, s: &str, n: usize) -> Result<Vec<f64>, CliError> {
    let values: Result<Vec<f64>, _> = s.split(',').map(|x| x.trim().parse::<f64>()).collect();
    let values = values
        .map_err(|e| CliError::Usage(format!("--{name}: {e} in '{s}'; give {n} comma-separated numbers")))?;
    if values.len() != n {
        return Err(CliError::Usage(format!("--{name}: {} values given, the model needs {n}", values.len())));
    }
    Ok(values)
}

/// (rtol, atol) from `--rtol`/`--atol`: only with `--integrator adaptive`, positive and finite;
/// a missing one takes the adaptive integrator's default.
pub fn parse_tolerances(
    integrator: Option<IntegratorKind>,
    rtol: Option<f64>,
    atol: Option<f64>,
) -> Result<Option<[f64; 2]>, CliError> {
    if rtol.is_none() && atol.is_none() {
        return Ok(None);
    }
    if integrator != Some(IntegratorKind::Adaptive) {
        return Err(CliError::Usage(
            "--rtol/--atol set the error control of the adaptive integrator: add --integrator adaptive"
                .into(),
        ));
    }
    let pair = [
        rtol.unwrap_or(lagrange::integrate::DEFAULT_RTOL),
        atol.unwrap_or(lagrange::integrate::DEFAULT_ATOL),
    ];
    for (name, x) in [("rtol", pair[0]), ("atol", pair[1])] {
        if !(x > 0.0 && x.is_finite()) {
            return Err(CliError::Usage(format!(
                "--{name} {x}: give a positive tolerance, e.g. --{name} 1e-8"
            )));
        }
    }
    Ok(Some(pair))
}

/// The initial state (qpos, qvel, ctrl, act) of a run: `--q0`/`--v0`, else the keyframe's, else
/// `qpos0` at rest; `--ctrl`, else the keyframe's controls, else zero.
pub fn initial_state(model: &Model, request: &Request) -> Result<InitialState, CliError> {
    let (mut q0, mut v0) = (model.qpos0.clone(), vec![0.0; model.nv]);
    let mut ctrl = vec![0.0; model.actuators.len()];
    let mut act = vec![0.0; model.na()];
    if let Some(name) = &request.keyframe {
        let Some(k) = model.keyframe_id(name).map(|k| &model.keyframes[k]) else {
            let known: Vec<&str> = model.keyframes.iter().map(|k| k.name.as_str()).collect();
            return Err(CliError::Usage(format!(
                "--keyframe {name}: the model has no such keyframe (it has: {})",
                if known.is_empty() { "none".to_string() } else { known.join(", ") }
            )));
        };
        k.apply(&mut q0, &mut v0, &mut ctrl, &mut act);
    }
    if let Some(s) = &request.ctrl {
        ctrl = parse_list("ctrl", s, model.actuators.len())?;
    }
    if let Some(s) = &request.q0 {
        q0 = parse_list("q0", s, model.nq)?;
    }
    if let Some(s) = &request.v0 {
        v0 = parse_list("v0", s, model.nv)?;
    }
    Ok((q0, v0, ctrl, act))
}

/// (qpos, qvel, ctrl, act).
pub type InitialState = (Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>);

/// Simulates `model` per `request`, writing the CSV if asked; returns the summary.
pub fn simulate(model: &Model, request: &Request) -> Result<Summary, CliError> {
    let mut sim = Simulation::new(
        Arc::new(model.clone()),
        &SimOptions {
            integrator: request.integrator,
            timestep: request.dt,
            constraints: request.constraints,
            drift: Some(request.drift),
            tolerances: request.tolerances,
        },
    );
    let dt = sim.timestep;
    if !(dt > 0.0 && dt.is_finite()) {
        return Err(CliError::Usage(format!(
            "--dt {dt}: the step must be a positive, finite number of seconds, e.g. --dt 0.001"
        )));
    }
    if !(request.duration >= 0.0 && request.duration.is_finite()) {
        return Err(CliError::Usage(format!(
            "--duration {}: give a non-negative, finite number of seconds, e.g. --duration 5",
            request.duration
        )));
    }
    let (q0, v0, ctrl, act) = initial_state(model, request)?;
    let mut ctrl_schedule = match &request.ctrl_file {
        Some(f) => Some(Schedule::read(f, "--ctrl-file", request.input_interp, |n| {
            input_schedule::actuator_column(model, n)
        })?),
        None => None,
    };
    let mut tau_schedule = match &request.tau_file {
        Some(f) => Some(Schedule::read(f, "--tau-file", request.input_interp, |n| {
            input_schedule::dof_column(model, n)
        })?),
        None => None,
    };
    sim.set_state(&q0, &v0)?;
    sim.ctrl_mut().copy_from_slice(&ctrl);
    sim.set_act(&act)?;
    // The inputs of the step from the current state (and of its CSV row).
    let mut set_inputs = |sim: &mut Simulation| {
        let t = sim.data.time;
        if let Some(s) = ctrl_schedule.as_mut() {
            s.apply(t, sim.ctrl_mut());
        }
        if let Some(s) = tau_schedule.as_mut() {
            s.apply(t, sim.qfrc_applied_mut());
        }
    };
    set_inputs(&mut sim);
    let steps = (request.duration / dt).round() as u64;
    if !(request.view_fps > 0.0 && request.view_fps.is_finite()) {
        return Err(CliError::Usage(format!(
            "--view-fps {}: give a positive number of frames per second, e.g. --view-fps 60",
            request.view_fps
        )));
    }
    if let Some(path) = &request.plot {
        run_plot::check_path(path)?;
    }
    let mut viewer = request.view.as_ref().map(|_| view::scene::Recorder::new(&sim.model));
    let view_start = sim.data.time;
    let mut plot_series = request.plot.as_ref().map(|_| run_plot::Series::new(model, steps));
    let mut step_contacts = 0;
    let mut summary_probe = (sensor_columns::count(model) > 0).then(|| RowProbe::new(model)).flatten();
    let limit = if request.max_output_bytes == 0 { u64::MAX } else { request.max_output_bytes };
    if let Some(path) = &request.out {
        check_output_size(model, path, steps, limit)?;
    }
    interrupt::watch();
    let mut csv = match &request.out {
        Some(path) => {
            let mut w = RowFile::create(path, limit)?;
            let mut rows = TrajectoryCsv::new(model);
            rows.header(model, w.row()).map_err(|source| CliError::Io { file: w.label(), source })?;
            end_row(&mut w, limit, 0.0, 0)?;
            Some((w, rows))
        }
        None => None,
    };
    let progress =
        if steps >= 20_000 { super::progress::bar(Some(steps), "steps") } else { ProgressBar::hidden() };
    let energy_start = {
        let (kinetic, potential) = sim.energies();
        kinetic + potential
    };
    let mut energy = energy_start;
    let (mut max_dev, mut max_kinetic) = (0.0f64, 0.0f64);
    let mut wall = Duration::ZERO;
    let mut excursions = vec![0.0; model.joints.len()];
    let mut violation = sim.constraint_violation();
    let mut max_violation = violation;
    let mut redundant = None;
    let (mut max_penetration, mut max_contacts, mut max_iterations) = (0.0f64, 0usize, 0u32);
    // Why the run ended before its last step, if it did.
    let mut stopped: Option<CliError> = None;
    let mut interrupted = false;
    let mut taken = 0;
    for k in 0..=steps {
        // Every number of a row and of the summary is finite: the run stops before the first
        // state that is not.
        if let Some(what) = non_finite(&sim, energy, violation) {
            stopped = Some(diverged(&sim, k, &what));
            break;
        }
        if let Some((w, rows)) = csv.as_mut() {
            if let Err(e) = csv_row(w, rows, model, &sim, (energy, violation[0]), limit, k) {
                stopped = Some(e);
                break;
            }
        }
        if let Some(r) = viewer.as_mut() {
            // Frame n is the state nearest to n / fps after the start.
            let d = &sim.data;
            let due = r.frames.len() as f64 / request.view_fps - 0.5 * dt;
            if d.time - view_start >= due || k == steps {
                r.record(
                    &sim.model,
                    display_time(d.time),
                    d.qpos.as_slice(),
                    d.qvel.as_slice(),
                    d.act.as_slice(),
                    d.ctrl.as_slice(),
                );
            }
        }
        if let Some(p) = plot_series.as_mut() {
            p.push(k, sim.data.time, sim.data.qpos.as_slice(), energy, violation[0], step_contacts);
        }
        if k == steps {
            break;
        }
        if interrupt::requested() {
            interrupted = true;
            break;
        }
        let t0 = Instant::now();
        let report = match sim.step() {
            Ok(report) => report,
            Err(e) => {
                stopped = Some(e.into());
                break;
            }
        };
        wall += t0.elapsed();
        taken = k + 1;
        set_inputs(&mut sim);
        violation = report.constraint_violation;
        let (contacts, penetration) = contact_summary(&sim.data);
        step_contacts = contacts;
        max_contacts = max_contacts.max(contacts);
        max_penetration = max_penetration.max(penetration);
        let soft = sim.model.plan.solver.soft_weights().is_some();
        max_iterations =
            max_iterations.max(if soft { report.solver_iterations } else { sim.data.efc_iterations });
        max_violation = [max_violation[0].max(violation[0]), max_violation[1].max(violation[1])];
        let active = sim.data.efc_active_rows();
        if !soft && sim.data.nefc > 0 && sim.data.efc_rank < active {
            redundant = Some((sim.data.efc_rank, active));
        }
        // Energy monitoring is outside the timed step.
        let (kinetic, potential) = sim.energies();
        energy = kinetic + potential;
        if energy.is_finite() {
            max_kinetic = max_kinetic.max(kinetic);
            max_dev = max_dev.max((energy - energy_start).abs());
        }
        track_limit_excursions(model, sim.data.qpos.as_slice(), &mut excursions);
        if k % 4096 == 0 {
            progress.set_position(k);
        }
    }
    progress.finish_and_clear();
    // The page and the plot show the run as far as it went, also when it stopped early.
    let mut outputs = Vec::new();
    if let (Some(path), Some(r)) = (&request.view, &viewer) {
        match view::write_page(path, &sim.model, &r.frames) {
            Ok(line) => outputs.push(line),
            Err(e) if stopped.is_none() => return Err(e),
            Err(_) => {}
        }
    }
    if let (Some(path), Some(p)) = (&request.plot, &plot_series) {
        match run_plot::plot(path, model, p) {
            Ok(()) => outputs.push(format!("plot written to {}", path.display())),
            Err(e) if stopped.is_none() => return Err(e),
            Err(_) => {}
        }
    }
    if let Some(e) = stopped {
        let note = match csv {
            // The run's own error comes first; a failure to keep its rows is added to it.
            Some((w, _)) => partial_note(w).unwrap_or_else(|e| format!("its rows could not be kept: {e}")),
            None => String::new(),
        };
        return Err(e.with_note(&note));
    }
    let interrupted = if interrupted {
        let (partial, note) = match csv {
            Some((w, _)) => {
                let label = w.label();
                let replaces = w.replaces_a_file();
                let partial = w.keep_partial()?;
                let note = partial_text(&label, replaces, partial.as_deref());
                (partial, note)
            }
            None => (None, String::new()),
        };
        Some(Interruption { planned_steps: steps, partial, note })
    } else {
        if let Some((w, _)) = csv {
            w.commit()?;
        }
        None
    };
    // Joint limits and contacts end impacts inelastically: their energy loss is physics.
    let limited = model.options.flags.limit && model.joints.iter().any(|j| j.limits.is_some());
    let passive = !model.has_damping()
        && model.actuators.is_empty()
        && model.joints.iter().all(|j| j.friction == 0.0)
        && !limited
        && max_contacts == 0;
    let sensors = match summary_probe.as_mut() {
        Some(p) => sensor_columns::to_json(model, p.read(model, &sim.data).sensordata.as_slice()),
        None => serde_json::json!({}),
    };
    Ok(Summary {
        sensors,
        // The simulation's model: `--constraints` may have changed its mode, and with it the
        // contact budget the warnings quote.
        warnings: sim.data.warnings.messages(&sim.model),
        passive,
        contacts_dropped: sim.data.contacts_dropped,
        sleep: sim.model.options.flags.sleep.then(|| {
            let sl = &sim.data.sleep;
            [sl.nasleep() as u64, sim.model.sleep.ntree() as u64, sl.slept, sl.woken]
        }),
        constrained: sim.model.plan.has_constraints(),
        integrator: sim.integrator(),
        dt,
        notes: sim.notes.clone(),
        max_violation,
        max_penetration,
        max_contacts,
        max_solver_iterations: max_iterations,
        soft: sim.model.plan.solver.soft_weights().is_some(),
        unconverged: (sim.data.efc_unconverged, sim.data.efc_unconverged_residual),
        redundant,
        steps: taken,
        wall,
        energy_start,
        energy_end: energy,
        energy_max_dev: max_dev,
        energy_scale: energy_start.abs().max(max_kinetic).max(f64::MIN_POSITIVE),
        final_state: State::of(&sim.data),
        limit_excursions: model
            .joints
            .iter()
            .zip(&excursions)
            .filter(|(_, &e)| e > 0.0)
            .map(|(j, &e)| (j.name.clone(), e))
            .collect(),
        interrupted,
        outputs,
    })
}

/// Refuses, before the run, a CSV whose estimated size exceeds `limit`.
fn check_output_size(model: &Model, path: &Path, steps: u64, limit: u64) -> Result<(), CliError> {
    let columns = trajectory_csv::columns(model).len();
    let rows = steps.saturating_add(1);
    let estimate = rows.saturating_mul(columns as u64).saturating_mul(CSV_BYTES_PER_VALUE);
    if estimate > limit {
        return Err(CliError::Usage(format!(
            "--out {}: the trajectory would take about {} ({rows} rows × {columns} columns × ~{CSV_BYTES_PER_VALUE} bytes), over --max-output-bytes {limit} ({}): shorten --duration, or raise the bound (--max-output-bytes 0 for none)",
            path.display(),
            human_bytes(estimate),
            human_bytes(limit)
        )));
    }
    Ok(())
}

/// `13.5 GB`, `812 kB`, `120 bytes`.
pub fn human_bytes(n: u64) -> String {
    let x = n as f64;
    match n {
        0..1_000 => format!("{n} bytes"),
        1_000..1_000_000 => format!("{:.0} kB", x / 1e3),
        1_000_000..1_000_000_000 => format!("{:.1} MB", x / 1e6),
        1_000_000_000..1_000_000_000_000 => format!("{:.1} GB", x / 1e9),
        _ => format!("{:.1} TB", x / 1e12),
    }
}

/// Writes the CSV row of the current state (`step`), or the error that stops the run.
fn csv_row(
    w: &mut RowFile,
    rows: &mut TrajectoryCsv,
    model: &Model,
    sim: &Simulation,
    (energy, violation): (f64, f64),
    limit: u64,
    step: u64,
) -> Result<(), CliError> {
    // Formatting into the row buffer (a Vec) does not fail.
    match rows.row(model, sim, energy, violation, w.row()) {
        Ok(()) => {}
        Err(RowFailure::NonFinite(what)) => return Err(diverged(sim, step, &what)),
        Err(RowFailure::Io(source)) => return Err(CliError::Io { file: w.label(), source }),
    }
    end_row(w, limit, sim.data.time, step)
}

/// Completes a CSV row, or the error that stops the run: the size bound or a failed write.
fn end_row(w: &mut RowFile, limit: u64, time: f64, step: u64) -> Result<(), CliError> {
    match w.end_row() {
        Ok(()) => Ok(()),
        Err(RowError::Limit) => Err(CliError::Stopped(format!(
            "--out {}: the trajectory reached --max-output-bytes {limit} ({}) at t = {} s (step {step}): its values are longer than the ~{CSV_BYTES_PER_VALUE} bytes estimated before the run; raise the bound (--max-output-bytes 0 for none) or shorten --duration",
            w.label(),
            human_bytes(limit),
            display_time(time)
        ))),
        Err(RowError::Io(source)) => Err(CliError::Io { file: w.label(), source }),
    }
}

/// The first non-finite quantity of the row at the current state, named.
fn non_finite(sim: &Simulation, energy: f64, violation: [f64; 2]) -> Option<String> {
    let d = &sim.data;
    if let Some(i) = d.qpos.iter().position(|x| !x.is_finite()) {
        return Some(format!("qpos[{i}] is {}", d.qpos[i]));
    }
    if let Some(i) = d.qvel.iter().position(|x| !x.is_finite()) {
        return Some(format!("qvel[{i}] is {}", d.qvel[i]));
    }
    if let Some(i) = d.act.iter().position(|x| !x.is_finite()) {
        return Some(format!("act[{i}] is {}", d.act[i]));
    }
    if !energy.is_finite() {
        return Some(format!("the energy is {energy} (the state's magnitude overflows)"));
    }
    if let Some(v) = violation.iter().find(|x| !x.is_finite()) {
        return Some(format!("the constraint violation is {v}"));
    }
    None
}

/// The error of a run whose state at `step` is not finite.
fn diverged(sim: &Simulation, step: u64, what: &str) -> CliError {
    CliError::Stopped(format!(
        "the simulation diverged at t = {} s (step {step}): {what}; reduce --dt (now {} s), or use --integrator rk4 (or implicit for stiff damping); if it persists, check the initial state, the model's stiffnesses and inertias",
        display_time(sim.data.time),
        sim.timestep
    ))
}

/// Keeps the rows of a stopped run as the partial file; the note saying so.
fn partial_note(w: RowFile) -> Result<String, CliError> {
    let (label, replaces) = (w.label(), w.replaces_a_file());
    let partial = w.keep_partial()?;
    Ok(partial_text(&label, replaces, partial.as_deref()))
}

/// "the trajectory so far is in traj.partial.csv (complete rows); traj.csv is untouched".
/// (Empty for a target written in place.)
fn partial_text(label: &str, replaces: bool, partial: Option<&Path>) -> String {
    let Some(partial) = partial else {
        // Written in place (a device, a FIFO): nothing to keep apart.
        return String::new();
    };
    let target = if replaces {
        format!("the previous {label} is untouched")
    } else {
        format!("{label} was not written")
    };
    format!("the trajectory so far (whole rows, every value finite) is in {}; {target}", partial.display())
}

/// The number of touching contacts (contact normal rows) and the deepest penetration among them
/// in the rows of the last step.
fn contact_summary(data: &lagrange::Data) -> (usize, f64) {
    let (mut n, mut depth) = (0, 0.0f64);
    for i in 0..data.nefc {
        if data.efc_is_normal(i) {
            n += 1;
            depth = depth.max(-data.efc_pos[i]);
        }
    }
    (n, depth)
}

/// Records, per joint, how far beyond its limits the state has gone (0 if never).
fn track_limit_excursions(model: &Model, qpos: &[f64], excursions: &mut [f64]) {
    for (j, e) in model.joints.iter().zip(excursions.iter_mut()) {
        if let Some([lo, hi]) = j.limits {
            let q = qpos[j.qpos_adr];
            *e = e.max(lo - q).max(q - hi);
        }
    }
}

/// The `simulate --json` summary: one object (docs/cli.md, "simulate").
pub fn summary_json(model: &Model, s: &Summary) -> serde_json::Value {
    let simulated = s.steps as f64 * s.dt;
    let mut out = json!({
        "model": model.source.as_ref().map_or_else(|| model.name.clone(), |p| p.display().to_string()),
        "integrator": s.integrator,
        "dt": s.dt,
        "steps": s.steps,
        "time": display_time(s.final_state.time),
        "wall_s": s.wall.as_secs_f64(),
        "realtime_factor": simulated / wall_floor(s.wall),
        "energy": {"initial": s.energy_start, "final": s.energy_end, "max_abs_drift": s.energy_max_dev},
        "max_constraint_violation": {"position": s.max_violation[0], "velocity": s.max_violation[1]},
        "max_penetration": s.max_penetration,
        "max_contacts": s.max_contacts,
        "contacts_dropped": s.contacts_dropped,
        "solver": {"max_iterations": s.max_solver_iterations, "unconverged": s.unconverged.0,
                   "worst_unconverged_residual": s.unconverged.1},
        "q": s.final_state.q.as_slice(),
        "v": s.final_state.v.as_slice(),
        "act": s.final_state.act.as_slice(),
        "sensors": s.sensors,
        "warnings": s.warnings,
    });
    if let Some([asleep, trees, slept, woken]) = s.sleep {
        out["sleep"] = json!({"asleep": asleep, "trees": trees, "slept": slept, "woken": woken});
    }
    if let Some(i) = &s.interrupted {
        out["interrupted"] = json!({
            "planned_steps": i.planned_steps,
            "partial": i.partial.as_ref().map_or_else(String::new, |p| p.display().to_string()),
        });
    }
    out
}

/// The wall time in seconds, at least 1 ns (the real-time factor of a run too short to time
/// stays finite).
fn wall_floor(wall: Duration) -> f64 {
    wall.as_secs_f64().max(1e-9)
}

/// Relative energy drift of a passive scene beyond which `simulate` warns.
pub const ENERGY_DRIFT_WARNING: f64 = 1e-2;

/// The text summary `simulate` prints.
pub fn summary_text(model: &Model, request: &Request, s: &Summary) -> String {
    let state = &s.final_state;
    use std::fmt::Write as _;
    let mut out = String::new();
    let simulated = s.steps as f64 * s.dt;
    let wall = s.wall.as_secs_f64();
    let from = if request.integrator.is_some() { "requested" } else { "the model's <option>" };
    let dt_from = if request.dt.is_some() { "requested" } else { "the model's <option>" };
    let _ = writeln!(
        out,
        "simulated {simulated:.6} s in {} steps of {} s (from {dt_from}) with {} (from {from})",
        s.steps, s.dt, s.integrator
    );
    if let Some(i) = &s.interrupted {
        let _ = writeln!(
            out,
            "interrupted by a signal at t = {} s after {} of {} steps",
            display_time(state.time),
            s.steps,
            i.planned_steps
        );
    }
    for note in &s.notes {
        let _ = writeln!(out, "note: {note}");
    }
    for w in &s.warnings {
        let _ = writeln!(out, "warning: {w}");
    }
    let _ = writeln!(
        out,
        "wall time {:.3} ms ({:.3} µs/step), real-time factor {:.0}×",
        wall * 1e3,
        wall * 1e6 / s.steps.max(1) as f64,
        simulated / wall_floor(s.wall)
    );
    let damping = if model.has_damping() { " (joint damping dissipates energy)" } else { "" };
    let _ = writeln!(
        out,
        "energy: start {:.9} J, end {:.9} J, drift {:.3e} J, max |E−E0| {:.3e} J = {:.3e} relative{damping}",
        s.energy_start,
        s.energy_end,
        s.energy_end - s.energy_start,
        s.energy_max_dev,
        s.energy_max_dev / s.energy_scale
    );
    if s.constrained {
        let _ = writeln!(
            out,
            "constraint violation: max |φ| {:.3e} (limits: penetration), max |J v| {:.3e} (limits: approach speed) after each step ({})",
            s.max_violation[0],
            s.max_violation[1],
            if s.soft {
                "soft constraints: nothing is projected, as in MuJoCo"
            } else if request.drift.projection {
                "projected onto φ = 0, J v = 0 after each step"
            } else {
                "no projection"
            }
        );
    }
    let drift = s.energy_max_dev / s.energy_scale;
    if s.passive && drift > ENERGY_DRIFT_WARNING {
        let better = match s.integrator {
            "rk4" | "adaptive" => String::new(),
            _ => " or use --integrator rk4".to_string(),
        };
        let _ = writeln!(
            out,
            "warning: the energy of this passive scene (no damping, friction, actuators, limits or contacts) drifted by {drift:.3e} of its scale: the integration is inaccurate at this step; reduce --dt (now {} s){better}",
            s.dt
        );
    }
    if s.max_contacts > 0 {
        let _ = writeln!(
            out,
            "contacts: up to {} touching, deepest penetration after a step {:.3e} m",
            s.max_contacts, s.max_penetration
        );
    }
    if let Some([asleep, trees, slept, woken]) = s.sleep {
        let _ = writeln!(
            out,
            "sleeping islands: {asleep} of {trees} trees asleep at the end ({slept} fell asleep, {woken} woke during the run)"
        );
    }
    if s.contacts_dropped > 0 {
        let _ = writeln!(
            out,
            "warning: {} contacts were dropped: collision passes found more than the budget of {} contacts (the memory their constraint rows may take, lagrange::model::CONTACT_MEMORY); exclude pairs that need not touch (<contact><exclude>, contype/conaffinity)",
            s.contacts_dropped,
            model.contact_budget()
        );
    }
    if s.unconverged.0 > 0 {
        let _ = writeln!(
            out,
            "warning: {} friction solves stopped at the iteration limit ({} iterations) with residual up to {:.3e}: raise the limit or check the contact setup",
            s.unconverged.0, s.max_solver_iterations, s.unconverged.1
        );
    }
    if let Some((rank, rows)) = s.redundant {
        let _ = writeln!(
            out,
            "warning: the constraint rows are redundant (rank {rank} of {rows} rows of J M⁻¹ Jᵀ): the multipliers are the minimum-norm ones"
        );
    }
    for (joint, by) in &s.limit_excursions {
        let _ = writeln!(out, "note: joint '{joint}' went {by:.4} beyond its limits");
    }
    let _ = writeln!(out, "final state at t = {:.6} s:", state.time);
    for j in &model.joints {
        let q: Vec<String> = state.q.as_slice()[j.qpos_adr..j.qpos_adr + j.kind.nq()]
            .iter()
            .map(|x| format!("{x:+.6}"))
            .collect();
        let v: Vec<String> = state.v.as_slice()[j.dof_adr..j.dof_adr + j.kind.nv()]
            .iter()
            .map(|x| format!("{x:+.6}"))
            .collect();
        let _ = writeln!(out, "  {:<24} q = [{}]  v = [{}]", j.name, q.join(", "), v.join(", "));
    }
    // Activations, one per actuator with activation dynamics.
    let mut act = state.act.iter();
    for (i, a) in model.actuators.iter().enumerate().filter(|(_, a)| a.actnum() == 1) {
        let name = if a.name.is_empty() { format!("actuator{i}") } else { a.name.clone() };
        let _ = writeln!(out, "  {name:<24} act = {:+.6}", act.next().copied().unwrap_or(0.0));
    }
    out
}

fn run_model(model: &Model, request: &Request) -> Result<(), CliError> {
    let summary = simulate(model, request)?;
    if request.json {
        let value = summary_json(model, &summary);
        if let Some(path) = first_null(&value) {
            return Err(CliError::Stopped(format!(
                "the summary's {} is not finite (NaN or infinite): not printed",
                describe(&path)
            )));
        }
        stdout::print(&format!("{value}\n"))?;
    } else {
        let mut text = summary_text(model, request, &summary);
        if let (Some(out), None) = (&request.out, &summary.interrupted) {
            text += &format!("trajectory written to {}\n", out.display());
        }
        for line in &summary.outputs {
            text += &format!("{line}\n");
        }
        stdout::print(&text)?;
    }
    interrupted_error(&summary)
}

/// Err(Interrupted) with where the run stopped and what became of its file, if a signal stopped
/// it.
fn interrupted_error(summary: &Summary) -> Result<(), CliError> {
    match &summary.interrupted {
        None => Ok(()),
        Some(i) => {
            let mut message = format!(
                "interrupted at t = {} s after {} of {} steps",
                display_time(summary.final_state.time),
                summary.steps,
                i.planned_steps
            );
            if !i.note.is_empty() {
                message += &format!("; {}", i.note);
            }
            Err(CliError::Interrupted(message))
        }
    }
}

/// Runs `simulate` on a model file.
pub fn run_file(path: &Path, options: &LoadOptions, request: &Request) -> Result<(), CliError> {
    let model = load(path, options)?;
    run_model(&model, request)
}

/// `lagrange` with no arguments: the embedded Unitree Go1 scene (MuJoCo Menagerie, BSD-3-Clause,
/// `models/mjcf/unitree_go1`) standing on its floor on its own position servos from keyframe
/// `home`, 5 s with the model's `<option>` (Euler, 2 ms) and soft (MuJoCo-compatible) contacts.
pub fn default_run() -> Result<(), CliError> {
    // The two embedded files go to a fresh temporary folder (scene.xml includes go1.xml).
    let dir = std::env::temp_dir().join(format!("lagrange-default-{}", std::process::id()));
    let io = |source| CliError::Io { file: dir.display().to_string(), source };
    std::fs::create_dir_all(&dir).map_err(io)?;
    std::fs::write(dir.join("scene.xml"), DEFAULT_SCENE_XML).map_err(io)?;
    std::fs::write(dir.join("go1.xml"), DEFAULT_ROBOT_XML).map_err(io)?;
    let loaded = load(&dir.join("scene.xml"), &LoadOptions::default());
    let _ = std::fs::remove_dir_all(&dir);
    let model = loaded?;
    stdout::print(&format!(
        "lagrange {}: no arguments given, so simulating the embedded default scene: the Unitree Go1
quadruped (MuJoCo Menagerie, models/mjcf/unitree_go1) standing on its floor on its own
position servos, from keyframe 'home' holding its controls, with soft (MuJoCo-compatible)
contacts, joint limits and friction loss.
(Run `lagrange --help` for info/eval/simulate on your own URDF or MJCF.)\n\n{}\n",
        env!("CARGO_PKG_VERSION"),
        super::info::to_text(&model, None)
    ))?;
    let request = Request {
        duration: 5.0,
        dt: None,
        integrator: None,
        tolerances: None,
        constraints: None,
        drift: DriftCorrection::default(),
        json: false,
        keyframe: Some("home".into()),
        ctrl: None,
        ctrl_file: None,
        tau_file: None,
        input_interp: Interp::Linear,
        q0: None,
        v0: None,
        out: None,
        max_output_bytes: DEFAULT_MAX_OUTPUT_BYTES,
        view: None,
        view_fps: DEFAULT_VIEW_FPS,
        plot: None,
    };
    let summary = simulate(&model, &request)?;
    let z0 =
        model.keyframes.iter().find(|k| k.name == "home").and_then(|k| k.qpos.as_ref()).map_or(0.0, |q| q[2]);
    let text = format!(
        "{}base height: {z0:.4} m at the start, {:.6} m after {} s (MuJoCo 4.0's mj_step from the same keyframe: {DEFAULT_MUJOCO_HEIGHT} m); at most {} contacts, deepest penetration {:.2} mm\n",
        summary_text(&model, &request, &summary),
        summary.final_state.q[2],
        display_time(summary.final_state.time),
        summary.max_contacts,
        summary.max_penetration * 1e3
    );
    stdout::print(&text)?;
    interrupted_error(&summary)
}
