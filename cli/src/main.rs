//! The `lagrange` command line: `info`, `eval`, `simulate`, `bench`, `workprec`, `view`; with no arguments it simulates the
//! embedded default scene (the Go1 quadruped standing on its servos, soft contacts) and prints the summary.
//! Exit status (docs/cli.md, "Exit status"): 0 success, 1 error, 2 command-line usage (clap), 3 `eval` with
//! failed states, 130 interrupted by a signal, 141 stdout closed by its reader.

use clap::{Parser, Subcommand, ValueEnum};
mod cli;
use cli::{bench, bench_native, eval, info, simulate, view, workprec};
use lagrange::constraint::ConstraintMode;
use lagrange::forward::DriftCorrection;
use lagrange::integrate::IntegratorKind;
use lagrange::io::LoadOptions;
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "lagrange",
    version,
    about = "Multibody dynamics: load URDF and MJCF models, evaluate M, bias, ABA, simulate"
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    /// Folder to search for `package://NAME/...` (holds NAME/); repeatable; ROS_PACKAGE_PATH is
    /// searched after these.
    #[arg(long = "package-dir", global = true)]
    package_dirs: Vec<PathBuf>,
    /// Attach the URDF root link to the world with a free joint `root_joint` (like Pinocchio's
    /// free-flyer) instead of welding it.
    #[arg(long, global = true)]
    floating: bool,
    /// Use inertia tensors that violate the triangle inequality or have negative principal
    /// moments as written (as Pinocchio does), with a warning each, instead of refusing the model.
    #[arg(long, global = true)]
    accept_nonphysical_inertia: bool,
    /// Constraint model: `exact` (rigid, Lagrange multipliers) or `soft` (MuJoCo's convex model:
    /// solref/solimp, pyramidal or elliptic cones, Newton/CG/PGS). Default: soft for MJCF, exact
    /// for URDF.
    #[arg(long, value_enum, global = true)]
    constraints: Option<ConstraintsArg>,
    /// Turn off an `<option><flag>` switch by its MJCF name (limit, equality, constraint,
    /// spring, damper, gravity, …), for URDF and MJCF alike; repeatable.
    #[arg(long = "disable", global = true, value_name = "FLAG")]
    disabled_flags: Vec<String>,
    /// Clamp the torque applied to each URDF joint (actuator plus applied forces, e.g. a
    /// controller's) to its `<limit effort>`; MJCF models use `actuatorfrcrange` instead.
    #[arg(long, global = true)]
    clamp_effort: bool,
    /// The most contacts one collision pass keeps, instead of the default budget (500 with the
    /// exact mode, PGS or no-slip, whose rows × rows matrices grow with its square), within
    /// memory; contacts beyond it are dropped, counted and warned about.
    #[arg(long, global = true, value_name = "N", value_parser = clap::value_parser!(u32).range(1..))]
    max_contacts: Option<u32>,
}

#[derive(Clone, Copy, ValueEnum)]
enum ConstraintsArg {
    Exact,
    Soft,
}

impl From<ConstraintsArg> for ConstraintMode {
    fn from(a: ConstraintsArg) -> Self {
        match a {
            ConstraintsArg::Exact => ConstraintMode::Exact,
            ConstraintsArg::Soft => ConstraintMode::Soft,
        }
    }
}

#[derive(Subcommand)]
enum Command {
    /// Median time to load the model (parse + compile) and of FK, RNEA, CRBA and ABA on it.
    Bench {
        model: PathBuf,
        /// One JSON line instead of text.
        #[arg(long)]
        json: bool,
    },
    /// Side-by-side native benchmark, lagrange's part (run by validation/bench_native/run):
    /// per-batch times of FK, RNEA, CRBA, ABA and LᵀDL factor + solve over a states file, for
    /// `OP BUDGET_MS` commands read from stdin.
    #[command(hide = true)]
    BenchNative {
        model: PathBuf,
        /// Plain-text states file written by validation/bench_native/bench_native.py.
        #[arg(long)]
        states: PathBuf,
        /// Which block of the states file (its `robot` name).
        #[arg(long)]
        robot: String,
    },
    /// Print bodies, joints, sizes and the simulation plan.
    Info {
        model: PathBuf,
        /// Machine-readable JSON instead of text.
        #[arg(long)]
        json: bool,
    },
    /// Evaluate M, bias, ABA, poses, energies and centre of mass for a batch of states.
    Eval {
        model: PathBuf,
        /// JSON file `{"states": [{"q": [...], "v": [...], "tau": [...]}]}`.
        #[arg(long)]
        states: PathBuf,
        /// Accepted for symmetry with `info`: the output is always JSON.
        #[arg(long)]
        json: bool,
        /// Also output the Jacobian of this frame (world-aligned, rows: linear then angular);
        /// repeatable.
        #[arg(long = "jacobian")]
        jacobians: Vec<String>,
        /// Only the smooth kernels (M, bias, ABA's qacc, poses, energies, Jacobians): no
        /// `forward` block and no sensors.
        #[arg(long)]
        kernels_only: bool,
        /// Instead: N steps of the model's integrator from each state (as `mj_step` from
        /// MuJoCo's state): qpos, qvel, act, time after them, the contacts of the last step's
        /// collision pass, and the wall times of the steps and of one collision pass.
        #[arg(long, value_name = "N")]
        step: Option<u32>,
        /// Add `"derivatives"` to each state's result (docs/derivatives.md): `all` (RNEA, ABA,
        /// smooth forward dynamics and the step's transition Jacobians A, B), `smooth` (without
        /// the transition) or `hybrid` (as `all`, the transition's velocity and control columns
        /// analytic).
        #[arg(long, value_enum, num_args = 0..=1, default_missing_value = "all")]
        derivatives: Option<eval::Derivatives>,
        /// With `--step N` and `--constraints exact`: write to FILE the exact mode's constraint
        /// problem at the state after the steps (Delassus matrix, free row accelerations, row laws,
        /// the solver's forces, and its Gauss–Seidel and ADMM solves again from a cold start,
        /// timed; docs/constraints.md, "Exporting the exact mode's problem").
        #[arg(long, value_name = "FILE")]
        dump_contact_problem: Option<PathBuf>,
    },
    /// Simulate from a keyframe, a given state, or the model's reference configuration at rest,
    /// under gravity, with zero torques.
    Simulate {
        model: PathBuf,
        /// Simulated time in seconds.
        #[arg(long, default_value_t = 1.0, allow_hyphen_values = true)]
        duration: f64,
        /// Step size in seconds (default: the model's `<option timestep>`, 0.002 for URDF).
        #[arg(long, allow_hyphen_values = true)]
        dt: Option<f64>,
        /// Integrator (default: the model's `<option integrator>`, Euler for URDF).
        #[arg(long, value_enum)]
        integrator: Option<IntegratorArg>,
        /// Relative tolerance of `--integrator adaptive` (default 1e-8).
        #[arg(long, allow_hyphen_values = true)]
        rtol: Option<f64>,
        /// Absolute tolerance of `--integrator adaptive` (default 1e-10).
        #[arg(long, allow_hyphen_values = true)]
        atol: Option<f64>,
        /// Print one JSON summary object instead of text.
        #[arg(long)]
        json: bool,
        /// Do not project constrained states back onto φ = 0, J v = 0 after each step.
        #[arg(long)]
        no_projection: bool,
        /// Baumgarte stabilization gains α,β (J q̈ + J̇v + α J v + β φ = 0), e.g. `--baumgarte 20,100`.
        #[arg(long)]
        baumgarte: Option<String>,
        /// Start from this MJCF keyframe (`<key name>`); --q0/--v0 override its parts.
        #[arg(long)]
        keyframe: Option<String>,
        /// Initial configuration, comma-separated (nq values; default: the model's qpos0).
        #[arg(long, allow_hyphen_values = true)]
        q0: Option<String>,
        /// Initial velocity, comma-separated (nv values; default: zero).
        #[arg(long, allow_hyphen_values = true)]
        v0: Option<String>,
        /// Constant controls, comma-separated (one per actuator, MuJoCo's order; default: the
        /// keyframe's `ctrl`, else zero).
        #[arg(long, allow_hyphen_values = true)]
        ctrl: Option<String>,
        /// Controls over time: a CSV file with header `time,ACTUATOR,...` (any subset of the
        /// actuators; interpolated as --input-interp says, the last row held).
        #[arg(long, value_name = "FILE")]
        ctrl_file: Option<PathBuf>,
        /// Applied joint forces over time (MuJoCo's qfrc_applied; drives URDF robots): a CSV file
        /// with header `time,JOINT,...` (a one-dof joint by name, any dof as JOINT[k]).
        #[arg(long, value_name = "FILE")]
        tau_file: Option<PathBuf>,
        /// Values of --ctrl-file and --tau-file between their rows: `linear` interpolation or
        /// `hold` (zero-order hold).
        #[arg(long, value_enum, default_value_t = cli::input_schedule::Interp::Linear)]
        input_interp: cli::input_schedule::Interp,
        /// Write the trajectory to this CSV file: time, q, v, act, ctrl, actuator_force, energy,
        /// constraint violation and sensors per step.
        /// The file is replaced only when the run completes; a run that stops early keeps its
        /// rows in NAME.partial.csv.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Most bytes the --out CSV may take: a run whose estimate exceeds it is refused before it
        /// starts, one that reaches it stops (rows kept in NAME.partial.csv); 0: no bound.
        #[arg(long, value_name = "BYTES", default_value_t = simulate::DEFAULT_MAX_OUTPUT_BYTES)]
        max_output_bytes: u64,
        /// Write the run as a self-contained viewer page (HTML: poses, contact forces, joint
        /// values per frame; docs/viewer.md).
        #[arg(long, value_name = "FILE")]
        view: Option<PathBuf>,
        /// Frames per second of simulated time kept for --view.
        #[arg(long, default_value_t = simulate::DEFAULT_VIEW_FPS, allow_hyphen_values = true)]
        view_fps: f64,
        /// Plot joint positions, energy, constraint violation and contact count over time
        /// (.svg or .png).
        #[arg(long, value_name = "FILE")]
        plot: Option<PathBuf>,
    },
    /// Show the model (or a trajectory, or a live simulation) in a browser: writes one
    /// self-contained HTML page, or serves it on 127.0.0.1 with --live (docs/viewer.md).
    View {
        model: PathBuf,
        /// A `simulate --out` CSV of this model to play (slider, play button, contact forces).
        #[arg(long)]
        trajectory: Option<PathBuf>,
        /// Show this keyframe (the live run starts from it; its controls act on a trajectory's
        /// recomputed contact forces).
        #[arg(long)]
        keyframe: Option<String>,
        /// Constant controls, comma-separated (one per actuator), over the keyframe's.
        #[arg(long, allow_hyphen_values = true)]
        ctrl: Option<String>,
        /// The page to write (default: MODEL's file name with .html, in the current folder).
        #[arg(long, value_name = "FILE", conflicts_with = "live")]
        out: Option<PathBuf>,
        /// Serve the page on 127.0.0.1 and stream a simulation run in real time (server-sent
        /// events); prints the URL.
        #[arg(long)]
        live: bool,
        /// The --live server's port (0: any free port).
        #[arg(long, default_value_t = view::DEFAULT_PORT, requires = "live")]
        port: u16,
        /// Simulated seconds of the --live run (default: until Ctrl-C).
        #[arg(long, requires = "live", allow_hyphen_values = true)]
        duration: Option<f64>,
        /// Frames per second kept from --trajectory or streamed by --live.
        #[arg(long, default_value_t = simulate::DEFAULT_VIEW_FPS, allow_hyphen_values = true)]
        fps: f64,
    },
    /// Work-precision: each integrator's error against a reference solution (adaptive, rtol
    /// 1e-13) and its CPU time, over step sizes and tolerances; table, JSON, log-log plot.
    Workprec {
        /// The model (not needed with --from-json).
        #[arg(required_unless_present = "from_json")]
        model: Option<PathBuf>,
        /// Integrators, comma-separated: euler, rk4, implicitfast, adaptive (default: all).
        #[arg(long, allow_hyphen_values = true)]
        integrators: Option<String>,
        /// Step sizes of the fixed-step integrators, comma-separated; each must divide the
        /// largest (default: the model's timestep × 4, 2, 1, 1/2, 1/4, 1/8).
        #[arg(long, allow_hyphen_values = true)]
        dts: Option<String>,
        /// Relative tolerances of the adaptive integrator, comma-separated (atol = rtol/100;
        /// default 1e-4,1e-6,1e-8,1e-10).
        #[arg(long, allow_hyphen_values = true)]
        rtols: Option<String>,
        /// Simulated time in seconds, a whole number of the largest step (default: 2 s).
        #[arg(long, allow_hyphen_values = true)]
        duration: Option<f64>,
        /// Timed repeats of each run; the CPU time is their minimum.
        #[arg(long, default_value_t = 3)]
        repeats: u32,
        /// Print the JSON object {model, duration, reference, rows} instead of the table.
        #[arg(long)]
        json: bool,
        /// Write a log-log plot of error against CPU time (.svg or .png).
        #[arg(long, value_name = "FILE")]
        plot: Option<PathBuf>,
        /// Start from this keyframe (default: the model's first keyframe, else qpos0 at rest).
        #[arg(long)]
        keyframe: Option<String>,
        /// Initial configuration, comma-separated (overrides the keyframe's).
        #[arg(long, allow_hyphen_values = true)]
        q0: Option<String>,
        /// Initial velocity, comma-separated (overrides the keyframe's).
        #[arg(long, allow_hyphen_values = true)]
        v0: Option<String>,
        /// Write the reference trajectory at the sample times and the run's settings to this
        /// JSON file (input of validation/workprec_mujoco.py).
        #[arg(long, value_name = "FILE")]
        dump_reference: Option<PathBuf>,
        /// Add the rows of another `workprec --json` file (e.g. MuJoCo's) to the table, JSON and
        /// plot; repeatable.
        #[arg(long = "extra-rows", value_name = "FILE")]
        extra_rows: Vec<PathBuf>,
        /// Take the rows from a saved `workprec --json` output instead of measuring a model.
        #[arg(long, value_name = "FILE", conflicts_with_all = ["model", "integrators", "dts", "rtols", "duration", "keyframe", "q0", "v0", "dump_reference"])]
        from_json: Option<PathBuf>,
    },
}

#[derive(Clone, Copy, ValueEnum)]
enum IntegratorArg {
    /// Semi-implicit Euler (first order).
    Euler,
    /// Classical Runge–Kutta (fourth order).
    Rk4,
    /// MuJoCo's implicitfast (velocity-implicit in the joint-damping derivatives).
    Implicitfast,
    /// MuJoCo's implicit (implicitfast plus the Coriolis/centrifugal velocity derivatives).
    Implicit,
    /// Variational (discrete Euler–Lagrange, trapezoidal; second order, symplectic,
    /// momentum-preserving; equality constraints held by multipliers).
    Variational,
    /// Dormand–Prince 5(4) with error control (rtol 1e-8, atol 1e-10), internal steps within
    /// each --dt interval.
    Adaptive,
}

impl From<IntegratorArg> for IntegratorKind {
    fn from(a: IntegratorArg) -> Self {
        match a {
            IntegratorArg::Euler => IntegratorKind::Euler,
            IntegratorArg::Rk4 => IntegratorKind::Rk4,
            IntegratorArg::Adaptive => IntegratorKind::Adaptive,
            IntegratorArg::Implicitfast => IntegratorKind::ImplicitFast,
            IntegratorArg::Implicit => IntegratorKind::Implicit,
            IntegratorArg::Variational => IntegratorKind::Variational,
        }
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let options = LoadOptions {
        package_dirs: cli.package_dirs,
        floating: cli.floating,
        accept_nonphysical_inertia: cli.accept_nonphysical_inertia,
        disabled_flags: cli.disabled_flags,
        clamp_effort: cli.clamp_effort,
        max_contacts: cli.max_contacts.map(|n| n as usize),
    };
    let mode = cli.constraints.map(ConstraintMode::from);
    let result = match cli.command {
        None => simulate::default_run(),
        Some(Command::Info { model, json }) => info::run(&model, &options, json, mode),
        Some(Command::Bench { model, json }) => bench::run(&model, &options, json),
        Some(Command::BenchNative { model, states, robot }) => {
            bench_native::run(&model, &options, &states, &robot)
        }
        Some(Command::Workprec {
            model,
            integrators,
            dts,
            rtols,
            duration,
            repeats,
            json,
            plot,
            keyframe,
            q0,
            v0,
            dump_reference,
            extra_rows,
            from_json,
        }) => {
            let request = workprec::Request {
                model,
                from_json,
                integrators,
                dts,
                rtols,
                duration,
                repeats,
                json,
                plot,
                keyframe,
                q0,
                v0,
                dump_reference,
                extra_rows,
                constraints: mode,
            };
            workprec::run(&options, &request)
        }
        Some(Command::View { model, trajectory, keyframe, ctrl, out, live, port, duration, fps }) => {
            let request = view::Request {
                trajectory,
                keyframe,
                ctrl,
                out,
                live,
                port,
                duration,
                fps,
                constraints: mode,
            };
            view::run(&model, &options, &request)
        }
        Some(Command::Eval {
            model,
            states,
            json: _,
            jacobians,
            kernels_only,
            step,
            derivatives,
            dump_contact_problem,
        }) => eval::run(
            &model,
            &options,
            &states,
            &jacobians,
            mode,
            kernels_only,
            step,
            derivatives,
            dump_contact_problem.as_deref(),
        ),
        Some(Command::Simulate {
            model,
            duration,
            dt,
            integrator,
            rtol,
            atol,
            json,
            no_projection,
            baumgarte,
            keyframe,
            q0,
            v0,
            ctrl,
            ctrl_file,
            tau_file,
            input_interp,
            out,
            max_output_bytes,
            view,
            view_fps,
            plot,
        }) => simulate::parse_baumgarte(baumgarte.as_deref()).and_then(|baumgarte| {
            let integrator = integrator.map(IntegratorKind::from);
            let tolerances = simulate::parse_tolerances(integrator, rtol, atol)?;
            let drift =
                DriftCorrection { projection: !no_projection, baumgarte, ..DriftCorrection::default() };
            let request = simulate::Request {
                duration,
                dt,
                integrator,
                tolerances,
                constraints: mode,
                drift,
                json,
                keyframe,
                q0,
                v0,
                ctrl,
                ctrl_file,
                tau_file,
                input_interp,
                out,
                max_output_bytes,
                view,
                view_fps,
                plot,
            };
            simulate::run_file(&model, &options, &request)
        }),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // stderr's own failures are ignored (no panic): there is nowhere left to report them.
            let message = cli::in_cli_terms(&e.to_string());
            let _ = match &e {
                // A closed stdout ends the run quietly, as for a Unix tool in a pipe.
                cli::CliError::StdoutClosed => Ok(()),
                cli::CliError::Interrupted(_) => writeln!(std::io::stderr(), "lagrange: {message}"),
                _ => writeln!(std::io::stderr(), "error: {message}"),
            };
            ExitCode::from(e.exit_code())
        }
    }
}
