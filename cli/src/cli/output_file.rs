//! Output files that are never destroyed (`simulate --out`, `workprec --plot`,
//! `--dump-reference`). A file is written under a temporary name in its target's folder
//! (`traj.tmp-XXXXXX.csv`, tempfile's `NamedTempFile`) and renamed onto the target only once it
//! is complete ([`OutputFile::commit`]), so a previous file is replaced by a complete one or not
//! at all. What a run that stopped early computed is kept under a name that says so
//! ([`partial_path`]: `traj.partial.csv`) by [`OutputFile::keep_partial`]. A target that exists
//! and is not a regular file (a device such as `/dev/stdout` or `/dev/full`, a FIFO) is written in
//! place: there is nothing to rename onto it.
//!
//! [`RowFile`] writes such a file row by row and hands the file whole rows only, so it ends on a
//! row boundary whatever stops the run (a write error is cut back to the last whole row), and it
//! bounds the file's size.

use super::CliError;
use std::fs::{File, Permissions};
use std::io::Write;
use std::path::{Path, PathBuf};
use tempfile::NamedTempFile;

/// `dir/traj.partial.csv` for `dir/traj.csv` (`name.partial` without an extension).
pub fn partial_path(target: &Path) -> PathBuf {
    let stem = target.file_stem().map_or_else(|| "output".into(), |s| s.to_string_lossy().into_owned());
    let name = match target.extension() {
        Some(ext) => format!("{stem}.partial.{}", ext.to_string_lossy()),
        None => format!("{stem}.partial"),
    };
    target.with_file_name(name)
}

enum Kind {
    /// A new or regular file: written under a temporary name beside `dest` (the target with
    /// symbolic links resolved), renamed onto it when complete.
    Replace {
        tmp: NamedTempFile,
        dest: PathBuf,
        /// The previous file's permissions, kept by the new one.
        previous: Option<Permissions>,
    },
    /// Not a regular file (device, FIFO): written in place.
    Direct(File),
}

/// One output file being written (see the module doc).
pub struct OutputFile {
    /// The target as the user named it (for messages).
    target: PathBuf,
    kind: Kind,
}

impl OutputFile {
    /// Starts writing `target`: a temporary file in its folder (or the target itself when it is
    /// a device or a FIFO). The target is not touched.
    pub fn create(target: &Path) -> Result<Self, CliError> {
        let io = |source| CliError::Io { file: target.display().to_string(), source };
        let metadata = std::fs::metadata(target).ok();
        if let Some(m) = &metadata {
            if !m.is_file() {
                if m.is_dir() {
                    return Err(CliError::Usage(format!(
                        "{}: is a folder; give a file name",
                        target.display()
                    )));
                }
                let file = std::fs::OpenOptions::new().write(true).open(target).map_err(io)?;
                return Ok(OutputFile { target: target.to_path_buf(), kind: Kind::Direct(file) });
            }
        }
        // Through a symbolic link to its file: the link stays, the file it names is replaced.
        let dest = match metadata {
            Some(_) => std::fs::canonicalize(target).map_err(io)?,
            None => target.to_path_buf(),
        };
        let dir = match dest.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let stem = dest.file_stem().map_or_else(|| "output".into(), |s| s.to_string_lossy().into_owned());
        let suffix = dest.extension().map_or_else(String::new, |e| format!(".{}", e.to_string_lossy()));
        let prefix = format!("{stem}.tmp-");
        let mut builder = tempfile::Builder::new();
        builder.prefix(&prefix).suffix(&suffix);
        // A new file gets the permissions of any file the user creates (0666 less the umask), not
        // the temporary file's 0600.
        #[cfg(unix)]
        let mode = {
            use std::os::unix::fs::PermissionsExt;
            Permissions::from_mode(0o666)
        };
        #[cfg(unix)]
        builder.permissions(mode);
        let tmp = builder.tempfile_in(&dir).map_err(|source| CliError::Io {
            file: format!("{} (a temporary file in {})", target.display(), dir.display()),
            source,
        })?;
        let previous = metadata.map(|m| m.permissions());
        Ok(OutputFile { target: target.to_path_buf(), kind: Kind::Replace { tmp, dest, previous } })
    }

    /// The target as the user named it, for messages.
    pub fn label(&self) -> String {
        self.target.display().to_string()
    }

    /// Whether the target existed (as a file) before this run: it still does, untouched, until
    /// [`OutputFile::commit`].
    pub fn replaces_a_file(&self) -> bool {
        matches!(&self.kind, Kind::Replace { previous: Some(_), .. })
    }

    /// The open file being written.
    pub fn file(&mut self) -> &mut File {
        match &mut self.kind {
            Kind::Replace { tmp, .. } => tmp.as_file_mut(),
            Kind::Direct(f) => f,
        }
    }

    /// Writes `bytes` as the whole content.
    pub fn write_all(&mut self, bytes: &[u8]) -> Result<(), CliError> {
        let file = self.label();
        self.file().write_all(bytes).map_err(|source| CliError::Io { file, source })
    }

    /// The content is complete: renames it onto the target (which it replaces), on disk first.
    pub fn commit(self) -> Result<(), CliError> {
        self.persist_to(None).map(|_| ())
    }

    /// The run stopped early: keeps what was written as [`partial_path`] of the target (replacing
    /// an earlier partial file) and leaves the target untouched; Ok(None) for a target written in
    /// place.
    pub fn keep_partial(self) -> Result<Option<PathBuf>, CliError> {
        self.persist_to(Some(()))
    }

    fn persist_to(self, partial: Option<()>) -> Result<Option<PathBuf>, CliError> {
        let label = self.label();
        match self.kind {
            Kind::Direct(_) => Ok(None),
            Kind::Replace { tmp, dest, previous } => {
                let io = |source| CliError::Io { file: label.clone(), source };
                tmp.as_file().sync_all().map_err(io)?;
                if let (Some(p), None) = (previous, partial) {
                    tmp.as_file().set_permissions(p).map_err(io)?;
                }
                let to = match partial {
                    Some(()) => partial_path(&dest),
                    None => dest,
                };
                tmp.persist(&to).map_err(|e| CliError::Io {
                    file: format!("{label} (renaming the complete file onto {})", to.display()),
                    source: e.error,
                })?;
                Ok(partial.map(|()| to))
            }
        }
    }
}

/// Why a row was not written.
pub enum RowError {
    /// The file would exceed its size bound (the row is dropped).
    Limit,
    /// Writing failed (the file is cut back to its last whole row).
    Io(std::io::Error),
}

/// Bytes gathered before they go to the file, in whole rows.
const CHUNK: usize = 1 << 16;

/// A file written in whole rows with a size bound (see the module doc). Rows are formatted into
/// a buffer whose capacity is kept (no allocation per row once the longest row has been seen).
pub struct RowFile {
    out: OutputFile,
    buf: Vec<u8>,
    /// The end of the last whole row in `buf`.
    complete: usize,
    /// Bytes in the file (whole rows).
    written: u64,
    /// Most bytes the file may hold (`u64::MAX`: no bound).
    limit: u64,
}

impl RowFile {
    /// Starts writing `target` (see [`OutputFile::create`]) with at most `limit` bytes.
    pub fn create(target: &Path, limit: u64) -> Result<Self, CliError> {
        Ok(RowFile {
            out: OutputFile::create(target)?,
            buf: Vec::with_capacity(2 * CHUNK),
            complete: 0,
            written: 0,
            limit,
        })
    }

    /// The target as the user named it.
    pub fn label(&self) -> String {
        self.out.label()
    }

    /// Whether a previous file is kept until the run completes.
    pub fn replaces_a_file(&self) -> bool {
        self.out.replaces_a_file()
    }

    /// The buffer the current row is formatted into (`write!` appends).
    pub fn row(&mut self) -> &mut Vec<u8> {
        &mut self.buf
    }

    /// The current row is complete: counts it against the bound and hands full chunks to the
    /// file.
    pub fn end_row(&mut self) -> Result<(), RowError> {
        if self.written.saturating_add(self.buf.len() as u64) > self.limit {
            self.buf.truncate(self.complete);
            return Err(RowError::Limit);
        }
        self.complete = self.buf.len();
        if self.complete >= CHUNK {
            self.flush_rows().map_err(RowError::Io)?;
        }
        Ok(())
    }

    /// Writes the whole rows buffered; on failure cuts the file back to its last whole row.
    fn flush_rows(&mut self) -> std::io::Result<()> {
        self.buf.truncate(self.complete);
        let result = self.out.file().write_all(&self.buf);
        match result {
            Ok(()) => {
                self.written += self.buf.len() as u64;
                self.buf.clear();
                self.complete = 0;
                Ok(())
            }
            Err(e) => {
                // A write cut short (a full disk) may have left part of a row: drop it. (A device
                // written in place cannot be cut back; there is nothing to keep there.)
                let _ = self.out.file().set_len(self.written);
                self.buf.clear();
                self.complete = 0;
                Err(e)
            }
        }
    }

    /// All rows written: flushes them and replaces the target.
    pub fn commit(mut self) -> Result<(), CliError> {
        let label = self.label();
        self.flush_rows().map_err(|source| CliError::Io { file: label, source })?;
        self.out.commit()
    }

    /// The run stopped: keeps the whole rows written as the partial file (see
    /// [`OutputFile::keep_partial`]); a row in progress is dropped.
    pub fn keep_partial(mut self) -> Result<Option<PathBuf>, CliError> {
        // What could not be written is lost; what was, is kept.
        let _ = self.flush_rows();
        self.out.keep_partial()
    }
}
