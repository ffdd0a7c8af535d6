//! `lagrange view`: the model, a trajectory or a live simulation in a browser (docs/viewer.md).
//! The page is one self-contained HTML file ([`html`]) with the scene and per-frame poses
//! ([`scene`]); `--trajectory` reads a `simulate --out` CSV ([`trajectory`]) and recomputes each
//! kept state's contacts and forces with `forward`; `--live` serves the page and streams the frames
//! of a simulation run in real time ([`live`]). `simulate --view` writes the page of its own run
//! through [`write_page`].

pub mod html;
pub mod live;
pub mod scene;
pub mod trajectory;

use super::interrupt;
use super::output_file::OutputFile;
use super::simulate::{self, initial_state};
use super::{stdout, CliError};
use lagrange::constraint::ConstraintMode;
use lagrange::io::{load, LoadOptions};
use lagrange::sim::{SimOptions, Simulation};
use lagrange::Model;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// What `lagrange view` shows and where.
pub struct Request {
    /// A `simulate --out` CSV to play (None: one state).
    pub trajectory: Option<PathBuf>,
    /// The keyframe shown (or the live run's start); its controls act on a trajectory's states
    /// when the file has no `ctrl` columns.
    pub keyframe: Option<String>,
    /// Constant controls (comma-separated), over the keyframe's.
    pub ctrl: Option<String>,
    /// The page to write (default: the model file's name with `.html`, in the current folder).
    pub out: Option<PathBuf>,
    /// Serve the page and stream a simulation instead of writing a file.
    pub live: bool,
    /// The live server's port on 127.0.0.1 (0: any free port).
    pub port: u16,
    /// Simulated seconds of the live run (None: until Ctrl-C).
    pub duration: Option<f64>,
    /// Frames per second kept from a trajectory or streamed live.
    pub fps: f64,
    /// The constraint mode (None: the format's default).
    pub constraints: Option<ConstraintMode>,
}

/// The default live port.
pub const DEFAULT_PORT: u16 = 8765;

/// Runs `lagrange view`.
pub fn run(path: &Path, options: &LoadOptions, request: &Request) -> Result<(), CliError> {
    if !(request.fps > 0.0 && request.fps.is_finite()) {
        return Err(CliError::Usage(format!(
            "--fps {}: give a positive number of frames per second",
            request.fps
        )));
    }
    let model = load(path, options)?;
    let sim_options = SimOptions { constraints: request.constraints, ..SimOptions::default() };
    let sim = Simulation::new(Arc::new(model), &sim_options);
    let start = simulate::Request {
        keyframe: request.keyframe.clone(),
        ctrl: request.ctrl.clone(),
        ..simulate::Request::at_rest()
    };
    let (q0, v0, ctrl, act) = initial_state(&sim.model, &start)?;
    if request.live {
        return run_live(sim, request, (q0, v0, ctrl, act));
    }
    let model = sim.model.clone();
    let mut recorder = scene::Recorder::new(&model);
    match &request.trajectory {
        Some(file) => {
            for row in trajectory::read(file, &model, request.fps)? {
                let ctrl = row.ctrl.as_deref().unwrap_or(&ctrl);
                recorder.record(&model, row.time, &row.qpos, &row.qvel, &row.act, ctrl);
            }
        }
        None => recorder.record(&model, 0.0, &q0, &v0, &act, &ctrl),
    }
    let out = request.out.clone().unwrap_or_else(|| {
        let stem = path.file_stem().map_or_else(|| "scene".into(), |s| s.to_string_lossy().into_owned());
        PathBuf::from(format!("{stem}.html"))
    });
    let line = write_page(&out, &model, &recorder.frames)?;
    stdout::print(&format!("{line}\n"))
}

/// Writes the page of `frames` of `model` to `path` (replaced only when complete); the line that
/// says so, with warnings about what is not drawn.
pub fn write_page(path: &Path, model: &Model, frames: &scene::Frames) -> Result<String, CliError> {
    let (scene_json, warnings) = scene::scene_json(model);
    let page = html::page(&scene_json, &frames.to_json(), false);
    let mut file = OutputFile::create(path)?;
    file.write_all(page.as_bytes())?;
    file.commit()?;
    let mut line = format!(
        "viewer written to {} ({} frame{}, {:.1} MB): open it in a browser",
        path.display(),
        frames.len(),
        if frames.len() == 1 { "" } else { "s" },
        page.len() as f64 / 1e6
    );
    for w in warnings {
        line += &format!("\nwarning: viewer: {w}");
    }
    Ok(line)
}

/// `view --live`: serves the page and streams the frames of a run paced at real time.
fn run_live(mut sim: Simulation, request: &Request, state: simulate::InitialState) -> Result<(), CliError> {
    let (q0, v0, ctrl, act) = state;
    if let Some(d) = request.duration {
        if !(d >= 0.0 && d.is_finite()) {
            return Err(CliError::Usage(format!(
                "--duration {d}: give a non-negative, finite number of seconds"
            )));
        }
    }
    sim.set_state(&q0, &v0)?;
    sim.ctrl_mut().copy_from_slice(&ctrl);
    sim.set_act(&act)?;
    let model = sim.model.clone();
    let (scene_json, warnings) = scene::scene_json(&model);
    // The page holds the initial state as its frame 0 (the camera frames it); the stream sends
    // the frames after it.
    let mut recorder = scene::Recorder::new(&model);
    let d = &sim.data;
    recorder.record(
        &model,
        d.time,
        d.qpos.as_slice(),
        d.qvel.as_slice(),
        d.act.as_slice(),
        d.ctrl.as_slice(),
    );
    let page = html::page(&scene_json, &recorder.frames.to_json(), true);
    let server = live::Server::start(request.port, page)?;
    interrupt::watch();
    let until = match request.duration {
        Some(d) => format!("for {d} s of simulated time"),
        None => "until Ctrl-C".into(),
    };
    let mut text =
        format!("lagrange view: serving {} — open it in a browser; simulating {until}\n", server.url());
    for w in warnings {
        text += &format!("warning: viewer: {w}\n");
    }
    stdout::print(&text)?;
    let nslot = model.bodies.len() + model.mocap_pose0.len();
    let interval = 1.0 / request.fps;
    let wall0 = Instant::now();
    let mut result = Ok(());
    for k in 1u64.. {
        let t = k as f64 * interval;
        if request.duration.is_some_and(|d| t > d + 1e-12) || interrupt::requested() {
            break;
        }
        while sim.data.time < t - 0.5 * sim.timestep {
            if let Err(e) = sim.step() {
                result = Err(CliError::from(e));
                break;
            }
        }
        if result.is_err() {
            break;
        }
        let d = &sim.data;
        recorder.record(
            &model,
            d.time,
            d.qpos.as_slice(),
            d.qvel.as_slice(),
            d.act.as_slice(),
            d.ctrl.as_slice(),
        );
        if let Some(frame) = recorder.frames.last_json(nslot, model.nq) {
            server.publish(frame.to_string());
        }
        // Only the last frame is needed: the recorder's buffers restart.
        recorder.frames = scene::Frames::default();
        let ahead = Duration::from_secs_f64(t).saturating_sub(wall0.elapsed());
        // Sleep in slices so that Ctrl-C is seen soon.
        let until = Instant::now() + ahead;
        while Instant::now() < until && !interrupt::requested() {
            std::thread::sleep((until - Instant::now()).min(Duration::from_millis(50)));
        }
    }
    let clients = server.clients();
    server.finish(Duration::from_secs(2));
    result?;
    let how = if interrupt::requested() { "interrupted" } else { "ended" };
    stdout::print(&format!(
        "lagrange view: the live run {how} at t = {:.3} s; {clients} viewer connection{}\n",
        sim.data.time,
        if clients == 1 { "" } else { "s" }
    ))
}
