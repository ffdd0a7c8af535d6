//! The exact mode with the ADMM contact solver (src/constraint/admm.rs): a 1000:1 mass-ratio
//! stack stays at rest for 10 s without gaining energy, every solve converged. (The bin of
//! tests/stability.rs still gains energy with ADMM too: see docs/constraints.md.)

use lagrange::constraint::{ConstraintMode, ExactContactSolver};
use lagrange::dynamics::{kinetic_energy, potential_energy};
use lagrange::integrate::step;
use lagrange::{Data, Model};

mod common;

use common::contact_scenes::mass_ratio;

fn load_admm(label: &str, mjcf: &str) -> Model {
    let mut model = common::load_mjcf_text("exact_admm", label, mjcf);
    model.set_constraint_mode(ConstraintMode::Exact);
    model.plan.solver.exact_mut().expect("exact mode").settings.solver = ExactContactSolver::Admm;
    model
}

fn energy(model: &Model, data: &mut Data) -> f64 {
    let (q, v) = (data.qpos.clone(), data.qvel.clone());
    kinetic_energy(model, data, q.as_slice(), v.as_slice()).unwrap() + potential_energy(model, data)
}

/// Steps `seconds`; returns the largest energy rise above the start, the final kinetic energy
/// and the number of unconverged solves.
fn run(model: &Model, data: &mut Data, seconds: f64) -> (f64, f64, u64) {
    let e0 = energy(model, data);
    let mut rise: f64 = 0.0;
    let n = (seconds / model.options.timestep).round() as usize;
    for k in 0..n {
        step(model, data).unwrap_or_else(|e| panic!("step {k}: {e}"));
        assert!(data.qpos.iter().all(|x| x.is_finite()), "step {k}: non-finite state");
        let e = energy(model, data);
        rise = rise.max(e - e0);
    }
    let (q, v) = (data.qpos.clone(), data.qvel.clone());
    (rise, kinetic_energy(model, data, q.as_slice(), v.as_slice()).unwrap(), data.efc_unconverged)
}

#[test]
fn an_admm_1000_to_1_stack_stays_at_rest_for_10_s() {
    let model = load_admm("ratio1000", &mass_ratio(1000.0));
    let mut data = Data::new(&model);
    let (rise, kinetic, unconverged) = run(&model, &mut data, 10.0);
    eprintln!("ratio1000 admm: rise {rise:e} J, kinetic {kinetic:e} J, unconverged {unconverged}");
    assert!(rise <= 1e-9, "the stack gained {rise:e} J");
    assert!(kinetic < 1e-8, "still moving after 10 s: {kinetic:e} J");
    assert_eq!(unconverged, 0, "unconverged solves");
    // The last solve converged.
    assert!(data.efc_converged);
}
