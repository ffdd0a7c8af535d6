//! Broken MJCF models (`tests/data/mjcf/errors/`, each with one defect; its README records what
//! MuJoCo 4.0.0 says) give typed errors naming the file, the line, the element, the attribute
//! where there is one, what is wrong and the fix. Unknown attributes are warnings, not errors.

use lagrange::io::{load, LoadOptions};
use std::path::PathBuf;

fn path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/mjcf/errors").join(name)
}

/// Loads `name` expecting an error; returns its message.
fn message(name: &str) -> String {
    match load(&path(name), &LoadOptions::default()) {
        Ok(_) => panic!("{name}: expected an error, the model loaded"),
        Err(e) => {
            let m = e.to_string();
            eprintln!("{name}: {m}");
            m
        }
    }
}

/// Asserts that the message contains each part.
fn mentions(name: &str, parts: &[&str]) {
    let m = message(name);
    for p in parts {
        assert!(m.contains(p), "{name}: message lacks '{p}':\n{m}");
    }
}

#[test]
fn unknown_class_names_the_class_element_and_line() {
    mentions(
        "unknown_class.xml",
        &[
            "unknown_class.xml:11",
            "<geom>",
            "unknown default class 'nonexistent'",
            "define <default class=\"nonexistent\">",
        ],
    );
    mentions("unknown_childclass.xml", &["unknown_childclass.xml:4", "<body>", "'missing_class'"]);
}

#[test]
fn include_cycles_and_repeats_are_errors() {
    mentions(
        "include_cycle.xml",
        &[
            "include_cycle_part.xml:6",
            "<include>",
            "include cycle",
            "include_cycle.xml includes",
            "remove one",
        ],
    );
    mentions("include_self.xml", &["include_self.xml:3", "include cycle"]);
    mentions(
        "include_twice.xml",
        &["include_twice.xml:5", "<include>", "include_twice_part.xml", "second time"],
    );
}

#[test]
fn missing_files_name_the_path_tried() {
    mentions(
        "missing_include.xml",
        &["missing_include.xml:8", "<include>", "parts/does_not_exist.xml", "main model's folder"],
    );
    mentions(
        "missing_mesh.xml",
        &["missing_mesh.xml:6", "<mesh>", "meshes/missing.stl", "does not exist", "meshdir"],
    );
}

#[test]
fn wrong_value_counts_name_the_attribute() {
    mentions(
        "wrong_value_count.xml",
        &["wrong_value_count.xml:4", "<body>", "'pos' has 2 values, it takes 3"],
    );
    mentions(
        "wrong_value_count_quat.xml",
        &["wrong_value_count_quat.xml:6", "<geom>", "'quat' has 3 values, it takes 4"],
    );
    mentions("too_many_values.xml", &["too_many_values.xml:5", "<joint>", "'axis' has 4 values, it takes 3"]);
    mentions("bad_number.xml", &["bad_number.xml:6", "<geom>", "'size'", "'abc', which is not a number"]);
}

#[test]
fn bad_keywords_list_the_allowed_ones() {
    mentions(
        "bad_joint_type.xml",
        &["bad_joint_type.xml:5", "<joint>", "'type' is 'revolute'", "free, ball, slide, hinge"],
    );
    mentions("bad_eulerseq.xml", &["bad_eulerseq.xml:3", "<compiler>", "'eulerseq' is 'xyw'", "x y z X Y Z"]);
}

#[test]
fn structural_errors_follow_mujoco() {
    mentions(
        "ball_followed_by_rotation.xml",
        &["ball_followed_by_rotation.xml:6", "<joint>", "after ball joint 'ball'", "child body"],
    );
    mentions(
        "free_not_top_level.xml",
        &["free_not_top_level.xml:7", "body 'child'", "free joint", "top-level"],
    );
    mentions("fromto_with_pos.xml", &["fromto_with_pos.xml:6", "<geom>", "'fromto' and 'pos'", "remove pos"]);
    mentions("two_orientations.xml", &["two_orientations.xml:4", "<body>", "'euler' conflicts with 'quat'"]);
    mentions("duplicate_class.xml", &["duplicate_class.xml:7", "default class 'twin'", "twice"]);
    mentions("malformed_xml.xml", &["malformed_xml.xml:7:3", "malformed XML"]);
}

#[test]
fn non_physical_mass_is_an_error_with_the_fix() {
    mentions(
        "unbalanced_inertia.xml",
        &["unbalanced_inertia.xml:7", "'b'", "triangle inequality", "balanceinertia"],
    );
}

#[test]
fn unknown_attributes_are_warnings_with_file_and_line() {
    let model =
        load(&path("unknown_attribute.xml"), &LoadOptions::default()).expect("a warning, not an error");
    let w: Vec<&String> = model.warnings.iter().filter(|w| w.contains("unknown attribute 'rpy'")).collect();
    assert_eq!(w.len(), 1, "{:?}", model.warnings);
    assert!(w[0].contains("unknown_attribute.xml:5") && w[0].contains("<joint>"), "{}", w[0]);
}

#[test]
fn equality_constraints_name_existing_distinct_objects() {
    mentions(
        "equality_unknown_body.xml",
        &["equality_unknown_body.xml:19", "<connect>", "unknown body 'nope'", "define it or fix the name"],
    );
    mentions(
        "equality_joint_not_scalar.xml",
        &[
            "equality_joint_not_scalar.xml:19",
            "<joint>",
            "joint 'ball' is a ball joint",
            "hinge and slide joints only",
            "connect or weld",
        ],
    );
    mentions(
        "equality_same_body.xml",
        &[
            "equality_same_body.xml:19",
            "<weld>",
            "equality 'w'",
            "body 'b' is constrained to itself",
            "two different",
        ],
    );
    mentions(
        "equality_sites_and_bodies.xml",
        &[
            "equality_sites_and_bodies.xml:19",
            "<connect>",
            "'body1' cannot be combined with 'site1'",
            "site form",
        ],
    );
}

#[test]
fn polycoef_takes_one_to_five_numbers() {
    mentions(
        "equality_polycoef_too_long.xml",
        &["equality_polycoef_too_long.xml:19", "<joint>", "'polycoef' has 6 values, it takes 1 to 5"],
    );
    mentions(
        "equality_polycoef_not_number.xml",
        &["equality_polycoef_not_number.xml:19", "<joint>", "'polycoef'", "'x', which is not a number"],
    );
}

#[test]
fn tendons_actuators_and_contacts_name_what_they_act_on() {
    mentions(
        "tendon_ball_joint.xml",
        &[
            "tendon_ball_joint.xml:19",
            "<joint>",
            "joint 'ball' is a ball joint",
            "fixed tendon",
            "remove the term from tendon 't2'",
        ],
    );
    mentions(
        "actuator_unknown_joint.xml",
        &["actuator_unknown_joint.xml:19", "<motor>", "unknown joint 'nope'", "define it or fix the name"],
    );
    mentions(
        "actuator_kv_and_dampratio.xml",
        &["actuator_kv_and_dampratio.xml:19", "<position>", "'dampratio' cannot be given together with 'kv'"],
    );
    mentions("pair_unknown_geom.xml", &["pair_unknown_geom.xml:19", "<pair>", "unknown geom 'nope'"]);
    mentions(
        "pair_bad_condim.xml",
        &["pair_bad_condim.xml:19", "<pair>", "'condim' is 2", "1 (frictionless), 3"],
    );
    mentions(
        "exclude_unknown_body.xml",
        &["exclude_unknown_body.xml:19", "<exclude>", "unknown body 'nope'"],
    );
}

#[test]
fn composition_errors_name_the_element_line_and_what_mujoco_does() {
    mentions("composite_grid.xml", &["composite_grid.xml:3", "<composite>", "MuJoCo 4.0 rejects it"]);
    mentions(
        "body_plugin.xml",
        &["body_plugin.xml:7", "<plugin>", "MuJoCo would run plugin 'mujoco.elasticity.cable'"],
    );
    mentions(
        "attach_unknown_model.xml",
        &["attach_unknown_model.xml:6", "<attach>", "sub-model (<asset><model name>)", "'gripper'"],
    );
    mentions(
        "mesh_builtin.xml",
        &[
            "mesh_builtin.xml:6",
            "body 'b'",
            "mesh 'ball'",
            "all vertices are in one plane",
            "contype=\"0\" conaffinity=\"0\"",
        ],
    );
}
