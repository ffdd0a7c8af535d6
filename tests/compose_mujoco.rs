//! Composed MJCF models (`<attach>`, `<replicate>`: src/io/mjcf/attach.rs, replicate.rs) against
//! MuJoCo 4.0's compiled names (tests/data/mujoco/compose/, validation/mujoco_compose_golden.py):
//! the named joints, sites, tendons, actuators and sensors in MuJoCo's order, the named geoms and
//! bodies, the equality count and the excluded body pairs. The
//! masses, joints, qpos0 and dynamics of the same files (M, qfrc_bias, qacc at random states, to
//! 1e-9) are checked by tests/mujoco.rs (`compose_*`).

mod common;

use lagrange::io::{load, LoadOptions};
use lagrange::model::FrameKind;
use lagrange::Model;
use serde::Deserialize;

#[derive(Deserialize)]
struct Golden {
    model: String,
    bodies: Vec<String>,
    joints: Vec<String>,
    geoms: Vec<String>,
    sites: Vec<String>,
    tendons: Vec<String>,
    actuators: Vec<String>,
    sensors: Vec<String>,
    neq: usize,
    excludes: Vec<[String; 2]>,
}

fn named<'a>(names: impl IntoIterator<Item = &'a String>) -> Vec<&'a str> {
    names.into_iter().map(String::as_str).filter(|n| !n.is_empty()).collect()
}

fn check(scene: &str) {
    let file = common::repo_path(&format!("tests/data/mujoco/compose/{scene}.json"));
    let text = std::fs::read_to_string(&file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    let g: Golden = serde_json::from_str(&text).unwrap();
    let model: Model = load(&common::repo_path(&g.model), &LoadOptions::default())
        .unwrap_or_else(|e| panic!("{scene}: {e}"));
    let body = |b: usize| model.bodies[b].name.as_str();

    // MuJoCo's unnamed joints are named `joint{id}` here: compare the named ones.
    let joints: Vec<&str> = model.joints.iter().map(|j| j.name.as_str()).collect();
    let theirs = named(&g.joints);
    assert_eq!(
        joints.iter().copied().filter(|n| theirs.contains(n)).collect::<Vec<_>>(),
        theirs,
        "{scene}: joints"
    );

    // Bodies without joints are welded into their parents here: every MuJoCo body is a link frame.
    for b in g.bodies.iter().skip(1) {
        assert!(
            model.frames.iter().any(|f| &f.name == b && f.kind == FrameKind::Link),
            "{scene}: no body '{b}'"
        );
    }
    let mut ours: Vec<&str> = named(model.geoms.iter().map(|x| &x.name));
    let mut theirs: Vec<&str> = named(&g.geoms);
    ours.sort();
    theirs.sort();
    assert_eq!(ours, theirs, "{scene}: named geoms");

    let sites: Vec<&str> =
        model.frames.iter().filter(|f| f.kind == FrameKind::Site).map(|f| f.name.as_str()).collect();
    assert_eq!(sites, named(&g.sites), "{scene}: sites");
    assert_eq!(named(model.tendons.iter().map(|t| &t.name)), named(&g.tendons), "{scene}: tendons");
    assert_eq!(named(model.actuators.iter().map(|a| &a.name)), named(&g.actuators), "{scene}: actuators");
    assert_eq!(named(model.sensors.iter().map(|s| &s.name)), named(&g.sensors), "{scene}: sensors");
    assert_eq!(model.equalities.len(), g.neq, "{scene}: equality constraints");
    let excludes: Vec<[String; 2]> = model
        .contact_excludes
        .iter()
        .map(|e| [body(e.body1).to_string(), body(e.body2).to_string()])
        .collect();
    assert_eq!(excludes, g.excludes, "{scene}: excluded body pairs");
    println!(
        "{scene}: {} bodies, {} joints, {} geoms, {} actuators, {} sensors match MuJoCo's names",
        g.bodies.len(),
        g.joints.len(),
        g.geoms.len(),
        g.actuators.len(),
        g.sensors.len()
    );
}

#[test]
fn attach_gripper_twice_on_an_arm() {
    check("compose_attach");
}

#[test]
fn attach_a_whole_world_body() {
    check("compose_attach_world");
}

#[test]
fn replicate_ring_nested_and_frames() {
    check("compose_replicate");
}

/// A hostile `sep` (every name of every copy carries it) is refused with the limit and the fix,
/// before any copy is made; a separator at the limit loads.
#[test]
fn replicate_refuses_a_separator_beyond_the_limit() {
    use lagrange::io::mjcf::MAX_SEP;
    let scene = |sep: &str| {
        format!(
            "<mujoco><worldbody><replicate count='3' offset='0.3 0 0' sep='{sep}'><body name='b'><freejoint/><geom size='.1'/></body></replicate></worldbody></mujoco>"
        )
    };
    let path = std::path::Path::new("sep.xml");
    let long = "x".repeat(MAX_SEP + 1);
    let err = lagrange::io::load_str(&scene(&long), path, &LoadOptions::default()).unwrap_err().to_string();
    assert!(err.contains("sep") && err.contains(&format!("{} characters", MAX_SEP + 1)), "{err}");
    assert!(err.contains("give a short separator"), "{err}");
    let ok = lagrange::io::load_str(&scene(&"x".repeat(MAX_SEP)), path, &LoadOptions::default()).unwrap();
    assert_eq!(ok.bodies.len(), 4);
}
