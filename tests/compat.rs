//! Regression tests for compatibility bug classes and fuzzing findings, each built from
//! a small hand-made file (tests/data/compat/ or generated here): load what MuJoCo and Pinocchio
//! load, refuse only what they refuse — with file, line, element and fix — and never panic, hang,
//! or load NaN.

mod common;

use lagrange::io::{load, LoadOptions};
use lagrange::mass::read_mesh;
use lagrange::spatial::Vec3;
use std::path::{Path, PathBuf};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/compat").join(name)
}

fn load_ok(name: &str, options: &LoadOptions) -> lagrange::Model {
    load(&data(name), options).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// The error message of a file that must be refused, checked for every needle.
fn refused(path: &Path, options: &LoadOptions, needles: &[&str]) -> String {
    let msg = match load(path, options) {
        Ok(_) => panic!("{}: loaded, expected an error", path.display()),
        Err(e) => e.to_string(),
    };
    for n in needles {
        assert!(msg.contains(n), "missing '{n}' in: {msg}");
    }
    msg
}

fn temp_dir(tag: &str) -> PathBuf {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("lagrange-compat-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn finite_model(m: &lagrange::Model) -> bool {
    m.bodies.iter().all(|b| {
        let i = &b.inertia;
        i.mass.is_finite() && i.h.iter().chain(i.i_origin.iter()).all(|x| x.is_finite())
    })
}

// --- 1. Compatibility bug classes -------------------------------------------------------------

#[test]
fn round_off_inertia_is_zero_not_negative() {
    // Principal moments −2e-20, 1e-20, 1e-20: round-off (below MuJoCo's mjMINVAL), not a negative
    // moment. Pinocchio loads this file; so do we, with the tensor as written.
    let m = load_ok("roundoff_inertia.urdf", &LoadOptions::default());
    assert_eq!(m.nv, 1);
    assert!((m.bodies[1].inertia.mass - 1.5).abs() < 1e-15);
    assert!(finite_model(&m));
    // A genuinely negative moment is still refused (tests/load_errors.rs covers the message).
}

#[test]
fn world_welded_body_never_needs_its_mass() {
    // 'stand' is welded to the world and its inertia would come from a misoriented mesh in exact
    // mode: the mass is never used, so the model loads, with a warning saying so.
    let m = load_ok("welded_open_mesh.xml", &LoadOptions::default());
    assert_eq!(m.nv, 1);
    let w = m.warnings.iter().find(|w| w.contains("welded to the world")).expect("a warning");
    assert!(w.contains("welded_open_mesh.xml:8") && w.contains("body 'stand'"), "{w}");
}

#[test]
fn included_file_may_have_a_mujocoinclude_root() {
    let m = load_ok("fragment_main.xml", &LoadOptions::default());
    assert_eq!(m.nv, 1);
    assert_eq!(m.joints[0].name, "knuckle");
}

#[test]
fn shared_load_options_act_on_mjcf_or_say_they_do_not_apply() {
    let path = data("nonphysical_inertia.xml");
    refused(
        &path,
        &LoadOptions::default(),
        &["nonphysical_inertia.xml:5", "body 'odd'", "triangle inequality"],
    );
    let accept = LoadOptions { accept_nonphysical_inertia: true, ..Default::default() };
    let m = load(&path, &accept).unwrap();
    assert!(m.warnings.iter().any(|w| w.contains("kept as written")), "{:?}", m.warnings);
    let float = LoadOptions { floating: true, package_dirs: vec!["/tmp".into()], ..Default::default() };
    let m = load(&path, &LoadOptions { accept_nonphysical_inertia: true, ..float }).unwrap();
    for needle in ["LoadOptions::floating applies to URDF only", "LoadOptions::package_dirs applies to URDF"]
    {
        assert!(m.warnings.iter().any(|w| w.contains(needle)), "no '{needle}' in {:?}", m.warnings);
    }
}

#[test]
fn open_meshes_follow_mujoco_per_inertia_mode() {
    // MuJoCo 4.0 on tests/data/meshes/open_cube.stl (a unit cube without its top face) at density
    // 1000: legacy and exact integrate the open surface (mass 804.1666…, principal moments 147.083,
    // 123.975, 123.975), convex takes the hull (1000), shell the surface (5000). We match each, with
    // a warning where the surface is open.
    let dir = temp_dir("open_mesh");
    let mesh = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/meshes/open_cube.stl");
    for (mode, mass, warned) in [
        ("legacy", 804.166_666_666_666_6, true),
        ("exact", 804.166_666_666_666_6, true),
        ("convex", 1000.0, false),
        ("shell", 5000.0, false),
    ] {
        let path = dir.join(format!("open_{mode}.xml"));
        std::fs::write(
            &path,
            format!(
                r#"<mujoco><asset><mesh name="m" file="{}" inertia="{mode}"/></asset>
<worldbody><body name="b"><joint type="hinge"/><geom type="mesh" mesh="m"/></body></worldbody></mujoco>"#,
                mesh.display()
            ),
        )
        .unwrap();
        let m = load(&path, &LoadOptions::default()).unwrap_or_else(|e| panic!("{mode}: {e}"));
        assert!(
            (m.bodies[1].inertia.mass - mass).abs() < 1e-9 * mass,
            "{mode}: {}",
            m.bodies[1].inertia.mass
        );
        let open = m.warnings.iter().any(|w| w.contains("not closed"));
        assert_eq!(open, warned, "{mode}: {:?}", m.warnings);
    }
    // The principal moments of the legacy result are MuJoCo's body_inertia.
    let m = load(&dir.join("open_legacy.xml"), &LoadOptions::default()).unwrap();
    let (moments, _) = lagrange::mass::principal_axes(&m.bodies[1].inertia.i_com());
    for (got, want) in moments.iter().zip([123.975_390_62, 123.975_390_62, 147.083_333_33]) {
        assert!((got - want).abs() < 1e-6 * want, "{moments:?}");
    }
}

// --- 2. Found by fuzzing ----------------------------------------------------------------------

#[test]
fn msh_face_index_beyond_the_vertices_is_an_error() {
    let dir = temp_dir("msh");
    // A tetrahedron: 4 vertices, no normals or texture coordinates, 4 faces, one index −1.
    let mut bytes = Vec::new();
    for n in [4i32, 0, 0, 4] {
        bytes.extend_from_slice(&n.to_le_bytes());
    }
    for v in [[0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]] {
        v.iter().for_each(|x| bytes.extend_from_slice(&x.to_le_bytes()));
    }
    for f in [[0i32, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, -1]] {
        f.iter().for_each(|x| bytes.extend_from_slice(&x.to_le_bytes()));
    }
    let path = dir.join("bad_index.msh");
    std::fs::write(&path, &bytes).unwrap();
    let msg = read_mesh(&path, &Vec3::new(1.0, 1.0, 1.0)).unwrap_err().to_string();
    assert!(msg.contains("face 3 refers to vertex -1") && msg.contains("4 vertices"), "{msg}");
}

fn nested_bodies(depth: usize) -> String {
    let mut s = String::from("<mujoco><worldbody>\n");
    for _ in 0..depth {
        s.push_str("<body><joint/><geom size=\".1\" contype=\"0\" conaffinity=\"0\"/>\n");
    }
    s.push_str(&"</body>".repeat(depth));
    s.push_str("</worldbody></mujoco>\n");
    s
}

#[test]
fn deep_nesting_loads_up_to_the_limit_and_is_refused_beyond() {
    let dir = temp_dir("deep");
    // 395 nested bodies load, on a test thread's 2 MB stack too.
    let path = dir.join("deep_395.xml");
    std::fs::write(&path, nested_bodies(395)).unwrap();
    let m = load(&path, &LoadOptions::default()).unwrap();
    assert_eq!(m.nv, 395);
    // Five thousand are refused with the limit named (before: a stack overflow at ~3000).
    let path = dir.join("deep_5000.xml");
    std::fs::write(&path, nested_bodies(5000)).unwrap();
    refused(&path, &LoadOptions::default(), &["deep_5000.xml:", "nest more than 400 levels"]);
}

#[test]
fn huge_finite_numbers_are_refused_with_file_and_line() {
    let o = LoadOptions::default();
    refused(
        &data("huge_inertial_origin.urdf"),
        &o,
        &["huge_inertial_origin.urdf:6", "link 'arm'", "1e200", "absurdly large"],
    );
    refused(&data("huge_sizes.xml"), &o, &["huge_sizes.xml:4", "geom 'big'", "size 1e200"]);
    refused(&data("huge_pos.xml"), &o, &["huge_pos.xml:4", "<body>", "body 'far'", "-1e308"]);
    refused(&data("huge_mesh_scale.xml"), &o, &["huge_mesh_scale.xml:6", "mesh's scale 1e200"]);
}

/// The load warning of `m` that contains `needle`.
fn warning(m: &lagrange::Model, needle: &str) -> String {
    m.warnings
        .iter()
        .find(|w| w.contains(needle))
        .cloned()
        .unwrap_or_else(|| panic!("no '{needle}' in {:?}", m.warnings))
}

#[test]
fn massless_moving_links_follow_one_rule_in_both_formats() {
    // One rule for URDF and MJCF: a joint whose subtree carries no mass or inertia makes M singular;
    // the model loads (Pinocchio loads it), with a warning naming the joint, and a simulation stops
    // at its first step naming it (tests/sim_errors.rs). Before, URDF loaded it silently.
    let m = load_ok("massless_leaf.urdf", &LoadOptions::default());
    let w = warning(&m, "moves nothing");
    for needle in ["massless_leaf.urdf:8", "joint 'wrist' moves nothing", "link 'tool'", "<inertial>"] {
        assert!(w.contains(needle), "missing '{needle}' in: {w}");
    }
    assert!(!w.contains("body '"), "URDF message in MJCF terms: {w}");
    // A massless link between two joints whose child has mass is a gimbal: defined dynamics, no
    // warning.
    let m = load_ok("massless_middle.urdf", &LoadOptions::default());
    assert_eq!(m.nv, 2);
    assert!(m.warnings.iter().all(|w| !w.contains("moves nothing")), "{:?}", m.warnings);
    // The same in MJCF (tests/data/mjcf/errors/massless_moving_body.xml: a hinge on a body without
    // mass; MuJoCo refuses it, and a second warning says so).
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/mjcf/errors/massless_moving_body.xml");
    let m = load(&path, &LoadOptions::default()).unwrap();
    let w = warning(&m, "moves nothing");
    assert!(
        w.contains("massless_moving_body.xml:5") && w.contains("joint 'j'") && w.contains("body 'ghost'"),
        "{w}"
    );
    warning(&m, "MuJoCo refuses such a model");
}

#[test]
fn identical_joints_are_named_as_singular() {
    // MuJoCo loads this (Pinocchio does not): it loads with a warning naming both joints.
    let m = load_ok("two_identical_joints.xml", &LoadOptions::default());
    let w = warning(&m, "repeats the motion");
    for needle in
        ["two_identical_joints.xml:5", "joint 'x1'", "repeats the motion of joint(s) 'x2'", "singular"]
    {
        assert!(w.contains(needle), "missing '{needle}' in: {w}");
    }
}

#[test]
fn messages_use_the_file_s_own_terms() {
    // MJCF: "body", MuJoCo's attributes; URDF: "link", `<mass value>`.
    let msg = refused(
        &data("nonphysical_inertia.xml"),
        &LoadOptions::default(),
        &["body 'odd'", "<inertial diaginertia"],
    );
    assert!(!msg.contains("link '") && !msg.contains("<inertia> values"), "{msg}");
    // A URDF loop is reported as a cycle, not as a second parent.
    refused(
        &data("cycle.urdf"),
        &LoadOptions::default(),
        &["cycle.urdf:7", "joint 'close'", "'a', 'b' form a cycle"],
    );
}

// --- 4. Resource limits -----------------------------------------------------------------------

#[test]
fn include_depth_is_bounded() {
    let dir = temp_dir("includes");
    let n = 40;
    for k in 0..n {
        let body = if k + 1 < n { format!("<include file=\"inc{}.xml\"/>", k + 1) } else { String::new() };
        std::fs::write(dir.join(format!("inc{k}.xml")), format!("<mujoco>{body}</mujoco>")).unwrap();
    }
    std::fs::write(dir.join("main.xml"), "<mujoco><include file=\"inc0.xml\"/></mujoco>").unwrap();
    refused(&dir.join("main.xml"), &LoadOptions::default(), &["<include>", "more than 32 nested includes"]);
}

#[test]
fn link_and_dof_counts_are_bounded() {
    let dir = temp_dir("counts");
    let mut s = String::from("<robot name=\"big\"><link name=\"l0\"/>");
    for k in 1..=3001 {
        s.push_str(&format!(
            "<link name=\"l{k}\"><inertial><mass value=\"1\"/><inertia ixx=\"1\" iyy=\"1\" izz=\"1\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial></link><joint name=\"j{k}\" type=\"continuous\"><parent link=\"l{}\"/><child link=\"l{k}\"/></joint>",
            k - 1
        ));
    }
    s.push_str("</robot>");
    let path = dir.join("big.urdf");
    std::fs::write(&path, s).unwrap();
    refused(&path, &LoadOptions::default(), &["3001 degrees of freedom", "limit of 3000"]);
    // Links beyond the limit are refused before the second (slower) URDF parse.
    let mut s = String::from("<robot name=\"many\"><link name=\"l0\"/>");
    for k in 1..=10_001 {
        s.push_str(&format!("<link name=\"l{k}\"/><joint name=\"j{k}\" type=\"fixed\"><parent link=\"l{}\"/><child link=\"l{k}\"/></joint>", k - 1));
    }
    s.push_str("</robot>");
    let path = dir.join("many.urdf");
    std::fs::write(&path, s).unwrap();
    refused(&path, &LoadOptions::default(), &["10002 links", "limit of 10000"]);
}

#[test]
fn contact_rows_that_move_nothing_get_no_force() {
    // Found by fuzzing (the unmutated panda at a random state): the fingers, overlapping below
    // their limits, touch along a normal that no dof can move (Delassus diagonal 5e-30 beside
    // 1e2); dividing round-off by round-off gave an infinite force and NaN accelerations.
    let model =
        load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("models/panda/panda.urdf"), &LoadOptions::default())
            .unwrap();
    let q = [
        0.13092641012126394,
        -0.47381965191556175,
        0.12784852518823708,
        0.06465027657791445,
        -0.4514118771169262,
        -0.44652976540889755,
        -0.24504377283484846,
        -0.21076163689358607,
        0.16743995290757696,
    ];
    let v = [
        -0.8637823629512975,
        0.2898388408138217,
        -0.03541390189171967,
        -0.14139441407914166,
        -0.4420610063963575,
        -0.13422682075550707,
        0.2467756994335928,
        0.2834793965271598,
        -0.2694435487696456,
    ];
    let mut data = lagrange::Data::new(&model);
    common::forward_at(&model, &mut data, &q, &v);
    assert!(data.contacts.len() >= 4, "{} contacts", data.contacts.len());
    assert!(data.qacc.iter().all(|x| x.is_finite()), "{:?}", data.qacc.as_slice());
    assert!(data.efc_force.iter().take(data.nefc).all(|x| x.is_finite()));
}

#[test]
fn frictional_solve_never_diverges_to_nan() {
    // Found by fuzzing (the unmodified go1 scene at a random state: the trunk 8.6 cm into the
    // floor, four knees beyond their limits, fast slips): projected Gauss–Seidel with the sliding
    // law grew without bound to ±inf. It now restarts with the symmetric cone projection.
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("models/mjcf/unitree_go1/scene.xml");
    let model = load(&path, &LoadOptions::default()).unwrap();
    let q = [
        0.0,
        0.0,
        0.445,
        -0.7286742640584936,
        0.1553655897051232,
        -0.3573897392307025,
        0.5631766372347158,
        0.10470028804371312,
        -0.40560559523581907,
        0.17331161232061731,
        0.4838924760647323,
        -0.296634066697107,
        0.3611236150663315,
        -0.17985339345520135,
        -0.03701476393834224,
        -0.32778949450617323,
        -0.34871707738131863,
        0.2856122245672317,
        -0.48401050339308305,
    ];
    let v = [
        -0.32587034979990515,
        0.1969582498124054,
        -0.4777259439719388,
        -0.0880886672433876,
        0.6248697593202586,
        -0.88820911824561,
        -0.8848158663574064,
        -0.701786562732162,
        0.8307765561479314,
        0.7274124782321456,
        0.3369603121981224,
        0.6495460763701888,
        0.6043653946731986,
        0.7198664592396375,
        0.30541993761014785,
        0.34551232917034636,
        0.07704165357650794,
        0.8557783079830759,
    ];
    let model = common::with_mode(model, lagrange::constraint::ConstraintMode::Exact);
    let mut data = lagrange::Data::new(&model);
    common::forward_at(&model, &mut data, &q, &v);
    assert_eq!(data.contacts.len(), 4);
    assert!(data.qacc.iter().all(|x| x.is_finite()), "{:?}", data.qacc.as_slice());
    assert!(data.efc_converged && data.efc_safe_friction);
}

#[test]
fn absurd_coefficients_of_tendons_and_mimics_are_refused() {
    // Found by fuzzing: a fixed-tendon coefficient of 1e308 and a mimic multiplier of 1e308 loaded
    // and gave non-finite accelerations.
    let dir = temp_dir("coefficients");
    let path = dir.join("tendon.xml");
    std::fs::write(
        &path,
        r#"<mujoco><worldbody><body><joint name="a"/><geom size=".1"/><body pos="0 0 -.3"><joint name="b"/><geom size=".1"/></body></body></worldbody>
<tendon><fixed name="t"><joint joint="a" coef="1"/>
<joint joint="b" coef="1e308"/></fixed></tendon></mujoco>"#,
    )
    .unwrap();
    refused(
        &path,
        &LoadOptions::default(),
        &["tendon.xml:3", "tendon 't', joint 'b'", "1e308", "absurdly large"],
    );
    let path = dir.join("mimic.urdf");
    std::fs::write(
        &path,
        r#"<robot name="m"><link name="a"/>
<link name="b"><inertial><origin xyz="0 0 .1"/><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
<link name="c"><inertial><origin xyz="0 0 .1"/><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
<joint name="j1" type="continuous"><parent link="a"/><child link="b"/></joint>
<joint name="j2" type="continuous"><parent link="a"/><child link="c"/>
<mimic joint="j1" multiplier="1e308"/></joint></robot>"#,
    )
    .unwrap();
    refused(&path, &LoadOptions::default(), &["mimic.urdf:6", "joint 'j2'", "mimic multiplier", "1e308"]);
}

#[test]
fn limits_must_be_ordered() {
    // Found by fuzzing: a URDF <limit upper="-inf"> loaded (MuJoCo loads it too) and gave NaN at
    // the limit; MuJoCo refuses the same thing in MJCF ("range[0] should be smaller than
    // range[1]", and so did the MJCF loader already). URDF now follows the same rule: lower below
    // upper, an infinite bound only on its own side.
    let dir = temp_dir("limits");
    let path = dir.join("limit.urdf");
    std::fs::write(
        &path,
        r#"<robot name="l"><link name="a"/>
<link name="b"><inertial><origin xyz="0 0 .1"/><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
<joint name="j" type="revolute"><parent link="a"/><child link="b"/><limit lower="-1" upper="-inf" effort="1" velocity="1"/></joint></robot>"#,
    )
    .unwrap();
    refused(
        &path,
        &LoadOptions::default(),
        &["limit.urdf:3", "joint 'j'", "lower limit -1 is not below the upper limit -inf"],
    );
    let path = dir.join("range.xml");
    std::fs::write(&path, "<mujoco><worldbody><body><joint name=\"h\" range=\"1 -1\" limited=\"true\"/><geom size=\".1\"/></body></worldbody></mujoco>")
        .unwrap();
    refused(
        &path,
        &LoadOptions::default(),
        &["range.xml:1", "attribute 'range' is [1, -1]", "lower limit must be below the upper"],
    );
}

#[test]
fn absurd_options_are_refused() {
    // Found by fuzzing: <option gravity="0 -1e308 -9.81"> loaded and gave non-finite accelerations.
    let dir = temp_dir("options");
    let path = dir.join("gravity.xml");
    std::fs::write(&path, r#"<mujoco><option gravity="0 -1e308 -9.81"/><worldbody><body><joint type="ball"/><geom size=".1" pos="0 0 .2"/></body></worldbody></mujoco>"#).unwrap();
    refused(
        &path,
        &LoadOptions::default(),
        &["gravity.xml", "<option>", "gravity", "-1e308", "absurdly large"],
    );
    // And <compiler settotalmass="1e308"> (a later finding).
    let path = dir.join("total.xml");
    std::fs::write(&path, r#"<mujoco><compiler settotalmass="1e308"/><worldbody><body><joint/><geom size=".1" pos="0 0 .2"/></body></worldbody></mujoco>"#).unwrap();
    refused(&path, &LoadOptions::default(), &["total.xml", "<compiler>", "settotalmass", "1e308"]);
}

#[test]
fn negative_and_negative_zero_sizes() {
    // Found by fuzzing: a URDF <cylinder radius="-0"> reached parry's cylinder, which asserts a
    // positive sign (a panic). −0 is zero (and loads); a negative size is refused (as before).
    let dir = temp_dir("sizes");
    let robot = |radius: &str| {
        format!(
            r#"<robot name="s"><link name="a"/>
<link name="b"><inertial><origin xyz="0 0 .1"/><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial>
<collision><geometry><cylinder radius="{radius}" length="0.4"/></geometry></collision></link>
<joint name="j" type="continuous"><parent link="a"/><child link="b"/></joint></robot>"#
        )
    };
    let path = dir.join("zero.urdf");
    std::fs::write(&path, robot("-0")).unwrap();
    let m = load(&path, &LoadOptions::default()).unwrap();
    let mut data = lagrange::Data::new(&m);
    common::forward_at(&m, &mut data, &[0.3], &[0.0]);
    assert!(data.qacc[0].is_finite());
    let path = dir.join("negative.urdf");
    std::fs::write(&path, robot("-0.1")).unwrap();
    refused(
        &path,
        &LoadOptions::default(),
        &["negative.urdf:3", "link 'b'", "negative or non-finite size [-0.1, 0.4]"],
    );
}

#[test]
fn huge_quaternion_components_and_contact_parameters() {
    // Found by fuzzing: quat="3 1 -2 1e200" and a weld relpose quaternion with -1e308 overflowed
    // their norm (NaN qpos0, NaN weld rows); friction="1e200" loaded. Quaternions are now scaled
    // before normalizing (MuJoCo normalizes them too); absurd contact parameters are refused.
    let dir = temp_dir("quaternions");
    let path = dir.join("quat.xml");
    std::fs::write(
        &path,
        r#"<mujoco><worldbody><body quat="3 1 -2 1e200"><freejoint/><geom size=".1"/></body></worldbody></mujoco>"#,
    )
    .unwrap();
    let m = load(&path, &LoadOptions::default()).unwrap();
    assert!(m.qpos0.iter().all(|x| x.is_finite()), "{:?}", m.qpos0);
    // The quaternion is (0, 0, 0, 1) to round-off: a half turn about z.
    assert!((m.qpos0[6].abs() - 1.0).abs() < 1e-15, "{:?}", m.qpos0);
    let path = dir.join("friction.xml");
    std::fs::write(
        &path,
        r#"<mujoco><worldbody><geom type="plane" size="1 1 .1"/><body><freejoint/><geom size=".1" friction="1e200 0 0"/></body></worldbody></mujoco>"#,
    )
    .unwrap();
    refused(&path, &LoadOptions::default(), &["friction.xml:1", "contact parameter", "1e200"]);
}

#[test]
fn lengths_beyond_a_thousand_kilometres_are_refused() {
    // Found by fuzzing: a capsule fromto 4.3e9 m long and a joint anchored 4.3e9 m away (below the
    // 1e12 bound on other quantities) loaded and gave NaN accelerations.
    let dir = temp_dir("lengths");
    let path = dir.join("long.xml");
    std::fs::write(
        &path,
        r#"<mujoco><worldbody><body><joint/>
<geom type="capsule" fromto="0 0 0 0.2 4294967295 0" size="0.02" mass="0.4"/></body></worldbody></mujoco>"#,
    )
    .unwrap();
    refused(&path, &LoadOptions::default(), &["long.xml:2", "<geom>", "2.1474836475e9", "beyond 1e6"]);
}

#[test]
fn mesh_files_are_bounded() {
    // A hostile mesh must not exhaust memory: files over 512 MB are refused before they are read
    // (a sparse file here, so the test costs nothing), and so are meshes over 1e7 vertices or 2e7
    // triangles once parsed.
    let dir = temp_dir("mesh_limits");
    let path = dir.join("huge.stl");
    let f = std::fs::File::create(&path).unwrap();
    f.set_len(600 * 1024 * 1024).unwrap();
    let msg = read_mesh(&path, &Vec3::new(1.0, 1.0, 1.0)).unwrap_err().to_string();
    assert!(msg.contains("629145600 bytes") && msg.contains("limit of 536870912"), "{msg}");
    let _ = std::fs::remove_file(&path);
}

#[test]
fn absurd_tendon_springs_and_fluid_options_are_refused() {
    // Found by fuzzing: a spatial tendon's damping of 1e308 and a wind of -1e200 loaded and gave
    // non-finite accelerations.
    let dir = temp_dir("absurd_options");
    let path = dir.join("tendon_damping.xml");
    std::fs::write(
        &path,
        r#"<mujoco><worldbody><site name="a"/><body pos="0 0 -0.3"><joint name="j"/><geom size=".1"/><site name="b"/></body></worldbody>
<tendon><spatial name="t" damping="1e308"><site site="a"/><site site="b"/></spatial></tendon></mujoco>"#,
    )
    .unwrap();
    refused(
        &path,
        &LoadOptions::default(),
        &["tendon_damping.xml:2", "tendon 't'", "1e308", "absurdly large"],
    );
    let path = dir.join("wind.xml");
    std::fs::write(
        &path,
        r#"<mujoco><option density="1.2" wind="2 0 -1e200"/><worldbody><body><freejoint/><geom size=".1"/></body></worldbody></mujoco>"#,
    )
    .unwrap();
    refused(&path, &LoadOptions::default(), &["option", "wind", "1e200", "absurdly large"]);
    // Found by fuzzing too: a geom's fluidcoef entry of 1e308 (ellipsoid fluid model).
    let path = dir.join("fluidcoef.xml");
    std::fs::write(
        &path,
        r#"<mujoco><option density="1.2"/><worldbody><body><freejoint/>
<geom name="c" type="capsule" size="0.03 0.2" fluidshape="ellipsoid" fluidcoef="0.4 0.2 1.2 1e308 0.8"/></body></worldbody></mujoco>"#,
    )
    .unwrap();
    refused(&path, &LoadOptions::default(), &["fluidcoef.xml:2", "fluidcoef", "1e308", "absurdly large"]);
}

/// A geom's partial `solref` (one value) keeps the default's second entry, as MuJoCo 4.0 reads it
/// (MyoSuite's myoarm_tabletennis_native.xml writes solref="0.01"; MuJoCo: geom_solref [0.05, 1]
/// for solref="0.05").
#[test]
fn partial_geom_solref_keeps_the_default_damping_ratio() {
    let model = lagrange::Model::from_str(
        r#"<mujoco><worldbody><geom name="g" size="0.1" solref="0.05"/></worldbody></mujoco>"#,
    )
    .unwrap();
    assert_eq!(model.geoms[0].contact.solref, [0.05, 1.0]);
}

/// Found by fuzzing (2026-11-27): sizes in a file that would exhaust memory are typed errors
/// naming the element — a user sensor's `dim` and a contact sensor's `num` of 2³² − 1, a
/// built-in plate or supersphere of ~10²⁰⁰ points — and a chain of 300 links stacked in one
/// place (tens of thousands of candidate contacts) keeps the soft solver's work bounded: the
/// contact budget follows the depth of the dof tree, and the overflow is a warning.
#[test]
fn fuzzed_sizes_are_refused_and_contact_work_is_bounded() {
    let dir = temp_dir("fuzz_sizes");
    let world = |body: &str, extra: &str| {
        format!("<mujoco><worldbody><body><joint name=\"j\"/><geom size=\".1\"/><site name=\"s\"/></body>{body}</worldbody>{extra}</mujoco>")
    };
    let cases = [
        ("user_dim", world("", "<sensor><user name=\"u\" dim=\"4294967295\"/></sensor>"), "sensordata"),
        (
            "contact_num",
            world(
                "",
                "<sensor><contact name=\"c\" site=\"s\" num=\"4294967295\" data=\"found dist\"/></sensor>",
            ),
            "sensordata",
        ),
        (
            "plate",
            world("", "<asset><mesh name=\"p\" builtin=\"plate\" params=\"1e200 3\"/></asset>"),
            "at most 10^6 points",
        ),
        (
            "supersphere",
            world("", "<asset><mesh name=\"p\" builtin=\"supersphere\" params=\"1e9 1 1\"/></asset>"),
            "at most 10^6 points",
        ),
    ];
    for (name, text, needle) in cases {
        let path = dir.join(format!("{name}.xml"));
        std::fs::write(&path, text).unwrap();
        refused(&path, &LoadOptions::default(), &[needle]);
    }
    let chain: String =
        (0..300).map(|_| "<body><joint/><geom size=\".1\"/>").collect::<String>() + &"</body>".repeat(300);
    let model = lagrange::Model::from_str(&format!(
        "<mujoco><worldbody><geom type=\"plane\" size=\"0 0 1\"/><body>{chain}</body></worldbody></mujoco>"
    ))
    .unwrap();
    assert_eq!(model.contact_budget(), lagrange::model::INITIAL_CONTACTS);
    let mut data = lagrange::Data::new(&model);
    lagrange::forward::forward(&model, &mut data);
    assert!(data.qacc.iter().all(|x| x.is_finite()));
    assert_eq!(data.contacts.len(), lagrange::model::INITIAL_CONTACTS);
    assert_eq!(data.warnings.contact_full.number, 1);
}
