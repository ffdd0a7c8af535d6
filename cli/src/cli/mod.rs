//! The command implementations of the `lagrange` binary (docs/architecture.md, "Layers"). They live with the
//! binary, not in the library: argument types are not part of the library API.

pub mod bench;
pub mod bench_native;
pub mod contact_problem;
pub mod eval;
pub mod eval_step;
pub mod eval_stream;
pub mod finite_json;
pub mod info;
pub mod input_schedule;
pub mod interrupt;
pub mod output_file;
pub mod plot_file;
pub mod progress;
pub mod run_plot;
pub mod sensor_columns;
pub mod simulate;
pub mod stdout;
pub mod trajectory_csv;
pub mod view;
pub mod workprec;
pub mod workprec_plot;

use thiserror::Error;

/// Exit status of a run that failed (bad input, a load error, a divergence, an I/O error).
pub const EXIT_FAILURE: u8 = 1;
/// Exit status of `eval` when some states failed (their entries are `{"error": ...}`).
pub const EXIT_STATES_FAILED: u8 = 3;
/// Exit status of a run stopped by SIGINT, SIGTERM or SIGHUP (128 + SIGINT, as shells report).
pub const EXIT_INTERRUPTED: u8 = 130;
/// Exit status when stdout was closed by its reader (128 + SIGPIPE, what a shell reports for a
/// Unix tool that a closed pipe ended).
pub const EXIT_STDOUT_CLOSED: u8 = 141;

/// Errors of the command line.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum CliError {
    #[error(transparent)]
    Load(#[from] lagrange::io::LoadError),
    #[error(transparent)]
    Sim(#[from] lagrange::sim::SimError),
    #[error(transparent)]
    Api(#[from] lagrange::error::InputError),
    #[error("{file}: {detail}")]
    Input { file: String, detail: String },
    #[error("{0}")]
    Usage(String),
    #[error("{file}: {source}")]
    Io {
        file: String,
        #[source]
        source: std::io::Error,
    },
    /// A run that stopped before its end (divergence, output bound), with what became of its
    /// output file.
    #[error("{0}")]
    Stopped(String),
    /// SIGINT, SIGTERM or SIGHUP stopped the run; where it stopped and what was kept.
    #[error("{0}")]
    Interrupted(String),
    /// `eval`: some states gave non-finite results; the reasons of the first few.
    #[error("{failed} of {total} states failed (their results are {{\"error\": ...}} entries): {first}")]
    StatesFailed { failed: usize, total: usize, first: String },
    /// The reader of stdout closed it (e.g. `lagrange eval ... | head`): the run ends quietly.
    #[error("stdout was closed")]
    StdoutClosed,
}

impl CliError {
    /// The process exit status this error ends the run with (docs/cli.md, "Exit status").
    pub fn exit_code(&self) -> u8 {
        match self {
            CliError::Interrupted(_) => EXIT_INTERRUPTED,
            CliError::StatesFailed { .. } => EXIT_STATES_FAILED,
            CliError::StdoutClosed => EXIT_STDOUT_CLOSED,
            _ => EXIT_FAILURE,
        }
    }

    /// The error with `note` appended to its message (what became of the output file).
    pub fn with_note(self, note: &str) -> CliError {
        if note.is_empty() {
            return self;
        }
        match self {
            CliError::Interrupted(m) => CliError::Interrupted(format!("{m}; {note}")),
            e => CliError::Stopped(format!("{}; {note}", in_cli_terms(&e.to_string()))),
        }
    }
}

/// The library's messages name its API (`LoadOptions::package_dirs`, `SimOptions::timestep`, …);
/// on the command line the same choices are flags. Rewrites a message's API terms into the flags
/// that set them, for errors and warnings printed by the binary.
pub fn in_cli_terms(message: &str) -> String {
    const TERMS: [(&str, &str); 9] = [
        ("LoadOptions::disabled_flags += ", "--disable "),
        ("set LoadOptions::accept_nonphysical_inertia", "pass --accept-nonphysical-inertia"),
        ("LoadOptions::accept_nonphysical_inertia", "--accept-nonphysical-inertia"),
        ("LoadOptions::package_dirs is empty", "no --package-dir given"),
        ("LoadOptions::package_dirs", "--package-dir"),
        ("LoadOptions::floating", "--floating"),
        ("LoadOptions::clamp_effort", "--clamp-effort"),
        ("SimOptions::timestep", "--dt"),
        ("SimOptions::integrator = ", "--integrator "),
    ];
    TERMS.iter().fold(message.to_string(), |m, (api, flag)| m.replace(api, flag))
}
