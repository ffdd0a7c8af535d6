//! The command implementations of the `lagrange` binary (docs/architecture.md, "Layers"). They live with the
//! binary, not in the library: argument types are not part of the library API.

pub mod bench;
pub mod bench_native;
pub mod eval;
pub mod info;
pub mod sensor_columns;
pub mod simulate;
pub mod workprec;
pub mod workprec_plot;

use thiserror::Error;

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
