//! Running the `lagrange` binary from the tests of the command line, and the repository root
//! they run in (where `models/` and `tests/data/` are). The tolerances are the library's
//! (`tests/common/mod.rs`, included by each test file as `common`).

use std::path::{Path, PathBuf};

/// The repository root (the workspace's, one folder above this crate).
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().expect("cli/ sits in the repository").to_path_buf()
}

/// Runs the `lagrange` binary from the repository root: (success, stdout, stderr).
pub fn lagrange(args: &[&str]) -> (bool, String, String) {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_lagrange"))
        .args(args)
        .current_dir(root())
        .output()
        .expect("the binary runs");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into(),
        String::from_utf8_lossy(&out.stderr).into(),
    )
}
