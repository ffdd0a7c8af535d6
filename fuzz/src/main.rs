//! `lagrange-fuzz`: a stable-Rust mutation fuzzer for the loaders.
//!
//! One target per input format (URDF, MJCF with includes, STL, OBJ, MSH); each execution mutates a
//! seed from `models/` and `tests/data/` (see `mutate.rs`) and drives load → compile → one
//! `forward` at a random state (see `target.rs`). Findings, each saved with its input under
//! `--findings DIR`:
//! - **panic**: caught in the worker, saved once per panic location;
//! - **non-finite**: a model that loaded although a derived number is NaN or infinite;
//! - **crash** (a stack overflow or abort kills the worker) and **hang** (one input over
//!   `--timeout-ms`): seen by the supervisor, which saves the input and restarts the worker.
//!
//! Inputs whose outcome (refusal message kind) is new join the mutation pool, a cheap stand-in for
//! coverage feedback.
//!
//! ```text
//! cargo run --release -p lagrange-fuzz -- all --seconds 60          # the short CI run
//! cargo run --release -p lagrange-fuzz -- mjcf --execs 1000000      # a long run of one target
//! ```
//!
//! Exits 1 if any finding was made.

mod mutate;
mod target;

use clap::Parser;
use rand::rngs::SmallRng;
use rand::{Rng, SeedableRng};
use std::collections::HashSet;
use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};
use target::{Outcome, Target};

#[derive(Parser)]
#[command(about = "Mutation fuzzer for lagrange's URDF, MJCF, STL, OBJ and MSH loaders")]
struct Args {
    /// urdf, mjcf, stl, obj, msh, or all; or replay=FILE to rerun a saved model input
    target: String,
    /// Executions per target (the run stops at whichever of --execs and --seconds comes first)
    #[arg(long, default_value_t = u64::MAX)]
    execs: u64,
    /// Seconds per target
    #[arg(long, default_value_t = 60.0)]
    seconds: f64,
    /// Random seed
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// An input running longer than this is a hang
    #[arg(long, default_value_t = 5000)]
    timeout_ms: u64,
    /// Where findings are saved
    #[arg(long, default_value = "target/fuzz-findings")]
    findings: PathBuf,
    /// The repository root holding models/ and tests/data/
    #[arg(long, default_value = ".")]
    root: PathBuf,
    /// Internal: run as the worker process of one target
    #[arg(long, hide = true)]
    worker: bool,
}

fn main() {
    let args = Args::parse();
    if let Some(file) = args.target.strip_prefix("replay=") {
        replay(Path::new(file), args.seed);
        return;
    }
    if args.worker {
        let target = Target::parse(&args.target).expect("worker target");
        worker(&args, target);
        return;
    }
    let targets: Vec<Target> = if args.target == "all" {
        Target::ALL.to_vec()
    } else {
        match Target::parse(&args.target) {
            Some(t) => vec![t],
            None => {
                eprintln!("error: unknown target '{}'; use urdf, mjcf, stl, obj, msh or all", args.target);
                std::process::exit(2);
            }
        }
    };
    let mut total_findings = 0;
    for t in targets {
        total_findings += supervise(&args, t);
    }
    if total_findings > 0 {
        eprintln!("{total_findings} finding(s) saved under {}", args.findings.display());
        std::process::exit(1);
    }
}

/// The largest input kept in the mutation pool (bytes).
const MAX_POOL_INPUT: usize = 64 * 1024;

/// Runs one saved input (a model file; meshes through the scenes of its folder) with 100 random
/// states and prints what each did.
fn replay(file: &Path, seed: u64) {
    let mut rng = SmallRng::seed_from_u64(seed);
    for k in 0..100 {
        match target::run_model(file, &mut rng) {
            Outcome::Refused(why) => {
                println!("refused: {why}");
                return;
            }
            Outcome::NonFinite(what) => {
                println!("state {k}: {what}");
                std::process::exit(1);
            }
            Outcome::Loaded => {}
        }
    }
    println!("loaded; 100 random states finite");
}

/// Runs worker processes for `target` until its budget is spent; restarts a worker that dies and
/// saves the input it died on. Returns the number of findings.
fn supervise(args: &Args, target: Target) -> usize {
    let start = Instant::now();
    let work = std::env::temp_dir().join(format!("lagrange-fuzz-{}-{}", target.name(), std::process::id()));
    let (mut execs, mut findings, mut restarts, mut loaded) = (0u64, 0usize, 0u64, 0u64);
    let exe = std::env::current_exe().expect("current exe");
    while execs < args.execs && start.elapsed().as_secs_f64() < args.seconds {
        let remaining_s = args.seconds - start.elapsed().as_secs_f64();
        let mut child = Command::new(&exe)
            .arg(target.name())
            .args(["--worker", "--execs", &(args.execs - execs).to_string()])
            .args(["--seconds", &remaining_s.to_string()])
            .args(["--seed", &(args.seed.wrapping_mul(1000) + restarts).to_string()])
            .args(["--timeout-ms", &args.timeout_ms.to_string()])
            .arg("--findings")
            .arg(&args.findings)
            .arg("--root")
            .arg(&args.root)
            .env("LAGRANGE_FUZZ_WORK", &work)
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("spawn worker");
        let (mut last_execs, mut last_loaded, mut last_input) = (0u64, 0u64, String::new());
        for line in BufReader::new(child.stdout.take().expect("stdout")).lines().map_while(Result::ok) {
            if let Some(rest) = line.strip_prefix("progress ") {
                let mut it = rest.split_whitespace();
                last_execs = it.next().and_then(|x| x.parse().ok()).unwrap_or(last_execs);
                last_loaded = it.next().and_then(|x| x.parse().ok()).unwrap_or(last_loaded);
            } else if let Some(rest) = line.strip_prefix("finding ") {
                findings += 1;
                println!("[{}] finding: {rest}", target.name());
            } else if let Some(rest) = line.strip_prefix("input ") {
                last_input = rest.to_string();
            }
        }
        let status = child.wait().expect("wait worker");
        execs += last_execs;
        loaded += last_loaded;
        if !status.success() {
            // The worker died (stack overflow, abort) or the watchdog stopped a hang (exit 3).
            let kind = if status.code() == Some(3) { "hang" } else { "crash" };
            findings += 1;
            let saved =
                save_finding(&args.findings, target, kind, Path::new(&last_input), &format!("{status}"));
            println!("[{}] finding: {kind} ({status}) on {}", target.name(), saved.display());
            restarts += 1;
            execs += 1;
        } else {
            break;
        }
    }
    let _ = std::fs::remove_dir_all(&work);
    let secs = start.elapsed().as_secs_f64();
    println!(
        "[{}] {execs} executions in {secs:.1} s ({:.0}/s), {loaded} loaded, {restarts} worker restart(s), {findings} finding(s)",
        target.name(),
        execs as f64 / secs.max(1e-9)
    );
    findings
}

/// Copies the input at `input` into the findings folder with a note; returns the copy's path.
fn save_finding(dir: &Path, target: Target, kind: &str, input: &Path, note: &str) -> PathBuf {
    let _ = std::fs::create_dir_all(dir);
    let ext = input.extension().and_then(|e| e.to_str()).unwrap_or("bin");
    let bytes = std::fs::read(input).unwrap_or_default();
    let hash =
        bytes.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| (h ^ b as u64).wrapping_mul(0x100_0000_01b3));
    let path = dir.join(format!("{}-{kind}-{hash:016x}.{ext}", target.name()));
    let _ = std::fs::write(&path, &bytes);
    let _ = std::fs::write(
        path.with_extension(format!("{ext}.txt")),
        format!("{note}\nfrom {}\n", input.display()),
    );
    path
}

/// The worker: mutates and runs inputs until the budget is spent, printing progress lines for the
/// supervisor.
fn worker(args: &Args, target: Target) {
    let work = PathBuf::from(std::env::var("LAGRANGE_FUZZ_WORK").expect("LAGRANGE_FUZZ_WORK"));
    if !work.join("models").exists() {
        target::copy_seed_tree(&args.root, &work).expect("copy seed tree");
    }
    let seeds = target::seeds(&args.root, target);
    if seeds.is_empty() {
        eprintln!("no seeds for {}", target.name());
        std::process::exit(2);
    }
    let scenes = if target.is_xml() {
        Vec::new()
    } else {
        target::write_mesh_scenes(&work.join("tests/data/meshes"), target).expect("scenes")
    };
    let includes: Vec<String> =
        seeds.iter().filter_map(|s| s.rel.file_name().map(|f| f.to_string_lossy().into_owned())).collect();
    // The pool: seeds, then inputs with a new outcome.
    let mut pool: Vec<(PathBuf, Vec<u8>)> = seeds.into_iter().map(|s| (s.rel, s.bytes)).collect();
    let mut outcomes: HashSet<String> = HashSet::new();
    let mut seen_findings: HashSet<String> = HashSet::new();
    let mut rng = SmallRng::seed_from_u64(args.seed);

    // Panics are findings, reported once per location; the default hook's output is silenced.
    let last_panic = Arc::new(std::sync::Mutex::new(String::new()));
    {
        let last_panic = last_panic.clone();
        std::panic::set_hook(Box::new(move |info| {
            let loc = info.location().map(|l| format!("{}:{}", l.file(), l.line())).unwrap_or_default();
            let msg = info
                .payload()
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| info.payload().downcast_ref::<String>().cloned())
                .unwrap_or_default();
            *last_panic.lock().unwrap() = format!("{loc}: {msg}");
        }));
    }
    // The watchdog: an input running longer than the timeout ends the worker with exit code 3.
    let started_ms = Arc::new(AtomicU64::new(0));
    let epoch = Instant::now();
    {
        let started_ms = started_ms.clone();
        let timeout = args.timeout_ms;
        std::thread::spawn(move || loop {
            std::thread::sleep(Duration::from_millis(100));
            let s = started_ms.load(Ordering::Relaxed);
            if s > 0 && epoch.elapsed().as_millis() as u64 > s + timeout {
                std::process::exit(3);
            }
        });
    }

    let stdout = std::io::stdout();
    let (mut execs, mut loaded) = (0u64, 0u64);
    let mut current_input = PathBuf::new();
    while execs < args.execs && epoch.elapsed().as_secs_f64() < args.seconds {
        let k = rng.random_range(0..pool.len());
        let other = &pool[rng.random_range(0..pool.len())].1;
        let (rel, base) = &pool[k];
        let input = mutate::mutate(&mut rng, base, other, target.is_xml(), &includes);
        let dir = work.join(rel.parent().unwrap_or(Path::new("")));
        let ext = rel.extension().and_then(|e| e.to_str()).unwrap_or("bin");
        let path = dir.join(format!("__fuzz.{ext}"));
        if path != current_input {
            current_input = path.clone();
            let _ = writeln!(stdout.lock(), "input {}", path.display());
        }
        if std::fs::write(&path, &input).is_err() {
            continue;
        }
        let scene = scenes.get(rng.random_range(0..scenes.len().max(1))).cloned();
        let mut exec_rng = SmallRng::seed_from_u64(rng.random());
        started_ms.store(epoch.elapsed().as_millis() as u64 + 1, Ordering::Relaxed);
        let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| match &scene {
            None => target::run_model(&path, &mut exec_rng),
            Some(scene) => target::run_mesh(&path, scene, &mut exec_rng),
        }));
        let took = epoch.elapsed().as_millis() as u64 + 1 - started_ms.load(Ordering::Relaxed);
        started_ms.store(0, Ordering::Relaxed);
        if let Some(slow) = std::env::var("LAGRANGE_FUZZ_SLOW_MS").ok().and_then(|s| s.parse::<u64>().ok()) {
            if took >= slow {
                eprintln!("slow input: {took} ms, {} bytes, {}", input.len(), path.display());
                let _ = std::fs::copy(&path, std::env::temp_dir().join(format!("slow-{execs}.{ext}")));
            }
        }
        execs += 1;
        let finding = match result {
            Err(_) => Some(("panic", last_panic.lock().unwrap().clone())),
            Ok(Outcome::NonFinite(what)) => Some(("nonfinite", what)),
            Ok(Outcome::Loaded) => {
                loaded += 1;
                None
            }
            Ok(Outcome::Refused(kind)) => {
                // Small inputs only: a 4 MB chain in the pool would make every later execution
                // of it slow (the deep-nesting mutation still makes big ones fresh each time).
                if input.len() <= MAX_POOL_INPUT
                    && outcomes.len() < 2000
                    && outcomes.insert(kind)
                    && pool.len() < 4000
                {
                    pool.push((rel.clone(), input.clone()));
                }
                None
            }
        };
        if let Some((kind, what)) = finding {
            // Panics once per location; non-finite models up to 20 (their causes differ).
            let key = if kind == "panic" {
                format!("{kind}:{}", what.split(": ").next().unwrap_or(""))
            } else {
                format!("{kind}:{}", seen_findings.len().min(20))
            };
            if seen_findings.insert(key) {
                let saved = save_finding(&args.findings, target, kind, &path, &what);
                let _ = writeln!(stdout.lock(), "finding {kind}: {what} ({})", saved.display());
            }
        }
        if execs % 500 == 0 {
            let _ = writeln!(stdout.lock(), "progress {execs} {loaded}");
        }
    }
    let _ = writeln!(stdout.lock(), "progress {execs} {loaded}");
}
