//! Runs N steps of one integrator (or N ABA calls) on a model, for counting instructions per step
//! with callgrind (`validation/step_cost.sh` runs it at two N and takes the
//! difference, so loading and warm-up cancel):
//!
//!     cargo run --release --example step_cost -- MODEL {aba|euler|rk4|implicit|implicitfast|variational|variational:TOL|adaptive} N [TILT]
//!
//! (`variational:1e-10`: Newton's residual tolerance 1e-10 instead of round-off.)
//!
//! The state starts at the model's `qpos0` tilted by TILT rad (default 0.3) per hinge and slide,
//! with a small velocity (0.1·((k mod 5) − 2) on dof k, scaled by TILT/0.3);
//! the step is the model's timestep. Prints the final state's first coordinate (so the work is
//! not optimized away).

use lagrange::dynamics::aba;
use lagrange::integrate::{IntegratorKind, Variational};
use lagrange::io::{load, LoadOptions};
use lagrange::Data;
use std::hint::black_box;
use std::path::Path;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() != 4 && args.len() != 5 {
        eprintln!(
            "usage: step_cost MODEL {{aba|euler|rk4|implicit|implicitfast|variational|adaptive}} N [TILT]"
        );
        std::process::exit(2);
    }
    let model = load(Path::new(&args[1]), &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    let n: usize = args[3].parse().expect("N is a count");
    let tilt: f64 = args.get(4).map_or(0.3, |t| t.parse().expect("TILT is a number"));
    let mut data = Data::new(&model);
    for j in &model.joints {
        if j.kind.nq() == 1 {
            data.qpos[j.qpos_adr] += tilt;
        }
    }
    for k in 0..model.nv {
        data.qvel[k] = 0.1 * ((k % 5) as f64 - 2.0) * tilt / 0.3;
    }
    let h = model.options.timestep;
    let kind = match args[2].as_str() {
        "aba" => None,
        "euler" => Some(IntegratorKind::Euler),
        "rk4" => Some(IntegratorKind::Rk4),
        "implicit" => Some(IntegratorKind::Implicit),
        "implicitfast" => Some(IntegratorKind::ImplicitFast),
        "variational" => Some(IntegratorKind::Variational),
        "adaptive" => Some(IntegratorKind::Adaptive),
        other if other.starts_with("variational:") => None,
        other => panic!("unknown mode {other}"),
    };
    let variational_tol: Option<f64> =
        args[2].strip_prefix("variational:").map(|t| t.parse().expect("variational:TOL takes a number"));
    match kind {
        None if variational_tol.is_none() => {
            let tau = vec![0.0; model.nv];
            for _ in 0..n {
                let (q, v) = (data.qpos.clone(), data.qvel.clone());
                let qacc = aba(&model, &mut data, black_box(q.as_slice()), v.as_slice(), &tau).unwrap()[0];
                // A cheap update so that successive calls see different states.
                data.qvel[0] += 1e-9 * qacc;
            }
        }
        _ => {
            let mut stepper: Box<dyn lagrange::integrate::Stepper> = match (kind, variational_tol) {
                (Some(kind), _) => kind.build(&model),
                (None, Some(tol)) => Box::new(Variational::with_tolerance(&model, tol)),
                (None, None) => unreachable!(),
            };
            let mut iterations = 0u64;
            for _ in 0..n {
                iterations += stepper.step(&model, &mut data, h).solver_iterations as u64;
            }
            eprintln!("mean solver iterations per step: {:.2}", iterations as f64 / n.max(1) as f64);
        }
    }
    println!("{}", black_box(data.qpos[0]));
}
