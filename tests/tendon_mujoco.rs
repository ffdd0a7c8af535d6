//! Tendons against MuJoCo 4.0's `mj_forward` and `mj_step` (tests/data/mujoco/tendon/, generated
//! by validation/mujoco_tendon_golden.py from the scenes of tests/data/tendon): at seeded random
//! states, every tendon's length, Jacobian, velocity and wrap points (sphere and cylinder wraps
//! with and without side site, the inside wrap, a pulley with divisor, site paths through several
//! bodies), the actuators on spatial tendons (length, moment), `qfrc_passive` (tendon springs
//! with a dead band, dampers), the constraint rows (tendon friction loss and limit; `efc_type`,
//! `efc_id` exactly, `efc_force` with the scene's tight solver), `qacc` and tendon sensors to
//! [`REF_REL`] relative; then a 200-step trajectory to [`SOFT_REL`].

mod common;

use common::{rel_err_vec, report_and_assert, MaxErr, INSIDE_WRAP_REL, REF_REL, SOFT_REL};
use lagrange::forward::forward;
use lagrange::integrate::step;
use lagrange::model::EfcType;
use lagrange::{Data, Model};
use serde::Deserialize;
use std::path::PathBuf;

#[derive(Deserialize)]
struct Golden {
    scene: String,
    tendon_lengthspring: Vec<Vec<f64>>,
    states: Vec<State>,
    trajectory: Trajectory,
}

#[derive(Deserialize)]
struct State {
    qpos: Vec<f64>,
    qvel: Vec<f64>,
    ctrl: Vec<f64>,
    ten_length: Vec<f64>,
    ten_velocity: Vec<f64>,
    #[serde(rename = "ten_J")]
    ten_j: Vec<Vec<f64>>,
    ten_wrapadr: Vec<usize>,
    ten_wrapnum: Vec<usize>,
    wrap_obj: Vec<i64>,
    wrap_xpos: Vec<Vec<f64>>,
    actuator_length: Vec<f64>,
    actuator_velocity: Vec<f64>,
    actuator_moment: Vec<Vec<f64>>,
    qfrc_passive: Vec<f64>,
    qfrc_actuator: Vec<f64>,
    efc_type: Vec<i64>,
    efc_id: Vec<usize>,
    efc_force: Vec<f64>,
    qacc: Vec<f64>,
    sensordata: Vec<f64>,
}

#[derive(Deserialize)]
struct Trajectory {
    qpos0: Vec<f64>,
    qvel0: Vec<f64>,
    ctrl: Vec<f64>,
    steps: Vec<Step>,
}

#[derive(Deserialize)]
struct Step {
    qpos: Vec<f64>,
    qvel: Vec<f64>,
}

/// MuJoCo's `mjtConstraint` number of a row kind.
fn mujoco_efc_type(t: EfcType) -> i64 {
    match t {
        EfcType::Equality => 0,
        EfcType::FrictionDof => 1,
        EfcType::FrictionTendon => 2,
        EfcType::LimitJoint => 3,
        EfcType::LimitTendon => 4,
        EfcType::ContactFrictionless => 5,
        EfcType::ContactPyramidal => 6,
        EfcType::ContactElliptic => 7,
    }
}

fn golden(name: &str) -> Golden {
    let file =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("tests/data/mujoco/tendon/{name}.json"));
    let text = std::fs::read_to_string(&file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", file.display()))
}

fn set_state(data: &mut Data, q: &[f64], v: &[f64], ctrl: &[f64]) {
    data.qpos.as_mut_slice().copy_from_slice(q);
    data.qvel.as_mut_slice().copy_from_slice(v);
    data.ctrl.as_mut_slice().copy_from_slice(ctrl);
}

fn row(m: &nalgebra::DMatrix<f64>, i: usize) -> Vec<f64> {
    m.row(i).iter().copied().collect()
}

#[test]
fn wraps_match_mujoco() {
    let g = golden("wraps");
    let model = Model::from_file(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(&g.scene)).unwrap();
    let mut data = Data::new(&model);
    let mut spring = MaxErr::new("tendon_lengthspring (springlength -1 resolved at qpos_spring)", REF_REL);
    for (t, ls) in g.tendon_lengthspring.iter().enumerate() {
        spring.add(rel_err_vec(&model.tendons[t].spring_length, ls), || format!("tendon {t}"));
    }
    let mut length = MaxErr::new("ten_length", REF_REL);
    let mut jac = MaxErr::new("ten_J", REF_REL);
    let mut vel = MaxErr::new("ten_velocity", REF_REL);
    let mut wraps = MaxErr::new("wrap_xpos (wrap_obj, ten_wrapnum exact)", REF_REL);
    let mut inside = MaxErr::new("inside wrap: ten_J, ten_velocity, wrap_xpos", INSIDE_WRAP_REL);
    let mut act = MaxErr::new("actuator_length, _velocity, _moment", REF_REL);
    let mut passive = MaxErr::new("qfrc_passive", REF_REL);
    let mut frc = MaxErr::new("qfrc_actuator", REF_REL);
    let mut efc = MaxErr::new("efc_force (efc_type, efc_id exact)", REF_REL);
    let mut qacc = MaxErr::new("qacc", REF_REL);
    let mut sensors = MaxErr::new("sensordata (tendonpos, tendonvel, actuatorpos/vel)", REF_REL);
    for (k, s) in g.states.iter().enumerate() {
        set_state(&mut data, &s.qpos, &s.qvel, &s.ctrl);
        forward(&model, &mut data);
        for t in 0..model.tendons.len() {
            let at = || format!("state {k} tendon {t} ({})", model.tendons[t].name);
            length.add(rel_err_vec(&[data.ten_length[t]], &[s.ten_length[t]]), at);
            // The inside wrap's point: MuJoCo's Newton tolerance (INSIDE_WRAP_REL).
            let is_inside = model.tendons[t].name == "inside";
            let (jac, vel, wraps) = if is_inside {
                (&mut inside, None, None)
            } else {
                (&mut jac, Some(&mut vel), Some(&mut wraps))
            };
            jac.add(rel_err_vec(&row(&data.ten_j, t), &s.ten_j[t]), at);
            let vel_err = rel_err_vec(&[data.ten_velocity[t]], &[s.ten_velocity[t]]);
            match vel {
                Some(v) => v.add(vel_err, at),
                None => jac.add(vel_err, at),
            }
            let wraps = match wraps {
                Some(w) => w,
                None => jac,
            };
            let (adr, n) = (s.ten_wrapadr[t], s.ten_wrapnum[t]);
            let same = data.ten_wrapadr[t] == adr
                && data.ten_wrapnum[t] == n
                && data.wrap_obj[adr..adr + n] == s.wrap_obj[adr..adr + n];
            if !same {
                wraps.add(f64::NAN, || {
                    format!(
                        "{}: wrap_obj {:?} vs MuJoCo's {:?}",
                        at(),
                        &data.wrap_obj[data.ten_wrapadr[t]..data.ten_wrapadr[t] + data.ten_wrapnum[t]],
                        &s.wrap_obj[adr..adr + n]
                    )
                });
                continue;
            }
            for w in adr..adr + n {
                let p = data.wrap_xpos[w];
                wraps.add(rel_err_vec(p.as_slice(), &s.wrap_xpos[w]), || format!("{} point {w}", at()));
            }
        }
        for a in 0..model.actuators.len() {
            let at = || format!("state {k} actuator {a}");
            act.add(rel_err_vec(&[data.actuator_length[a]], &[s.actuator_length[a]]), at);
            act.add(rel_err_vec(&[data.actuator_velocity[a]], &[s.actuator_velocity[a]]), at);
            act.add(rel_err_vec(&row(&data.actuator_moment, a), &s.actuator_moment[a]), at);
        }
        passive.add(rel_err_vec(data.qfrc_passive.as_slice(), &s.qfrc_passive), || format!("state {k}"));
        frc.add(rel_err_vec(data.qfrc_actuator.as_slice(), &s.qfrc_actuator), || format!("state {k}"));
        let types: Vec<i64> = (0..data.nefc).map(|i| mujoco_efc_type(data.efc_type[i])).collect();
        let ids: Vec<usize> = data.efc_id[..data.nefc].to_vec();
        if types != s.efc_type || ids != s.efc_id {
            efc.add(f64::NAN, || {
                format!("state {k}: rows {types:?} {ids:?} vs MuJoCo's {:?} {:?}", s.efc_type, s.efc_id)
            });
        } else {
            efc.add(rel_err_vec(&data.efc_force.as_slice()[..data.nefc], &s.efc_force), || {
                format!("state {k}")
            });
        }
        qacc.add(rel_err_vec(data.qacc.as_slice(), &s.qacc), || format!("state {k}"));
        sensors.add(rel_err_vec(data.sensordata.as_slice(), &s.sensordata), || format!("state {k}"));
    }
    // The trajectory.
    let mut traj = MaxErr::new("200-step mj_step trajectory (qpos, qvel)", SOFT_REL);
    set_state(&mut data, &g.trajectory.qpos0, &g.trajectory.qvel0, &g.trajectory.ctrl);
    for (i, s) in g.trajectory.steps.iter().enumerate() {
        step(&model, &mut data).unwrap();
        traj.add(rel_err_vec(data.qpos.as_slice(), &s.qpos), || format!("step {i} qpos"));
        traj.add(rel_err_vec(data.qvel.as_slice(), &s.qvel), || format!("step {i} qvel"));
    }
    report_and_assert(&[
        &spring, &length, &jac, &vel, &wraps, &inside, &act, &passive, &frc, &efc, &qacc, &sensors, &traj,
    ]);
}

/// A cylinder wrap whose straight segment misses the circle on the side away from the side site
/// (the Aero hand's index and ring tendons): MuJoCo 4.0 wraps only when the side site is behind
/// the circle. Lengths, Jacobians, wrap points and the trajectory against MuJoCo.
#[test]
fn side_site_behind_or_beside_matches_mujoco() {
    let g = golden("side_behind");
    let model = Model::from_file(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(&g.scene)).unwrap();
    let mut data = Data::new(&model);
    let mut length = MaxErr::new("ten_length", REF_REL);
    let mut jac = MaxErr::new("ten_J", REF_REL);
    let mut wraps = MaxErr::new("wrap_xpos (wrap_obj, ten_wrapnum exact)", REF_REL);
    let (mut wrapped, mut straight) = (0, 0);
    for (k, s) in g.states.iter().enumerate() {
        set_state(&mut data, &s.qpos, &s.qvel, &s.ctrl);
        forward(&model, &mut data);
        for t in 0..model.tendons.len() {
            let at = || format!("state {k} tendon {}", model.tendons[t].name);
            length.add(rel_err_vec(&[data.ten_length[t]], &[s.ten_length[t]]), at);
            jac.add(rel_err_vec(&row(&data.ten_j, t), &s.ten_j[t]), at);
            let (adr, n) = (s.ten_wrapadr[t], s.ten_wrapnum[t]);
            if n == 4 {
                wrapped += 1;
            } else {
                straight += 1;
            }
            if data.ten_wrapnum[t] != n || data.wrap_obj[adr..adr + n] != s.wrap_obj[adr..adr + n] {
                wraps.add(f64::NAN, || {
                    format!("{}: wrap_obj differs from MuJoCo's {:?}", at(), &s.wrap_obj[adr..adr + n])
                });
                continue;
            }
            for w in adr..adr + n {
                wraps.add(rel_err_vec(data.wrap_xpos[w].as_slice(), &s.wrap_xpos[w]), || {
                    format!("{} point {w}", at())
                });
            }
        }
    }
    // Both cases occur: "front" never wraps, "back" wraps round the back.
    assert!(wrapped > 0 && straight > 0, "wrapped {wrapped}, straight {straight}");
    let mut traj = MaxErr::new("200-step mj_step trajectory (qpos, qvel)", SOFT_REL);
    set_state(&mut data, &g.trajectory.qpos0, &g.trajectory.qvel0, &g.trajectory.ctrl);
    for (i, s) in g.trajectory.steps.iter().enumerate() {
        step(&model, &mut data).unwrap();
        traj.add(rel_err_vec(data.qpos.as_slice(), &s.qpos), || format!("step {i} qpos"));
        traj.add(rel_err_vec(data.qvel.as_slice(), &s.qvel), || format!("step {i} qvel"));
    }
    report_and_assert(&[&length, &jac, &wraps, &traj]);
}
