//! Geoms and sites placed as MuJoCo places them when they share their body's frame or inertial
//! frame (`geom_sameframe`, `site_sameframe`; src/io/sameframe.rs), and the frame MuJoCo moves a
//! mesh into (`mesh_pos`, `mesh_quat`; src/mass/eig3.rs), against MuJoCo 4.0
//! (`tests/data/mujoco/sameframe.json`, written by `validation/mujoco_sameframe_golden.py`):
//! - every mesh under tests/data/meshes/mujoco at scales 1, 0.001 and 10: the frame of its hull
//!   (`MeshGraph::box_frame`) is MuJoCo's `mesh_pos`, `mesh_quat`;
//! - tests/data/mjcf/sameframe/flags.xml (every flag, reached exactly and from a few 1e-7 away)
//!   and the MJCF models under models/mjcf: the flags are MuJoCo's, and at qpos0 the world pose of
//!   every geom (in MuJoCo's frame of it) and every site is MuJoCo's `geom_xpos`/`geom_xmat`,
//!   `site_xpos`/`site_xmat`. A mesh that does not collide has no hull, so neither its MuJoCo
//!   frame nor its flag is computed (lagrange keeps its own pose): it is counted and left out.

mod common;

use common::repo_path;
use lagrange::model::{FrameKind, SameFrame};
use lagrange::prelude::*;
use lagrange::spatial::{quat_to_matrix, Transform};
use serde_json::Value;

/// World poses and mesh frames agree with MuJoCo's to this (m, and rotation-matrix entries).
const POSE_ABS: f64 = 1e-12;

fn golden() -> Value {
    let path = repo_path("tests/data/mujoco/sameframe.json");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).expect("sameframe.json parses")
}

fn nums(v: &Value) -> Vec<f64> {
    v.as_array().expect("array").iter().map(|x| x.as_f64().expect("number")).collect()
}

/// The largest difference between a pose and MuJoCo's position and row-major rotation matrix.
fn pose_err(x: &Transform, pos: &[f64], mat: &[f64]) -> f64 {
    let p = (0..3).map(|k| (x.pos[k] - pos[k]).abs()).fold(0.0, f64::max);
    (0..9).map(|k| (x.rot[(k / 3, k % 3)] - mat[k]).abs()).fold(p, f64::max)
}

#[test]
fn mesh_frames_are_mujocos() {
    let doc = golden();
    let meshes = doc["scenes"]["meshes"].as_array().expect("meshes");
    let dir = repo_path("tests/data/meshes/mujoco");
    let mut worst = 0.0f64;
    for m in meshes {
        let (file, scale) = (m["file"].as_str().unwrap(), m["scale"].as_f64().unwrap());
        let xml = format!(
            r#"<mujoco><compiler meshdir="{}"/><asset><mesh name="m" file="{file}" scale="{scale:?} {scale:?} {scale:?}"/></asset><worldbody><body><freejoint/><inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/><geom type="mesh" mesh="m" mass="0"/></body></worldbody></mujoco>"#,
            dir.display()
        );
        let model = common::load_mjcf_text("sameframe", "mesh", &xml);
        let hull = model.geoms[0].hull_graph.as_ref().unwrap_or_else(|| panic!("{file} at {scale}: no hull"));
        let (pos, q) = (nums(&m["mesh_pos"]), nums(&m["mesh_quat"]));
        let r = quat_to_matrix(q[0], q[1], q[2], q[3]);
        let mat: Vec<f64> = (0..9).map(|k| r[(k / 3, k % 3)]).collect();
        let err = pose_err(&Transform::new(hull.box_frame.1, hull.box_frame.0), &pos, &mat);
        assert!(err <= POSE_ABS, "{file} at scale {scale}: mesh frame {err:.1e} from MuJoCo's");
        worst = worst.max(err);
    }
    println!(
        "{} mesh frames (file, scale) match MuJoCo's mesh_pos/mesh_quat, worst {worst:.1e}",
        meshes.len()
    );
    assert!(meshes.len() >= 30);
}

#[test]
fn flags_and_poses_are_mujocos() {
    let doc = golden();
    let mut counts = [0usize; 5];
    let (mut not_computed, mut worst) = (0, 0.0f64);
    for g in doc["scenes"]["models"].as_array().expect("models") {
        let name = g["model"].as_str().unwrap();
        let model = Model::from_file(repo_path(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        let mut data = Data::new(&model);
        forward(&model, &mut data);
        let flags: Vec<u64> =
            g["geom_sameframe"].as_array().unwrap().iter().map(|v| v.as_u64().unwrap()).collect();
        assert_eq!(flags.len(), model.geoms.len(), "{name}: geom count");
        let (xpos, xmat) = (g["geom_xpos"].as_array().unwrap(), g["geom_xmat"].as_array().unwrap());
        for (i, geom) in model.geoms.iter().enumerate() {
            let is_mesh = matches!(geom.shape, lagrange::model::spec::Shape::Mesh { .. });
            if is_mesh && geom.hull_graph.is_none() {
                assert_eq!(model.links.geom_sameframe[i], SameFrame::None);
                not_computed += 1;
                continue;
            }
            let flag = model.links.geom_sameframe[i].mujoco_code() as u64;
            assert_eq!(flag, flags[i], "{name}: geom {i} ({}) geom_sameframe", geom.name);
            counts[flag as usize] += 1;
            let frame = geom
                .hull_graph
                .as_ref()
                .map_or(Transform::identity(), |h| Transform::new(h.box_frame.1, h.box_frame.0));
            let err = pose_err(&(data.x_world_geom[i] * frame), &nums(&xpos[i]), &nums(&xmat[i]));
            assert!(err <= POSE_ABS, "{name}: geom {i} ({}) pose {err:.1e} from MuJoCo's", geom.name);
            worst = worst.max(err);
        }
        let sites: Vec<usize> =
            (0..model.frames.len()).filter(|&f| model.frames[f].kind == FrameKind::Site).collect();
        let flags: Vec<u64> =
            g["site_sameframe"].as_array().unwrap().iter().map(|v| v.as_u64().unwrap()).collect();
        assert_eq!(flags.len(), sites.len(), "{name}: site count");
        let (xpos, xmat) = (g["site_xpos"].as_array().unwrap(), g["site_xmat"].as_array().unwrap());
        for (i, &f) in sites.iter().enumerate() {
            let flag = model.links.site_sameframe[f].mujoco_code() as u64;
            assert_eq!(flag, flags[i], "{name}: site {i} ({}) site_sameframe", model.frames[f].name);
            counts[flag as usize] += 1;
            let x = data.x_world_body[model.frames[f].body] * model.frames[f].x_body_frame;
            let err = pose_err(&x, &nums(&xpos[i]), &nums(&xmat[i]));
            assert!(
                err <= POSE_ABS,
                "{name}: site {i} ({}) pose {err:.1e} from MuJoCo's",
                model.frames[f].name
            );
            worst = worst.max(err);
        }
    }
    println!(
        "geoms and sites by MuJoCo's flag (none, body, inertia, bodyrot, inertiarot): {counts:?}; \
         {not_computed} non-colliding meshes left out; worst pose {worst:.1e}"
    );
    assert!(counts.iter().all(|&n| n > 0), "every flag is exercised");
}
