//! The collision layer: contact distance, normal and points for every pair of primitive kinds (and
//! a mesh hull) against closed forms; the candidate-pair filters and parameter combination of
//! MuJoCo's collision detection; and the typed errors of bad collision geometry.

mod common;

use common::COLLISION_ABS;
use lagrange::collision::{collide, CollisionModel, EXACT_REACH};
use lagrange::io::{load, LoadOptions};
use lagrange::kinematics::forward_kinematics;
use lagrange::model::Contact;
use lagrange::spatial::Vec3;
use lagrange::{Data, Model};
use std::path::PathBuf;

/// Loads an MJCF text (written to the temp directory beside a copy of the test meshes' folder
/// path, so `file=` can name `tests/data/meshes/...` absolutely).
fn mjcf(name: &str, body: &str) -> Result<Model, String> {
    let text = format!("<mujoco model=\"{name}\"><compiler angle=\"radian\"/>{body}</mujoco>");
    let path: PathBuf = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("lagrange-collision-{}-{name}.xml", std::process::id()));
    std::fs::write(&path, text).unwrap();
    let model = load(&path, &LoadOptions::default()).map_err(|e| e.to_string());
    let _ = std::fs::remove_file(&path);
    model
}

/// The contacts of a scene at its `qpos0` (MuJoCo's inclusion: dist below the margin).
fn contacts(model: &Model) -> Vec<Contact> {
    let mut data = Data::new(model);
    forward_kinematics(model, &mut data, &model.qpos0).unwrap();
    collide(model, &CollisionModel::new(model), &mut data, 0.0);
    data.contacts.clone()
}

fn close(a: &Vec3, b: &Vec3) -> bool {
    (a - b).amax() <= COLLISION_ABS
}

/// One contact with the given distance, normal (geom 1 → geom 2) and position.
fn assert_contact(c: &Contact, dist: f64, normal: Vec3, pos: Vec3) {
    let n = c.frame.row(0).transpose();
    println!("  dist {:+.15} normal {:?} pos {:?}", c.dist, n.as_slice(), c.pos.as_slice());
    assert!((c.dist - dist).abs() <= COLLISION_ABS, "dist {} vs {dist}", c.dist);
    assert!(close(&n, &normal), "normal {n:?} vs {normal:?}");
    assert!(close(&c.pos, &pos), "pos {:?} vs {pos:?}", c.pos);
    let f = c.frame;
    assert!((f * f.transpose() - nalgebra::Matrix3::identity()).amax() <= 1e-14, "frame not orthonormal");
}

fn free(pos: &str, extra: &str, geom: &str) -> String {
    format!("<body pos=\"{pos}\" {extra}><freejoint/>{geom}</body>")
}

#[test]
fn sphere_against_plane_and_sphere() {
    let m = mjcf(
        "sp",
        &format!(
            "<worldbody><geom type=\"plane\" size=\"1 1 0.1\"/>{}</worldbody>",
            free("0.3 0 0.08", "", "<geom type=\"sphere\" size=\"0.1\"/>")
        ),
    )
    .unwrap();
    let c = contacts(&m);
    assert_eq!(c.len(), 1);
    assert_contact(&c[0], -0.02, Vec3::z(), Vec3::new(0.3, 0.0, -0.01));
    let m = mjcf(
        "ss",
        &format!(
            "<worldbody>{}{}</worldbody>",
            free("0 0 1", "", "<geom type=\"sphere\" size=\"0.1\"/>"),
            free("0.25 0 1", "", "<geom type=\"sphere\" size=\"0.2\"/>")
        ),
    )
    .unwrap();
    let c = contacts(&m);
    assert_contact(&c[0], -0.05, Vec3::x(), Vec3::new(0.075, 0.0, 1.0));
}

#[test]
fn capsule_against_plane_touches_at_both_ends_and_against_a_capsule() {
    // Horizontal along x (fromto), 0.01 into the floor: one contact per end sphere.
    let m = mjcf(
        "cp",
        &format!(
            "<worldbody><geom type=\"plane\" size=\"1 1 0.1\"/>{}</worldbody>",
            free("0 0 0.04", "", "<geom type=\"capsule\" fromto=\"-0.2 0 0 0.2 0 0\" size=\"0.05\"/>")
        ),
    )
    .unwrap();
    let mut c = contacts(&m);
    c.sort_by(|a, b| a.pos.x.total_cmp(&b.pos.x));
    assert_eq!(c.len(), 2);
    assert_contact(&c[0], -0.01, Vec3::z(), Vec3::new(-0.2, 0.0, -0.005));
    assert_contact(&c[1], -0.01, Vec3::z(), Vec3::new(0.2, 0.0, -0.005));
    // Tangent 1 along the capsule's axis (MuJoCo's frame hint).
    assert!(close(&c[0].frame.row(1).transpose().abs(), &Vec3::x()));
    // Two crossed capsules: axes along x at z = 0 and along y at z = 0.15, radii 0.1.
    let m = mjcf(
        "cc",
        &format!(
            "<worldbody>{}{}</worldbody>",
            free("0 0 1", "", "<geom type=\"capsule\" fromto=\"-0.3 0 0 0.3 0 0\" size=\"0.1\"/>"),
            free("0 0 1.15", "", "<geom type=\"capsule\" fromto=\"0 -0.3 0 0 0.3 0\" size=\"0.1\"/>")
        ),
    )
    .unwrap();
    let c = contacts(&m);
    assert_contact(&c[0], -0.05, Vec3::z(), Vec3::new(0.0, 0.0, 1.075));
}

#[test]
fn box_against_plane_touches_at_its_lowest_corners() {
    // Flat, 0.02 deep: the four bottom corners.
    let m = mjcf(
        "bp",
        &format!(
            "<worldbody><geom type=\"plane\" size=\"1 1 0.1\"/>{}</worldbody>",
            free("0 0 0.08", "", "<geom type=\"box\" size=\"0.2 0.1 0.1\"/>")
        ),
    )
    .unwrap();
    let c = contacts(&m);
    assert_eq!(c.len(), 4);
    for k in &c {
        assert!((k.dist + 0.02).abs() <= COLLISION_ABS && (k.pos.x.abs() - 0.2).abs() <= COLLISION_ABS);
    }
    // Tilted by 0.3 rad about y: one corner lowest, at centre height − (a cos θ + c sin θ).
    let (a, cc, t) = (0.2f64, 0.1f64, 0.3f64);
    let z = a * t.sin() + cc * t.cos() - 0.01;
    let m = mjcf(
        "bt",
        &format!(
            "<worldbody><geom type=\"plane\" size=\"1 1 0.1\"/>{}</worldbody>",
            free(&format!("0 0 {z}"), "euler=\"0 0.3 0\"", "<geom type=\"box\" size=\"0.2 0.1 0.1\"/>")
        ),
    )
    .unwrap();
    let c = contacts(&m);
    assert_eq!(c.len(), 2, "the lower edge's two corners");
    for k in &c {
        assert!((k.dist + 0.01).abs() <= COLLISION_ABS, "dist {}", k.dist);
        assert!((k.pos.x - (a * t.cos() - cc * t.sin())).abs() <= COLLISION_ABS, "x {}", k.pos.x);
    }
}

#[test]
fn cylinder_against_plane_on_its_side_and_on_its_cap() {
    let m = mjcf(
        "cyl",
        &format!(
            "<worldbody><geom type=\"plane\" size=\"1 1 0.1\"/>{}</worldbody>",
            free(
                "0 0 0.09",
                "euler=\"1.5707963267948966 0 0\"",
                "<geom type=\"cylinder\" size=\"0.1 0.2\"/>"
            )
        ),
    )
    .unwrap();
    let c = contacts(&m);
    assert_eq!(c.len(), 2, "a line contact: both rim ends");
    for k in &c {
        assert!((k.dist + 0.01).abs() <= COLLISION_ABS && (k.pos.y.abs() - 0.2).abs() <= COLLISION_ABS);
    }
    let m = mjcf(
        "cylup",
        &format!(
            "<worldbody><geom type=\"plane\" size=\"1 1 0.1\"/>{}</worldbody>",
            free("0 0 0.19", "", "<geom type=\"cylinder\" size=\"0.1 0.2\"/>")
        ),
    )
    .unwrap();
    let c = contacts(&m);
    assert_eq!(c.len(), 3, "standing on its cap: a triangle of rim points");
    for k in &c {
        assert!(
            (k.dist + 0.01).abs() <= COLLISION_ABS
                && ((k.pos.x.powi(2) + k.pos.y.powi(2)).sqrt() - 0.1).abs() <= COLLISION_ABS
        );
    }
}

#[test]
fn ellipsoid_against_plane_and_sphere_uses_its_exact_surface() {
    // Radii (0.3, 0.2, 0.1) turned by a about x: lowest point at depth ‖D Rᵀ z‖ below the centre.
    let a = 0.4f64;
    let depth = ((0.2 * a.sin()).powi(2) + (0.1 * a.cos()).powi(2)).sqrt();
    let m = mjcf(
        "ep",
        &format!(
            "<worldbody><geom type=\"plane\" size=\"1 1 0.1\"/>{}</worldbody>",
            free("0 0 0.1", &format!("euler=\"{a} 0 0\""), "<geom type=\"ellipsoid\" size=\"0.3 0.2 0.1\"/>")
        ),
    )
    .unwrap();
    let c = contacts(&m);
    assert_eq!(c.len(), 1);
    assert!((c[0].dist - (0.1 - depth)).abs() <= COLLISION_ABS, "{} vs {}", c[0].dist, 0.1 - depth);
    // A sphere on the ellipsoid's x axis (GJK/EPA on the support maps).
    let m = mjcf(
        "es",
        &format!(
            "<worldbody>{}{}</worldbody>",
            free("0 0 1", "", "<geom type=\"sphere\" size=\"0.1\"/>"),
            free("0.38 0 1", "", "<geom type=\"ellipsoid\" size=\"0.3 0.2 0.1\"/>")
        ),
    )
    .unwrap();
    let c = contacts(&m);
    assert_contact(&c[0], -0.02, Vec3::x(), Vec3::new(0.09, 0.0, 1.0));
}

#[test]
fn sphere_and_box_pairs_in_closed_form() {
    // Sphere (geom 1, lower type) beside a box face: normal from the sphere to the box, −x.
    let m = mjcf(
        "sb",
        &format!(
            "<worldbody>{}{}</worldbody>",
            free("0.35 0 1", "", "<geom type=\"sphere\" size=\"0.1\"/>"),
            free("0 0 1", "", "<geom type=\"box\" size=\"0.3 0.3 0.3\"/>")
        ),
    )
    .unwrap();
    let c = contacts(&m);
    assert_contact(&c[0], -0.05, -Vec3::x(), Vec3::new(0.275, 0.0, 1.0));
    // Two boxes stacked 0.01 into each other.
    let m = mjcf(
        "bb",
        &format!(
            "<worldbody>{}{}</worldbody>",
            free("0 0 1", "", "<geom type=\"box\" size=\"0.2 0.2 0.1\"/>"),
            free("0 0 1.19", "", "<geom type=\"box\" size=\"0.1 0.1 0.1\"/>")
        ),
    )
    .unwrap();
    // MuJoCo's box–box manifold: the small box's four bottom corners, midway between the faces.
    let c = contacts(&m);
    assert_eq!(c.len(), 4);
    for contact in &c {
        assert!(
            (contact.dist + 0.01).abs() <= COLLISION_ABS
                && close(&contact.frame.row(0).transpose(), &Vec3::z())
        );
        let p = contact.pos;
        assert!(
            (p.x.abs() - 0.1).abs() <= COLLISION_ABS && (p.y.abs() - 0.1).abs() <= COLLISION_ABS,
            "{p:?}"
        );
        assert!((p.z - 1.095).abs() <= COLLISION_ABS, "{p:?}");
    }
}

#[test]
fn mesh_collides_by_its_hull() {
    // The unit cube [0, 1]³ of the file, its bottom face 0.01 into the floor.
    let cube = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/meshes/cube.obj");
    let m = mjcf("mesh", &format!(
        "<asset><mesh name=\"cube\" file=\"{}\"/></asset><worldbody><geom type=\"plane\" size=\"1 1 0.1\"/>{}</worldbody>",
        cube.display(),
        free("0 0 -0.01", "", "<geom type=\"mesh\" mesh=\"cube\"/>"))).unwrap();
    let hull = m.geoms[1].hull().expect("a colliding mesh has a hull");
    let lowest = hull.iter().map(|v| v.z).fold(f64::INFINITY, f64::min);
    let c = contacts(&m);
    println!("cube hull: {} vertices, lowest z {lowest}; {} contacts", hull.len(), c.len());
    assert_eq!(c.len(), 4, "a face on the floor: four spread vertices");
    for k in &c {
        assert!((k.dist - (-0.01 + lowest)).abs() <= COLLISION_ABS, "dist {}", k.dist);
    }
}

#[test]
fn candidate_pairs_follow_mujocos_filters() {
    let scene = |contact: &str, extra: &str| {
        mjcf("filters", &format!(
            "<option><flag {contact}/></option><worldbody><geom name=\"floor\" type=\"plane\" size=\"1 1 0.1\"/>
             <body name=\"a\" pos=\"0 0 1\"><freejoint/><geom name=\"ga\" size=\"0.1\"/>
               <body name=\"b\" pos=\"0 0 0.1\"><joint type=\"hinge\"/><geom name=\"gb\" size=\"0.1\"/>
                 <body name=\"c\" pos=\"0 0 0.1\"><joint type=\"hinge\"/><geom name=\"gc\" size=\"0.1\" contype=\"2\" conaffinity=\"2\"/></body></body></body>
             <body name=\"d\" pos=\"1 0 1\"><freejoint/><geom name=\"gd\" size=\"0.1\" priority=\"1\" friction=\"0.3 0.01 0.002\" condim=\"4\"/></body>
             </worldbody>{extra}"))
        .unwrap()
    };
    let names = |m: &Model| -> Vec<String> {
        m.collision_pairs
            .iter()
            .map(|p| format!("{}-{}", m.geoms[p.geom[0]].name, m.geoms[p.geom[1]].name))
            .collect()
    };
    let m = scene("", "");
    let pairs = names(&m);
    println!("pairs: {pairs:?}");
    // Parent–child (a–b, b–c) filtered; c has bits 2: only pairs with bit-2 partners (none).
    assert_eq!(pairs, ["floor-ga", "floor-gb", "floor-gd", "ga-gd", "gb-gd"]);
    // Priority: d's parameters win over the floor's; friction 5-vector unpacked.
    let fd = m.collision_pairs.iter().find(|p| m.geoms[p.geom[1]].name == "gd" && p.geom[0] == 0).unwrap();
    assert_eq!((fd.condim, fd.friction), (4, [0.3, 0.3, 0.01, 0.002, 0.002]));
    // <exclude> and an explicit <pair> with its own parameters (a–c would be filtered otherwise).
    let m = scene(
        "",
        "<contact><exclude body1=\"a\" body2=\"d\"/><pair geom1=\"ga\" geom2=\"gc\" condim=\"1\"/></contact>",
    );
    let pairs = names(&m);
    println!("with exclude and pair: {pairs:?}");
    assert!(pairs.contains(&"ga-gc".to_string()) && !pairs.contains(&"ga-gd".to_string()));
    assert_eq!(m.collision_pairs.iter().find(|p| p.pair.is_some()).unwrap().condim, 1);
    // Contacts switched off: no pairs at all.
    assert!(scene("contact=\"disable\"", "").collision_pairs.is_empty());
    // Solmix mixing at equal priority, MuJoCo's mj_contactParam.
    let m = mjcf("mix", "<worldbody><body><freejoint/><geom size=\"0.1\" solmix=\"3\" solref=\"0.04 1\"/></body>
        <body pos=\"1 0 0\"><freejoint/><geom size=\"0.1\" solmix=\"1\" solref=\"0.02 2\"/></body></worldbody>").unwrap();
    let p = &m.collision_pairs[0];
    assert!((p.solref[0] - 0.035).abs() < 1e-15 && (p.solref[1] - 1.25).abs() < 1e-15, "{:?}", p.solref);
}

#[test]
fn urdf_collision_geoms_pair_all_but_parent_and_child() {
    // base — l1 — l2 in a chain and l3 on the base: every pair of collision geoms on different
    // bodies except parent and child (l1–l2) and MuJoCo's exception: the world (here the base,
    // welded to it) collides with its children.
    let link = |name: &str| {
        format!(
        "<link name=\"{name}\"><inertial><mass value=\"1\"/><inertia ixx=\"0.01\" ixy=\"0\" ixz=\"0\" iyy=\"0.01\" iyz=\"0\" izz=\"0.01\"/></inertial>\
         <collision><geometry><box size=\"0.1 0.1 0.1\"/></geometry></collision><visual><geometry><sphere radius=\"0.1\"/></geometry></visual></link>")
    };
    let joint = |name: &str, parent: &str, child: &str| {
        format!(
        "<joint name=\"{name}\" type=\"revolute\"><parent link=\"{parent}\"/><child link=\"{child}\"/><axis xyz=\"0 0 1\"/>\
         <limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1\"/></joint>")
    };
    let urdf = format!(
        "<robot name=\"r\">{}{}{}{}{}{}{}</robot>",
        link("base"),
        link("l1"),
        link("l2"),
        link("l3"),
        joint("j1", "base", "l1"),
        joint("j2", "l1", "l2"),
        joint("j3", "base", "l3")
    );
    let model =
        lagrange::io::load_urdf_str(&urdf, std::path::Path::new("r.urdf"), &LoadOptions::default()).unwrap();
    let pairs: Vec<(String, String)> = model
        .collision_pairs
        .iter()
        .map(|p| (model.geoms[p.geom[0]].link.clone(), model.geoms[p.geom[1]].link.clone()))
        .collect();
    println!("URDF pairs: {pairs:?}");
    let has = |a: &str, b: &str| pairs.iter().any(|(x, y)| (x == a && y == b) || (x == b && y == a));
    assert!(
        has("base", "l1") && has("base", "l2") && has("base", "l3") && has("l1", "l3") && has("l2", "l3")
    );
    assert!(!has("l1", "l2"));
    assert_eq!(pairs.len(), 5, "visual geoms never collide");
}

#[test]
fn exact_mode_detects_a_little_beyond_the_margin() {
    // A sphere 1e-4 above the floor: no contact by MuJoCo's rule, one within the exact reach.
    let m = mjcf(
        "reach",
        &format!(
            "<worldbody><geom type=\"plane\" size=\"1 1 0.1\"/>{}</worldbody>",
            free("0 0 0.1001", "", "<geom type=\"sphere\" size=\"0.1\"/>")
        ),
    )
    .unwrap();
    assert!(contacts(&m).is_empty());
    let mut data = Data::new(&m);
    forward_kinematics(&m, &mut data, &m.qpos0).unwrap();
    collide(&m, &CollisionModel::new(&m), &mut data, EXACT_REACH);
    assert_eq!(data.contacts.len(), 1);
    assert!((data.contacts[0].dist - 1e-4).abs() <= COLLISION_ABS);
}

#[test]
fn bad_collision_geometry_is_a_typed_error() {
    let flat = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/meshes/flat_square.obj");
    let err = mjcf("flat", &format!(
        "<asset><mesh name=\"flat\" file=\"{}\"/></asset><worldbody><body><freejoint/><inertial pos=\"0 0 0\" mass=\"1\" diaginertia=\"0.1 0.1 0.1\"/><geom type=\"mesh\" mesh=\"flat\"/></body></worldbody>",
        flat.display())).unwrap_err();
    println!("{err}");
    assert!(err.contains(".xml:1") || err.contains(".xml"), "{err}");
    assert!(
        err.contains("flat_square.obj") && (err.contains("convex hull") || err.contains("plane")),
        "{err}"
    );
    let err = mjcf(
        "zero",
        "<worldbody><body><freejoint/><geom type=\"box\" size=\"0.1 0 0.1\"/></body></worldbody>",
    )
    .unwrap_err();
    println!("{err}");
    assert!(err.contains("size") && err.contains("positive"), "{err}");
    let err =
        mjcf("kind", "<worldbody><body><freejoint/><geom type=\"blob\" size=\"0.1\"/></body></worldbody>")
            .unwrap_err();
    println!("{err}");
    assert!(err.contains("type") && err.contains("blob"), "{err}");
    let err =
        mjcf("condim", "<worldbody><body><freejoint/><geom size=\"0.1\" condim=\"2\"/></body></worldbody>")
            .unwrap_err();
    println!("{err}");
    assert!(err.contains("condim") && err.contains("1, 3, 4 or 6"), "{err}");
}

/// `<exclude>` names file bodies: a jointless body fused into its parent (one compiled body)
/// keeps its own identity, so excluding the parent against a third body leaves the fused child's
/// geoms colliding with it — as in MuJoCo 4.0, which gives the palm–finger box pair 4 contacts
/// here (found on Menagerie's Aero hand, whose palm hangs jointless under its mount).
#[test]
fn excluding_a_parent_does_not_exclude_its_fused_child() {
    let model = mjcf(
        "exclude_fused",
        r#"<worldbody>
             <body name="mount"><geom name="mount_box" type="box" size="0.1 0.1 0.02" pos="0 0 -0.5"/>
               <body name="palm"><geom name="palm_box" type="box" size="0.1 0.1 0.02"/></body>
             </body>
             <body name="finger" pos="0 0 0.03"><freejoint/><geom name="finger_box" type="box" size="0.02 0.02 0.02"/></body>
           </worldbody>
           <contact><exclude body1="mount" body2="finger"/></contact>"#,
    )
    .unwrap();
    let found = contacts(&model);
    assert_eq!(found.len(), 4, "{found:?}");
    let names: Vec<&str> = found[0].geom.iter().map(|&g| model.geoms[g].name.as_str()).collect();
    assert_eq!(names, ["palm_box", "finger_box"]);
    // The excluded pair itself stays out: mount against finger (moved down onto the mount's box).
    let model = mjcf(
        "exclude_fused_mount",
        r#"<worldbody>
             <body name="mount"><geom name="mount_box" type="box" size="0.1 0.1 0.02"/>
               <body name="palm"><geom name="palm_box" type="box" size="0.1 0.1 0.02" pos="0 0 0.5"/></body>
             </body>
             <body name="finger" pos="0 0 0.03"><freejoint/><geom name="finger_box" type="box" size="0.02 0.02 0.02"/></body>
           </worldbody>
           <contact><exclude body1="mount" body2="finger"/></contact>"#,
    )
    .unwrap();
    assert!(contacts(&model).is_empty());
}

/// A capsule standing upright on a floor: its tangent hint (the axis) is along the normal, and
/// the frame is MuJoCo 4.0's (normal z, tangents x and y; its mju_normalize3 makes the vanished
/// tangent x), with finite constraint rows and accelerations in both modes (the frame was NaN).
#[test]
fn an_upright_capsule_on_a_floor_has_mujocos_frame() {
    let model = mjcf(
        "upright_capsule",
        r#"<worldbody><geom type="plane" size="0 0 1"/>
           <body pos="0.5 0 0.3"><joint type="hinge" axis="0 1 0"/>
             <geom type="capsule" fromto="0 0 0 0 0 -0.31" size="0.02"/></body></worldbody>"#,
    )
    .unwrap();
    let c = contacts(&model);
    assert_eq!(c.len(), 1);
    assert_eq!(c[0].frame.row(1).transpose(), Vec3::x());
    assert_eq!(c[0].frame.row(2).transpose(), Vec3::y());
    for mode in [lagrange::constraint::ConstraintMode::Soft, lagrange::constraint::ConstraintMode::Exact] {
        let mut model = model.clone();
        model.set_constraint_mode(mode);
        let mut data = Data::new(&model);
        lagrange::forward::forward(&model, &mut data);
        assert!(data.efc_j.rows(0, data.nefc).iter().all(|x| x.is_finite()), "{mode:?}");
        assert!(data.qacc.iter().all(|x| x.is_finite()), "{mode:?}");
    }
}
