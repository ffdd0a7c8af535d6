//! The values of a URDF file, read from the XML tree (roxmltree) after checking them.
//!
//! `check_values` walks every element the loader reads and reports the first missing or
//! unreadable attribute at its line, before anything is built. The readers below then take the
//! values with the URDF specification's defaults (<http://wiki.ros.org/urdf/XML>) and the
//! version rules of urdfdom, the reference parser that ROS and Pinocchio use:
//! - `<origin quat_xyzw>` (URDF ≥ 1.1) gives the orientation as a quaternion (normalized; both
//!   `rpy` and `quat_xyzw` is an error); older files ignore it;
//! - `<limit>` in URDF ≥ 1.2: an omitted bound is unbounded (±∞), `upper < lower` and negative
//!   `effort`/`velocity` are errors; older files default the bounds and effort to 0;
//! - `<sphere>`, `<box>`, `<cylinder>`, `<capsule>` sizes must be positive in URDF ≥ 1.2.

use super::{elements, is, Ctx};
use crate::io::LoadError;
use crate::spatial::{quat_to_matrix, Mat3, Transform, Vec3};
use roxmltree::Node;

/// The URDF version of `<robot version>` (a missing or malformed value is 1.0, as urdfdom).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub(super) struct Version(pub u32, pub u32);

impl Version {
    pub(super) fn of(robot: Node) -> Self {
        robot
            .attribute("version")
            .and_then(|v| v.trim().split_once('.'))
            .and_then(|(a, b)| Some(Version(a.parse().ok()?, b.parse().ok()?)))
            .unwrap_or(Version(1, 0))
    }
}

/// `name` of `node` as a number (already checked by [`check_values`]; NaN stays NaN).
pub(super) fn number(node: Node, name: &str) -> Option<f64> {
    node.attribute(name).and_then(|v| v.trim().parse().ok())
}

/// `name` of `node` as `N` numbers separated by white space.
pub(super) fn numbers<const N: usize>(node: Node, name: &str) -> Option<[f64; N]> {
    let mut out = [0.0; N];
    let mut parts = node.attribute(name)?.split_whitespace();
    for o in &mut out {
        *o = parts.next()?.parse().ok()?;
    }
    parts.next().is_none().then_some(out)
}

/// The first child element of `node` named `tag`.
pub(super) fn child<'a, 'i>(node: Node<'a, 'i>, tag: &str) -> Option<Node<'a, 'i>> {
    elements(node).find(|c| is(c, tag))
}

/// The pose of `<origin>` under `node` (identity without one); every value must be finite.
pub(super) fn origin(ctx: &Ctx, node: Node, version: Version, owner: &str) -> Result<Transform, LoadError> {
    let Some(o) = child(node, "origin") else {
        return Ok(Transform::identity());
    };
    let xyz = numbers::<3>(o, "xyz").unwrap_or([0.0; 3]);
    let rpy = numbers::<3>(o, "rpy").unwrap_or([0.0; 3]);
    let quat = if version >= Version(1, 1) { o.attribute("quat_xyzw") } else { None };
    let bad = |detail: String| ctx.invalid(o, format!("{owner}: {detail}"));
    if let Some(q) = quat {
        if o.attribute("rpy").is_some() {
            return Err(bad("<origin> has both rpy and quat_xyzw; give one orientation".into()));
        }
        let v = numbers::<4>(o, "quat_xyzw")
            .ok_or_else(|| bad(format!("<origin quat_xyzw=\"{q}\"> is not 4 numbers separated by spaces")))?;
        if !v.iter().chain(&xyz).all(|x| x.is_finite()) {
            return Err(bad(format!("the <origin> has a non-finite value (xyz {xyz:?}, quat_xyzw {v:?})")));
        }
        let norm = v.iter().map(|x| x * x).sum::<f64>().sqrt();
        // A zero quaternion is the identity, as urdfdom reads it.
        let rot = if norm > 0.0 { quat_to_matrix(v[3], v[0], v[1], v[2]) } else { Mat3::identity() };
        return Ok(Transform::new(rot, Vec3::new(xyz[0], xyz[1], xyz[2])));
    }
    if !xyz.iter().chain(&rpy).all(|x| x.is_finite()) {
        return Err(bad(format!(
            "the <origin> has a non-finite value (xyz {xyz:?}, rpy {rpy:?}); give finite numbers"
        )));
    }
    Ok(Transform::from_xyz_rpy(xyz, rpy))
}

/// A joint's `<limit>`: lower, upper, effort, with the version's defaults and checks.
pub(super) struct Limit {
    pub lower: f64,
    pub upper: f64,
    pub effort: f64,
}

pub(super) fn limit(
    ctx: &Ctx,
    joint: Node,
    limit: Node,
    version: Version,
    name: &str,
) -> Result<Limit, LoadError> {
    let v12 = version >= Version(1, 2);
    let (unbounded, zero) = (f64::INFINITY, 0.0);
    let lower = number(limit, "lower").unwrap_or(if v12 { -unbounded } else { zero });
    let upper = number(limit, "upper").unwrap_or(if v12 { unbounded } else { zero });
    let effort = number(limit, "effort").unwrap_or(if v12 { unbounded } else { zero });
    if v12 {
        let bad = |detail: String| {
            ctx.invalid(joint, format!("joint '{name}': {detail} (URDF ≥ 1.2); fix the <limit>"))
        };
        for (what, x) in [("lower", lower), ("upper", upper), ("effort", effort)] {
            if x.is_nan() {
                return Err(bad(format!("<limit {what}> is not a number")));
            }
        }
        if upper < lower {
            return Err(bad(format!(
                "the upper position limit ({upper}) is smaller than the lower one ({lower})"
            )));
        }
        for what in ["effort", "velocity", "acceleration", "deceleration", "jerk"] {
            if let Some(x) = number(limit, what).filter(|x| *x < 0.0 || x.is_nan()) {
                return Err(bad(format!("<limit {what}=\"{x}\"> must be ≥ 0")));
            }
        }
    }
    Ok(Limit { lower, upper, effort })
}

/// How to read an attribute: the number of floats (0 = any text) and whether it is required.
type AttrRule = (&'static str, usize, bool);

const INERTIA_ATTRS: [AttrRule; 6] = [
    ("ixx", 1, true),
    ("ixy", 1, true),
    ("ixz", 1, true),
    ("iyy", 1, true),
    ("iyz", 1, true),
    ("izz", 1, true),
];

/// Finds the first element (among those the loader reads) with a missing or unreadable value.
pub(super) fn check_values(robot: Node, ctx: &Ctx, version_1_2: bool) -> Option<LoadError> {
    for top in elements(robot) {
        let owner = format!("{} '{}'", top.tag_name().name(), top.attribute("name").unwrap_or(""));
        let kept: Vec<Node> = match top.tag_name().name() {
            "link" => elements(top)
                .filter(|c| matches!(c.tag_name().name(), "inertial" | "visual" | "collision"))
                .collect(),
            "joint" => elements(top).collect(),
            // Materials (colours, textures) only affect drawing: the loader does not read them.
            _ => continue,
        };
        for node in kept.into_iter().flat_map(|k| k.descendants().filter(|n| n.is_element())) {
            if let Some(e) = check_element(node, ctx, &owner, version_1_2) {
                return Some(e);
            }
        }
    }
    None
}

fn check_element(node: Node, ctx: &Ctx, owner: &str, version_1_2: bool) -> Option<LoadError> {
    let tag = node.tag_name().name();
    let velocity_required = !version_1_2;
    let (attrs, children): (&[AttrRule], &[&str]) = match tag {
        "origin" => (&[("xyz", 3, false), ("rpy", 3, false)], &[]),
        "axis" => (&[("xyz", 3, true)], &[]),
        "inertial" => (&[], &["mass", "inertia"]),
        "mass" => (&[("value", 1, true)], &[]),
        "inertia" => (&INERTIA_ATTRS, &[]),
        "visual" | "collision" => (&[], &["geometry"]),
        "box" => (&[("size", 3, true)], &[]),
        "cylinder" | "capsule" => (&[("radius", 1, true), ("length", 1, true)], &[]),
        "sphere" => (&[("radius", 1, true)], &[]),
        "mesh" => (&[("filename", 0, true), ("scale", 3, false)], &[]),
        "limit" if velocity_required => {
            (&[("lower", 1, false), ("upper", 1, false), ("effort", 1, false), ("velocity", 1, true)], &[])
        }
        "limit" => {
            (&[("lower", 1, false), ("upper", 1, false), ("effort", 1, false), ("velocity", 1, false)], &[])
        }
        "dynamics" => (&[("damping", 1, false), ("friction", 1, false)], &[]),
        "mimic" => (&[("joint", 0, true), ("multiplier", 1, false), ("offset", 1, false)], &[]),
        "safety_controller" => (
            &[
                ("soft_lower_limit", 1, false),
                ("soft_upper_limit", 1, false),
                ("k_position", 1, false),
                ("k_velocity", 1, true),
            ],
            &[],
        ),
        "calibration" => (&[("rising", 1, false), ("falling", 1, false)], &[]),
        "geometry" => {
            const SHAPES: [&str; 5] = ["box", "cylinder", "capsule", "sphere", "mesh"];
            let shapes: Vec<Node> = elements(node).collect();
            return match shapes.as_slice() {
                [s] if SHAPES.contains(&s.tag_name().name()) => None,
                [s] => Some(ctx.invalid(
                    node,
                    format!(
                        "{owner}: unknown geometry <{}>; use one of <box>, <cylinder>, <capsule>, <sphere>, <mesh>",
                        s.tag_name().name()
                    ),
                )),
                _ => Some(ctx.invalid(
                    node,
                    format!(
                        "{owner}: <geometry> must hold exactly one of <box>, <cylinder>, <capsule>, <sphere>, \
                         <mesh> (found {})",
                        shapes.len()
                    ),
                )),
            };
        }
        _ => return None,
    };
    for &(attr, count, required) in attrs {
        let Some(value) = node.attribute(attr) else {
            if required {
                return Some(
                    ctx.invalid(
                        node,
                        format!("{owner}: <{tag}> has no {attr} attribute; add {attr}=\"...\""),
                    ),
                );
            }
            continue;
        };
        let ok = match count {
            0 => true,
            1 => value.trim().parse::<f64>().is_ok(),
            n => {
                let parts: Vec<&str> = value.split_whitespace().collect();
                parts.len() == n && parts.iter().all(|p| p.parse::<f64>().is_ok())
            }
        };
        if !ok {
            let want = if count == 1 {
                "a number".to_string()
            } else {
                format!("{count} numbers separated by spaces")
            };
            return Some(
                ctx.invalid(
                    node,
                    format!("{owner}: <{tag} {attr}=\"{value}\"> is not {want}; fix the value"),
                ),
            );
        }
    }
    // URDF ≥ 1.2: primitive sizes must be positive and finite (urdfdom's check).
    if !velocity_required && matches!(tag, "sphere" | "box" | "cylinder" | "capsule") {
        for &(attr, _, _) in attrs {
            let value = node.attribute(attr).unwrap_or("");
            let positive =
                value.split_whitespace().all(|v| v.parse::<f64>().is_ok_and(|x| x.is_finite() && x > 0.0));
            if !positive {
                return Some(ctx.invalid(
                    node,
                    format!("{owner}: <{tag}>: {attr} must be positive and finite in URDF ≥ 1.2 (found \"{value}\"); fix it"),
                ));
            }
        }
    }
    for &child in children {
        if !elements(node).any(|c| c.tag_name().name() == child) {
            return Some(ctx.invalid(node, format!("{owner}: <{tag}> has no <{child}>; add one")));
        }
    }
    None
}
