//! The command implementations behind `src/bin/lagrange.rs` (DESIGN.md, layer 9), kept in the
//! library so they are testable.

pub mod bench;
pub mod eval;
pub mod info;
pub mod simulate;

use thiserror::Error;

/// Errors of the command line.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum CliError {
    #[error(transparent)]
    Load(#[from] crate::io::LoadError),
    #[error(transparent)]
    Sim(#[from] crate::sim::SimError),
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
