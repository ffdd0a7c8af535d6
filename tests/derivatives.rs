//! Analytic derivatives of inverse and forward dynamics (`lagrange::derivatives`) against central
//! differences (Richardson-extrapolated) of the library's own kernels (RNEA, ABA, `forward`'s `qacc_smooth`), on random
//! trees with every joint type and on the shipped robots, fixed and floating.

mod common;

use common::*;
use lagrange::derivatives::{aba_derivatives, rnea_derivatives, smooth_derivatives, DerivativesWork};
use lagrange::dynamics::{aba, rnea};
use lagrange::forward::forward;
use lagrange::io::{load, LoadOptions};
use lagrange::model::integrate_configuration;
use lagrange::{Data, Model};
use nalgebra::DMatrix;

/// Base step of the differences: Richardson-extrapolated central differences
/// (4 D(h/2) − D(h)) / 3 cancel the h² term, leaving h⁴ truncation (1e-16) and ≈ 3 ε |f| / h
/// round-off (≈ 7e-12 |f|).
const H: f64 = 1e-4;

/// Central differences of `f` along each tangent direction of q and each component of v and of a
/// third argument w: (∂f/∂q, ∂f/∂v, ∂f/∂w), Richardson-extrapolated.
fn central(
    model: &Model,
    q: &[f64],
    v: &[f64],
    w: &[f64],
    mut f: impl FnMut(&[f64], &[f64], &[f64]) -> Vec<f64>,
) -> [DMatrix<f64>; 3] {
    let nv = model.nv;
    let mut out = [DMatrix::zeros(nv, nv), DMatrix::zeros(nv, nv), DMatrix::zeros(nv, nv)];
    // D(h) of each argument along unit direction k.
    let mut d = |k: usize, arg: usize, h: f64| -> Vec<f64> {
        let mut e = vec![0.0; nv];
        e[k] = 1.0;
        let mut eval = |s: f64| -> Vec<f64> {
            let (mut qs, mut vs, mut ws) = (q.to_vec(), v.to_vec(), w.to_vec());
            match arg {
                0 => integrate_configuration(model, &mut qs, &e, s).unwrap(),
                1 => vs[k] += s,
                _ => ws[k] += s,
            }
            f(&qs, &vs, &ws)
        };
        let (p, m) = (eval(h), eval(-h));
        p.iter().zip(&m).map(|(a, b)| (a - b) / (2.0 * h)).collect()
    };
    for k in 0..nv {
        for (arg, o) in out.iter_mut().enumerate() {
            let (d1, d2) = (d(k, arg, H), d(k, arg, H / 2.0));
            for i in 0..nv {
                o[(i, k)] = (4.0 * d2[i] - d1[i]) / 3.0;
            }
        }
    }
    out
}

fn cases() -> Vec<(String, Model)> {
    let mut all = robots();
    for seed in 0..6 {
        all.push((format!("random tree {seed}"), random_tree(seed, 8)));
    }
    all
}

#[test]
fn rnea_derivatives_match_central_differences() {
    let mut worst = [0.0f64; 2];
    for (name, model) in cases() {
        let mut data = Data::new(&model);
        let mut work = DerivativesWork::new(&model);
        let mut r = rng(7);
        for _ in 0..3 {
            let (q, v, a) = (random_q(&model, &mut r), random_v(&model, &mut r), random_tau(&model, &mut r));
            rnea_derivatives(&model, &mut data, &mut work, &q, &v, &a).unwrap();
            let mut d2 = Data::new(&model);
            let [dq, dv, da] = central(&model, &q, &v, &a, |q, v, a| {
                rnea(&model, &mut d2, q, v, a).unwrap().as_slice().to_vec()
            });
            worst[0] =
                worst[0].max(assert_close_mat(&format!("{name} dtau/dq"), &work.dtau_dq, &dq, DERIV_FD_REL));
            worst[1] =
                worst[1].max(assert_close_mat(&format!("{name} dtau/dv"), &work.dtau_dv, &dv, DERIV_FD_REL));
            // ∂τ/∂a = M: a check of the differences themselves.
            let m = lagrange::dynamics::crba(&model, &mut d2, &q).unwrap().clone();
            assert_close_mat(&format!("{name} dtau/da"), &m, &da, DERIV_FD_REL);
        }
    }
    println!("worst: dtau/dq {:.2e}, dtau/dv {:.2e}", worst[0], worst[1]);
}

#[test]
fn aba_derivatives_match_central_differences() {
    for (name, model) in cases() {
        let mut data = Data::new(&model);
        let mut work = DerivativesWork::new(&model);
        let mut r = rng(11);
        for _ in 0..3 {
            let (q, v, tau) =
                (random_q(&model, &mut r), random_v(&model, &mut r), random_tau(&model, &mut r));
            aba_derivatives(&model, &mut data, &mut work, &q, &v, &tau).unwrap();
            let mut d2 = Data::new(&model);
            let qacc = aba(&model, &mut d2, &q, &v, &tau).unwrap().clone();
            assert_close_vec(&format!("{name} qacc"), work.qacc.as_slice(), qacc.as_slice(), ALGO_REL);
            let [dq, dv, dtau] = central(&model, &q, &v, &tau, |q, v, t| {
                aba(&model, &mut d2, q, v, t).unwrap().as_slice().to_vec()
            });
            assert_close_mat(&format!("{name} dqacc/dq"), &work.dqacc_dq, &dq, DERIV_FD_REL);
            assert_close_mat(&format!("{name} dqacc/dv"), &work.dqacc_dv, &dv, DERIV_FD_REL);
            assert_close_mat(&format!("{name} dqacc/dtau"), &work.dqacc_dtau, &dtau, DERIV_FD_REL);
        }
    }
}

/// `qacc_smooth` of MJCF models with joint damping, springs, armature and position, velocity and
/// motor actuators (hinge, slide and free joints): the passive and actuator forces' derivatives
/// are in.
/// A three-hinge arm with a fixed tendon (spring stretched beyond its dead band, damper) and a
/// spatial tendon (a damper in `TENDON_ARM_SPATIAL`): the tendons' passive forces in the
/// derivatives.
const TENDON_ARM: &str = "<mujoco><worldbody><site name='s0' pos='0.1 0 0'/>
  <body><joint name='a' axis='0 1 0'/><geom type='capsule' fromto='0 0 0 0 0 -0.3' size='0.03'/>
    <body pos='0 0 -0.3'><joint name='b' axis='0 1 0'/><geom type='capsule' fromto='0 0 0 0 0 -0.3' size='0.03'/>
      <site name='s1' pos='0.05 0 -0.2'/>
      <body pos='0 0 -0.3'><joint name='c' axis='1 0 0'/><geom type='sphere' size='0.05'/></body></body></body>
  </worldbody><tendon>
  <fixed stiffness='40' damping='3' springlength='-0.2 0.1'><joint joint='a' coef='1'/><joint joint='b' coef='-0.5'/><joint joint='c' coef='2'/></fixed>
  <spatial><site site='s0'/><site site='s1'/></spatial></tendon></mujoco>";

#[test]
fn smooth_derivatives_match_central_differences() {
    let tendon_arm = common::load_mjcf_text("derivatives", "tendon_arm", TENDON_ARM);
    // The spatial tendon's damper −b J(q)ᵀ J(q) v: its v-derivative b JᵀJ is exact, its
    // q-derivative (J's change along the path) is left out, so only ∂/∂v is compared.
    let spatial_text = TENDON_ARM.replace("<spatial>", "<spatial damping='5'>");
    let tendon_arm_spatial = common::load_mjcf_text("derivatives", "tendon_arm_spatial", &spatial_text);
    for file in [
        "models/mjcf/franka_emika_panda/panda.xml",
        "models/mjcf/unitree_go1/go1.xml",
        "models/mjcf/humanoid/humanoid.xml",
        "tendon_arm",
        "tendon_arm_spatial",
    ] {
        let model = if file == "tendon_arm" {
            tendon_arm.clone()
        } else if file == "tendon_arm_spatial" {
            tendon_arm_spatial.clone()
        } else {
            load(&repo_path(file), &LoadOptions::default()).unwrap()
        };
        let mut data = Data::new(&model);
        let mut work = DerivativesWork::new(&model);
        let mut r = rng(3);
        let q = random_q(&model, &mut r);
        let v = random_v(&model, &mut r);
        let ctrl: Vec<f64> = (0..model.actuators.len()).map(|i| 0.3 * (i as f64).sin()).collect();
        data.qpos.copy_from_slice(&q);
        data.qvel.copy_from_slice(&v);
        data.ctrl.copy_from_slice(&ctrl);
        smooth_derivatives(&model, &mut data, &mut work).unwrap();
        let mut d2 = Data::new(&model);
        d2.ctrl.copy_from_slice(&ctrl);
        let mut f = |q: &[f64], v: &[f64], _: &[f64]| {
            d2.qpos.copy_from_slice(q);
            d2.qvel.copy_from_slice(v);
            forward(&model, &mut d2);
            d2.qacc_smooth.as_slice().to_vec()
        };
        let qacc = f(&q, &v, &[]);
        assert_close_vec(&format!("{file} qacc_smooth"), work.qacc.as_slice(), &qacc, ALGO_REL);
        let zero = vec![0.0; model.nv];
        let [dq, dv, _] = central(&model, &q, &v, &zero, f);
        if file != "tendon_arm_spatial" {
            assert_close_mat(&format!("{file} dqacc/dq"), &work.dqacc_dq, &dq, DERIV_FD_REL);
        }
        assert_close_mat(&format!("{file} dqacc/dv"), &work.dqacc_dv, &dv, DERIV_FD_REL);
    }
}

#[test]
fn wrong_sizes_are_errors() {
    let model = load_robot("panda", false);
    let other = load_robot("ur5", false);
    let mut data = Data::new(&model);
    let mut work = DerivativesWork::new(&other);
    let (q, v) = (model.neutral(), vec![0.0; model.nv]);
    assert!(rnea_derivatives(&model, &mut data, &mut work, &q, &v, &v).is_err());
    let mut work = DerivativesWork::new(&model);
    assert!(aba_derivatives(&model, &mut data, &mut work, &q[1..], &v, &v).is_err());
    assert!(rnea_derivatives(&model, &mut data, &mut work, &q, &v, &v).is_ok());
}
