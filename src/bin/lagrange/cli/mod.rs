//! The command implementations of the `lagrange` binary (docs/architecture.md, "Layers"). They live with the
//! binary, not in the library: argument types are not part of the library API.

pub mod bench;
pub mod bench_native;
pub mod eval;
pub mod info;
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
