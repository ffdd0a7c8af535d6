//! Standard output through a locked, buffered writer whose errors are typed instead of the
//! panics of `print!`: a reader that closed the pipe (`lagrange eval ... | head`) ends the run
//! quietly ([`CliError::StdoutClosed`], exit status 141 as for a Unix tool a closed pipe ended);
//! any other failure (a full disk: stdout redirected to `/dev/full`) is an error naming `<stdout>`.

use super::CliError;
use serde::Serialize;
use std::io::{BufWriter, StdoutLock, Write};

/// The name stdout goes by in error messages.
pub const STDOUT: &str = "<stdout>";

/// The typed error of a failed write to stdout.
pub fn stdout_error(source: std::io::Error) -> CliError {
    if source.kind() == std::io::ErrorKind::BrokenPipe {
        CliError::StdoutClosed
    } else {
        CliError::Io { file: STDOUT.to_string(), source }
    }
}

/// Locked, buffered stdout. Call [`Stdout::finish`] to flush and learn whether everything
/// arrived (dropping it flushes too, silently).
pub struct Stdout(BufWriter<StdoutLock<'static>>);

impl Default for Stdout {
    fn default() -> Self {
        Self::lock()
    }
}

impl Stdout {
    /// Locks stdout for this writer's lifetime.
    pub fn lock() -> Self {
        Stdout(BufWriter::with_capacity(1 << 16, std::io::stdout().lock()))
    }

    /// Writes `text` as it is.
    pub fn print(&mut self, text: &str) -> Result<(), CliError> {
        self.0.write_all(text.as_bytes()).map_err(stdout_error)
    }

    /// Writes `value` as compact JSON (no newline).
    pub fn json(&mut self, value: &impl Serialize) -> Result<(), CliError> {
        serde_json::to_writer(&mut self.0, value).map_err(|e| stdout_error(e.into()))
    }

    /// Flushes what is buffered.
    pub fn finish(mut self) -> Result<(), CliError> {
        self.0.flush().map_err(stdout_error)
    }
}

/// Writes `text` to stdout and flushes it.
pub fn print(text: &str) -> Result<(), CliError> {
    let mut out = Stdout::lock();
    out.print(text)?;
    out.finish()
}
