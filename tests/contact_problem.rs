//! The exact mode's problem taken out of `Data` (src/constraint/contact_problem.rs,
//! `ContactProblem`): on small scenes after a few steps, its Delassus matrix is symmetric positive
//! semi-definite and equals J M⁻¹ Jᵀ recomputed here from `efc_j` and a dense solve of M; G λ + g
//! is the constrained row acceleration J q̈ + J̇v of `forward`; and the solver's λ (the forward's,
//! and the Gauss–Seidel and ADMM solves again from a cold start) solves it: the residual of
//! `ContactProblem::residual` below the ADMM tolerance.

use lagrange::constraint::{BlockLaw, ConstraintMode, ContactProblem, ExactContactSolver, ADMM_TOLERANCE};
use lagrange::dynamics::crba;
use lagrange::forward::forward;
use lagrange::integrate::step;
use lagrange::{Data, Model};
use nalgebra::{DMatrix, DVector, SymmetricEigen};

mod common;

use common::ALGO_REL;

fn exact(label: &str, mjcf: &str) -> Model {
    let mut model = common::load_mjcf_text("contact_problem", label, mjcf);
    model.set_constraint_mode(ConstraintMode::Exact);
    model
}

/// The state after `steps` steps from `v0`, then `forward` there: the problem's data.
fn settle(model: &Model, steps: usize, v0: &[(usize, f64)]) -> Data {
    let mut data = Data::new(model);
    for &(k, v) in v0 {
        data.qvel[k] = v;
    }
    for k in 0..steps {
        step(model, &mut data).unwrap_or_else(|e| panic!("step {k}: {e}"));
    }
    forward(model, &mut data);
    data
}

/// Checks G, g and every λ of the problem at `data`'s state; returns it.
fn check(model: &Model, data: &Data, label: &str) -> ContactProblem {
    let problem = ContactProblem::from_data(model, data).unwrap();
    let n = problem.nrows();
    assert_eq!(n, data.nefc, "{label}: rows");
    assert!(n > 0, "{label}: no rows");
    let g = &problem.delassus;
    // Symmetric, and positive semi-definite up to round-off.
    let scale = g.amax();
    for i in 0..n {
        for j in 0..n {
            assert_eq!(g[(i, j)], g[(j, i)], "{label}: G[{i},{j}] not symmetric");
        }
    }
    let eig = SymmetricEigen::new(g.clone()).eigenvalues;
    let min = eig.min();
    assert!(min >= -1e-12 * scale, "{label}: smallest eigenvalue {min:e} (largest entry {scale:e})");
    // J M⁻¹ Jᵀ from efc_j and a dense LU solve of M (CRBA at the same q).
    let j = data.efc_j.rows(0, n).into_owned();
    let mut scratch = Data::new(model);
    let m: DMatrix<f64> = crba(model, &mut scratch, data.qpos.as_slice()).unwrap().clone();
    let minv_jt = m.lu().solve(&j.transpose()).expect("M is regular");
    let dense = &j * minv_jt;
    let err = (g - &dense).amax();
    assert!(err <= ALGO_REL * (1.0 + dense.amax()), "{label}: |G − J M⁻¹ Jᵀ| = {err:e}");
    // σ = G λ + g is the row acceleration J q̈ + J̇v of forward's constrained q̈.
    let sigma = g * &problem.lambda + &problem.free;
    let jqacc = &j * &data.qacc + DVector::from_column_slice(&data.efc_jdotv.as_slice()[..n]);
    let err = (&sigma - &jqacc).amax();
    assert!(
        err <= 1e-9 * (1.0 + jqacc.amax() + problem.free.amax()),
        "{label}: |Gλ + g − J q̈ − J̇v| = {err:e}"
    );
    // Every solution solves the problem.
    let r = problem.residual(problem.lambda.as_slice()).unwrap();
    eprintln!("{label}: {n} rows, forward residual {r:?}, {} iterations", problem.iterations);
    assert!(r.relative <= ADMM_TOLERANCE, "{label}: forward's λ residual {r:?}");
    for solver in [ExactContactSolver::Pgs, ExactContactSolver::Admm] {
        let mut copy = data.clone();
        let s = problem.solve(model, &mut copy, solver).unwrap();
        let r = problem.residual(s.lambda.as_slice()).unwrap();
        eprintln!("{label} {solver:?}: {} iterations, residual {r:?}", s.iterations);
        assert!(s.converged, "{label} {solver:?}: not converged");
        assert!(r.relative <= ADMM_TOLERANCE, "{label} {solver:?}: residual {r:?}");
    }
    problem
}

/// Two stacked boxes at rest: eight contacts, each a cone of three rows.
#[test]
fn a_stack_at_rest_exports_a_cone_problem_that_its_forces_solve() {
    let model = exact("stack2", &common::contact_scenes::stack(2));
    let data = settle(&model, 20, &[]);
    let problem = check(&model, &data, "stack2");
    assert!(problem.blocks.iter().filter(|b| b.law == BlockLaw::Cone).count() >= 8);
    assert!(problem.blocks.iter().all(|b| b.len == 3 && b.friction == [1.0, 1.0]));
}

/// A box on the floor (given 1 m/s along x, it slides) and a hinged rod against its limit.
const SLIDE: &str = "<mujoco><option timestep='0.002'/><worldbody><geom type='plane' size='0 0 1'/>\
    <body pos='0 0 0.05'><freejoint/><geom type='box' size='0.05 0.05 0.05' friction='0.3'/></body>\
    <body pos='1 0 1'><joint type='hinge' axis='0 1 0' range='-10 0'/>\
    <geom type='capsule' fromto='0 0 0 0.3 0 0' size='0.02'/></body>\
    </worldbody></mujoco>";

/// A box sliding on the floor: its contacts obey the sliding law, whose residual the forces meet
/// too; and a pendulum on a hinge at its limit gives a unilateral row beside them.
#[test]
fn sliding_contacts_and_limits_are_exported_with_their_laws() {
    let model = exact("slide", SLIDE);
    let data = settle(&model, 5, &[(0, 1.0)]);
    let problem = check(&model, &data, "slide");
    assert!(problem.blocks.iter().any(|b| b.law == BlockLaw::Sliding), "{:?}", problem.blocks);
    assert!(problem.blocks.iter().any(|b| b.law == BlockLaw::Unilateral), "{:?}", problem.blocks);
}

/// The problem is the exact mode's, of a forward: a soft model and a data after a step (whose
/// rows the drift correction re-evaluated at the new q) are refused with a typed error.
#[test]
fn the_problem_needs_an_exact_forward() {
    let mut model = exact("slide1", SLIDE);
    let mut data = settle(&model, 3, &[(0, 1.0)]);
    step(&model, &mut data).unwrap();
    let err = ContactProblem::from_data(&model, &data).unwrap_err().to_string();
    assert!(err.contains("call forward first"), "{err}");
    forward(&model, &mut data);
    let problem = ContactProblem::from_data(&model, &data).unwrap();
    let err = problem.residual(&[0.0]).unwrap_err().to_string();
    assert!(err.contains("lambda"), "{err}");
    model.set_constraint_mode(ConstraintMode::Soft);
    let mut soft = Data::new(&model);
    forward(&model, &mut soft);
    let err = ContactProblem::from_data(&model, &soft).unwrap_err().to_string();
    assert!(err.contains("soft mode"), "{err}");
}
