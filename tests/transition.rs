//! Transition Jacobians of a step (`lagrange::derivatives::transition_jacobians`) against MuJoCo
//! 4.0's `mjd_transitionFD` (golden data in `tests/data/mujoco/transition/`, from
//! `validation/mujoco_transition_golden.py`): the go1 standing and walking on its floor, the
//! humanoid falling onto its floor, the contact-free panda arm (implicitfast), a gripper holding
//! a box (validation/scenes/gripper_box.xml), at
//! `TRANSITION_REL` where every nudged step keeps the nominal contact set; plus the
//! library's own checks (state restored, forward vs centred).

mod common;

use common::*;
use lagrange::derivatives::{transition_jacobians, TransitionMethod, TransitionOptions, TransitionWork};
use lagrange::model::options::Integrator;
use lagrange::Data;
use serde::Deserialize;

#[derive(Deserialize)]
struct Golden {
    model: String,
    eps: f64,
    centered: bool,
    states: Vec<State>,
}

#[derive(Deserialize)]
struct State {
    qpos: Vec<f64>,
    qvel: Vec<f64>,
    act: Vec<f64>,
    ctrl: Vec<f64>,
    qacc_warmstart: Vec<f64>,
    ncon: usize,
    contact_set_same: bool,
    #[serde(rename = "A")]
    a: Vec<Vec<f64>>,
    #[serde(rename = "B")]
    b: Vec<Vec<f64>>,
}

fn rows(m: &[Vec<f64>]) -> nalgebra::DMatrix<f64> {
    let (r, c) = (m.len(), m.first().map_or(0, |x| x.len()));
    nalgebra::DMatrix::from_fn(r, c, |i, j| m[i][j])
}

/// The golden file of `scene`, its model (tight solver) and a data with state `s` set.
fn load_state(golden: &Golden, data: &mut Data, s: usize) {
    let st = &golden.states[s];
    data.qpos.copy_from_slice(&st.qpos);
    data.qvel.copy_from_slice(&st.qvel);
    data.act.copy_from_slice(&st.act);
    data.ctrl.copy_from_slice(&st.ctrl);
    data.qacc_warmstart.copy_from_slice(&st.qacc_warmstart);
}

fn read_golden(scene: &str) -> Golden {
    let file = repo_path(&format!("tests/data/mujoco/transition/{scene}.json"));
    serde_json::from_str(&std::fs::read_to_string(&file).unwrap()).unwrap()
}

/// Stage skipping (MuJoCo's mj_stepSkip) changes only the order of round-off: from the same
/// (the input's) warm start, [A B] with skipping equals the plain differences (every nudge a
/// whole step) to `SKIP_REL`. The nominal warm start (the default) moves the nudged solves'
/// stopping points within the solver's tolerance: within `NOMINAL_WARMSTART_REL`. All leave the
/// state and warm start as they were.
fn check_skip_equals_plain(scene: &str, integrator: Option<Integrator>) {
    let golden = read_golden(scene);
    let mut model = tight_model(repo_path(&golden.model).to_str().unwrap());
    if let Some(i) = integrator {
        model.options.integrator = i;
    }
    let scene = format!("{scene} ({:?})", model.options.integrator);
    let mut data = Data::new(&model);
    let (mut fast, mut plain, mut warm) =
        (TransitionWork::new(&model), TransitionWork::new(&model), TransitionWork::new(&model));
    let options = TransitionOptions { eps: golden.eps, centered: golden.centered, ..Default::default() };
    let skipped = TransitionOptions { nominal_warmstart: false, ..options };
    let whole = TransitionOptions { skip: false, ..skipped };
    for s in 0..golden.states.len() {
        load_state(&golden, &mut data, s);
        transition_jacobians(&model, &mut data, &mut plain, &whole).unwrap();
        transition_jacobians(&model, &mut data, &mut fast, &skipped).unwrap();
        transition_jacobians(&model, &mut data, &mut warm, &options).unwrap();
        assert_eq!(data.qacc_warmstart.as_slice(), &golden.states[s].qacc_warmstart[..]);
        // [A B] norm-wise, as against MuJoCo: the panda's B is round-off (its forces at their
        // range bounds).
        let theirs = ab(&plain.a, &plain.b);
        let (ours, nominal) = (ab(&fast.a, &fast.b), ab(&warm.a, &warm.b));
        println!(
            "{scene} state {s}: [A B] skipping vs plain {:.2e}, nominal warm start vs plain {:.2e}",
            rel_err_mat(&ours, &theirs),
            rel_err_mat(&nominal, &theirs)
        );
        assert_close_mat(&format!("{scene} state {s} [A B] skipped"), &ours, &theirs, SKIP_REL);
        assert_close_mat(
            &format!("{scene} state {s} [A B] nominal warm start"),
            &nominal,
            &theirs,
            NOMINAL_WARMSTART_REL,
        );
    }
}

/// [A B] side by side.
fn ab(a: &nalgebra::DMatrix<f64>, b: &nalgebra::DMatrix<f64>) -> nalgebra::DMatrix<f64> {
    nalgebra::DMatrix::from_fn(a.nrows(), a.ncols() + b.ncols(), |i, j| {
        if j < a.ncols() {
            a[(i, j)]
        } else {
            b[(i, j - a.ncols())]
        }
    })
}

#[test]
fn skipping_equals_plain_differences() {
    for scene in ["go1_standing", "go1_walking", "humanoid_floor", "panda_free", "gripper_box"] {
        check_skip_equals_plain(scene, None);
    }
    // The other integrators: implicit (its own LU, M recomputed), implicitfast (the factor of
    // M − h D overwrites M's), RK4 (nothing skipped, the nominal warm start only).
    for integrator in [Integrator::Implicit, Integrator::ImplicitFast, Integrator::Rk4] {
        check_skip_equals_plain("go1_walking", Some(integrator));
        check_skip_equals_plain("humanoid_floor", Some(integrator));
    }
}

fn check_scene(scene: &str) {
    let file = repo_path(&format!("tests/data/mujoco/transition/{scene}.json"));
    let golden: Golden = serde_json::from_str(&std::fs::read_to_string(&file).unwrap()).unwrap();
    let model = tight_model(repo_path(&golden.model).to_str().unwrap());
    let mut data = Data::new(&model);
    let mut work = TransitionWork::new(&model);
    // MuJoCo's procedure: every nudge from the input's warm start (stages skipped).
    let options = TransitionOptions {
        eps: golden.eps,
        centered: golden.centered,
        nominal_warmstart: false,
        ..Default::default()
    };
    for (s, st) in golden.states.iter().enumerate() {
        data.qpos.copy_from_slice(&st.qpos);
        data.qvel.copy_from_slice(&st.qvel);
        data.act.copy_from_slice(&st.act);
        data.ctrl.copy_from_slice(&st.ctrl);
        data.qacc_warmstart.copy_from_slice(&st.qacc_warmstart);
        transition_jacobians(&model, &mut data, &mut work, &options).unwrap();
        assert_eq!(data.qpos.as_slice(), &st.qpos[..], "{scene}: the state is restored");
        let at = |w: &str| format!("{scene} state {s} ({} contacts) {w}", st.ncon);
        // [A B], the Jacobian of x′ in (x, u), norm-wise: B alone can be all but zero (forces at
        // their range bounds) and a one-sided difference at a control bound carries ε|x′|/ε.
        let ours = nalgebra::DMatrix::from_fn(work.a.nrows(), work.a.ncols() + work.b.ncols(), |i, j| {
            if j < work.a.ncols() {
                work.a[(i, j)]
            } else {
                work.b[(i, j - work.a.ncols())]
            }
        });
        let (ga, gb) = (rows(&st.a), if st.b.is_empty() { work.b.clone() } else { rows(&st.b) });
        let theirs = nalgebra::DMatrix::from_fn(ga.nrows(), ga.ncols() + gb.ncols(), |i, j| {
            if j < ga.ncols() {
                ga[(i, j)]
            } else {
                gb[(i, j - ga.ncols())]
            }
        });
        let e = rel_err_mat(&ours, &theirs);
        if st.contact_set_same {
            assert_close_mat(&at("[A B]"), &ours, &theirs, TRANSITION_REL);
            println!(
                "{}: [A B] {e:.2e}, A alone {:.2e}, B alone {:.2e}",
                at(""),
                rel_err_mat(&work.a, &ga),
                rel_err_mat(&work.b, &gb)
            );
        } else {
            println!("{}: contact set changes under the nudges; [A B] {e:.2e} (reported)", at(""));
        }
    }
}

#[test]
fn transition_go1_standing() {
    check_scene("go1_standing");
}

#[test]
fn transition_go1_walking() {
    check_scene("go1_walking");
}

#[test]
fn transition_humanoid_floor() {
    check_scene("humanoid_floor");
}

#[test]
fn transition_panda_contact_free() {
    check_scene("panda_free");
}

#[test]
fn transition_gripper_holding_a_box() {
    check_scene("gripper_box");
}

/// Forward differences agree with centred ones to O(ε) on the contact-free arm, and a bad ε is
/// an error that leaves the state alone.
#[test]
fn forward_differences_and_bad_eps() {
    let model = tight_model(repo_path("models/mjcf/franka_emika_panda/panda.xml").to_str().unwrap());
    let mut data = Data::new(&model);
    // Away from the joint limits (the fingers' lower limit is their qpos0).
    data.qpos[3] = -1.5;
    data.qpos[5] = 1.5;
    data.qpos[7] = 0.02;
    data.qpos[8] = 0.02;
    let mut work = TransitionWork::new(&model);
    transition_jacobians(&model, &mut data, &mut work, &TransitionOptions::default()).unwrap();
    let centred = (work.a.clone(), work.b.clone());
    let forward = TransitionOptions { eps: 1e-7, centered: false, ..Default::default() };
    transition_jacobians(&model, &mut data, &mut work, &forward).unwrap();
    assert_close_mat("forward vs centred A", &work.a, &centred.0, 1e-4);
    assert_close_mat("forward vs centred B", &work.b, &centred.1, 1e-4);
    let q = data.qpos.clone();
    let bad = TransitionOptions { eps: -1.0, ..Default::default() };
    assert!(transition_jacobians(&model, &mut data, &mut work, &bad).is_err());
    assert_eq!(data.qpos, q);
}

/// [A B] of the hybrid method (analytic velocity and control columns) and of the plain centred
/// differences at the state in `data`, their relative difference asserted below `HYBRID_REL`;
/// returns the number of analytic columns.
fn check_hybrid(label: &str, model: &lagrange::Model, data: &mut Data) -> usize {
    let mut plain = TransitionWork::new(model);
    let mut hybrid = TransitionWork::new(model);
    let fd = TransitionOptions { skip: false, nominal_warmstart: false, ..Default::default() };
    transition_jacobians(model, data, &mut plain, &fd).unwrap();
    // From the input's warm start as the differences, so that the position columns are theirs.
    let options = TransitionOptions {
        method: TransitionMethod::Hybrid,
        nominal_warmstart: false,
        ..Default::default()
    };
    transition_jacobians(model, data, &mut hybrid, &options).unwrap();
    let (ours, theirs) = (ab(&hybrid.a, &hybrid.b), ab(&plain.a, &plain.b));
    let n = hybrid.analytic_columns();
    println!(
        "{label} ({:?}, {} rows): hybrid ({n} analytic columns) vs centred differences [A B] {:.2e}",
        model.options.integrator,
        data.nefc,
        rel_err_mat(&ours, &theirs)
    );
    assert_close_mat(&format!("{label} hybrid [A B]"), &ours, &theirs, HYBRID_REL);
    n
}

/// The model of `text` with the tight solver of `tight_model`.
fn tight_text(text: &str) -> lagrange::Model {
    let mut model = lagrange::Model::from_str(text).unwrap();
    let o = &mut model.options;
    o.solver = lagrange::model::options::Solver::Newton;
    o.tolerance = 1e-15;
    o.iterations = 1000;
    o.ls_iterations = 100;
    o.ls_tolerance = 1e-12;
    model
}

#[test]
fn hybrid_equals_differences_golden_scenes() {
    for scene in ["go1_standing", "go1_walking", "humanoid_floor", "panda_free", "gripper_box"] {
        let golden = read_golden(scene);
        let model = tight_model(repo_path(&golden.model).to_str().unwrap());
        let mut data = Data::new(&model);
        for s in 0..golden.states.len() {
            load_state(&golden, &mut data, s);
            if golden.states[s].contact_set_same {
                let n = check_hybrid(&format!("{scene} state {s}"), &model, &mut data);
                assert!(n >= model.nv, "{scene}: the velocity columns are analytic");
            }
        }
    }
}

/// A box resting on a plane (four pyramidal contacts), Euler and implicitfast.
#[test]
fn hybrid_box_on_plane() {
    for integrator in ["Euler", "implicitfast"] {
        let model = tight_text(&format!(
            r#"<mujoco><option timestep="0.002" integrator="{integrator}"/><worldbody>
            <geom type="plane" size="5 5 .1"/>
            <body pos="0 0 0.1"><freejoint/><geom type="box" size=".1 .08 .1" mass="1"/></body>
            </worldbody></mujoco>"#
        ));
        let mut data = Data::new(&model);
        for _ in 0..300 {
            lagrange::integrate::step(&model, &mut data).unwrap();
        }
        data.qvel[0] = 0.01;
        data.qvel[5] = 0.02;
        check_hybrid(&format!("box on plane ({integrator})"), &model, &mut data);
    }
}

/// A joint limit, a joint equality, damping, a motor, a position servo and a velocity servo.
#[test]
fn hybrid_limit_equality_actuators() {
    for integrator in ["Euler", "implicitfast"] {
        let model = tight_text(&format!(
            r#"<mujoco><option timestep="0.002" integrator="{integrator}"/><worldbody>
            <body><joint name="a" type="hinge" axis="0 1 0" range="-30 30" damping="0.1"/>
              <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03"/>
              <body pos="0.3 0 0"><joint name="b" type="hinge" axis="0 1 0" damping="0.1"/>
                <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03"/></body></body>
            <body pos="0 1 0"><joint name="c" type="hinge" axis="0 1 0"/>
              <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03"/></body>
            </worldbody>
            <equality><joint joint1="c" joint2="b" polycoef="0 0.5 0 0 0"/></equality>
            <actuator><motor joint="a"/><position joint="b" kp="5"/><velocity joint="c" kv="0.3"/></actuator>
            </mujoco>"#
        ));
        let mut data = Data::new(&model);
        data.qpos.copy_from_slice(&[0.55, 0.2, 0.1]);
        data.qvel.copy_from_slice(&[0.1, -0.2, 0.3]);
        data.ctrl.copy_from_slice(&[0.1, 0.2, 0.3]);
        lagrange::forward::forward(&model, &mut data);
        assert!(data.nefc >= 2, "the limit and the equality are rows");
        let n = check_hybrid(&format!("limit and equality ({integrator})"), &model, &mut data);
        assert_eq!(n, model.nv + 3, "every column analytic but the positions");
    }
}

/// Without constraint rows every column is analytic: a floating body with a ball-jointed arm
/// (rotations' exponential map), hinge springs and damping, a fixed tendon with a spring, a motor,
/// a position servo and a tendon actuator, Euler and implicitfast.
#[test]
fn hybrid_contact_free_all_analytic() {
    for integrator in ["Euler", "implicitfast"] {
        let model = tight_text(&format!(
            r#"<mujoco><option timestep="0.002" integrator="{integrator}"><flag contact="disable"/></option>
            <worldbody><body pos="0 0 1"><freejoint/><geom type="box" size=".1 .08 .06" mass="2"/>
              <body pos="0.1 0 0"><joint name="s" type="ball" damping="0.05"/>
                <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03"/>
                <body pos="0.3 0 0"><joint name="a" type="hinge" axis="0 1 0" stiffness="3" springref="0.2" damping="0.1"/>
                  <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03"/>
                  <body pos="0.3 0 0"><joint name="b" type="slide" axis="1 0 0" damping="0.2"/>
                    <geom type="sphere" size="0.04"/></body></body></body></body>
            </worldbody>
            <tendon><fixed name="t" stiffness="2" damping="0.1"><joint joint="a" coef="1"/><joint joint="b" coef="-0.5"/></fixed></tendon>
            <actuator><motor joint="a"/><position joint="b" kp="5" kv="0.5"/><motor tendon="t" gear="2"/></actuator>
            </mujoco>"#
        ));
        let mut data = Data::new(&model);
        let (nq, nv) = (model.nq, model.nv);
        let dq: Vec<f64> = (0..nv).map(|i| 0.3 * (i as f64 + 1.0).sin()).collect();
        lagrange::model::integrate_configuration(&model, data.qpos.as_mut_slice(), &dq, 1.0).unwrap();
        assert_eq!(data.qpos.len(), nq);
        for i in 0..nv {
            data.qvel[i] = 0.4 * (1.7 * i as f64).cos();
        }
        data.ctrl.copy_from_slice(&[0.3, 0.1, -0.2]);
        let n = check_hybrid(&format!("contact-free ({integrator})"), &model, &mut data);
        assert_eq!(n, 2 * nv + 3, "every column analytic");
    }
}
