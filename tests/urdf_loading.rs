//! The URDF loader on hand-written models: joint types, depth-first file order, q/v layout,
//! stored joint data, fusion of fixed links, `--floating`, mesh and `package://` resolution.

mod common;

use common::ALGO_REL;
use lagrange::io::{load, load_spec, load_urdf_str, LoadOptions};
use lagrange::model::spec::{JointType, Shape};
use lagrange::model::{EqualityKind, JointKind};
use lagrange::spatial::{Mat3, Transform, Vec3};
use lagrange::Model;
use std::f64::consts::FRAC_PI_2;
use std::path::{Path, PathBuf};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/urdf").join(name)
}

fn all_joints(floating: bool) -> Model {
    let options = LoadOptions { floating, ..Default::default() };
    load(&data("all_joints.urdf"), &options).unwrap_or_else(|e| panic!("{e}"))
}

/// 1-based line of the first line of `file` containing `needle`.
fn line_of(file: &Path, needle: &str) -> u32 {
    let text = std::fs::read_to_string(file).unwrap();
    let i = text.lines().position(|l| l.contains(needle)).unwrap_or_else(|| panic!("{needle} not in file"));
    i as u32 + 1
}

fn assert_close(a: f64, b: f64, what: &str) {
    assert!((a - b).abs() <= ALGO_REL * (1.0 + b.abs()), "{what}: {a} != {b}");
}

fn assert_vec(a: &Vec3, b: &Vec3, what: &str) {
    assert!((a - b).norm() <= ALGO_REL * (1.0 + b.norm()), "{what}: {a:?} != {b:?}");
}

fn assert_mat(a: &Mat3, b: &Mat3, what: &str) {
    assert!((a - b).norm() <= ALGO_REL * (1.0 + b.norm()), "{what}: {a:?} != {b:?}");
}

fn assert_transform(a: &Transform, b: &Transform, what: &str) {
    assert_mat(&a.rot, &b.rot, what);
    assert_vec(&a.pos, &b.pos, what);
}

fn xyz_rpy(x: [f64; 3], r: [f64; 3]) -> Transform {
    Transform::from_xyz_rpy(x, r)
}

/// Unique scratch folder under the system temp dir.
fn scratch(tag: &str) -> PathBuf {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("lagrange-urdf-loading-{}-{tag}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn joint_order_is_depth_first_in_file_order() {
    let m = all_joints(false);
    let names: Vec<&str> = m.joints.iter().map(|j| j.name.as_str()).collect();
    // Not name order (b, c, d, x, y, z) nor link order: depth-first from `base`, children in
    // the file order of their joints, the fixed `a_mount` traversed between `z_slide`'s subtree
    // and `x_free`.
    assert_eq!(names, ["z_slide", "y_planar", "b_arm", "c_wrist", "d_finger", "x_free"]);
    let bodies: Vec<&str> = m.bodies.iter().map(|b| b.name.as_str()).collect();
    assert_eq!(bodies, ["world", "slider", "sled", "arm", "wrist", "finger", "drone"]);
    // Parents: base and mount are welded to the world, so slider, arm, finger, drone hang from it.
    let parents: Vec<usize> = m.bodies.iter().skip(1).map(|b| b.parent).collect();
    assert_eq!(parents, [0, 1, 0, 3, 0, 0]);
}

#[test]
fn spec_links_are_in_preorder_with_source_lines() {
    let path = data("all_joints.urdf");
    let spec = load_spec(&path, &LoadOptions::default()).unwrap();
    assert_eq!(spec.name, "all_joints");
    assert_eq!(spec.source.as_deref(), Some(path.as_path()));
    assert_eq!(spec.gravity, Vec3::new(0.0, 0.0, -9.81));
    let names: Vec<&str> = spec.links.iter().map(|l| l.name.as_str()).collect();
    assert_eq!(names, ["base", "slider", "sled", "mount", "arm", "wrist", "tool", "finger", "drone"]);
    let parents: Vec<Option<usize>> = spec.links.iter().map(|l| l.parent).collect();
    assert_eq!(parents, [None, Some(0), Some(1), Some(0), Some(3), Some(4), Some(5), Some(3), Some(0)]);
    let root = &spec.links[0];
    assert_eq!((root.joint.name.as_str(), root.joint.jtype), ("world_joint", JointType::Fixed));
    let types: Vec<JointType> = spec.links.iter().skip(1).map(|l| l.joint.jtype).collect();
    use JointType::*;
    assert_eq!(types, [Prismatic, Planar, Fixed, Revolute, Continuous, Fixed, Revolute, Floating]);

    let file = path.display().to_string();
    for l in &spec.links {
        assert_eq!(l.loc.file, file);
        assert_eq!(l.loc.line, line_of(&path, &format!("<link name=\"{}\"", l.name)), "link {}", l.name);
        if l.parent.is_some() {
            let j = &l.joint;
            assert_eq!(
                j.loc.line,
                line_of(&path, &format!("<joint name=\"{}\"", j.name)),
                "joint {}",
                j.name
            );
        }
    }
    // <inertial> of `mount` is the line after its <link>.
    let mount = &spec.links[3];
    let inertial = mount.inertial.as_ref().unwrap();
    assert_eq!(inertial.loc.line, mount.loc.line + 1);
    assert_eq!(inertial.mass, 1.0);
    assert_transform(
        &inertial.x_link_inertial,
        &xyz_rpy([0.2, 0.0, 0.0], [0.0, 0.0, FRAC_PI_2]),
        "mount inertial",
    );
    assert_mat(&inertial.inertia, &Mat3::from_diagonal(&Vec3::new(1.0, 2.0, 3.0)), "mount inertia");
    // Off-diagonal entries are stored symmetrically.
    let arm = spec.links[4].inertial.as_ref().unwrap();
    assert_eq!((arm.inertia[(0, 1)], arm.inertia[(1, 0)]), (0.001, 0.001));
    // A link without <inertial> is massless.
    assert!(spec.links[1].inertial.is_none());
    // Raw axis and origin.
    let b_arm = &spec.links[4].joint;
    assert_eq!(b_arm.axis, Vec3::new(0.0, 0.0, 2.0));
    assert_transform(&b_arm.x_parent_joint, &xyz_rpy([0.1, 0.0, 0.2], [FRAC_PI_2, 0.0, 0.0]), "b_arm origin");
    assert_eq!(b_arm.armature, 0.0);
}

#[test]
fn q_and_v_layout() {
    let m = all_joints(false);
    assert_eq!((m.nq, m.nv), (14, 13));
    let qpos: Vec<usize> = m.joints.iter().map(|j| j.qpos_adr).collect();
    let dofs: Vec<usize> = m.joints.iter().map(|j| j.dof_adr).collect();
    assert_eq!(qpos, [0, 1, 4, 5, 6, 7]);
    assert_eq!(dofs, [0, 1, 4, 5, 6, 7]);
    let kinds: Vec<&str> = m.joints.iter().map(|j| j.kind.type_name()).collect();
    assert_eq!(kinds, ["prismatic", "planar", "revolute", "continuous", "revolute", "free"]);
}

#[test]
fn axes_are_normalized() {
    let m = all_joints(false);
    let kind = |name: &str| m.joints[m.joint_id(name).unwrap()].kind.clone();
    match kind("z_slide") {
        JointKind::Prismatic { axis } => assert_vec(&axis, &Vec3::new(0.0, 0.6, 0.8), "z_slide axis"),
        k => panic!("z_slide is {k:?}"),
    }
    match kind("b_arm") {
        JointKind::Revolute { axis, continuous: false } => assert_vec(&axis, &Vec3::z(), "b_arm axis"),
        k => panic!("b_arm is {k:?}"),
    }
    match kind("c_wrist") {
        JointKind::Revolute { axis, continuous: true } => assert_vec(&axis, &Vec3::x(), "c_wrist axis"),
        k => panic!("c_wrist is {k:?}"),
    }
    match kind("y_planar") {
        JointKind::Planar { normal, .. } => assert_vec(&normal, &Vec3::z(), "y_planar normal"),
        k => panic!("y_planar is {k:?}"),
    }
    // A missing <axis> is x.
    // (Moving links carry mass: a massless leaf is refused, see tests/compat.rs.)
    let text = r#"<robot name="r"><link name="a"/><link name="b"><inertial><origin xyz="0 0.1 0.1"/><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
        <joint name="j" type="revolute"><parent link="a"/><child link="b"/>
        <limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>"#;
    let m = load_urdf_str(text, Path::new("inline.urdf"), &LoadOptions::default()).unwrap();
    assert_eq!(m.joints[0].kind, JointKind::Revolute { axis: Vec3::x(), continuous: false });
}

#[test]
fn limits_dynamics_and_mimic_are_stored() {
    let m = all_joints(false);
    let j = |name: &str| &m.joints[m.joint_id(name).unwrap()];
    assert_eq!(j("z_slide").limits, Some([-0.5, 0.5]));
    assert_eq!(j("b_arm").limits, Some([-1.0, 1.25]));
    assert_eq!(j("d_finger").limits, Some([0.0, 0.04]));
    // Continuous joints are unlimited even with a <limit> (effort/velocity only).
    assert_eq!(j("c_wrist").limits, None);
    assert_eq!(j("y_planar").limits, None);
    assert_eq!(j("x_free").limits, None);
    assert_eq!((j("b_arm").damping, j("b_arm").friction), (0.5, 0.2));
    assert_eq!((j("c_wrist").damping, j("c_wrist").friction), (0.05, 0.0));
    assert_eq!((j("z_slide").damping, j("z_slide").friction), (0.0, 0.0));
    // The mimic is an equality constraint (d_finger = 2 · b_arm + 0.1), the only one.
    let (b_arm, d_finger) = (m.joint_id("b_arm").unwrap(), m.joint_id("d_finger").unwrap());
    assert_eq!(m.equalities.len(), 1);
    assert_eq!(m.equalities[0].name, "mimic:d_finger");
    assert_eq!(
        m.equalities[0].kind,
        EqualityKind::Mimic { joint: d_finger, leader: b_arm, multiplier: 2.0, offset: 0.1 }
    );
    assert_eq!(m.dof_damping[j("b_arm").dof_adr], 0.5);
    assert!(m.joints.iter().all(|j| j.armature == 0.0));

    // <mimic> defaults: multiplier 1, offset 0.
    let text = r#"<robot name="r"><link name="a"/><link name="b"><inertial><origin xyz="0 0.1 0.1"/><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link><link name="c"><inertial><origin xyz="0 0.1 0.1"/><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
        <joint name="j1" type="continuous"><parent link="a"/><child link="b"/></joint>
        <joint name="j2" type="continuous"><parent link="a"/><child link="c"/><mimic joint="j1"/></joint>
        </robot>"#;
    let m = load_urdf_str(text, Path::new("inline.urdf"), &LoadOptions::default()).unwrap();
    assert_eq!(
        m.equalities[0].kind,
        EqualityKind::Mimic { joint: 1, leader: 0, multiplier: 1.0, offset: 0.0 }
    );
}

#[test]
fn every_link_is_a_frame() {
    let m = all_joints(false);
    for link in ["base", "slider", "sled", "mount", "arm", "wrist", "tool", "finger", "drone"] {
        assert!(m.frame_id(link).is_some(), "no frame for link {link}");
    }
    assert_eq!(m.frames.len(), 9);
    let frame = |name: &str| &m.frames[m.frame_id(name).unwrap()];
    let a_mount = xyz_rpy([0.5, 0.0, 0.0], [0.0, 0.0, FRAC_PI_2]);
    let e_tool = xyz_rpy([0.05, 0.0, 0.0], [0.0, FRAC_PI_2, 0.0]);
    assert_eq!(frame("mount").body, 0);
    assert_transform(&frame("mount").x_body_frame, &a_mount, "mount frame");
    assert_eq!(frame("tool").body, 4);
    assert_transform(&frame("tool").x_body_frame, &e_tool, "tool frame");
    assert_eq!(frame("arm").body, 3);
    assert_transform(&frame("arm").x_body_frame, &Transform::identity(), "arm frame");
    // A movable joint after a fixed one: its placement is composed through the fused link.
    let b_arm = xyz_rpy([0.1, 0.0, 0.2], [FRAC_PI_2, 0.0, 0.0]);
    assert_transform(&m.bodies[3].x_parent_joint, &(a_mount * b_arm), "arm placement");
    let c_wrist = xyz_rpy([0.0, 0.0, 0.5], [0.1, 0.2, 0.3]);
    assert_transform(&m.bodies[4].x_parent_joint, &c_wrist, "wrist placement");
}

/// Inertia about the common centre of mass of point-massed bodies given by (m, com, I_com).
fn combine(parts: &[(f64, Vec3, Mat3)]) -> (f64, Vec3, Mat3) {
    let mass: f64 = parts.iter().map(|p| p.0).sum();
    let com = parts.iter().map(|p| p.1 * p.0).fold(Vec3::zeros(), |a, b| a + b) / mass;
    let mut i = Mat3::zeros();
    for (m, c, ic) in parts {
        let d = c - com;
        i += ic + (Mat3::identity() * d.dot(&d) - d * d.transpose()) * *m;
    }
    (mass, com, i)
}

#[test]
fn fixed_children_are_fused_into_their_parent_body() {
    // Welded to the world: base (2 kg at (0, 0, 0.1)) and mount (1 kg; its inertial origin
    // (0.2, 0, 0) in a frame turned 90° about z and moved by (0.5, 0, 0): (0.5, 0.2, 0)).
    let m = all_joints(false);
    let world = &m.bodies[0];
    assert_close(world.mass(), 3.0, "world mass");
    assert_vec(&world.com(), &Vec3::new(0.5 / 3.0, 0.2 / 3.0, 0.2 / 3.0), "world com");
    // Mount's diag(1, 2, 3) turned 90° about z twice (inertial rpy, then joint rpy) is diag(1, 2, 3).
    let (_, _, i) = combine(&[
        (2.0, Vec3::new(0.0, 0.0, 0.1), Mat3::identity() * 0.1),
        (1.0, Vec3::new(0.5, 0.2, 0.0), Mat3::from_diagonal(&Vec3::new(1.0, 2.0, 3.0))),
    ]);
    assert_mat(&world.inertia_com(), &i, "world inertia");

    // Wrist (0.3 kg at its origin) + tool (0.2 kg; com (0, 0, 0.1) in a frame pitched 90° and
    // moved by (0.05, 0, 0): (0.15, 0, 0)) → 0.5 kg at (0.06, 0, 0).
    let wrist = &m.bodies[4];
    assert_eq!(wrist.name, "wrist");
    assert_close(wrist.mass(), 0.5, "wrist mass");
    assert_vec(&wrist.com(), &Vec3::new(0.06, 0.0, 0.0), "wrist com");
    // Tool's diag(0.002, 0.002, 0.001) pitched 90° about y: diag(0.001, 0.002, 0.002).
    let (_, _, i) = combine(&[
        (0.3, Vec3::zeros(), Mat3::identity() * 0.001),
        (0.2, Vec3::new(0.15, 0.0, 0.0), Mat3::from_diagonal(&Vec3::new(0.001, 0.002, 0.002))),
    ]);
    assert_mat(&wrist.inertia_com(), &i, "wrist inertia");

    // An inertial with a general rpy: the body's inertia is R I Rᵀ.
    let arm = &m.bodies[3];
    let r = xyz_rpy([0.0; 3], [0.3, -0.2, 0.1]).rot;
    let i_arm = Mat3::new(0.02, 0.001, 0.0, 0.001, 0.02, 0.0, 0.0, 0.0, 0.005);
    assert_mat(&arm.inertia_com(), &(r * i_arm * r.transpose()), "arm inertia");
    assert_vec(&arm.com(), &Vec3::new(0.0, 0.0, 0.25), "arm com");
    // Massless link: no mass.
    assert_eq!(m.bodies[1].mass(), 0.0);
    let total = 2.0 + 1.0 + 1.5 + 0.8 + 0.3 + 0.2 + 0.1 + 0.5;
    // total_mass counts the moving bodies; body 0 carries the links welded to the world.
    assert_close(m.total_mass() + m.bodies[0].mass(), total, "total mass");
}

#[test]
fn floating_adds_a_root_free_joint() {
    let m = all_joints(true);
    assert_eq!((m.nq, m.nv), (21, 19));
    let root = &m.joints[0];
    assert_eq!(root.name, "root_joint");
    assert_eq!(root.kind, JointKind::Free);
    assert_eq!((root.qpos_adr, root.dof_adr, root.parent, root.body), (0, 0, 0, 1));
    assert_eq!(m.bodies[1].name, "base");
    assert_transform(&m.bodies[1].x_parent_joint, &Transform::identity(), "root placement");
    // The welded mount now rides on the floating base.
    assert_close(m.bodies[1].mass(), 3.0, "base mass");
    assert_vec(&m.bodies[1].com(), &Vec3::new(0.5 / 3.0, 0.2 / 3.0, 0.2 / 3.0), "base com");
    let names: Vec<&str> = m.joints.iter().map(|j| j.name.as_str()).collect();
    assert_eq!(names, ["root_joint", "z_slide", "y_planar", "b_arm", "c_wrist", "d_finger", "x_free"]);
    let qpos: Vec<usize> = m.joints.iter().map(|j| j.qpos_adr).collect();
    let dofs: Vec<usize> = m.joints.iter().map(|j| j.dof_adr).collect();
    assert_eq!(qpos, [0, 7, 8, 11, 12, 13, 14]);
    assert_eq!(dofs, [0, 6, 7, 10, 11, 12, 13]);
    assert_eq!(m.neutral()[..7], [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]);
}

#[test]
fn geoms_are_kept_in_file_order_with_origins() {
    let m = all_joints(false);
    let base: Vec<_> = m.geoms.iter().filter(|g| g.link == "base").collect();
    assert_eq!(base.len(), 3);
    assert_eq!(base[0].shape, Shape::Box { size: Vec3::new(0.2, 0.3, 0.1) });
    assert!(!base[0].collision);
    assert_vec(&base[0].x_body_geom.pos, &Vec3::new(0.0, 0.0, 0.05), "box origin");
    assert_eq!(base[1].shape, Shape::Cylinder { radius: 0.05, length: 0.4 });
    assert!(base[1].collision);
    assert_transform(&base[1].x_body_geom, &xyz_rpy([0.0, 0.0, 0.1], [FRAC_PI_2, 0.0, 0.0]), "cylinder");
    match &base[2].shape {
        Shape::Mesh { source, scale } => {
            assert_eq!(source.path(), Some(data("meshes/tetra.stl").as_path()));
            assert_eq!(*scale, Vec3::new(0.1, 0.2, 0.3));
        }
        s => panic!("expected the mesh, got {s:?}"),
    }
    // The tool's sphere moves into the wrist body with the tool's placement.
    let tool: Vec<_> = m.geoms.iter().filter(|g| g.link == "tool").collect();
    assert_eq!(tool.len(), 1);
    assert_eq!(tool[0].shape, Shape::Sphere { radius: 0.02 });
    assert_eq!(tool[0].body, 4);
    let e_tool = xyz_rpy([0.05, 0.0, 0.0], [0.0, FRAC_PI_2, 0.0]);
    assert_transform(&tool[0].x_body_geom, &e_tool, "sphere placement");
    let arm: Vec<_> = m.geoms.iter().filter(|g| g.link == "arm").collect();
    assert_eq!(arm[0].shape, Shape::Capsule { radius: 0.03, length: 0.5 });
}

/// Writes `root/<package>/meshes/part.stl` and a URDF in `root/urdf/` referencing it.
fn package_fixture(root: &Path, package: &str) -> PathBuf {
    let meshes = root.join("pkgs").join(package).join("meshes");
    std::fs::create_dir_all(&meshes).unwrap();
    std::fs::copy(data("meshes/tetra.stl"), meshes.join("part.stl")).unwrap();
    let urdf_dir = root.join("urdf");
    std::fs::create_dir_all(&urdf_dir).unwrap();
    let urdf = urdf_dir.join("robot.urdf");
    let text = format!(
        r#"<robot name="pkg"><link name="a"><visual><geometry>
        <mesh filename="package://{package}/meshes/part.stl"/></geometry></visual></link></robot>"#
    );
    std::fs::write(&urdf, text).unwrap();
    urdf
}

fn mesh_path(m: &Model) -> PathBuf {
    match &m.geoms[0].shape {
        Shape::Mesh { source, scale } => {
            assert_eq!(*scale, Vec3::new(1.0, 1.0, 1.0));
            source.path().expect("a URDF mesh is a file").to_path_buf()
        }
        s => panic!("expected a mesh, got {s:?}"),
    }
}

#[test]
fn package_uris_resolve_through_package_dirs() {
    let root = scratch("pkgdirs");
    let package = "lagrange_test_pkg_dirs";
    let urdf = package_fixture(&root, package);
    let expected = root.join("pkgs").join(package).join("meshes/part.stl");
    // A folder holding the package, after one that does not.
    let options =
        LoadOptions { package_dirs: vec![root.join("nowhere"), root.join("pkgs")], ..Default::default() };
    assert_eq!(mesh_path(&load(&urdf, &options).unwrap()), expected);
    // The package folder itself.
    let options = LoadOptions { package_dirs: vec![root.join("pkgs").join(package)], ..Default::default() };
    assert_eq!(mesh_path(&load(&urdf, &options).unwrap()), expected);
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn package_uris_resolve_through_ros_package_path() {
    let root = scratch("rospath");
    // A package name no other test uses: tests run in parallel and share the environment.
    let package = "lagrange_test_pkg_ros_package_path";
    let urdf = package_fixture(&root, package);
    let ros = format!("{}:{}", root.join("nowhere").display(), root.join("pkgs").display());
    std::env::set_var("ROS_PACKAGE_PATH", ros);
    let result = load(&urdf, &LoadOptions::default());
    std::env::remove_var("ROS_PACKAGE_PATH");
    let m = result.unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(mesh_path(&m), root.join("pkgs").join(package).join("meshes/part.stl"));
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn file_uris_and_absolute_paths_resolve() {
    let root = scratch("fileuri");
    let mesh = root.join("part.stl");
    std::fs::copy(data("meshes/tetra.stl"), &mesh).unwrap();
    for filename in [format!("file://{}", mesh.display()), mesh.display().to_string()] {
        let text = format!(
            r#"<robot name="f"><link name="a"><collision><geometry>
            <mesh filename="{filename}" scale="2 2 2"/></geometry></collision></link></robot>"#
        );
        let m = load_urdf_str(&text, &root.join("elsewhere/f.urdf"), &LoadOptions::default()).unwrap();
        assert_eq!(
            m.geoms[0].shape,
            Shape::Mesh {
                source: lagrange::mass::MeshSource::File(mesh.clone()),
                scale: Vec3::new(2.0, 2.0, 2.0)
            }
        );
        assert!(m.geoms[0].collision);
    }
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn single_link_model() {
    let text = r#"<robot name="one"><link name="only"><inertial><mass value="1"/>
        <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link></robot>"#;
    let m = load_urdf_str(text, Path::new("one.urdf"), &LoadOptions::default()).unwrap();
    assert_eq!((m.nq, m.nv, m.joints.len()), (0, 0, 0));
    assert_eq!(m.frame_id("only"), Some(0));
    let m = load_urdf_str(text, Path::new("one.urdf"), &LoadOptions { floating: true, ..Default::default() })
        .unwrap();
    assert_eq!((m.nq, m.nv), (7, 6));
    assert_close(m.bodies[1].mass(), 1.0, "mass");
}

#[test]
fn a_joint_named_world_joint_does_not_clash_with_the_weld() {
    let text = r#"<robot name="w"><link name="world"/><link name="base"/>
        <joint name="world_joint" type="fixed"><parent link="world"/><child link="base"/></joint></robot>"#;
    let m = load_urdf_str(text, Path::new("w.urdf"), &LoadOptions::default()).unwrap();
    assert_eq!(m.nq, 0);
    assert!(m.frame_id("base").is_some());
}

/// The example-robot-data models in `models/` load with the joint order and sizes recorded in
/// the Pinocchio golden files (which list joints in lagrange's depth-first file order).
#[test]
fn real_models_match_the_recorded_joint_order() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for robot in ["ur5", "panda", "solo12"] {
        let golden = root.join(format!("tests/data/pinocchio/{robot}.json"));
        let golden: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(golden).unwrap()).unwrap();
        let options = LoadOptions { floating: golden["floating"].as_bool().unwrap(), ..Default::default() };
        let model = root.join(golden["model"].as_str().unwrap());
        let m = load(&model, &options).unwrap_or_else(|e| panic!("{robot}: {e}"));
        assert_eq!(m.nq as u64, golden["nq"].as_u64().unwrap(), "{robot} nq");
        assert_eq!(m.nv as u64, golden["nv"].as_u64().unwrap(), "{robot} nv");
        let names: Vec<&str> = m.joints.iter().map(|j| j.name.as_str()).collect();
        let expected: Vec<&str> =
            golden["joint_names"].as_array().unwrap().iter().map(|n| n.as_str().unwrap()).collect();
        assert_eq!(names, expected, "{robot} joint order");
        assert!(m.frame_id(golden["root_link"].as_str().unwrap()).is_some(), "{robot} root frame");
    }
}

/// Truncated and mangled versions of a valid file give errors, never panics.
#[test]
fn never_panics_on_truncated_or_mangled_input() {
    let path = data("all_joints.urdf");
    let text = std::fs::read_to_string(&path).unwrap();
    let options = LoadOptions::default();
    for cut in (0..text.len()).filter(|&i| text.is_char_boundary(i)) {
        let _ = load_urdf_str(&text[..cut], &path, &options);
    }
    let lines: Vec<&str> = text.lines().collect();
    for skip in 0..lines.len() {
        let mangled: Vec<&str> =
            lines.iter().enumerate().filter(|(i, _)| *i != skip).map(|(_, l)| *l).collect();
        let _ = load_urdf_str(&mangled.join("\n"), &path, &options);
    }
    for (from, to) in
        [("\"", "'"), ("0", "-"), ("1", "nan"), ("link", "lnk"), ("type=\"", "type=\"x"), ("> <", "")]
    {
        let mut start = 0;
        while let Some(i) = text[start..].find(from) {
            let at = start + i;
            let mangled = format!("{}{}{}", &text[..at], to, &text[at + from.len()..]);
            let _ = load_urdf_str(&mangled, &path, &options);
            start = at + from.len();
        }
    }
}
