//! Broken models give typed errors whose messages name the file, the line, the element, what is
//! wrong and how to fix it. Each test loads through `lagrange::io::load`, so the compile-step
//! checks (axis, mass, inertia) are covered too.

use lagrange::io::{load, LoadError, LoadOptions};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

/// Writes `text` to a fresh file `<tag>.urdf` in a unique temp folder and returns its path.
fn write_urdf(tag: &str, text: &str) -> PathBuf {
    static COUNTER: AtomicUsize = AtomicUsize::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("lagrange-load-errors-{}-{n}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("{tag}.urdf"));
    std::fs::write(&path, text).unwrap();
    path
}

/// Loads `text` (written to a temp file) and returns the error and the file's path.
fn load_err(tag: &str, text: &str) -> (LoadError, String) {
    load_err_with(tag, text, &LoadOptions::default())
}

fn load_err_with(tag: &str, text: &str, options: &LoadOptions) -> (LoadError, String) {
    let path = write_urdf(tag, text);
    match load(&path, options) {
        Ok(_) => panic!("{tag}: expected an error"),
        Err(e) => (e, path.display().to_string()),
    }
}

/// 1-based line of the first line of `text` containing `needle`.
fn line_of(text: &str, needle: &str) -> usize {
    text.lines().position(|l| l.contains(needle)).unwrap_or_else(|| panic!("{needle} not in text")) + 1
}

/// Asserts that `message` contains every one of `parts`.
fn assert_mentions(message: &str, parts: &[&str]) {
    eprintln!("{message}");
    for p in parts {
        assert!(message.contains(p), "message lacks {p:?}:\n{message}");
    }
}

/// Two links joined by `joint` (the joint's attributes and body given), each link with `extra`.
fn two_links(joint_type: &str, joint_body: &str, link_b_body: &str) -> String {
    format!(
        r#"<?xml version="1.0"?>
<robot name="r">
  <link name="a"/>
  <link name="b">
{link_b_body}
  </link>
  <joint name="j" type="{joint_type}">
    <parent link="a"/>
    <child link="b"/>
{joint_body}
  </joint>
</robot>
"#
    )
}

const UNIT_INERTIAL: &str = r#"    <inertial>
      <mass value="1"/>
      <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/>
    </inertial>"#;

#[test]
fn malformed_xml_reports_line_and_column() {
    let text = "<robot name=\"r\">\n  <link name=\"a\">\n  </lnk>\n</robot>\n";
    let (e, file) = load_err("malformed", text);
    assert!(matches!(e, LoadError::Xml { line: 3, .. }), "{e:?}");
    let m = e.to_string();
    assert_mentions(&m, &[&format!("{file}:3:"), "malformed XML", "'link'", "Fix the XML syntax"]);
}

#[test]
fn unknown_joint_type() {
    let text = two_links("hinge", "", "");
    let (e, file) = load_err("unknown_type", &text);
    assert!(matches!(e, LoadError::UnknownJointType { .. }), "{e:?}");
    let line = line_of(&text, "<joint name=\"j\"");
    assert_mentions(
        &e.to_string(),
        &[
            &format!("{file}:{line}:"),
            "joint 'j'",
            "unknown joint type 'hinge'",
            "use one of revolute, continuous",
        ],
    );
}

#[test]
fn missing_parent_link() {
    let text = r#"<robot name="r">
  <link name="a"/>
  <link name="b"/>
  <joint name="j" type="fixed">
    <parent link="nope"/>
    <child link="b"/>
  </joint>
</robot>"#;
    let (e, file) = load_err("missing_parent", text);
    assert!(matches!(e, LoadError::MissingLink { role: "parent", .. }), "{e:?}");
    assert_mentions(
        &e.to_string(),
        &[
            &format!("{file}:4:"),
            "joint 'j'",
            "parent link 'nope' is not defined",
            "add <link name=\"nope\">",
        ],
    );
}

#[test]
fn missing_child_link() {
    let text = r#"<robot name="r">
  <link name="a"/>
  <joint name="j" type="revolute">
    <parent link="a"/>
    <child link="ghost"/>
  </joint>
</robot>"#;
    let (e, file) = load_err("missing_child", text);
    assert!(matches!(e, LoadError::MissingLink { role: "child", .. }), "{e:?}");
    assert_mentions(
        &e.to_string(),
        &[
            &format!("{file}:3:"),
            "joint 'j'",
            "child link 'ghost' is not defined",
            "add <link name=\"ghost\">",
        ],
    );
}

#[test]
fn joint_without_parent_element() {
    let text = r#"<robot name="r">
  <link name="a"/>
  <link name="b"/>
  <joint name="j" type="fixed">
    <child link="b"/>
  </joint>
</robot>"#;
    let (e, file) = load_err("no_parent_element", text);
    assert!(matches!(e, LoadError::Invalid { .. }), "{e:?}");
    assert_mentions(
        &e.to_string(),
        &[&format!("{file}:4:"), "joint 'j'", "has no <parent>", "add <parent link="],
    );
}

#[test]
fn cycle_names_its_links_and_a_joint() {
    // `r` is the only root; a → b → c → a is unreachable from it.
    let text = r#"<robot name="r">
  <link name="r"/>
  <link name="a"/>
  <link name="b"/>
  <link name="c"/>
  <joint name="j1" type="fixed"><parent link="a"/><child link="b"/></joint>
  <joint name="j2" type="fixed"><parent link="b"/><child link="c"/></joint>
  <joint name="j3" type="fixed"><parent link="c"/><child link="a"/></joint>
</robot>"#;
    let (e, file) = load_err("cycle", text);
    assert!(matches!(e, LoadError::Cycle { .. }), "{e:?}");
    assert_mentions(
        &e.to_string(),
        &[
            &format!("{file}:8:"),
            "joint 'j3'",
            "'a', 'b', 'c' form a cycle",
            "must be a tree",
            "remove or re-parent",
        ],
    );

    // Every link on a loop: there is no root at all.
    let text = r#"<robot name="r">
  <link name="a"/>
  <link name="b"/>
  <joint name="ab" type="revolute"><parent link="a"/><child link="b"/></joint>
  <joint name="ba" type="revolute"><parent link="b"/><child link="a"/></joint>
</robot>"#;
    let (e, file) = load_err("cycle_no_root", text);
    assert_mentions(&e.to_string(), &[&format!("{file}:5:"), "joint 'ba'", "'a', 'b' form a cycle"]);
}

#[test]
fn two_roots() {
    let text = r#"<robot name="r">
  <link name="a"/>
  <link name="b"/>
  <link name="c"/>
  <joint name="j" type="fixed"><parent link="a"/><child link="b"/></joint>
</robot>"#;
    let (e, file) = load_err("two_roots", text);
    assert!(matches!(e, LoadError::MultipleRoots { .. }), "{e:?}");
    assert_mentions(&e.to_string(), &[&file, "2 root links ('a', 'c')", "connect the others with joints"]);
}

#[test]
fn link_with_two_parent_joints() {
    let text = r#"<robot name="r">
  <link name="a"/>
  <link name="b"/>
  <link name="c"/>
  <joint name="j1" type="fixed"><parent link="a"/><child link="c"/></joint>
  <joint name="j2" type="fixed"><parent link="b"/><child link="c"/></joint>
</robot>"#;
    let (e, file) = load_err("two_parents", text);
    assert!(matches!(e, LoadError::TwoParents { .. }), "{e:?}");
    assert_mentions(
        &e.to_string(),
        &[
            &format!("{file}:6:"),
            "joint 'j2'",
            "link 'c' already has parent joint 'j1'",
            "equality constraint",
        ],
    );
}

#[test]
fn zero_axis() {
    let text = two_links(
        "revolute",
        r#"    <axis xyz="0 0 0"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>"#,
        UNIT_INERTIAL,
    );
    let (e, file) = load_err("zero_axis", &text);
    assert!(matches!(e, LoadError::ZeroAxis { .. }), "{e:?}");
    let line = line_of(&text, "<joint name=\"j\"");
    assert_mentions(
        &e.to_string(),
        &[&format!("{file}:{line}:"), "joint 'j'", "axis is zero", "nonzero <axis xyz="],
    );
}

#[test]
fn negative_mass() {
    let inertial = UNIT_INERTIAL.replace("<mass value=\"1\"/>", "<mass value=\"-2.5\"/>");
    let text = two_links("continuous", "", &inertial);
    let (e, file) = load_err("negative_mass", &text);
    assert!(matches!(e, LoadError::NegativeMass { .. }), "{e:?}");
    let line = line_of(&text, "<inertial>");
    assert_mentions(
        &e.to_string(),
        &[&format!("{file}:{line}:"), "link 'b'", "negative mass -2.5", "≥ 0", "fix <mass value="],
    );
}

#[test]
fn inertia_with_a_negative_principal_moment() {
    let inertial = UNIT_INERTIAL.replace("ixx=\"1\"", "ixx=\"-1\"");
    let text = two_links("continuous", "", &inertial);
    let (e, file) = load_err("negative_moment", &text);
    assert!(matches!(e, LoadError::NonPhysicalInertia { .. }), "{e:?}");
    let line = line_of(&text, "<inertial>");
    assert_mentions(
        &e.to_string(),
        &[
            &format!("{file}:{line}:"),
            "link 'b'",
            "include a negative one",
            "positive semi-definite",
            "fix the <inertia>",
        ],
    );
}

#[test]
fn inertia_violating_the_triangle_inequality() {
    let inertial = UNIT_INERTIAL.replace("izz=\"1\"", "izz=\"3\"");
    let text = two_links("continuous", "", &inertial);
    let (e, file) = load_err("triangle", &text);
    assert!(matches!(e, LoadError::NonPhysicalInertia { .. }), "{e:?}");
    let line = line_of(&text, "<inertial>");
    assert_mentions(
        &e.to_string(),
        &[
            &format!("{file}:{line}:"),
            "link 'b'",
            "violate the triangle inequality",
            "I1 + I2 ≥ I3",
            "fix the <inertia>",
        ],
    );
}

#[test]
fn unresolvable_package_uri() {
    // A collision mesh takes part in contact: it must be found.
    let mesh = r#"    <collision>
      <geometry>
        <mesh filename="package://lagrange_no_such_pkg/meshes/b.stl"/>
      </geometry>
    </collision>"#;
    let text = two_links("fixed", "", mesh);
    let options =
        LoadOptions { package_dirs: vec![PathBuf::from("/nonexistent/lagrange/pkgs")], ..Default::default() };
    let (e, file) = load_err_with("package", &text, &options);
    assert!(matches!(e, LoadError::PackageNotFound { .. }), "{e:?}");
    let line = line_of(&text, "<mesh ");
    assert_mentions(
        &e.to_string(),
        &[
            &format!("{file}:{line}:"),
            "link 'b'",
            "package 'lagrange_no_such_pkg' not found",
            "/nonexistent/lagrange/pkgs",
            "LoadOptions::package_dirs",
            "ROS_PACKAGE_PATH",
        ],
    );
}

#[test]
fn mesh_that_resolves_but_does_not_exist() {
    let mesh = r#"    <collision>
      <geometry><mesh filename="meshes/missing.stl"/></geometry>
    </collision>"#;
    let text = two_links("fixed", "", mesh);
    let (e, file) = load_err("missing_mesh", &text);
    assert!(matches!(e, LoadError::MeshNotFound { .. }), "{e:?}");
    let line = line_of(&text, "<mesh ");
    let expected_path = Path::new(&file).parent().unwrap().join("meshes/missing.stl");
    assert_mentions(
        &e.to_string(),
        &[
            &format!("{file}:{line}:"),
            "link 'b'",
            &format!("mesh file '{}' does not exist", expected_path.display()),
            "fix the filename",
        ],
    );
}

#[test]
fn mesh_inside_a_found_package_that_does_not_exist() {
    let root = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("lagrange-load-errors-{}-pkg", std::process::id()));
    std::fs::create_dir_all(root.join("lagrange_err_pkg/meshes")).unwrap();
    let mesh = r#"    <collision><geometry><mesh filename="package://lagrange_err_pkg/meshes/nope.stl"/></geometry></collision>"#;
    let text = two_links("fixed", "", mesh);
    let options = LoadOptions { package_dirs: vec![root.clone()], ..Default::default() };
    let (e, file) = load_err_with("pkg_mesh_missing", &text, &options);
    assert!(matches!(e, LoadError::MeshNotFound { .. }), "{e:?}");
    let line = line_of(&text, "<mesh ");
    let expected = root.join("lagrange_err_pkg/meshes/nope.stl");
    assert_mentions(
        &e.to_string(),
        &[&format!("{file}:{line}:"), "link 'b'", &expected.display().to_string(), "does not exist"],
    );
}

#[test]
fn duplicate_link_name() {
    let text = r#"<robot name="r">
  <link name="a"/>
  <link name="b"/>
  <link name="a"/>
  <joint name="j" type="fixed"><parent link="a"/><child link="b"/></joint>
</robot>"#;
    let (e, file) = load_err("duplicate_link", text);
    assert!(matches!(e, LoadError::DuplicateName { element: "link", .. }), "{e:?}");
    assert_mentions(
        &e.to_string(),
        &[&format!("{file}:4:"), "link 'a' is defined twice", "rename one of them"],
    );
}

#[test]
fn duplicate_joint_name() {
    let text = r#"<robot name="r">
  <link name="a"/>
  <link name="b"/>
  <link name="c"/>
  <joint name="j" type="fixed"><parent link="a"/><child link="b"/></joint>
  <joint name="j" type="fixed"><parent link="a"/><child link="c"/></joint>
</robot>"#;
    let (e, file) = load_err("duplicate_joint", text);
    assert!(matches!(e, LoadError::DuplicateName { element: "joint", .. }), "{e:?}");
    assert_mentions(
        &e.to_string(),
        &[&format!("{file}:6:"), "joint 'j' is defined twice", "rename one of them"],
    );
}

#[test]
fn file_that_does_not_exist() {
    let path =
        std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("lagrange-load-errors-no-such-dir/robot.urdf");
    let e = load(&path, &LoadOptions::default()).unwrap_err();
    assert!(matches!(e, LoadError::Io { .. }), "{e:?}");
    assert_mentions(&e.to_string(), &[&path.display().to_string(), "cannot read the file", "check the path"]);
}

#[test]
fn no_links() {
    let (e, file) = load_err("empty", "<robot name=\"r\">\n</robot>\n");
    assert!(matches!(e, LoadError::Empty { .. }), "{e:?}");
    assert_mentions(&e.to_string(), &[&file, "no links", "add at least one <link"]);
}

#[test]
fn root_element_is_not_robot() {
    let (e, file) = load_err("not_robot", "<?xml version=\"1.0\"?>\n<mujoco model=\"m\"/>\n");
    assert_mentions(&e.to_string(), &[&format!("{file}:2:"), "<mujoco>", "not <robot>"]);
}

#[test]
fn unreadable_number_is_located() {
    // The value checks reject the file; the loader finds the element and line.
    let text = two_links("fixed", r#"    <origin xyz="1 2" rpy="0 0 0"/>"#, "");
    let (e, file) = load_err("bad_number", &text);
    let line = line_of(&text, "<origin");
    assert_mentions(&e.to_string(), &[&format!("{file}:{line}:"), "joint 'j'", "xyz=\"1 2\"", "3 numbers"]);

    let inertial = UNIT_INERTIAL.replace("izz=\"1\"", "izz=\"one\"");
    let text = two_links("fixed", "", &inertial);
    let (e, file) = load_err("bad_inertia", &text);
    let line = line_of(&text, "<inertia ");
    assert_mentions(&e.to_string(), &[&format!("{file}:{line}:"), "link 'b'", "izz=\"one\"", "not a number"]);

    // A missing required element.
    let text = two_links("fixed", "", "    <inertial><mass value=\"1\"/></inertial>");
    let (e, file) = load_err("no_inertia", &text);
    let line = line_of(&text, "<inertial>");
    assert_mentions(&e.to_string(), &[&format!("{file}:{line}:"), "link 'b'", "has no <inertia>", "add one"]);
}

/// A chain of links `l0 → l1 → …` joined by `joints` (name, type, extra body), each child link
/// with a unit inertia.
fn chain(joints: &[(&str, &str, &str)]) -> String {
    let mut t = String::from("<?xml version=\"1.0\"?>\n<robot name=\"r\">\n  <link name=\"l0\"/>\n");
    for (i, (name, jtype, body)) in joints.iter().enumerate() {
        t += &format!("  <link name=\"l{}\">\n{UNIT_INERTIAL}\n  </link>\n", i + 1);
        t += &format!(
            "  <joint name=\"{name}\" type=\"{jtype}\">\n    <parent link=\"l{i}\"/>\n    <child link=\"l{}\"/>\n    <axis xyz=\"0 0 1\"/>\n    <limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1\"/>\n{body}\n  </joint>\n",
            i + 1
        );
    }
    t + "</robot>\n"
}

#[test]
fn mimic_of_an_undefined_joint_is_an_error() {
    // urdfdom and Pinocchio ignore such a mimic; lagrange makes it an error (an intended coupling
    // silently lost is a different robot).
    let text = chain(&[("a", "revolute", ""), ("j", "revolute", "    <mimic joint=\"nope\"/>")]);
    let (e, file) = load_err("mimic_undefined", &text);
    let line = line_of(&text, "<mimic");
    assert_mentions(
        &e.to_string(),
        &[
            &format!("{file}:{line}:"),
            "<mimic>",
            "joint 'j' mimics joint 'nope'",
            "not defined",
            "fix the name",
        ],
    );
}

#[test]
fn mimic_of_itself_is_an_error() {
    let text = chain(&[("j", "revolute", "    <mimic joint=\"j\" multiplier=\"2\"/>")]);
    let (e, file) = load_err("mimic_self", &text);
    let line = line_of(&text, "<mimic");
    assert_mentions(
        &e.to_string(),
        &[&format!("{file}:{line}:"), "<mimic>", "joint 'j' mimics itself", "name the joint it follows"],
    );
}

#[test]
fn mimic_cycles_are_errors_naming_the_joints() {
    let text = chain(&[
        ("a", "revolute", "    <mimic joint=\"b\"/>"),
        ("b", "revolute", "    <mimic joint=\"a\"/>"),
    ]);
    let (e, file) = load_err("mimic_cycle2", &text);
    let line = line_of(&text, "<mimic");
    assert_mentions(
        &e.to_string(),
        &[
            &format!("{file}:{line}:"),
            "<mimic>",
            "'a', 'b' form a cycle",
            "a mimics b, b mimics a",
            "remove one <mimic>",
        ],
    );
    // A longer cycle behind a joint that only follows it.
    let text = chain(&[
        ("x", "prismatic", "    <mimic joint=\"a\"/>"),
        ("a", "revolute", "    <mimic joint=\"b\"/>"),
        ("b", "continuous", "    <mimic joint=\"c\"/>"),
        ("c", "revolute", "    <mimic joint=\"a\"/>"),
    ]);
    let (e, _) = load_err("mimic_cycle3", &text);
    assert_mentions(&e.to_string(), &["'a', 'b', 'c' form a cycle", "a mimics b, b mimics c, c mimics a"]);
    assert!(!e.to_string().contains("'x'"), "{e}");
}

#[test]
fn mimic_of_a_fixed_joint_is_an_error() {
    let text = chain(&[("f", "fixed", ""), ("j", "revolute", "    <mimic joint=\"f\"/>")]);
    let (e, file) = load_err("mimic_of_fixed", &text);
    let line = line_of(&text, "<mimic");
    assert_mentions(
        &e.to_string(),
        &[
            &format!("{file}:{line}:"),
            "joint 'j' mimics joint 'f'",
            "fixed (fused into its parent)",
            "make 'f' revolute or prismatic",
        ],
    );
}

#[test]
fn mimic_needs_one_dof_joints() {
    // The follower must be revolute, continuous or prismatic ...
    let text = chain(&[("a", "revolute", ""), ("p", "planar", "    <mimic joint=\"a\"/>")]);
    let (e, file) = load_err("mimic_planar", &text);
    let line = line_of(&text, "<mimic");
    assert_mentions(
        &e.to_string(),
        &[
            &format!("{file}:{line}:"),
            "joint 'p' is planar",
            "only revolute, continuous and prismatic joints can mimic",
        ],
    );
    // ... and so must the joint it follows.
    let text = chain(&[("fl", "floating", ""), ("j", "revolute", "    <mimic joint=\"fl\"/>")]);
    let (e, _) = load_err("mimic_of_floating", &text);
    assert_mentions(
        &e.to_string(),
        &["joint 'j' mimics joint 'fl', which is floating", "remove the <mimic>"],
    );
}

#[test]
fn mimic_on_a_fixed_joint_is_ignored_with_a_warning() {
    // Reduced models (e.g. example-robot-data's talos_reduced) lock a gripper joint by making it fixed
    // and keep its <mimic>: nothing to couple, so a warning, not an error.
    let text = chain(&[("a", "revolute", ""), ("f", "fixed", "    <mimic joint=\"a\"/>")]);
    let path = write_urdf("mimic_on_fixed", &text);
    let model = load(&path, &LoadOptions::default()).expect("loads with a warning");
    assert!(model.equalities.is_empty());
    let line = line_of(&text, "<mimic");
    assert_eq!(model.warnings.len(), 1, "{:?}", model.warnings);
    assert_mentions(
        &model.warnings[0],
        &[&format!("{}:{line}:", path.display()), "joint 'f' is fixed", "mimic joint=\"a\"", "ignored"],
    );
}

#[test]
fn floating_root_joint_name_clash() {
    let text = r#"<robot name="r">
  <link name="a"/>
  <link name="b"/>
  <joint name="root_joint" type="fixed"><parent link="a"/><child link="b"/></joint>
</robot>"#;
    let options = LoadOptions { floating: true, ..Default::default() };
    let (e, file) = load_err_with("root_clash", text, &options);
    assert_mentions(
        &e.to_string(),
        &[&format!("{file}:4:"), "joint 'root_joint'", "LoadOptions::floating", "rename it"],
    );
}

#[test]
fn urdf_1_2_checks_are_located() {
    // urdfdom's checks for `version="1.2"` files are reported at the element they concern.
    let text = r#"<robot name="r" version="1.2">
  <link name="a">
    <inertial>
      <mass value="1"/>
      <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/>
    </inertial>
    <collision>
      <geometry><sphere radius="0"/></geometry>
    </collision>
  </link>
</robot>"#;
    let (e, file) = load_err("v12_sphere", text);
    assert_mentions(&e.to_string(), &[&format!("{file}:8:"), "<sphere>", "radius must be positive"]);

    let text = r#"<robot name="r" version="1.2">
  <link name="a"/>
  <link name="b"/>
  <joint name="j" type="revolute">
    <parent link="a"/>
    <child link="b"/>
    <limit lower="1" upper="-1"/>
  </joint>
</robot>"#;
    let (e, file) = load_err("v12_limit", text);
    assert_mentions(
        &e.to_string(),
        &[&format!("{file}:4:"), "joint 'j'", "upper position limit", "URDF ≥ 1.2"],
    );
}

#[test]
fn load_error_stays_small() {
    // Clippy's `result_large_err` limit: every `Result<_, LoadError>` moves this many bytes.
    assert!(std::mem::size_of::<LoadError>() < 128, "{}", std::mem::size_of::<LoadError>());
}

#[test]
fn a_missing_visual_mesh_is_a_warning_and_the_visual_is_dropped() {
    let mesh = r#"    <visual><geometry><mesh filename="file:///nonexistent/lagrange/TrunkYaw.mesh"/></geometry></visual>"#;
    let text = two_links("fixed", "", mesh);
    let path = write_urdf("visual_mesh_missing", &text);
    let model = load(&path, &LoadOptions::default()).expect("a visual mesh cannot stop the load");
    assert!(model.geoms.is_empty(), "{:?}", model.geoms);
    assert_eq!(model.warnings.len(), 1, "{:?}", model.warnings);
    let line = line_of(&text, "<mesh ");
    assert_mentions(
        &model.warnings[0],
        &[
            &format!("{}:{line}", path.display()),
            "/nonexistent/lagrange/TrunkYaw.mesh",
            "does not exist",
            "visual dropped",
        ],
    );
}

#[test]
fn a_visual_mesh_under_an_unresolved_package_is_a_warning() {
    // A `.dae` under an unresolved `package://` must not stop the load (visual meshes
    // never take part in the dynamics); the warning names the package and the places searched.
    let mesh = r#"    <visual><geometry><mesh filename="package://lagrange_no_such_pkg/meshes/b.dae"/></geometry></visual>"#;
    let text = two_links("fixed", "", mesh);
    let path = write_urdf("visual_package_missing", &text);
    let options =
        LoadOptions { package_dirs: vec![PathBuf::from("/nonexistent/lagrange/pkgs")], ..Default::default() };
    let model = load(&path, &options).expect("a visual mesh cannot stop the load");
    assert!(model.geoms.is_empty(), "{:?}", model.geoms);
    assert_eq!(model.warnings.len(), 1, "{:?}", model.warnings);
    let line = line_of(&text, "<mesh ");
    assert_mentions(
        &model.warnings[0],
        &[
            &format!("{}:{line}", path.display()),
            "package 'lagrange_no_such_pkg' not found",
            "visual dropped",
        ],
    );
}

#[test]
fn nonphysical_inertia_is_refused_unless_accepted() {
    let inertial = r#"    <inertial><mass value="1"/><inertia ixx="0.001" iyy="0.001" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>"#;
    let text = two_links("continuous", "", inertial);
    let (e, _) = load_err("triangle", &text);
    assert_mentions(&e.to_string(), &["triangle inequality", "LoadOptions::accept_nonphysical_inertia"]);
    let path = write_urdf("triangle_accepted", &text);
    let options = LoadOptions { accept_nonphysical_inertia: true, ..Default::default() };
    let model = load(&path, &options).expect("accepted as written");
    let i = model.bodies[1].inertia_com();
    assert_eq!((i[(0, 0)], i[(1, 1)], i[(2, 2)]), (0.001, 0.001, 0.01), "kept exactly as written");
    assert!(model.warnings.iter().any(|w| w.contains("kept as written")), "{:?}", model.warnings);
}
