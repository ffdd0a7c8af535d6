//! Agreement with MuJoCo 4.0.0 on the MJCF corpus: the hand-written feature files in
//! `tests/data/mjcf/` (one MJCF feature each, described in a comment at the top of each file) and
//! the shipped robots in `models/mjcf/`. Golden data: `tests/data/mujoco/<name>.json`, produced by
//! `validation/mujoco_golden.py` with the `mujoco` package (see validation/README.md).
//!
//! Per model: nq/nv, joint names in order with their qpos/dof addresses and types, gravity,
//! timestep, qpos0, armature, joint limits, keyframes; per body (by name): mass, centre of mass
//! and inertia about it in body axes; per state (qpos0 and five random ones): M (CRBA), bias
//! forces (RNEA with zero acceleration), forward dynamics (ABA), and the world pose of every body
//! and named site — all at `REF_REL` relative (from `common`).
//!
//! Run with `cargo test --release --test mujoco -- --nocapture` for the per-model table.

mod common;

use common::*;
use lagrange::dynamics::{aba, bias_forces, crba};
use lagrange::io::{load, LoadOptions};
use lagrange::kinematics::forward_kinematics;
use lagrange::model::{FrameKind, JointKind};
use lagrange::spatial::quat_to_matrix;
use lagrange::{Data, Model};
use serde::Deserialize;

#[derive(Deserialize)]
struct Golden {
    name: String,
    model: String,
    nq: usize,
    nv: usize,
    gravity: [f64; 3],
    timestep: f64,
    qpos0: Vec<f64>,
    dof_armature: Vec<f64>,
    /// Σ body_mass over every body but the world (welded bodies included).
    total_mass: f64,
    joint_names: Vec<String>,
    bodies: Vec<BodyRef>,
    joints: Vec<JointRef>,
    sites: Vec<SiteRef>,
    keyframes: Vec<KeyRef>,
    states: Vec<State>,
}

#[derive(Deserialize)]
struct BodyRef {
    id: usize,
    /// MuJoCo's name, or `body{id}` if unnamed.
    name: String,
    mass: f64,
    /// Centre of mass in the body frame (`body_ipos`).
    com: [f64; 3],
    /// Inertia about the centre of mass in body axes: R(body_iquat)·diag(body_inertia)·Rᵀ.
    inertia: [[f64; 3]; 3],
}

#[derive(Deserialize)]
struct JointRef {
    name: String,
    #[serde(rename = "type")]
    jtype: String,
    qposadr: usize,
    dofadr: usize,
    range: Option<[f64; 2]>,
}

#[derive(Deserialize)]
struct SiteRef {
    /// MuJoCo's name, or `site{id}` if unnamed (unnamed sites are not compared).
    name: String,
    mujoco_name: String,
}

#[derive(Deserialize)]
struct KeyRef {
    name: String,
    time: f64,
    /// MuJoCo's compiled key_qpos / key_qvel: full length, padded from qpos0 / zeros,
    /// quaternions normalized.
    qpos: Vec<f64>,
    qvel: Vec<f64>,
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
    /// World pose of every body, by MuJoCo id; quaternions [w, x, y, z] with w ≥ 0.
    xpos: Vec<[f64; 3]>,
    xquat: Vec<[f64; 4]>,
    site_xpos: Vec<[f64; 3]>,
    site_xquat: Vec<[f64; 4]>,
}

/// Whether a lagrange joint kind is the MuJoCo joint type.
fn same_type(kind: &JointKind, mujoco: &str) -> bool {
    matches!(
        (kind, mujoco),
        (JointKind::Revolute { .. }, "hinge")
            | (JointKind::Prismatic { .. }, "slide")
            | (JointKind::Ball, "ball")
            | (JointKind::Free, "free")
    )
}

/// Stacks the rotation matrices and sign-aligned quaternions of world poses against the
/// reference quaternions (see tests/pinocchio.rs).
fn push_rotation(
    x: &lagrange::spatial::Transform,
    quat_ref: &[f64; 4],
    rot: &mut Vec<f64>,
    rot_ref: &mut Vec<f64>,
    quat: &mut Vec<f64>,
    quat_ref_out: &mut Vec<f64>,
) {
    let r_ref = quat_to_matrix(quat_ref[0], quat_ref[1], quat_ref[2], quat_ref[3]);
    rot.extend_from_slice(x.rot.as_slice());
    rot_ref.extend_from_slice(r_ref.as_slice());
    // Both sides canonicalize w ≥ 0, but a w within round-off of 0 may flip: align signs.
    let ours = x.quat_wxyz();
    let dot: f64 = ours.iter().zip(quat_ref).map(|(a, b)| a * b).sum();
    quat.extend(ours.iter().map(|a| if dot < 0.0 { -a } else { *a }));
    quat_ref_out.extend_from_slice(quat_ref);
}

fn check_model(name: &str) {
    let file = repo_path(&format!("tests/data/mujoco/{name}.json"));
    let text = std::fs::read_to_string(&file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    let golden: Golden = serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    assert_eq!(golden.name, name);

    let path = repo_path(&golden.model);
    let model: Model = load(&path, &LoadOptions::default())
        .unwrap_or_else(|e| panic!("{name}: loading {}: {e}", path.display()));

    // Structure: mismatches are collected (and reported with the numbers) rather than stopping
    // at the first one; the dynamics are only compared when nq/nv and the joint order agree.
    let mut structure: Vec<String> = Vec::new();
    if (model.nq, model.nv) != (golden.nq, golden.nv) {
        structure.push(format!("(nq, nv) = {:?}, MuJoCo {:?}", (model.nq, model.nv), (golden.nq, golden.nv)));
    }
    let names: Vec<&str> = model.joints.iter().map(|j| j.name.as_str()).collect();
    if names != golden.joint_names {
        structure.push(format!("joint names in order: {names:?}, MuJoCo {:?}", golden.joint_names));
    }
    for jr in &golden.joints {
        let Some(j) = model.joint_id(&jr.name).map(|j| &model.joints[j]) else {
            structure.push(format!("no joint '{}'", jr.name));
            continue;
        };
        if (j.qpos_adr, j.dof_adr) != (jr.qposadr, jr.dofadr) {
            structure.push(format!(
                "joint '{}': (qpos_adr, dof_adr) = {:?}, MuJoCo {:?}",
                jr.name,
                (j.qpos_adr, j.dof_adr),
                (jr.qposadr, jr.dofadr)
            ));
        }
        if !same_type(&j.kind, &jr.jtype) {
            structure.push(format!("joint '{}': type {}, MuJoCo {}", jr.name, j.kind.type_name(), jr.jtype));
        }
        if j.limits.is_some() != jr.range.is_some() {
            structure
                .push(format!("joint '{}': limits {:?}, MuJoCo range {:?}", jr.name, j.limits, jr.range));
        }
    }
    let mut body_frame: Vec<Option<usize>> = vec![None; golden.bodies.len()];
    for b in golden.bodies.iter().skip(1) {
        match model.frame_id(&b.name) {
            Some(f) if model.frames[f].kind == FrameKind::Link => body_frame[b.id] = Some(f),
            Some(f) => structure.push(format!("body '{}': frame kind {:?}", b.name, model.frames[f].kind)),
            None => structure.push(format!("no frame for body '{}'", b.name)),
        }
    }
    let named_sites: Vec<(usize, &SiteRef)> =
        golden.sites.iter().enumerate().filter(|(_, s)| !s.mujoco_name.is_empty()).collect();
    let mut site_frame: Vec<Option<usize>> = vec![None; golden.sites.len()];
    for &(i, s) in &named_sites {
        match model.site_id(&s.name) {
            Some(f) => site_frame[i] = Some(f),
            None => structure.push(format!("no site frame '{}'", s.name)),
        }
    }
    if model.keyframes.len() != golden.keyframes.len() {
        structure.push(format!("{} keyframes, MuJoCo {}", model.keyframes.len(), golden.keyframes.len()));
    }
    let dynamics_comparable = (model.nq, model.nv) == (golden.nq, golden.nv) && names == golden.joint_names;

    // Model-level quantities.
    let mut e_gravity = MaxErr::new(&format!("{name}: gravity"), REF_REL);
    e_gravity.add(rel_err_vec(model.gravity.as_slice(), &golden.gravity), || "gravity".into());
    let mut e_timestep = MaxErr::new(&format!("{name}: timestep"), REF_REL);
    e_timestep.add(rel_err(model.options.timestep, golden.timestep), || "timestep".into());
    let mut e_qpos0 = MaxErr::new(&format!("{name}: qpos0"), REF_REL);
    let mut e_armature = MaxErr::new(&format!("{name}: dof armature"), REF_REL);
    if dynamics_comparable {
        let (err, i) = rel_err_vec_at(&model.qpos0, &golden.qpos0);
        e_qpos0.add(err, || format!("qpos0[{i}]: {} vs {}", model.qpos0[i], golden.qpos0[i]));
        let (err, i) = rel_err_vec_at(&model.dof_armature, &golden.dof_armature);
        e_armature.add(err, || format!("dof {i}: {} vs {}", model.dof_armature[i], golden.dof_armature[i]));
    }
    let mut e_limits = MaxErr::new(&format!("{name}: joint limits"), REF_REL);
    for jr in &golden.joints {
        let lim = model.joint_id(&jr.name).and_then(|j| model.joints[j].limits);
        if let (Some(ours), Some(theirs)) = (lim, jr.range) {
            let (err, i) = rel_err_vec_at(&ours, &theirs);
            e_limits.add(err, || format!("joint '{}' [{i}]: {:?} vs {:?}", jr.name, ours, theirs));
        }
    }

    // Mass properties per body (each MJCF body's own, in its frame).
    let mut e_mass = MaxErr::new(&format!("{name}: body masses"), REF_REL);
    let mut e_com = MaxErr::new(&format!("{name}: body centres of mass (stacked)"), REF_REL);
    // Inline-mesh tensors (mesh_inline.xml) agree with MuJoCo's to ~2e-8 only, as mesh files do
    // (tests/mujoco_meshes.rs): masses and centres of mass agree to 1e-16, the principal-axis
    // fit differs; the mesh tolerance, not the f64 one, applies there.
    let inertia_tol = if name.starts_with("mesh_") { common::MESH_MUJOCO_REL } else { REF_REL };
    let mut e_inertia = MaxErr::new(&format!("{name}: body inertias about the COM"), inertia_tol);
    let mut e_total = MaxErr::new(&format!("{name}: total mass of all bodies (welded included)"), REF_REL);
    let (mut com, mut com_ref, mut com_names) = (vec![], vec![], vec![]);
    let mut total = 0.0;
    for b in golden.bodies.iter().skip(1) {
        let Some(f) = body_frame[b.id] else { continue };
        let inertia = &model.frames[f].inertia;
        total += inertia.mass;
        e_mass.add(rel_err(inertia.mass, b.mass), || {
            format!("body '{}': {} vs {}", b.name, inertia.mass, b.mass)
        });
        if b.mass > 0.0 {
            // MuJoCo's body_ipos of a massless body is meaningless (it equals body_pos).
            com.extend_from_slice(inertia.com().as_slice());
            com_ref.extend_from_slice(&b.com);
            com_names.push(b.name.as_str());
            let i_ours = inertia.i_com();
            let i_ref: Vec<f64> = (0..9).map(|k| b.inertia[k % 3][k / 3]).collect(); // column-major
            let (err, k) = rel_err_vec_at(i_ours.as_slice(), &i_ref);
            e_inertia.add(err, || {
                format!("body '{}' ({}, {}): {} vs {}", b.name, k % 3, k / 3, i_ours.as_slice()[k], i_ref[k])
            });
        }
    }
    if !com.is_empty() {
        let (err, i) = rel_err_vec_at(&com, &com_ref);
        e_com.add(err, || format!("body '{}' [{}]: {} vs {}", com_names[i / 3], i % 3, com[i], com_ref[i]));
    }
    e_total.add(rel_err(total, golden.total_mass), || format!("{total} vs {}", golden.total_mass));

    // Keyframes, in order: what the model holds, resolved like MuJoCo (missing or short vectors
    // are completed from qpos0 / zeros), against MuJoCo's compiled key_qpos/key_qvel.
    let mut e_keys = MaxErr::new(&format!("{name}: keyframes (qpos, qvel, time)"), REF_REL);
    if dynamics_comparable {
        for (k, (ours, theirs)) in model.keyframes.iter().zip(&golden.keyframes).enumerate() {
            if ours.name != theirs.name {
                structure.push(format!("keyframe {k}: name '{}', MuJoCo '{}'", ours.name, theirs.name));
            }
            let mut qpos = model.qpos0.clone();
            let mut qvel = vec![0.0; model.nv];
            if let Some(q) = &ours.qpos {
                qpos[..q.len().min(model.nq)].copy_from_slice(&q[..q.len().min(model.nq)]);
            }
            if let Some(v) = &ours.qvel {
                qvel[..v.len().min(model.nv)].copy_from_slice(&v[..v.len().min(model.nv)]);
            }
            let (err, i) = rel_err_vec_at(&qpos, &theirs.qpos);
            e_keys.add(err, || {
                format!("keyframe '{}' qpos[{i}]: {} vs {}", theirs.name, qpos[i], theirs.qpos[i])
            });
            let (err, i) = rel_err_vec_at(&qvel, &theirs.qvel);
            e_keys.add(err, || {
                format!("keyframe '{}' qvel[{i}]: {} vs {}", theirs.name, qvel[i], theirs.qvel[i])
            });
            e_keys.add(rel_err(ours.time, theirs.time), || format!("keyframe '{}' time", theirs.name));
        }
    }

    // Dynamics and poses per state.
    let mut e_m = MaxErr::new(&format!("{name}: M (CRBA)"), REF_REL);
    let mut e_bias = MaxErr::new(&format!("{name}: bias c(q,v) (RNEA)"), REF_REL);
    let mut e_qacc = MaxErr::new(&format!("{name}: qacc (ABA)"), REF_REL);
    let mut e_pos = MaxErr::new(&format!("{name}: body positions (stacked)"), REF_REL);
    let mut e_rot = MaxErr::new(&format!("{name}: body rotation matrices"), REF_REL);
    let mut e_quat = MaxErr::new(&format!("{name}: body quaternions (up to sign)"), REF_REL);
    let mut e_site_pos = MaxErr::new(&format!("{name}: named site positions"), REF_REL);
    let mut e_site_rot = MaxErr::new(&format!("{name}: named site rotation matrices"), REF_REL);
    if dynamics_comparable {
        let mut data = Data::new(&model);
        for (s, st) in golden.states.iter().enumerate() {
            assert_eq!(
                (st.q.len(), st.v.len(), st.tau.len()),
                (model.nq, model.nv, model.nv),
                "{name} state {s}"
            );

            let m = crba(&model, &mut data, &st.q).unwrap().clone();
            let (err, (r, c)) = rel_err_mat_at(&m, &matrix(&st.m, model.nv));
            e_m.add(err, || format!("state {s}, ({r}, {c}): {} vs {}", m[(r, c)], st.m[r][c]));

            let bias = bias_forces(&model, &mut data, &st.q, &st.v).unwrap().clone();
            let (err, i) = rel_err_vec_at(bias.as_slice(), &st.bias);
            e_bias.add(err, || format!("state {s}, [{i}]: {} vs {}", bias[i], st.bias[i]));

            let qacc = aba(&model, &mut data, &st.q, &st.v, &st.tau).unwrap().clone();
            let (err, i) = rel_err_vec_at(qacc.as_slice(), &st.qacc);
            e_qacc.add(err, || format!("state {s}, [{i}]: {} vs {}", qacc[i], st.qacc[i]));

            forward_kinematics(&model, &mut data, &st.q).unwrap();
            let (mut pos, mut pos_ref, mut rot, mut rot_ref, mut quat, mut quat_ref) =
                (vec![], vec![], vec![], vec![], vec![], vec![]);
            let mut which = vec![];
            for b in golden.bodies.iter().skip(1) {
                let Some(f) = body_frame[b.id] else { continue };
                let x = &data.x_world_frame[f];
                pos.extend_from_slice(x.pos.as_slice());
                pos_ref.extend_from_slice(&st.xpos[b.id]);
                push_rotation(x, &st.xquat[b.id], &mut rot, &mut rot_ref, &mut quat, &mut quat_ref);
                which.push(b.name.as_str());
            }
            if !which.is_empty() {
                let (err, i) = rel_err_vec_at(&pos, &pos_ref);
                e_pos
                    .add(err, || format!("state {s}, body '{}': {} vs {}", which[i / 3], pos[i], pos_ref[i]));
                let (err, i) = rel_err_vec_at(&rot, &rot_ref);
                e_rot.add(err, || format!("state {s}, body '{}'", which[i / 9]));
                let (err, i) = rel_err_vec_at(&quat, &quat_ref);
                e_quat.add(err, || format!("state {s}, body '{}'", which[i / 4]));
            }

            let (mut pos, mut pos_ref, mut rot, mut rot_ref, mut quat, mut quat_ref) =
                (vec![], vec![], vec![], vec![], vec![], vec![]);
            let mut which = vec![];
            for &(i, site) in &named_sites {
                let Some(f) = site_frame[i] else { continue };
                let x = &data.x_world_frame[f];
                pos.extend_from_slice(x.pos.as_slice());
                pos_ref.extend_from_slice(&st.site_xpos[i]);
                push_rotation(x, &st.site_xquat[i], &mut rot, &mut rot_ref, &mut quat, &mut quat_ref);
                which.push(site.name.as_str());
            }
            if !which.is_empty() {
                let (err, i) = rel_err_vec_at(&pos, &pos_ref);
                e_site_pos
                    .add(err, || format!("state {s}, site '{}': {} vs {}", which[i / 3], pos[i], pos_ref[i]));
                let (err, i) = rel_err_vec_at(&rot, &rot_ref);
                e_site_rot.add(err, || format!("state {s}, site '{}'", which[i / 9]));
            }
        }
    }

    println!(
        "{name} ({}): nq {} nv {}, {} bodies, {} joints, {} named sites, {} keyframes, {} states",
        golden.model,
        golden.nq,
        golden.nv,
        golden.bodies.len(),
        golden.joints.len(),
        named_sites.len(),
        golden.keyframes.len(),
        golden.states.len()
    );
    for s in &structure {
        println!("{name}: STRUCTURE MISMATCH: {s}");
    }
    let mut checks: Vec<&MaxErr> = vec![&e_gravity, &e_timestep, &e_total];
    if golden.bodies.len() > 1 {
        checks.extend([&e_mass, &e_inertia]);
    }
    if !com.is_empty() {
        checks.push(&e_com);
    }
    if golden.joints.iter().any(|j| j.range.is_some()) {
        checks.push(&e_limits);
    }
    if !golden.keyframes.is_empty() {
        checks.push(&e_keys);
    }
    checks.extend([&e_qpos0, &e_armature, &e_m, &e_bias, &e_qacc, &e_pos, &e_rot, &e_quat]);
    if !named_sites.is_empty() {
        checks.extend([&e_site_pos, &e_site_rot]);
    }
    if !structure.is_empty() {
        for c in &checks {
            c.report();
        }
        panic!("{name}: structure differs from MuJoCo's:\n{}", structure.join("\n"));
    }
    report_and_assert(&checks);
}

/// One test per golden file; `every_golden_file_has_a_test` keeps the list complete.
macro_rules! mujoco_tests {
    ($($test:ident => $name:literal),* $(,)?) => {
        $(
            #[test]
            fn $test() {
                check_model($name);
            }
        )*
        const TESTED: &[&str] = &[$($name),*];
    };
}

mujoco_tests! {
    // Hand-written feature files (tests/data/mjcf/*.xml).
    angle_degree => "angle_degree",
    angle_radian => "angle_radian",
    armature => "armature",
    balanceinertia => "balanceinertia",
    ball => "ball",
    boundmass_boundinertia => "boundmass_boundinertia",
    boundmass_empty_body => "boundmass_empty_body",
    compose_attach => "compose_attach",
    compose_attach_world => "compose_attach_world",
    compose_replicate => "compose_replicate",
    defaults => "defaults",
    eulerseq_xyz_intrinsic => "eulerseq_xyz_intrinsic",
    eulerseq_xyz_extrinsic_upper => "eulerseq_XYZ_extrinsic",
    eulerseq_zyx_intrinsic => "eulerseq_zyx_intrinsic",
    eulerseq_zyx_mixed_case => "eulerseq_zYx_mixed",
    eulerseq_zxz_proper => "eulerseq_zxz_proper",
    frames => "frames",
    free => "free",
    fromto => "fromto",
    geom_mass_density => "geom_mass_density",
    include_nested => "include_nested",
    inertiafromgeom_auto => "inertiafromgeom_auto",
    inertiafromgeom_false => "inertiafromgeom_false",
    inertiafromgeom_true => "inertiafromgeom_true",
    inertial_forms => "inertial_forms",
    joint_anchor_ref => "joint_anchor_ref",
    keyframes => "keyframes",
    mesh_inline => "mesh_inline",
    multijoint => "multijoint",
    orient_body => "orient_body",
    orient_geom => "orient_geom",
    settotalmass => "settotalmass",
    shellinertia => "shellinertia",
    static_bodies => "static_bodies",
    // Shipped robots (models/mjcf/).
    robot_humanoid => "humanoid",
    robot_franka_emika_panda => "franka_emika_panda",
    robot_unitree_go1 => "unitree_go1",
}

#[test]
fn every_golden_file_has_a_test() {
    let dir = repo_path("tests/data/mujoco");
    // Other scripts share the folder (validation/mujoco_mesh_golden.py writes meshes.json): the
    // golden files of this test are the ones with "kind": "feature" | "robot".
    let ours = |path: &std::path::Path| -> bool {
        let Ok(text) = std::fs::read_to_string(path) else { return false };
        let Ok(doc) = serde_json::from_str::<serde_json::Value>(&text) else { return false };
        matches!(doc.get("kind").and_then(|k| k.as_str()), Some("feature" | "robot"))
    };
    let mut files: Vec<String> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .filter_map(|e| e.ok())
        .filter(|e| ours(&e.path()))
        .filter_map(|e| e.file_name().to_str().and_then(|n| n.strip_suffix(".json")).map(String::from))
        .collect();
    files.sort();
    let mut tested: Vec<String> = TESTED.iter().map(|s| s.to_string()).collect();
    tested.sort();
    assert_eq!(files, tested, "tests/data/mujoco/*.json and the tests in tests/mujoco.rs differ");

    // Every feature file has golden data (rerun validation/mujoco_golden.py after adding one).
    let features = repo_path("tests/data/mjcf");
    for entry in std::fs::read_dir(&features).unwrap_or_else(|e| panic!("{}: {e}", features.display())) {
        let name = entry.unwrap().file_name().to_string_lossy().into_owned();
        if let Some(stem) = name.strip_suffix(".xml") {
            assert!(
                files.iter().any(|f| f == stem),
                "tests/data/mjcf/{name} has no tests/data/mujoco/{stem}.json"
            );
        }
    }
}
