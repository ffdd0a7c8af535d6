//! Runs N steps of one integrator (or N ABA calls) on a model, for counting instructions per step
//! with callgrind (issue 15 item 4; `validation/step_cost.sh` runs it at two N and takes the
//! difference, so loading and warm-up cancel):
//!
//!     cargo run --release --example step_cost -- MODEL {aba|euler|rk4|implicit|implicitfast|variational|adaptive} N
//!
//! The state starts at the model's `qpos0` tilted by 0.3 rad per hinge, with a small velocity;
//! the step is the model's timestep. Prints the final state's first coordinate (so the work is
//! not optimized away).

use lagrange::dynamics::aba;
use lagrange::forward::Plan;
use lagrange::integrate::{IntegratorKind, State};
use lagrange::io::{load, LoadOptions};
use lagrange::Data;
use std::hint::black_box;
use std::path::Path;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() != 4 {
        eprintln!("usage: step_cost MODEL {{aba|euler|rk4|implicit|implicitfast|variational|adaptive}} N");
        std::process::exit(2);
    }
    let model = load(Path::new(&args[1]), &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    let n: usize = args[3].parse().expect("N is a count");
    let mut state = State::neutral(&model);
    for j in &model.joints {
        if j.kind.nq() == 1 {
            state.q[j.qpos_adr] += 0.3;
        }
    }
    for k in 0..model.nv {
        state.v[k] = 0.1 * ((k % 5) as f64 - 2.0);
    }
    let mut data = Data::new(&model);
    let h = model.options.timestep;
    let kind = match args[2].as_str() {
        "aba" => None,
        "euler" => Some(IntegratorKind::Euler),
        "rk4" => Some(IntegratorKind::Rk4),
        "implicit" => Some(IntegratorKind::Implicit),
        "implicitfast" => Some(IntegratorKind::ImplicitFast),
        "variational" => Some(IntegratorKind::Variational),
        "adaptive" => Some(IntegratorKind::Adaptive),
        other => panic!("unknown mode {other}"),
    };
    match kind {
        None => {
            let tau = vec![0.0; model.nv];
            for _ in 0..n {
                let qacc = aba(&model, &mut data, black_box(state.q.as_slice()), state.v.as_slice(), &tau);
                // A cheap update so that successive calls see different states.
                state.v[0] += 1e-9 * qacc[0];
            }
        }
        Some(kind) => {
            let plan = Plan::new(&model, None);
            let mut stepper = kind.build(&model);
            let mut iterations = 0u64;
            for _ in 0..n {
                iterations += stepper.step(&model, &plan, &mut data, &mut state, h).solver_iterations as u64;
            }
            eprintln!("mean solver iterations per step: {:.2}", iterations as f64 / n.max(1) as f64);
        }
    }
    println!("{}", black_box(state.q[0]));
}
