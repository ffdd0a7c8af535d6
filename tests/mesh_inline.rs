//! Inline meshes (`<mesh vertex=… face=…>`, no file: src/io/mjcf/mesh_inline.rs) against MuJoCo
//! 4.0 (tests/data/mujoco/mesh_inline_rest.json, validation/mujoco_meshsrc_golden.py): an inline
//! box, an inline point cloud without faces (its convex hull) and a built-in icosphere
//! (src/io/mjcf/mesh_builtin.rs) dropped onto a plane follow
//! `mj_step` for 200 steps at the soft tolerance; their masses agree to f64 round-off and their
//! collision hulls are MuJoCo's compiled vertices (same distances from the centre of mass). Masses,
//! inertias, M and qfrc_bias of inline meshes are in tests/mujoco.rs (`mesh_inline`). Bad inline
//! meshes are typed load errors naming the line.

mod common;

use common::{state_rel_err, SOFT_REL};
use lagrange::prelude::*;
use serde_json::Value;

const SCENE: &str = "tests/data/mjcf/applied/mesh_inline_rest.xml";

fn golden() -> Value {
    serde_json::from_str(&std::fs::read_to_string("tests/data/mujoco/mesh_inline_rest.json").unwrap())
        .unwrap()
}

#[test]
fn inline_meshes_fall_and_rest_as_in_mujoco() {
    let golden = golden();
    let model = Model::from_file(SCENE).unwrap();
    let mut data = Data::new(&model);
    let mut worst = 0.0f64;
    let mut k = 0;
    for sample in golden["samples"].as_array().unwrap() {
        while k < sample["step"].as_u64().unwrap() {
            step(&model, &mut data).unwrap();
            k += 1;
        }
        worst = worst.max(state_rel_err(sample, &data));
        println!("step {k}: worst rel err so far {worst:.1e}, brick z {:.5}", data.qpos[2]);
    }
    // The brick rests on its 0.04 half-height face (MuJoCo: z = 0.0399 after 200 steps).
    assert!((data.qpos[2] - 0.04).abs() < 1e-3, "brick z {}", data.qpos[2]);
    assert!(worst <= SOFT_REL, "{worst:e}");
}

#[test]
fn inline_mesh_masses_and_hulls_are_mujocos() {
    let golden = golden();
    let model = Model::from_file(SCENE).unwrap();
    for (i, mesh) in golden["meshes"].as_array().unwrap().iter().enumerate() {
        let body = &model.bodies[i + 1];
        let mass = mesh["body_mass"].as_f64().unwrap();
        assert!((body.mass() - mass).abs() <= 1e-12 * mass, "{}: {} vs {mass}", body.name, body.mass());
        // MuJoCo's mesh_vert are in the mesh's inertial frame (origin at the centre of mass): the
        // distances of the hull's vertices from the body's centre of mass are theirs (f32).
        let g = model.geoms.iter().find(|g| g.body == i + 1).unwrap();
        let hull = g.hull().expect("an inline mesh collides by its hull");
        let mut ours: Vec<f64> =
            hull.iter().map(|v| (g.x_body_geom.act_point(v) - body.com()).norm()).collect();
        let mut theirs: Vec<f64> = mesh["vert"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap().powi(2)).sum::<f64>().sqrt())
            .collect();
        ours.sort_by(f64::total_cmp);
        theirs.sort_by(f64::total_cmp);
        // The cloud's interior point is in MuJoCo's mesh_vert, not on the hull.
        let theirs = &theirs[theirs.len() - ours.len()..];
        let err = ours.iter().zip(theirs).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        println!("{}: {} hull vertices, max distance difference {err:.1e} m", body.name, ours.len());
        assert!(err < 1e-7, "{}: {err:e}", body.name);
    }
}

fn load_err(mesh: &str) -> String {
    let xml = format!(
        "<mujoco>\n<asset>\n{mesh}\n</asset>\n<worldbody><body><freejoint/><geom type=\"mesh\" mesh=\"m\"/></body></worldbody></mujoco>"
    );
    Model::from_str(&xml).unwrap_err().to_string()
}

#[test]
fn bad_inline_meshes_are_typed_errors_naming_the_line() {
    let tet = "0 0 0  1 0 0  0 1 0  0 0 1";
    for (mesh, expect) in [
        (r#"<mesh name="m" vertex="0 0 0  1 0 0  0 1 0  0 0"/>"#.to_string(), "multiple of 3"),
        (r#"<mesh name="m" vertex="0 0 0  1 0 0  0 1 0"/>"#.to_string(), "at least 4 vertices"),
        (
            format!(r#"<mesh name="m" vertex="{tet}" face="0 1 2  0 1"/>"#),
            "face data must be a multiple of 3",
        ),
        (format!(r#"<mesh name="m" vertex="{tet}" face="0 1 2  0 1 4"/>"#), "vertex index 4 does not exist"),
        (format!(r#"<mesh name="m" vertex="{tet}" face="0 1 -1"/>"#), "vertex index -1 does not exist"),
        (format!(r#"<mesh vertex="{tet}"/>"#), "needs a 'name'"),
        (r#"<mesh name="m" vertex="0 0 0  1 0 0  2 0 0  3 0 0"/>"#.to_string(), "convex hull"),
        (
            r#"<mesh name="m" builtin="wedge" params="1 1 30 30 0.5"/>"#.to_string(),
            "at least 4 vertices required",
        ),
        (r#"<mesh name="m" builtin="sphere" params="5"/>"#.to_string(), "subdivision must be in 0..=4"),
        (r#"<mesh name="m" builtin="cone" params="8"/>"#.to_string(), "requires 2"),
        (r#"<mesh name="m" builtin="cube" params="8"/>"#.to_string(), "'builtin' is 'cube'"),
    ] {
        let err = load_err(&mesh);
        assert!(err.contains(expect), "{mesh}: {err}");
        assert!(err.contains(":3:"), "the error names the line: {err}");
    }
}
