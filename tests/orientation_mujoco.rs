//! MJCF orientations compiled as MuJoCo 4.0 compiles them, to the bit: `quat`, `axisangle`,
//! `euler` (degrees and radians, rotating and fixed axes), `xyaxes`, `zaxis` and `fromto` at
//! random values (tests/data/mujoco/orientation.json, written by
//! `validation/mujoco_orientation_golden.py`). Each body sits at the world's top level with a
//! sphere in its frame, other geoms on the world body: MuJoCo's `geom_xmat` at qpos0 is then its
//! compiled quaternion as a matrix, and lagrange's world rotation of each geom must equal it
//! exactly. A last bit matters: contacts on a face, an edge or a height-field prism seen at the
//! same angle resolve ties by it (docs/contact-scenes.md).

mod common;

use lagrange::prelude::*;
use serde_json::Value;

#[test]
fn orientations_compile_to_mujocos_bits() {
    let path = common::repo_path("tests/data/mujoco/orientation.json");
    let doc: Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    assert!(doc["generated_by"].as_str().unwrap().starts_with("validation/mujoco_orientation_golden.py"));
    let (mut geoms, mut worst, mut differ) = (0, 0.0f64, Vec::new());
    for case in doc["cases"].as_array().unwrap() {
        let name = case["name"].as_str().unwrap();
        let model = common::load_mjcf_text("orientation", name, case["mjcf"].as_str().unwrap());
        let mut data = Data::new(&model);
        forward(&model, &mut data);
        let (xmat, xpos) = (case["geom_xmat"].as_array().unwrap(), case["geom_xpos"].as_array().unwrap());
        assert_eq!(xmat.len(), model.geoms.len(), "{name}: geom count");
        // lagrange may order a model's geoms differently (static bodies join the world's link):
        // each of MuJoCo's geoms is matched by its position (random, so unique).
        for (i, (mat, pos)) in xmat.iter().zip(xpos).enumerate() {
            let mat: Vec<f64> = mat.as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
            let pos: Vec<f64> = pos.as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
            let dist = |x: &lagrange::spatial::Transform| {
                (0..3).map(|k| (x.pos[k] - pos[k]).abs()).fold(0.0, f64::max)
            };
            let x = model
                .geoms
                .iter()
                .map(|g| data.x_world_body[g.body] * g.x_body_geom)
                .min_by(|a, b| dist(a).total_cmp(&dist(b)))
                .expect("geoms");
            let err_pos = dist(&x);
            let err = (0..9).map(|k| (x.rot[(k / 3, k % 3)] - mat[k]).abs()).fold(0.0, f64::max);
            worst = worst.max(err);
            if err != 0.0 || err_pos > 1e-15 {
                differ.push(format!(
                    "{name}: geom {i} rotation {err:.1e}, position {err_pos:.1e} from MuJoCo's"
                ));
            }
            geoms += 1;
        }
    }
    println!(
        "{geoms} geom orientations against MuJoCo's geom_xmat: {} differ, worst {worst:.1e}",
        differ.len()
    );
    assert!(differ.is_empty(), "{}", differ.iter().take(10).cloned().collect::<Vec<_>>().join("\n"));
    assert!(geoms > 500);
}
