//! `lagrange eval MODEL --states FILE --step N --constraints exact --dump-contact-problem OUT`:
//! the exact mode's constraint problem at the state after the N steps, written to OUT as JSON
//! (`{"problems": [...]}`, one per input state; docs/cli.md, "eval", and docs/constraints.md,
//! "Exporting the exact mode's problem"). Each problem is the one `forward` solves at that state
//! ([`ContactProblem`]): the Delassus matrix `G` and free row acceleration `g` (σ = G λ + g), the
//! blocks of rows with their laws, the forward's own (warm-started) solve, and the exact mode's
//! Gauss–Seidel (with its polish) and ADMM solves of it again from a cold start, each timed alone
//! — the best of [`SOLVE_REPEATS`] solves, in µs — with the residual
//! [`ContactProblem::residual`] of every λ. Bounds are written only when finite (`lo` absent:
//! −∞, `hi` absent: +∞); a problem with a non-finite number is refused (no `null` is written).

use super::finite_json::{describe, first_null};
use super::CliError;
use lagrange::constraint::{ContactProblem, ExactContactSolver, ProblemResidual};
use lagrange::forward::forward;
use lagrange::{Data, Model};
use serde_json::{json, Value};
use std::time::Instant;

/// Solves timed per solver and problem; the best is reported.
pub const SOLVE_REPEATS: u32 = 10;

/// The residual as JSON.
fn residual_json(r: &ProblemResidual) -> Value {
    json!({"primal": r.primal, "dual": r.dual, "complementarity": r.complementarity, "relative": r.relative})
}

/// The problem of `forward` at `data`'s state (the model in exact mode), with `step` and the time
/// for the record.
pub fn problem_json(model: &Model, data: &mut Data, step: u32) -> Result<Value, CliError> {
    forward(model, data);
    let problem = ContactProblem::from_data(model, data)?;
    let n = problem.nrows();
    let g: Vec<Vec<f64>> = (0..n).map(|i| problem.delassus.row(i).iter().copied().collect()).collect();
    let blocks: Vec<Value> = problem
        .blocks
        .iter()
        .map(|b| {
            let mut v = json!({
                "first": b.first, "len": b.len, "kind": b.kind.name(), "id": b.id, "law": b.law.name(),
                "friction": b.friction, "direction": b.direction,
            });
            // A bound only when finite (JSON has no infinity): "lo" absent is −∞, "hi" absent +∞.
            for (key, x) in [("lo", b.lo), ("hi", b.hi)] {
                if x.is_finite() {
                    v[key] = json!(x);
                }
            }
            v
        })
        .collect();
    let forward_residual = problem.residual(problem.lambda.as_slice())?;
    let mut out = json!({
        "step": step, "time": data.time, "nv": model.nv, "nefc": n, "G": g, "g": problem.free.as_slice(),
        "blocks": blocks,
        "forward": {
            "lambda": problem.lambda.as_slice(), "iterations": problem.iterations,
            "residual": problem.residual, "converged": problem.converged,
            "ccp_residual": residual_json(&forward_residual),
        },
    });
    let mut scratch = data.clone();
    for (name, solver) in [("pgs", ExactContactSolver::Pgs), ("admm", ExactContactSolver::Admm)] {
        let t0 = Instant::now();
        let mut solution = problem.solve(model, &mut scratch, solver)?;
        let mut best = t0.elapsed().as_secs_f64() * 1e6;
        for _ in 1..SOLVE_REPEATS {
            let t0 = Instant::now();
            solution = problem.solve(model, &mut scratch, solver)?;
            best = best.min(t0.elapsed().as_secs_f64() * 1e6);
        }
        let residual = problem.residual(solution.lambda.as_slice())?;
        out[name] = json!({
            "lambda": solution.lambda.as_slice(), "iterations": solution.iterations,
            "residual": solution.residual, "converged": solution.converged, "solve_us": best,
            "repeats": SOLVE_REPEATS, "ccp_residual": residual_json(&residual),
        });
    }
    // A state whose problem is not finite (a diverged run) is refused, never written with nulls.
    if let Some(path) = first_null(&out) {
        return Err(CliError::Stopped(format!(
            "--dump-contact-problem: the problem after {step} steps is not finite ({})",
            describe(&path)
        )));
    }
    Ok(out)
}
