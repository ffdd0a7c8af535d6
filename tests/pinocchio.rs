//! Agreement with Pinocchio 4.1.0 on the four shipped robots (golden data in
//! `tests/data/pinocchio/<robot>.json`, produced by `validation/pinocchio_golden.py`; its README
//! describes the conventions). Per state: M, bias, forward dynamics, every link pose, kinetic and
//! potential energy, centre of mass and total mass, at `REF_REL` relative (from `common`).
//!
//! Run with `cargo test --release --test pinocchio -- --nocapture` for the per-robot table.

mod common;

use common::*;
use lagrange::dynamics::{aba, bias_forces, center_of_mass, crba, kinetic_energy, potential_energy};
use lagrange::io::{load, LoadOptions};
use lagrange::kinematics::forward_kinematics;
use lagrange::spatial::{quat_to_matrix, Vec3};
use lagrange::Data;
use serde::Deserialize;
use std::collections::BTreeMap;

#[derive(Deserialize)]
struct Golden {
    robot: String,
    model: String,
    floating: bool,
    gravity: [f64; 3],
    nq: usize,
    nv: usize,
    joint_names: Vec<String>,
    world_fixed: WorldFixed,
    states: Vec<State>,
}

/// Links welded to the world, which Pinocchio leaves out of total mass, com and potential.
#[derive(Deserialize)]
struct WorldFixed {
    links: Vec<String>,
    mass: f64,
    com: [f64; 3],
}

#[derive(Deserialize)]
struct State {
    q: Vec<f64>,
    v: Vec<f64>,
    tau: Vec<f64>,
    #[serde(rename = "M")]
    m: Vec<Vec<f64>>,
    bias: Vec<f64>,
    qacc: Vec<f64>,
    poses: BTreeMap<String, Pose>,
    kinetic: f64,
    potential: f64,
    com: [f64; 3],
    total_mass: f64,
}

#[derive(Deserialize)]
struct Pose {
    pos: [f64; 3],
    /// [w, x, y, z], sign canonicalized to w ≥ 0.
    quat: [f64; 4],
}

fn check_robot(robot: &str) {
    let file = repo_path(&format!("tests/data/pinocchio/{robot}.json"));
    let text = std::fs::read_to_string(&file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    let golden: Golden = serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    assert_eq!(golden.robot, robot);

    let path = repo_path(&golden.model);
    let options = LoadOptions { floating: golden.floating, ..Default::default() };
    let model = load(&path, &options).unwrap_or_else(|e| panic!("loading {}: {e}", path.display()));

    // Structure: sizes, joint order (ours is depth-first file order), gravity, frames.
    assert_eq!((model.nq, model.nv), (golden.nq, golden.nv), "{robot}: (nq, nv)");
    let names: Vec<&str> = model.joints.iter().map(|j| j.name.as_str()).collect();
    assert_eq!(names, golden.joint_names, "{robot}: joint names in order");
    let g_err = rel_err_vec(model.gravity.as_slice(), &golden.gravity);
    assert!(g_err <= REF_REL, "{robot}: gravity {:?} vs {:?}", model.gravity, golden.gravity);
    for link in &golden.world_fixed.links {
        let f = model.frame_id(link).unwrap_or_else(|| panic!("{robot}: no frame '{link}'"));
        assert_eq!(model.frames[f].body, 0, "{robot}: link '{link}' should be welded to the world");
    }
    if let Some(state) = golden.states.first() {
        let mut ours: Vec<&str> = model.frames.iter().map(|f| f.name.as_str()).collect();
        ours.sort_unstable();
        let theirs: Vec<&str> = state.poses.keys().map(|k| k.as_str()).collect();
        assert_eq!(ours, theirs, "{robot}: the set of link frames");
    }

    let mut e_m = MaxErr::new(&format!("{robot}: M (CRBA)"), REF_REL);
    let mut e_bias = MaxErr::new(&format!("{robot}: bias c(q,v) (RNEA)"), REF_REL);
    let mut e_qacc = MaxErr::new(&format!("{robot}: qacc (ABA)"), REF_REL);
    let mut e_pos = MaxErr::new(&format!("{robot}: link positions (all links stacked)"), REF_REL);
    let mut e_rot = MaxErr::new(&format!("{robot}: link rotation matrices (all links)"), REF_REL);
    let mut e_quat =
        MaxErr::new(&format!("{robot}: link quaternions, Transform::quat_wxyz (up to sign)"), REF_REL);
    let mut e_kin = MaxErr::new(&format!("{robot}: kinetic energy"), REF_REL);
    let mut e_pot = MaxErr::new(&format!("{robot}: potential energy"), REF_REL);
    let mut e_com = MaxErr::new(&format!("{robot}: centre of mass"), REF_REL);
    let mut e_mass = MaxErr::new(&format!("{robot}: total mass (moving bodies)"), REF_REL);
    let mut e_mass_all = MaxErr::new(&format!("{robot}: total mass incl. world-welded links"), REF_REL);
    let mut e_com_all = MaxErr::new(&format!("{robot}: centre of mass incl. world-welded links"), REF_REL);

    let mut data = Data::new(&model);
    let world = &model.bodies[0];
    for (s, st) in golden.states.iter().enumerate() {
        assert_eq!(
            (st.q.len(), st.v.len(), st.tau.len()),
            (model.nq, model.nv, model.nv),
            "{robot} state {s}"
        );
        let at = || format!("state {s}");

        let m = crba(&model, &mut data, &st.q).unwrap().clone();
        let (err, (r, c)) = rel_err_mat_at(&m, &matrix(&st.m, model.nv));
        e_m.add(err, || format!("state {s}, ({r}, {c})"));

        let bias = bias_forces(&model, &mut data, &st.q, &st.v).unwrap().clone();
        let (err, i) = rel_err_vec_at(bias.as_slice(), &st.bias);
        e_bias.add(err, || format!("state {s}, [{i}]"));

        let qacc = aba(&model, &mut data, &st.q, &st.v, &st.tau).unwrap().clone();
        let (err, i) = rel_err_vec_at(qacc.as_slice(), &st.qacc);
        e_qacc.add(err, || format!("state {s}, [{i}]"));

        forward_kinematics(&model, &mut data, &st.q).unwrap();
        let (mut pos, mut pos_ref, mut rot, mut rot_ref) = (vec![], vec![], vec![], vec![]);
        let (mut quat, mut quat_ref) = (vec![], vec![]);
        let link_names: Vec<&String> = st.poses.keys().collect();
        for (link, pose) in &st.poses {
            let f = model.frame_id(link).unwrap_or_else(|| panic!("{robot}: no frame '{link}'"));
            let x = &data.x_world_frame[f];
            pos.extend_from_slice(x.pos.as_slice());
            pos_ref.extend_from_slice(&pose.pos);
            // Rotation matrices are insensitive to the quaternion's sign.
            let r_ref = quat_to_matrix(pose.quat[0], pose.quat[1], pose.quat[2], pose.quat[3]);
            rot.extend_from_slice(x.rot.as_slice());
            rot_ref.extend_from_slice(r_ref.as_slice());
            // Both sides canonicalize w ≥ 0, but a w within round-off of 0 may flip: align signs.
            let ours = x.quat_wxyz();
            let dot: f64 = ours.iter().zip(&pose.quat).map(|(a, b)| a * b).sum();
            quat.extend(ours.iter().map(|a| if dot < 0.0 { -a } else { *a }));
            quat_ref.extend_from_slice(&pose.quat);
        }
        let (err, i) = rel_err_vec_at(&pos, &pos_ref);
        e_pos.add(err, || format!("state {s}, link {}", link_names[i / 3]));
        let (err, i) = rel_err_vec_at(&rot, &rot_ref);
        e_rot.add(err, || format!("state {s}, link {}", link_names[i / 9]));
        let (err, i) = rel_err_vec_at(&quat, &quat_ref);
        e_quat.add(err, || format!("state {s}, link {}", link_names[i / 4]));

        let pot = potential_energy(&model, &data);
        e_pot.add(rel_err(pot, st.potential), at);
        let com = center_of_mass(&model, &data);
        e_com.add(rel_err_vec(com.as_slice(), &st.com), at);

        let moving = model.total_mass();
        e_mass.add(rel_err(moving, st.total_mass), at);
        let all_ref = st.total_mass + golden.world_fixed.mass;
        e_mass_all.add(rel_err(moving + world.mass(), all_ref), at);
        // Body 0 (the world) holds the welded links' inertia in world coordinates.
        let com_all = (com * moving + world.com() * world.mass()) / (moving + world.mass());
        let com_all_ref = (Vec3::from(st.com) * st.total_mass
            + Vec3::from(golden.world_fixed.com) * golden.world_fixed.mass)
            / all_ref;
        e_com_all.add(rel_err_vec(com_all.as_slice(), com_all_ref.as_slice()), at);

        let kin = kinetic_energy(&model, &mut data, &st.q, &st.v).unwrap();
        e_kin.add(rel_err(kin, st.kinetic), at);
    }
    println!(
        "{robot}: nq {} nv {}, {} states, {} link frames",
        model.nq,
        model.nv,
        golden.states.len(),
        model.frames.len()
    );
    report_and_assert(&[
        &e_m,
        &e_bias,
        &e_qacc,
        &e_pos,
        &e_rot,
        &e_quat,
        &e_kin,
        &e_pot,
        &e_com,
        &e_mass,
        &e_mass_all,
        &e_com_all,
    ]);
}

#[test]
fn pinocchio_ur5() {
    check_robot("ur5");
}

#[test]
fn pinocchio_panda() {
    check_robot("panda");
}

#[test]
fn pinocchio_solo12() {
    check_robot("solo12");
}
