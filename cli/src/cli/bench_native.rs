//! `lagrange bench-native MODEL --states FILE --robot NAME` (hidden): lagrange's side of the
//! same-run native benchmark `validation/bench_native/run`, which times Pinocchio (C++) and MuJoCo
//! (C) on the same states with the same method (validation/README.md, "Native benchmark").
//!
//! Reads the block `robot NAME engine lagrange` of the plain-text states file written by
//! `validation/bench_native/bench_native.py` (`nq`, `nv`, `nstates`, then per state q, v, a, tau)
//! and prints JSON lines: `info`, `check` lines (results at the first states, for the script's
//! cross-check) and `ready` with the operations it knows. Then it reads commands `OP BUDGET_MS`
//! from stdin, one a line, and answers each with one line: the per-call time (µs) of every batch.
//! The driver sends the same operation to the three programs in turn (interleaved), many times.

use super::CliError;
use lagrange::derivatives::{aba_derivatives, rnea_derivatives, DerivativesWork};
use lagrange::dynamics::{aba, crba, crba_upper, factorize_mass_matrix, rnea, solve_mass_matrix};
use lagrange::io::{load, LoadOptions};
use lagrange::kinematics::forward_kinematics;
use lagrange::model::integrate_configuration;
use lagrange::{Data, Model};
use nalgebra::DVector;
use serde_json::json;
use std::hint::black_box;
use std::io::BufRead;
use std::path::Path;
use std::time::Instant;

struct State {
    q: Vec<f64>,
    v: Vec<f64>,
    a: Vec<f64>,
    tau: Vec<f64>,
}

fn input_error(file: &Path, detail: impl Into<String>) -> CliError {
    CliError::Input { file: file.display().to_string(), detail: detail.into() }
}

/// The states of `robot` for engine `lagrange` (q, v, a, tau each).
fn read_states(file: &Path, robot: &str) -> Result<Vec<State>, CliError> {
    let text = std::fs::read_to_string(file)
        .map_err(|source| CliError::Io { file: file.display().to_string(), source })?;
    let number = |t: &str| t.parse::<f64>().map_err(|_| input_error(file, format!("not a number: {t}")));
    let count = |t: &str| t.parse::<usize>().map_err(|_| input_error(file, format!("not a count: {t}")));
    let mut tokens = text.split_ascii_whitespace();
    while let Some(tok) = tokens.next() {
        if tok != "robot" {
            continue;
        }
        let mut next =
            |what: &str| tokens.next().ok_or_else(|| input_error(file, format!("ends before {what}")));
        let name = next("the robot name")?;
        let mut header = [""; 8];
        for h in header.iter_mut() {
            *h = next("the block header")?;
        }
        let [_, engine, _, nq, _, nv, _, n] = header;
        let (nq, nv, n) = (count(nq)?, count(nv)?, count(n)?);
        let mut states = Vec::with_capacity(n);
        for _ in 0..n {
            let mut read = |k: usize| -> Result<Vec<f64>, CliError> {
                (0..k).map(|_| next("a state").and_then(number)).collect()
            };
            let (q, v, a, tau) = (read(nq)?, read(nv)?, read(nv)?, read(nv)?);
            states.push(State { q, v, a, tau });
        }
        if name == robot && engine == "lagrange" {
            return Ok(states);
        }
    }
    Err(input_error(file, format!("no block for robot {robot} engine lagrange")))
}

/// The timing method shared with the C and C++ programs: a batch is one call per state (all
/// states in turn), or, with `prepare`, as many calls at one state prepared beforehand (untimed);
/// per-call time = batch time / calls. Two warm-up batches, then batches until `budget_ms` has
/// passed (at least 5). Returns the per-call times in µs, one per batch. `ctx` is what both
/// closures work on.
fn time_op<C>(
    ctx: &mut C,
    n: usize,
    budget_ms: f64,
    mut prepare: impl FnMut(&mut C, usize),
    mut call: impl FnMut(&mut C, usize) -> f64,
) -> Vec<f64> {
    let mut us = Vec::new();
    let start = Instant::now();
    let mut b = 0usize;
    while b < 2 || us.len() < 5 || (start.elapsed().as_secs_f64() * 1e3 < budget_ms && us.len() < 100_000) {
        prepare(ctx, b % n);
        let mut sink = 0.0;
        let t0 = Instant::now();
        for s in 0..n {
            sink += call(ctx, s);
        }
        let dt = t0.elapsed().as_secs_f64();
        black_box(sink);
        if b >= 2 {
            us.push(dt * 1e6 / n as f64);
        }
        b += 1;
    }
    us
}

fn emit_check(robot: &str, what: &str, state: usize, x: &[f64]) -> Result<(), CliError> {
    emit(&json!({"engine": "lagrange", "robot": robot, "check": what, "state": state, "x": x}))
}

/// One JSON line to stdout, flushed (the driver waits for it).
fn emit(value: &serde_json::Value) -> Result<(), CliError> {
    super::stdout::print(&format!("{value}\n"))
}

/// Runs `bench-native`.
pub fn run(path: &Path, options: &LoadOptions, states_file: &Path, robot: &str) -> Result<(), CliError> {
    let model: Model = load(path, options)?;
    let states = read_states(states_file, robot)?;
    if states.is_empty() || states[0].q.len() != model.nq || states[0].v.len() != model.nv {
        return Err(input_error(
            states_file,
            format!("{robot}: the states do not fit the model (nq {}, nv {})", model.nq, model.nv),
        ));
    }
    let mut data = Data::new(&model);
    let (n, nv) = (states.len(), model.nv);
    emit(&json!({"engine": "lagrange", "robot": robot, "info": {"nq": model.nq, "nv": nv,
        "nbody": model.nbody(), "nframes": model.frames.len(),
        "version": concat!(env!("CARGO_PKG_NAME"), " ", env!("CARGO_PKG_VERSION"))}}))?;
    let mut x = DVector::zeros(nv);
    for (s, st) in states.iter().enumerate().take(4) {
        emit_check(robot, "rnea", s, rnea(&model, &mut data, &st.q, &st.v, &st.a)?.as_slice())?;
        emit_check(robot, "crba", s, crba(&model, &mut data, &st.q)?.as_slice())?;
        factorize_mass_matrix(&model, &mut data);
        x.copy_from_slice(&st.tau);
        solve_mass_matrix(&model, &data, &mut x)?;
        emit_check(robot, "solve", s, x.as_slice())?;
        emit_check(robot, "aba", s, aba(&model, &mut data, &st.q, &st.v, &st.tau)?.as_slice())?;
    }
    let none = |_: &mut Data, _: usize| {};
    let last_frame = model.frames.len().checked_sub(1);
    let st = &states;
    let m = &model;
    let mut work = DerivativesWork::new(&model);
    // Forward differences of ABA (the baseline the analytic derivatives are measured against).
    let (mut q_fd, mut v_fd, mut e_fd) = (vec![0.0; model.nq], vec![0.0; nv], vec![0.0; nv]);
    emit(
        &json!({"ready": ["fk", "rnea", "crba", "aba", "factor_solve", "rnea_derivatives", "aba_derivatives", "aba_fd"]}),
    )?;
    for line in std::io::stdin().lock().lines() {
        let line = line.map_err(|source| CliError::Io { file: "stdin".into(), source })?;
        let mut words = line.split_ascii_whitespace();
        let (Some(op), Some(budget)) = (words.next(), words.next()) else {
            continue;
        };
        let budget_ms: f64 = budget
            .parse()
            .map_err(|_| CliError::Usage(format!("bench-native: not a budget in ms: {budget}")))?;
        let us = match op {
            "fk" => time_op(&mut data, n, budget_ms, none, |d, s| {
                // The states' sizes were checked by the calls above: a NaN result would show an error.
                match forward_kinematics(m, d, &st[s].q) {
                    Ok(()) => last_frame.map_or(0.0, |f| d.x_world_frame[f].pos[0]),
                    Err(_) => f64::NAN,
                }
            }),
            "rnea" => time_op(&mut data, n, budget_ms, none, |d, s| {
                rnea(m, d, &st[s].q, &st[s].v, &st[s].a).map_or(f64::NAN, |t| t[0])
            }),
            // The upper triangle, as Pinocchio's `crba` computes it (the check above compares the full M).
            "crba" => time_op(&mut data, n, budget_ms, none, |d, s| {
                crba_upper(m, d, &st[s].q).map_or(f64::NAN, |mm| mm[(0, nv - 1)])
            }),
            "aba" => time_op(&mut data, n, budget_ms, none, |d, s| {
                aba(m, d, &st[s].q, &st[s].v, &st[s].tau).map_or(f64::NAN, |a| a[0])
            }),
            // Factor + solve of the M of one state per batch (CRBA untimed), one right-hand side
            // per call.
            "factor_solve" => time_op(
                &mut (&mut data, &mut x),
                n,
                budget_ms,
                |(d, _), s| {
                    let _ = crba(m, d, &st[s].q);
                },
                |(d, x), s| {
                    x.copy_from_slice(&st[s].tau);
                    factorize_mass_matrix(m, d);
                    solve_mass_matrix(m, d, x).map_or(f64::NAN, |()| x[0])
                },
            ),
            "rnea_derivatives" => time_op(
                &mut (&mut data, &mut work),
                n,
                budget_ms,
                |_, _| {},
                |(d, w), s| {
                    rnea_derivatives(m, d, w, &st[s].q, &st[s].v, &st[s].a)
                        .map_or(f64::NAN, |()| w.dtau_dq[(0, 0)])
                },
            ),
            "aba_derivatives" => time_op(
                &mut (&mut data, &mut work),
                n,
                budget_ms,
                |_, _| {},
                |(d, w), s| {
                    aba_derivatives(m, d, w, &st[s].q, &st[s].v, &st[s].tau)
                        .map_or(f64::NAN, |()| w.dqacc_dq[(0, 0)])
                },
            ),
            // ∂q̈/∂q and ∂q̈/∂v by forward differences: 1 + 2 nv ABA calls (∂q̈/∂τ = M⁻¹ not included).
            "aba_fd" => time_op(&mut data, n, budget_ms, none, |d, s| {
                let mut sink = 0.0;
                let Ok(a0) = aba(m, d, &st[s].q, &st[s].v, &st[s].tau).map(|a| a[0]) else { return f64::NAN };
                for k in 0..nv {
                    q_fd.copy_from_slice(&st[s].q);
                    e_fd.fill(0.0);
                    e_fd[k] = 1.0;
                    let _ = integrate_configuration(m, &mut q_fd, &e_fd, 1e-6);
                    sink += aba(m, d, &q_fd, &st[s].v, &st[s].tau).map_or(f64::NAN, |a| a[0]) - a0;
                    v_fd.copy_from_slice(&st[s].v);
                    v_fd[k] += 1e-6;
                    sink += aba(m, d, &st[s].q, &v_fd, &st[s].tau).map_or(f64::NAN, |a| a[0]) - a0;
                }
                sink
            }),
            _ => return Err(CliError::Usage(format!("bench-native: unknown operation {op}"))),
        };
        emit(&json!({"engine": "lagrange", "robot": robot, "op": op, "us": us}))?;
    }
    Ok(())
}
