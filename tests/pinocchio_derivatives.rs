//! Analytic derivatives of RNEA and ABA against Pinocchio 4.1's `computeRNEADerivatives` and
//! `computeABADerivatives` on the URDF corpus robots (ur5, panda fixed; solo12 on a free joint),
//! golden data in `tests/data/pinocchio_derivatives/<robot>.json` from
//! `validation/pinocchio_derivatives_golden.py`, which converts Pinocchio's free-flyer
//! conventions (body-frame linear velocity, SE(3) tangent) to lagrange's with the exact
//! change-of-variables Jacobians. At `REF_REL` relative.

mod common;

use common::*;
use lagrange::derivatives::{aba_derivatives, rnea_derivatives, DerivativesWork};
use lagrange::Data;
use serde::Deserialize;

#[derive(Deserialize)]
struct Golden {
    model: String,
    floating: bool,
    nv: usize,
    states: Vec<State>,
}

#[derive(Deserialize)]
struct State {
    q: Vec<f64>,
    v: Vec<f64>,
    a: Vec<f64>,
    tau: Vec<f64>,
    rnea_tau: Vec<f64>,
    aba_qacc: Vec<f64>,
    dtau_dq: Vec<Vec<f64>>,
    dtau_dv: Vec<Vec<f64>>,
    dqacc_dq: Vec<Vec<f64>>,
    dqacc_dv: Vec<Vec<f64>>,
    dqacc_dtau: Vec<Vec<f64>>,
}

fn check_robot(robot: &str) {
    let file = repo_path(&format!("tests/data/pinocchio_derivatives/{robot}.json"));
    let text = std::fs::read_to_string(&file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    let golden: Golden = serde_json::from_str(&text).unwrap();
    let options = lagrange::io::LoadOptions { floating: golden.floating, ..Default::default() };
    let model = lagrange::io::load(&repo_path(&golden.model), &options).unwrap();
    assert_eq!(model.nv, golden.nv);
    let mut data = Data::new(&model);
    let mut work = DerivativesWork::new(&model);
    let n = model.nv;
    let mut worst: f64 = 0.0;
    for (s, st) in golden.states.iter().enumerate() {
        rnea_derivatives(&model, &mut data, &mut work, &st.q, &st.v, &st.a).unwrap();
        let at = |w: &str| format!("{robot} state {s} {w}");
        worst = worst.max(assert_close_vec(&at("tau"), data.tau.as_slice(), &st.rnea_tau, REF_REL));
        worst = worst.max(assert_close_mat(&at("dtau_dq"), &work.dtau_dq, &matrix(&st.dtau_dq, n), REF_REL));
        worst = worst.max(assert_close_mat(&at("dtau_dv"), &work.dtau_dv, &matrix(&st.dtau_dv, n), REF_REL));
        aba_derivatives(&model, &mut data, &mut work, &st.q, &st.v, &st.tau).unwrap();
        worst = worst.max(assert_close_vec(&at("qacc"), work.qacc.as_slice(), &st.aba_qacc, REF_REL));
        let pairs = [
            ("dqacc_dq", &work.dqacc_dq, &st.dqacc_dq),
            ("dqacc_dv", &work.dqacc_dv, &st.dqacc_dv),
            ("dqacc_dtau", &work.dqacc_dtau, &st.dqacc_dtau),
        ];
        for (name, ours, theirs) in pairs {
            worst = worst.max(assert_close_mat(&at(name), ours, &matrix(theirs, n), REF_REL));
        }
    }
    println!("{robot}: {} states, worst relative difference {worst:.2e}", golden.states.len());
}

#[test]
fn pinocchio_derivatives_ur5() {
    check_robot("ur5");
}

#[test]
fn pinocchio_derivatives_panda() {
    check_robot("panda");
}

#[test]
fn pinocchio_derivatives_solo12_floating() {
    check_robot("solo12");
}
