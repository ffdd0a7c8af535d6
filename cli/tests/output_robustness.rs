//! The command line's output guarantees (docs/cli.md, "Output files, interruption and exit status"), end to end on
//! small inputs: an interrupted or killed `simulate` leaves the previous `--out` file intact (and
//! an interrupted one keeps its whole rows in `NAME.partial.csv`); a diverging run keeps finite
//! rows only; a full disk and a closed pipe are a typed error and a quiet exit, never a panic;
//! `eval` turns a non-finite result into an error entry; sizes that cannot fit are refused.
#![cfg(unix)]

mod run;

use run::{lagrange, root};
use serde_json::Value;
use std::io::Read;
use std::os::unix::process::ExitStatusExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// A fresh, empty folder for one test.
fn folder(name: &str) -> PathBuf {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("lagrange-robust-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The `lagrange` binary with `args`, from the repository root.
fn command(args: &[&str]) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_lagrange"));
    c.args(args).current_dir(root());
    c
}

/// Files of `dir` whose name starts with `prefix`.
fn files_starting(dir: &Path, prefix: &str) -> Vec<PathBuf> {
    let mut out: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.file_name().unwrap().to_string_lossy().starts_with(prefix))
        .collect();
    out.sort();
    out
}

/// Asserts that `text` is a CSV of whole rows: a header, then rows of as many finite numbers;
/// returns the number of rows.
fn assert_whole_finite_rows(text: &str) -> usize {
    assert!(text.ends_with('\n'), "the file ends inside a row: {:?}", &text[text.len().saturating_sub(80)..]);
    let mut lines = text.lines();
    let columns = lines.next().expect("a header").split(',').count();
    let mut rows = 0;
    for line in lines {
        let values: Vec<f64> = line.split(',').map(|x| x.parse().expect("a number")).collect();
        assert_eq!(values.len(), columns, "a row of {} values under {columns} columns: {line}", values.len());
        assert!(values.iter().all(|x| x.is_finite()), "a non-finite value: {line}");
        rows += 1;
    }
    rows
}

/// A `simulate` that runs far longer than the test, writing `out`.
fn long_simulation(out: &Path) -> Command {
    let mut c = command(&[
        "simulate",
        "models/textbook/double_pendulum.urdf",
        "--q0",
        "1,1",
        "--dt",
        "1e-4",
        "--duration",
        "1e7",
        "--max-output-bytes",
        "0",
        "--out",
        out.to_str().unwrap(),
    ]);
    c.stdout(Stdio::piped()).stderr(Stdio::piped());
    c
}

/// Waits until `child` has written rows to its temporary file in `dir` (the target is untouched
/// meanwhile); a guard against a hang, not a timing check.
fn wait_until_written(dir: &Path, child: &mut Child) {
    let deadline = Instant::now() + Duration::from_secs(300);
    loop {
        let written = files_starting(dir, "traj.tmp-")
            .iter()
            .any(|p| std::fs::metadata(p).map(|m| m.len() > 0).unwrap_or(false));
        if written {
            return;
        }
        if Instant::now() > deadline {
            let _ = child.kill();
            let _ = child.wait();
            panic!("simulate wrote nothing");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

fn signal(child: &std::process::Child, sig: i32) {
    // SAFETY: kill(2) on the id of a child process this test spawned and has not reaped.
    let rc = unsafe { libc::kill(child.id() as libc::pid_t, sig) };
    assert_eq!(rc, 0);
}

#[test]
fn an_interrupted_simulation_keeps_the_previous_file_and_its_whole_rows_as_partial() {
    let dir = folder("sigint");
    let out = dir.join("traj.csv");
    std::fs::write(&out, "the previous trajectory\n").unwrap();
    let mut child = long_simulation(&out).spawn().unwrap();
    wait_until_written(&dir, &mut child);
    signal(&child, libc::SIGINT);
    let result = child.wait_with_output().unwrap();
    let (stdout, stderr) = (String::from_utf8_lossy(&result.stdout), String::from_utf8_lossy(&result.stderr));
    assert_eq!(result.status.code(), Some(130), "{stderr}");
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "the previous trajectory\n");
    let partial = std::fs::read_to_string(dir.join("traj.partial.csv")).unwrap();
    let rows = assert_whole_finite_rows(&partial);
    assert!(rows >= 1);
    // The summary says where the run stopped; stderr what became of the files.
    assert!(stdout.contains("interrupted by a signal at t = "), "{stdout}");
    assert!(stdout.contains("of 100000000000 steps"), "{stdout}");
    assert!(stderr.contains("traj.partial.csv") && stderr.contains("traj.csv is untouched"), "{stderr}");
    assert!(files_starting(&dir, "traj.tmp-").is_empty(), "no temporary file is left");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_killed_simulation_leaves_the_previous_file_intact() {
    let dir = folder("sigkill");
    let out = dir.join("traj.csv");
    std::fs::write(&out, "the previous trajectory\n").unwrap();
    let mut child = long_simulation(&out).spawn().unwrap();
    wait_until_written(&dir, &mut child);
    signal(&child, libc::SIGKILL);
    let result = child.wait_with_output().unwrap();
    assert_eq!(result.status.signal(), Some(libc::SIGKILL));
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "the previous trajectory\n");
    // What it had written stays in its temporary file, beside the target; nothing claims to be
    // a partial result.
    assert_eq!(files_starting(&dir, "traj.tmp-").len(), 1);
    assert!(files_starting(&dir, "traj.partial").is_empty());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_diverging_simulation_keeps_finite_rows_and_the_previous_file() {
    let dir = folder("diverge");
    let out = dir.join("traj.csv");
    std::fs::write(&out, "the previous trajectory\n").unwrap();
    // v0 = 1e150 rad/s: the kinetic energy overflows to inf at the third step, before the state
    // itself is NaN.
    let (ok, _, err) = lagrange(&[
        "simulate",
        "models/textbook/double_pendulum.urdf",
        "--v0",
        "1e150,0",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!ok);
    assert!(err.contains("diverged at t = 0.006 s (step 3): the energy is inf"), "{err}");
    assert!(err.contains("traj.partial.csv") && err.contains("traj.csv is untouched"), "{err}");
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "the previous trajectory\n");
    let partial = std::fs::read_to_string(dir.join("traj.partial.csv")).unwrap();
    assert_eq!(assert_whole_finite_rows(&partial), 3, "t = 0, 0.002, 0.004: the rows before the overflow");
    // Without --out the same run stops with the same error.
    let (ok, _, err) =
        lagrange(&["simulate", "models/textbook/double_pendulum.urdf", "--v0", "1e150,0", "--json"]);
    assert!(!ok && err.contains("the energy is inf"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_csv_size_is_bounded_before_and_during_the_run() {
    let dir = folder("bound");
    let out = dir.join("traj.csv");
    let target = out.to_str().unwrap();
    // 1e10 rows × 7 columns × ~20 bytes: refused before the run, with the estimate and the fix.
    let (ok, _, err) = lagrange(&[
        "simulate",
        "models/textbook/double_pendulum.urdf",
        "--duration",
        "1e6",
        "--dt",
        "1e-4",
        "--out",
        target,
    ]);
    assert!(!ok);
    assert!(
        err.contains("the trajectory would take about 1.4 TB (10000000001 rows × 7 columns × ~20 bytes)")
            && err.contains("over --max-output-bytes 2000000000 (2.0 GB)")
            && err.contains("--max-output-bytes 0 for none"),
        "{err}"
    );
    assert!(!out.exists());
    // Values of ~1e-20 print as ~40 digits, twice the estimate: 501 rows are estimated at 70 kB,
    // and the run reaches a bound of 75 kB before its end.
    let (ok, _, err) = lagrange(&[
        "simulate",
        "models/textbook/double_pendulum.urdf",
        "--q0",
        "1.2345e-20,-2.345e-20",
        "--v0",
        "3.21e-20,-1.1e-20",
        "--max-output-bytes",
        "75000",
        "--out",
        target,
    ]);
    assert!(!ok);
    assert!(
        err.contains("reached --max-output-bytes 75000 (75 kB)") && err.contains("traj.csv was not written"),
        "{err}"
    );
    let partial = std::fs::read(dir.join("traj.partial.csv")).unwrap();
    assert!(partial.len() <= 75_000 && partial.len() > 70_000, "{}", partial.len());
    let rows = assert_whole_finite_rows(std::str::from_utf8(&partial).unwrap());
    assert!(rows < 501, "{rows}");
    assert!(!out.exists());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_full_disk_is_a_clean_error_naming_the_file() {
    // --out on a full device: written in place (never renamed over), the error names it.
    let (ok, out, err) =
        lagrange(&["simulate", "models/textbook/double_pendulum.urdf", "--out", "/dev/full"]);
    assert!(!ok);
    assert!(out.is_empty() && err.starts_with("error: /dev/full: No space left on device"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    // stdout on a full device: `simulate`, `eval` and `info` end with an error naming stdout.
    let full = || std::fs::OpenOptions::new().write(true).open("/dev/full").unwrap();
    for args in [
        &["simulate", "models/textbook/double_pendulum.urdf"][..],
        &["info", "models/textbook/double_pendulum.urdf", "--json"][..],
    ] {
        let result = command(args).stdout(full()).output().unwrap();
        let err = String::from_utf8_lossy(&result.stderr);
        assert_eq!(result.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.starts_with("error: <stdout>: No space left on device"), "{args:?}: {err}");
    }
    let dir = folder("full");
    let states = dir.join("states.json");
    std::fs::write(&states, r#"{"states": [{"q": [0.1, 0.2]}]}"#).unwrap();
    let result =
        command(&["eval", "models/textbook/double_pendulum.urdf", "--states", states.to_str().unwrap()])
            .stdout(full())
            .output()
            .unwrap();
    let err = String::from_utf8_lossy(&result.stderr);
    assert_eq!(result.status.code(), Some(1), "{err}");
    assert!(err.starts_with("error: <stdout>: No space left on device"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_closed_pipe_ends_eval_quietly() {
    // 2000 states (≈ 3 MB of JSON, more than any pipe buffer); the reader takes 10 bytes and
    // closes the pipe, as `lagrange eval ... | head -c 10` does.
    let dir = folder("pipe");
    let states = dir.join("states.json");
    let list: Vec<Value> = (0..2000).map(|i| serde_json::json!({"q": [i as f64 * 1e-3, 0.2]})).collect();
    std::fs::write(&states, serde_json::json!({ "states": list }).to_string()).unwrap();
    let mut child =
        command(&["eval", "models/textbook/double_pendulum.urdf", "--states", states.to_str().unwrap()])
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
    let mut head = [0u8; 10];
    child.stdout.take().unwrap().read_exact(&mut head).unwrap();
    // (The pipe's read end is dropped here.)
    let result = child.wait_with_output().unwrap();
    assert_eq!(&head, br#"{"constrai"#);
    assert_eq!(
        result.status.code(),
        Some(141),
        "128 + SIGPIPE, as a shell reports a Unix tool a pipe closed"
    );
    assert_eq!(String::from_utf8_lossy(&result.stderr), "", "quiet: no panic, no message");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn eval_turns_a_non_finite_result_into_an_error_entry_and_exits_3() {
    let dir = folder("nonfinite");
    let states = dir.join("states.json");
    // The middle state's kinetic energy ½ vᵀMv overflows (v = 1e300).
    std::fs::write(
        &states,
        r#"{"states": [{"q": [0.1, 0.2]}, {"q": [0.3, 0.2], "v": [1e300, 0]}, {"q": [0.5, 0.2]}]}"#,
    )
    .unwrap();
    let result =
        command(&["eval", "models/textbook/double_pendulum.urdf", "--states", states.to_str().unwrap()])
            .output()
            .unwrap();
    let (out, err) = (String::from_utf8_lossy(&result.stdout), String::from_utf8_lossy(&result.stderr));
    assert_eq!(result.status.code(), Some(3), "{err}");
    assert!(!out.contains("null"), "{out}");
    let v: Value = serde_json::from_str(&out).unwrap();
    let results = v["results"].as_array().unwrap();
    assert_eq!(results.len(), 3);
    assert_eq!(
        results[1],
        serde_json::json!({"error": "states[1]: bias[0] is not finite (NaN or infinite)"})
    );
    for r in [&results[0], &results[2]] {
        assert!(r.get("error").is_none() && r["M"].is_array() && r["forward"]["qacc"].is_array(), "{r}");
    }
    assert_eq!(v["constraints"]["mode"], "exact");
    assert!(
        err.contains("1 of 3 states failed (their results are {\"error\": ...} entries): states[1]: bias[0]"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn simulate_json_has_no_null_even_for_an_untimed_run() {
    // 0 steps: no wall time to divide by; the real-time factor stays a number.
    let (ok, out, err) =
        lagrange(&["simulate", "models/textbook/double_pendulum.urdf", "--duration", "0", "--json"]);
    assert!(ok, "{err}");
    assert!(!out.contains("null"), "{out}");
    let v: Value = serde_json::from_str(&out).unwrap();
    assert_eq!((v["steps"].as_u64(), v["realtime_factor"].as_f64()), (Some(0), Some(0.0)));
}

#[test]
fn workprec_refuses_sizes_that_cannot_fit_before_allocating() {
    // 1e9 sample times: ~432 GB of samples (it used to abort on a 32 GB allocation).
    let (ok, _, err) =
        lagrange(&["workprec", "models/textbook/double_pendulum.xml", "--duration", "1e9", "--dts", "1"]);
    assert!(!ok);
    assert!(
        err.contains("1000000000 sample times") && err.contains("need about 432.0 GB of memory"),
        "{err}"
    );
    assert!(err.contains("shorten --duration or use a coarser largest --dts step"), "{err}");
    assert!(!err.contains("memory allocation"), "{err}");
}
