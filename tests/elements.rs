//! Equality constraints, tendons, actuators, contact pairs and exclusions load into the model's
//! typed sections with resolved indices and MuJoCo's values. `tests/data/elements/elements.xml`
//! holds one of each kind; the expected numbers are MuJoCo 4.0.0's (`MjModel.eq_data`,
//! `actuator_gainprm`, `pair_friction`, ..., printed with `mujoco.MjModel.from_xml_path`). A URDF
//! mimic chain becomes mimic equalities. The error cases without a file of their own in
//! `tests/data/mjcf/errors/` are written inline here.

use lagrange::io::{compile, load, mjcf, LoadOptions};
use lagrange::model::actuator::{ActuatorShortcut, BiasType, DynType, GainType, Transmission};
use lagrange::model::equality::{DEFAULT_SOLIMP, DEFAULT_SOLREF};
use lagrange::model::{EqualityKind, FrameKind, Model, PathElement, TendonKind};
use lagrange::spatial::{Mat3, Vec3};
use std::path::{Path, PathBuf};

fn elements_model() -> Model {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/elements/elements.xml");
    load(&path, &LoadOptions::default()).expect("elements.xml loads")
}

fn frame(m: &Model, name: &str, kind: FrameKind) -> usize {
    m.frames
        .iter()
        .position(|f| f.name == name && f.kind == kind)
        .unwrap_or_else(|| panic!("no frame {name}"))
}

fn joint(m: &Model, name: &str) -> usize {
    m.joint_id(name).unwrap_or_else(|| panic!("no joint {name}"))
}

fn geom(m: &Model, name: &str) -> usize {
    m.geoms.iter().position(|g| g.name == name).unwrap_or_else(|| panic!("no geom {name}"))
}

/// The first `N` entries of a parameter vector.
fn head<const N: usize>(v: &[f64]) -> [f64; N] {
    v[..N].try_into().unwrap()
}

#[test]
fn equality_constraints_resolve_to_frames_joints_and_tendons() {
    let m = elements_model();
    let body = |n: &str| frame(&m, n, FrameKind::Link);
    let site = |n: &str| frame(&m, n, FrameKind::Site);
    let world = body("world");
    assert_eq!(m.frames[world].body, 0);
    let names: Vec<&str> = m.equalities.iter().map(|e| e.name.as_str()).collect();
    assert_eq!(names, ["c_body", "c_site", "w_qpos0", "w_pose", "w_site", "j_poly", "j_lock", "t_eq"]);
    let kind = |i: usize| &m.equalities[i].kind;
    // connect: body form (body2 absent = world) and site form.
    assert_eq!(
        *kind(0),
        EqualityKind::Connect { frame1: body("c"), frame2: world, anchor: Some([0.0, 0.0, -0.1]) }
    );
    assert_eq!(*kind(1), EqualityKind::Connect { frame1: site("sa"), frame2: site("sb"), anchor: None });
    // weld: relpose absent (MuJoCo's all-zero quaternion) = taken at qpos0 ...
    assert_eq!(
        *kind(2),
        EqualityKind::Weld {
            frame1: body("b"),
            frame2: body("a"),
            anchor: [0.0; 3],
            relpose: None,
            torquescale: 1.0,
            sites: false
        }
    );
    // ... or given (its quaternion normalized, as MuJoCo's eq_data shows: 1 2 3 | 1 0 0 0).
    match kind(3) {
        EqualityKind::Weld { frame1, frame2, anchor, relpose: Some(x), torquescale, sites: false } => {
            assert_eq!((*frame1, *frame2, *anchor, *torquescale), (body("c"), world, [0.1, 0.0, 0.0], 0.5));
            assert_eq!(x.pos, Vec3::new(1.0, 2.0, 3.0));
            assert!((x.rot - Mat3::identity()).abs().max() < 1e-15);
        }
        k => panic!("w_pose is {k:?}"),
    }
    assert_eq!(
        *kind(4),
        EqualityKind::Weld {
            frame1: site("sb"),
            frame2: site("sc"),
            anchor: [0.0; 3],
            relpose: None,
            torquescale: 0.0,
            sites: true
        }
    );
    // polycoef: fewer than 5 values keep MuJoCo's defaults (0 1 0 0 0) for the rest.
    let (hinge, slide) = (joint(&m, "hinge"), joint(&m, "slide"));
    assert_eq!(
        *kind(5),
        EqualityKind::Joint { joint1: hinge, joint2: Some(slide), polycoef: [0.1, 2.0, 0.0, 0.0, 0.0] }
    );
    assert_eq!(
        *kind(6),
        EqualityKind::Joint { joint1: slide, joint2: None, polycoef: [0.0, 1.0, 0.0, 0.0, 0.0] }
    );
    assert_eq!(
        *kind(7),
        EqualityKind::Tendon { tendon1: 0, tendon2: Some(1), polycoef: [1.0, 2.0, 3.0, 0.0, 0.0] }
    );
    // <default><equality solref="0.05 1"/> applies to all; active and solimp per element.
    assert!(m.equalities.iter().all(|e| e.solref == [0.05, 1.0]));
    assert_eq!(
        m.equalities.iter().map(|e| e.active).collect::<Vec<_>>(),
        [true, false, true, true, true, true, true, true]
    );
    assert_eq!(m.equalities[2].solimp, [0.8, 0.9, 0.001, 0.5, 2.0]);
    assert_eq!(m.equalities[0].solimp, DEFAULT_SOLIMP);
    assert!(m.equalities[0].loc.to_string().ends_with("elements.xml:47"), "{}", m.equalities[0].loc);
}

#[test]
fn tendons_keep_mujoco_order_and_limits() {
    let m = elements_model();
    let names: Vec<&str> = m.tendons.iter().map(|t| t.name.as_str()).collect();
    assert_eq!(names, ["t1", "t2", "rope"]);
    let (hinge, slide) = (joint(&m, "hinge"), joint(&m, "slide"));
    assert_eq!(m.tendons[0].kind, TendonKind::Fixed { joints: vec![(hinge, 2.0), (slide, -1.0)] });
    assert_eq!(m.tendons[0].range, Some([-0.5, 0.5]), "range with autolimits: limited");
    assert_eq!(m.tendons[1].range, None);
    let (sa, sc) = (frame(&m, "sa", FrameKind::Site), frame(&m, "sc", FrameKind::Site));
    assert_eq!(
        m.tendons[2].kind,
        TendonKind::Spatial {
            path: vec!["sa".into(), "sc".into()],
            wraps: vec![PathElement::Site(sa), PathElement::Site(sc)]
        }
    );
}

/// One actuator's expected values (MuJoCo 4.0.0).
struct Expected {
    name: &'static str,
    shortcut: ActuatorShortcut,
    types: (DynType, GainType, BiasType),
    dynprm: [f64; 3],
    gainprm: [f64; 9],
    biasprm: [f64; 3],
    gear: [f64; 6],
    ctrlrange: Option<[f64; 2]>,
    forcerange: Option<[f64; 2]>,
    actrange: Option<[f64; 2]>,
}

#[test]
fn actuator_shortcuts_expand_as_mujoco_does() {
    use ActuatorShortcut as S;
    use BiasType as B;
    use DynType as D;
    use GainType as G;
    let m = elements_model();
    let g1 = |x: f64| [x, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    let gear1 = [1.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    let e = |name, shortcut, types, dynprm, gainprm, biasprm| Expected {
        name,
        shortcut,
        types,
        dynprm,
        gainprm,
        biasprm,
        gear: gear1,
        ctrlrange: None,
        forcerange: None,
        actrange: None,
    };
    let servo = (D::None, G::Fixed, B::Affine);
    let plain = (D::None, G::Fixed, B::None);
    let expected = [
        Expected {
            gear: [3.0, 0.0, 0.0, 0.0, 0.0, 0.0],
            ctrlrange: Some([-1.0, 1.0]),
            ..e("m", S::Motor, plain, [1.0, 0.0, 0.0], g1(1.0), [0.0; 3])
        },
        // dampratio 0.7 is stored as MuJoCo stores it before mj_setConst: biasprm[2] = +0.7
        // (MuJoCo's compiled model shows the resolved −3.3561865969).
        e(
            "p",
            S::Position,
            (D::FilterExact, G::Fixed, B::Affine),
            [0.1, 0.0, 0.0],
            g1(10.0),
            [0.0, -10.0, 0.7],
        ),
        // A <position> default class: the position servo inherits kp and kv; a <general> of the
        // class starts from the same parameters; a <motor> of the class only keeps the ranges.
        Expected {
            ctrlrange: Some([-1.0, 1.0]),
            forcerange: Some([-20.0, 20.0]),
            ..e("p_class", S::Position, servo, [1.0, 0.0, 0.0], g1(50.0), [0.0, -50.0, -5.0])
        },
        Expected {
            ctrlrange: Some([-1.0, 1.0]),
            forcerange: Some([-20.0, 20.0]),
            ..e("g_class", S::General, servo, [1.0, 0.0, 0.0], g1(50.0), [0.0, -50.0, -5.0])
        },
        // A <general> default with a fixed gain: a position servo takes kp = gainprm[0] and keeps
        // biasprm[2].
        Expected {
            gear: [2.0, 0.0, 0.0, 0.0, 0.0, 0.0],
            ..e("p_raw", S::Position, servo, [1.0, 0.0, 0.0], g1(7.0), [0.0, -7.0, -1.0])
        },
        Expected {
            ctrlrange: Some([-1.0, 1.0]),
            forcerange: Some([-20.0, 20.0]),
            ..e("m_class", S::Motor, plain, [1.0, 0.0, 0.0], g1(1.0), [0.0; 3])
        },
        e("v", S::Velocity, servo, [1.0, 0.0, 0.0], g1(3.0), [0.0, 0.0, -3.0]),
        Expected {
            actrange: Some([-1.0, 1.0]),
            ..e(
                "iv",
                S::IntVelocity,
                (D::Integrator, G::Fixed, B::Affine),
                [1.0, 0.0, 0.0],
                g1(4.0),
                [0.0, -4.0, 0.0],
            )
        },
        Expected {
            ctrlrange: Some([0.0, 1.0]),
            ..e(
                "d",
                S::Damper,
                (D::None, G::Affine, B::None),
                [1.0, 0.0, 0.0],
                [0.0, 0.0, -2.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
                [0.0; 3],
            )
        },
        e(
            "cyl",
            S::Cylinder,
            (D::Filter, G::Fixed, B::Affine),
            [1.0, 0.0, 0.0],
            g1(std::f64::consts::PI / 4.0 * 0.01),
            [1.0, 2.0, 3.0],
        ),
        e(
            "mus",
            S::Muscle,
            (D::Muscle, G::Muscle, B::Muscle),
            [0.01, 0.04, 0.0],
            [0.8, 1.2, 100.0, 200.0, 0.5, 1.6, 1.5, 1.3, 1.2],
            [0.8, 1.2, 100.0],
        ),
        Expected {
            ctrlrange: Some([0.0, 1.0]),
            ..e("ad", S::Adhesion, plain, [1.0, 0.0, 0.0], g1(5.0), [0.0; 3])
        },
        Expected {
            gear: [1.0, 2.0, 3.0, 4.0, 5.0, 6.0],
            forcerange: Some([-3.0, 3.0]),
            ..e(
                "g",
                S::General,
                (D::Filter, G::Affine, B::Affine),
                [0.3, 0.0, 0.0],
                [1.0, 2.0, 3.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
                [4.0, 5.0, 6.0],
            )
        },
        e("crank", S::General, plain, [1.0, 0.0, 0.0], g1(1.0), [0.0; 3]),
        Expected {
            gear: [0.0, 0.0, 1.0, 0.0, 0.0, 0.0],
            ..e("jip", S::Motor, plain, [1.0, 0.0, 0.0], g1(1.0), [0.0; 3])
        },
        // inheritrange 0.5 of the hinge's range [-1, 2]: the middle half.
        Expected {
            ctrlrange: Some([-0.25, 1.25]),
            ..e("inherit", S::Position, servo, [1.0, 0.0, 0.0], g1(1.0), [0.0, -1.0, 0.0])
        },
    ];
    assert_eq!(m.actuators.len(), expected.len());
    for (a, x) in m.actuators.iter().zip(&expected) {
        assert_eq!(a.name, x.name);
        let n = x.name;
        assert_eq!(a.shortcut, x.shortcut, "{n}");
        assert_eq!((a.dyntype, a.gaintype, a.biastype), x.types, "{n}");
        assert_eq!(head::<3>(&a.dynprm), x.dynprm, "{n} dynprm");
        assert!(
            a.gainprm.iter().zip(x.gainprm).all(|(g, e)| (g - e).abs() <= 1e-15 * e.abs()),
            "{n} gainprm {:?}",
            a.gainprm
        );
        assert_eq!(head::<3>(&a.biasprm), x.biasprm, "{n} biasprm");
        assert_eq!(a.gear, x.gear, "{n} gear");
        assert_eq!(
            (a.ctrlrange, a.forcerange, a.actrange),
            (x.ctrlrange, x.forcerange, x.actrange),
            "{n} ranges"
        );
        assert_eq!(a.actearly, n == "g", "{n} actearly");
    }
    let site = |s: &str| frame(&m, s, FrameKind::Site);
    let by_name = |n: &str| m.actuators.iter().find(|a| a.name == n).unwrap();
    assert_eq!(by_name("m").transmission, Transmission::Joint(joint(&m, "hinge")));
    assert_eq!(by_name("v").transmission, Transmission::Tendon(0));
    assert_eq!(by_name("mus").transmission, Transmission::Tendon(1));
    assert_eq!(
        by_name("ad").transmission,
        Transmission::Body(m.frames[frame(&m, "c", FrameKind::Link)].body)
    );
    assert_eq!(by_name("g").transmission, Transmission::Site { site: site("sc"), refsite: Some(site("sa")) });
    assert_eq!(
        by_name("crank").transmission,
        Transmission::SliderCrank { cranksite: site("sa"), slidersite: site("sb"), cranklength: 0.2 }
    );
    assert_eq!(by_name("jip").transmission, Transmission::JointInParent(joint(&m, "ball")));
    assert_eq!(
        m.actuators.iter().map(|a| a.actnum()).sum::<usize>(),
        5,
        "p, iv, cyl, mus, g have an activation"
    );
}

#[test]
fn contact_pairs_and_exclusions_in_mujoco_order() {
    let m = elements_model();
    // MuJoCo sorts pairs by body pair, the lower body first: p0 (world, c) before p1 (a, b),
    // and p1's geoms swapped to (ga, gb).
    let names: Vec<&str> = m.contact_pairs.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names, ["p0", "p1"]);
    let (p0, p1) = (&m.contact_pairs[0], &m.contact_pairs[1]);
    assert_eq!((p0.geom1, p0.geom2), (geom(&m, "floor"), geom(&m, "gc")));
    assert_eq!((p1.geom1, p1.geom2), (geom(&m, "ga"), geom(&m, "gb")));
    assert_eq!((p0.condim, p1.condim), (3, 4));
    assert_eq!(p0.friction, [1.0, 2.0, 3.0, 4.0, 5.0]);
    // <default><pair friction="0.7"/>: one value, the rest MuJoCo's defaults.
    assert_eq!(p1.friction, [0.7, 1.0, 0.005, 0.0001, 0.0001]);
    assert_eq!((p0.solreffriction, p1.solreffriction), ([-100.0, -10.0], [0.0, 0.0]));
    assert_eq!((p0.solref, p0.solimp), (DEFAULT_SOLREF, DEFAULT_SOLIMP));
    assert_eq!((p0.margin, p1.margin, p0.gap), (0.0, 0.01, 0.0));
    // exclude body1="c" body2="a": the compiled bodies, lower MuJoCo body first.
    let body_of = |n: &str| m.frames[frame(&m, n, FrameKind::Link)].body;
    assert_eq!(m.contact_excludes.len(), 1);
    assert_eq!((m.contact_excludes[0].body1, m.contact_excludes[0].body2), (body_of("a"), body_of("c")));
}

#[test]
fn urdf_mimic_chain_becomes_mimic_equalities() {
    let text = r#"<robot name="chain">
  <link name="l0"/>
  <link name="l1"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <link name="l2"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <link name="l3"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <joint name="a" type="revolute"><parent link="l0"/><child link="l1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="b" type="continuous"><parent link="l1"/><child link="l2"/>
    <mimic joint="a" multiplier="2" offset="0.1"/>
  </joint>
  <joint name="c" type="prismatic"><parent link="l2"/><child link="l3"/><limit lower="-1" upper="1" effort="1" velocity="1"/>
    <mimic joint="b" multiplier="-1"/>
  </joint>
</robot>
"#;
    let m = lagrange::io::load_urdf_str(text, Path::new("chain.urdf"), &LoadOptions::default()).unwrap();
    let (a, b, c) = (joint(&m, "a"), joint(&m, "b"), joint(&m, "c"));
    assert_eq!(m.equalities.len(), 2);
    assert_eq!(m.equalities[0].name, "mimic:b");
    assert_eq!(
        m.equalities[0].kind,
        EqualityKind::Mimic { joint: b, leader: a, multiplier: 2.0, offset: 0.1 }
    );
    assert_eq!(m.equalities[0].loc.to_string(), "chain.urdf:8", "the <mimic> element");
    assert_eq!(m.equalities[1].name, "mimic:c");
    assert_eq!(
        m.equalities[1].kind,
        EqualityKind::Mimic { joint: c, leader: b, multiplier: -1.0, offset: 0.0 }
    );
    assert!(m.equalities.iter().all(|e| e.active && e.solref == DEFAULT_SOLREF));
    assert!(m.warnings.is_empty(), "{:?}", m.warnings);
}

/// Compiles MJCF `text` (named `inline.xml`): the model, or the error message.
fn compile_mjcf(text: &str) -> Result<Model, String> {
    let spec =
        mjcf::parse_str(text, Path::new("inline.xml"), &LoadOptions::default()).map_err(|e| e.to_string())?;
    compile(&spec).map_err(|e| e.to_string())
}

/// A two-body model (joints hinge, slide, ball; sites sa, sb; fixed tendon t and spatial tendon
/// rope) with `sections` after the worldbody, and `compiler` attributes.
fn model_with(compiler: &str, sections: &str) -> String {
    format!(
        r#"<mujoco>
  <compiler {compiler}/>
  <worldbody>
    <body name="a">
      <joint name="hinge"/>
      <geom name="ga" size="0.1"/>
      <site name="sa"/>
      <body name="b">
        <joint name="slide" type="slide"/>
        <joint name="ball" type="ball"/>
        <geom size="0.1"/>
        <site name="sb" pos="0 0 -1"/>
      </body>
    </body>
  </worldbody>
  <tendon>
    <fixed name="t"><joint joint="hinge" coef="1"/></fixed>
    <spatial name="rope"><site site="sa"/><site site="sb"/></spatial>
  </tendon>
{sections}
</mujoco>
"#
    )
}

/// The error of `sections` in [`model_with`]; asserts it names the line of the element.
fn error_of(sections: &str) -> String {
    let text = model_with("", sections);
    let e = compile_mjcf(&text).err().unwrap_or_else(|| panic!("expected an error for {sections}"));
    // The element is the second line of `sections` (between the section's tags).
    let element = sections.lines().nth(1).unwrap().trim();
    let line = text.lines().position(|l| l.trim() == element).unwrap() + 1;
    assert!(e.contains(&format!("inline.xml:{line}:")), "line {line} not in: {e}");
    e
}

fn assert_mentions(message: &str, parts: &[&str]) {
    for p in parts {
        assert!(message.contains(p), "message lacks {p:?}:\n{message}");
    }
}

#[test]
fn equality_errors_name_the_object_and_the_fix() {
    let eq = |body: &str| format!("  <equality>\n    {body}\n  </equality>");
    assert_mentions(
        &error_of(&eq(r#"<connect site1="sa" site2="nope"/>"#)),
        &["<connect>", "unknown site 'nope'"],
    );
    assert_mentions(&error_of(&eq(r#"<joint joint1="nope"/>"#)), &["<joint>", "unknown joint 'nope'"]);
    assert_mentions(&error_of(&eq(r#"<tendon tendon1="nope"/>"#)), &["<tendon>", "unknown tendon 'nope'"]);
    assert_mentions(
        &error_of(&eq(r#"<joint joint1="ball"/>"#)),
        &["joint 'ball' is a ball joint", "hinge and slide"],
    );
    assert_mentions(
        &error_of(&eq(r#"<joint joint1="hinge" joint2="hinge"/>"#)),
        &["joint 'hinge' is constrained to itself"],
    );
    assert_mentions(
        &error_of(&eq(r#"<connect site1="sa" site2="sa"/>"#)),
        &["site 'sa' is constrained to itself"],
    );
    assert_mentions(
        &error_of(&eq(r#"<tendon tendon1="t" tendon2="t"/>"#)),
        &["tendon 't' is constrained to itself"],
    );
    // Without body2 the other body is the world: constraining the world to itself.
    assert_mentions(
        &error_of(&eq(r#"<weld body1="world"/>"#)),
        &["body 'world' is constrained to itself", "world"],
    );
    assert_mentions(&error_of(&eq(r#"<connect body1="a"/>"#)), &["'anchor' is missing", "site1 and site2"]);
    assert_mentions(&error_of(&eq(r#"<connect site1="sa"/>"#)), &["'site2' is missing"]);
    assert_mentions(&error_of(&eq(r#"<joint joint2="hinge"/>"#)), &["'joint1' is missing"]);
}

#[test]
fn equality_on_a_spatial_tendon_is_listed_with_a_warning() {
    let m = compile_mjcf(&model_with("", "  <equality><tendon name=\"e\" tendon1=\"rope\"/></equality>"))
        .unwrap();
    assert!(m.equalities.is_empty());
    assert!(m.elements.iter().any(|e| e.category == "equality" && e.name == "e"));
    assert!(m.warnings.iter().any(|w| w.contains("spatial tendon") && w.contains("'e'")), "{:?}", m.warnings);
}

/// Tendon stiffness, damping, frictionloss and armature are not simulated: a nonzero value is a
/// warning naming file, line, tendon and attribute (never silently dropped); zeros say nothing.
#[test]
fn unsimulated_tendon_terms_are_warnings() {
    // stiffness, damping and frictionloss are simulated (read into the tendon); armature is said.
    let m = compile_mjcf(&model_with(
        "",
        r#"  <tendon><fixed name="u" stiffness="10" damping="0" frictionloss="0.5 " armature="0.1"><joint joint="hinge" coef="1"/></fixed></tendon>"#,
    ))
    .unwrap();
    let about_u: Vec<&String> = m.warnings.iter().filter(|w| w.contains("'u'")).collect();
    assert_eq!(about_u.len(), 1, "{:?}", m.warnings);
    assert!(about_u[0].contains("inline.xml:") && about_u[0].contains("armature=\"0.1\" is not simulated"));
    let u = m.tendons.iter().find(|t| t.name == "u").unwrap();
    assert_eq!((u.stiffness, u.damping, u.frictionloss), (10.0, 0.0, 0.5));
}

#[test]
fn tendon_errors() {
    let tendon = |body: &str| format!("  <tendon>\n    {body}\n  </tendon>");
    assert_mentions(
        &error_of(&tendon(r#"<fixed name="u"><joint joint="nope" coef="1"/></fixed>"#)),
        &["unknown joint 'nope'"],
    );
    assert_mentions(
        &error_of(&tendon(r#"<fixed name="u"><joint joint="hinge"/></fixed>"#)),
        &["'coef' is missing"],
    );
    assert_mentions(
        &error_of(&tendon(
            r#"<fixed name="u"><joint joint="hinge" coef="1"/><joint joint="hinge" coef="2"/></fixed>"#,
        )),
        &["'hinge' appears twice in tendon 'u'", "add the coefficients"],
    );
    assert_mentions(&error_of(&tendon(r#"<fixed name="u"></fixed>"#)), &["tendon 'u' has no <joint>"]);
    assert_mentions(
        &error_of(&tendon(r#"<fixed name="u" limited="true"><joint joint="hinge" coef="1"/></fixed>"#)),
        &["'range' must be given with lower < upper", "limited=\"true\""],
    );
    assert_mentions(
        &error_of(&tendon(r#"<spatial name="u"><site site="sa"/><site site="nope"/></spatial>"#)),
        &["unknown site 'nope'"],
    );
}

#[test]
fn actuator_errors() {
    let act = |body: &str| format!("  <actuator>\n    {body}\n  </actuator>");
    assert_mentions(
        &error_of(&act(r#"<motor name="m"/>"#)),
        &["no transmission target", "give one of joint"],
    );
    assert_mentions(&error_of(&act(r#"<motor tendon="nope"/>"#)), &["<motor>", "unknown tendon 'nope'"]);
    assert_mentions(&error_of(&act(r#"<motor site="sa" refsite="nope"/>"#)), &["unknown site 'nope'"]);
    assert_mentions(&error_of(&act(r#"<adhesion body="nope" ctrlrange="0 1"/>"#)), &["unknown body 'nope'"]);
    assert_mentions(&error_of(&act(r#"<motor cranksite="sa"/>"#)), &["'slidersite' is missing"]);
    assert_mentions(
        &error_of(&act(r#"<motor cranksite="sa" slidersite="sb"/>"#)),
        &["'cranklength' is 0", "positive"],
    );
    assert_mentions(
        &error_of(&act(r#"<motor joint="hinge" refsite="sa"/>"#)),
        &["'refsite' is only used by a site transmission"],
    );
    assert_mentions(
        &error_of(&act(r#"<position joint="hinge" kv="-1"/>"#)),
        &["'kv' is -1", "cannot be negative"],
    );
    assert_mentions(
        &error_of(&act(r#"<adhesion body="a" ctrlrange="-1 1"/>"#)),
        &["'ctrlrange' cannot be negative for <adhesion>"],
    );
    assert_mentions(
        &error_of(&act(r#"<damper joint="hinge" kv="1"/>"#)),
        &["control-limited", "lower < upper"],
    );
    assert_mentions(
        &error_of(&act(r#"<general joint="hinge" actrange="-1 1"/>"#)),
        &["'actrange' is given but the actuator has no activation"],
    );
    assert_mentions(
        &error_of(&act(r#"<position joint="slide" inheritrange="1"/>"#)),
        &["inheritrange", "joint 'slide' has no range"],
    );
    assert_mentions(
        &error_of(&act(r#"<position joint="hinge" inheritrange="1" ctrlrange="0 1"/>"#)),
        &["'inheritrange' cannot be given together with 'ctrlrange'"],
    );
    assert_mentions(
        &error_of(&act(r#"<motor joint="hinge" ctrllimited="true"/>"#)),
        &["'ctrlrange' must be given"],
    );
    // Without autolimits a range needs its switch (MuJoCo's checklimited).
    let text = model_with(
        "autolimits=\"false\"",
        "  <actuator><motor joint=\"hinge\" ctrlrange=\"-1 1\"/></actuator>",
    );
    assert_mentions(
        &compile_mjcf(&text).unwrap_err(),
        &["'ctrlrange' is given without 'ctrllimited'", "autolimits"],
    );
}

#[test]
fn contact_errors() {
    assert_mentions(
        &error_of("  <contact>\n    <pair geom1=\"ga\"/>\n  </contact>"),
        &["'geom2' is missing"],
    );
    assert_mentions(
        &error_of("  <contact>\n    <exclude body1=\"a\"/>\n  </contact>"),
        &["'body2' is missing"],
    );
}

#[test]
fn untyped_actuators_are_listed_with_a_warning() {
    // MuJoCo 4's dcmotor and a general actuator with an so3 gain are not typed: listed, and the
    // warning says the control indices differ from MuJoCo's.
    let text = model_with(
        "",
        "  <actuator>\n    <general name=\"so3\" joint=\"ball\" gaintype=\"so3\" biastype=\"so3\"/>\n    <motor name=\"m\" joint=\"hinge\"/>\n  </actuator>",
    );
    let m = compile_mjcf(&text).unwrap();
    assert_eq!(m.actuators.len(), 1);
    assert_eq!(m.actuators[0].name, "m");
    assert!(m.elements.iter().any(|e| e.category == "actuator" && e.name == "so3"));
    assert!(
        m.warnings.iter().any(|w| w.contains("gaintype 'so3' is not typed") && w.contains("control indices")),
        "{:?}",
        m.warnings
    );
}
