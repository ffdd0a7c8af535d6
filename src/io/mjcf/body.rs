//! `<worldbody>` → links, depth-first in file order (MuJoCo's body order).
//!
//! An MJCF body becomes one spec link named after it, whose frame is the body frame. Its joints
//! need more care, because MuJoCo rotates a hinge about an axis through its `pos` (the anchor) and
//! applies several joints of one body in sequence, each about its own anchor, while a spec link
//! moves about its own origin. So a body with joints j1..jk whose anchors are not all at its origin
//! (or with more than one joint) becomes a chain: a massless link `body/j1` at anchor p1, then
//! `body/ji` offset by p(i) − p(i−1), and finally the body's link fixed at −pk from the last one —
//! the body frame is `X · T(p1) R1 T(−p1) · … · T(pk) Rk T(−pk)`, as in `mj_kinematics`. A hinge's
//! `ref` (and a slide's) is folded into the placement, `R(q − ref)`, so that q is MuJoCo's qpos.
//! `<frame>` elements only compose their pose onto their children and pass their `childclass`.

use super::assets::MeshAsset;
use super::attrs::Attrs;
use super::defaults::{Defaults, MAIN};
use super::geom::{geom, site};
use super::orientation::{axis_angle_matrix, rotation};
use super::xml::Element;
use super::{Compiler, InertiaFromGeom};
use crate::io::LoadError;
use crate::model::spec::{FrameSpec, InertialSpec, JointSpec, JointType, LinkSpec};
use crate::model::FrameKind;
use crate::spatial::{Mat3, Transform, Vec3};
use std::collections::HashMap;

/// The contents of a body with `<frame>`s flattened: each element with the pose of its enclosing
/// frame in the body frame and the child class in force.
struct Content<'e> {
    joints: Vec<(&'e Element, Transform, String)>,
    geoms: Vec<(&'e Element, Transform, String)>,
    sites: Vec<(&'e Element, Transform, String)>,
    inertial: Option<(&'e Element, Transform)>,
    bodies: Vec<(&'e Element, Transform, String)>,
}

/// Builds the spec links of `<worldbody>`.
pub(crate) struct TreeBuilder<'a> {
    compiler: &'a Compiler,
    defaults: &'a Defaults,
    meshes: &'a HashMap<String, MeshAsset>,
    materials: &'a HashMap<String, [f32; 4]>,
    pub links: Vec<LinkSpec>,
    pub warnings: Vec<String>,
    /// Passive elements of bodies and joints that are parsed, not simulated.
    pub kept: Vec<crate::model::Element>,
    /// Body `gravcomp` where nonzero: (link index, fraction).
    pub gravcomp: Vec<(usize, f64)>,
    /// Body `sleep` other than `auto`: (link index, policy).
    pub sleep: Vec<(usize, crate::model::sleep::SleepPolicy)>,
    /// MuJoCo's body and joint ids so far (world = body 0), for naming unnamed ones.
    next_body: usize,
    next_joint: usize,
}

impl<'a> TreeBuilder<'a> {
    pub fn new(
        compiler: &'a Compiler,
        defaults: &'a Defaults,
        meshes: &'a HashMap<String, MeshAsset>,
        materials: &'a HashMap<String, [f32; 4]>,
    ) -> Self {
        Self {
            compiler,
            defaults,
            meshes,
            materials,
            links: Vec::new(),
            warnings: Vec::new(),
            kept: Vec::new(),
            gravcomp: Vec::new(),
            sleep: Vec::new(),
            next_body: 1,
            next_joint: 0,
        }
    }

    /// Reads every `<worldbody>`: the world link (static geoms and sites) and the bodies below.
    pub fn worldbody(&mut self, root: &Element) -> Result<(), LoadError> {
        let loc = root.children_named("worldbody").next().map_or_else(|| root.loc.clone(), |w| w.loc.clone());
        self.links.push(LinkSpec {
            name: "world".into(),
            loc: loc.clone(),
            parent: None,
            joint: JointSpec::new("", JointType::Fixed, loc),
            inertial: None,
            inertia_from_geoms: false,
            geoms: Vec::new(),
            kind: FrameKind::Link,
            frames: Vec::new(),
            mocap: false,
        });
        for wb in root.children_named("worldbody") {
            let content = self.flatten(wb, Transform::identity(), MAIN)?;
            if let Some((j, _, _)) = content.joints.first() {
                return Err(LoadError::Invalid {
                    loc: j.loc.clone(),
                    element: j.tag.clone(),
                    detail: "the world body cannot have joints; put the joint in a <body>".into(),
                });
            }
            self.attach_geoms_and_sites(0, &content, Transform::identity(), false)?;
            for (b, x, class) in &content.bodies {
                self.body(b, 0, *x, class)?;
            }
        }
        Ok(())
    }

    /// Splits an element's children, descending into `<frame>`s.
    fn flatten<'e>(&mut self, e: &'e Element, x: Transform, class: &str) -> Result<Content<'e>, LoadError> {
        let mut c = Content { joints: vec![], geoms: vec![], sites: vec![], inertial: None, bodies: vec![] };
        self.flatten_into(e, x, class, &mut c)?;
        Ok(c)
    }

    fn flatten_into<'e>(
        &mut self,
        e: &'e Element,
        x: Transform,
        class: &str,
        c: &mut Content<'e>,
    ) -> Result<(), LoadError> {
        for child in &e.children {
            let entry = (child, x, class.to_string());
            match child.tag.as_str() {
                "joint" | "freejoint" => c.joints.push(entry),
                "geom" => c.geoms.push(entry),
                "site" => c.sites.push(entry),
                "body" => c.bodies.push(entry),
                "inertial" => c.inertial = Some((child, x)),
                "frame" => {
                    let a = Attrs::plain(child);
                    let pose = Transform::new(
                        rotation(&a, &self.compiler.angles)?,
                        a.vec3("pos")?.unwrap_or_default(),
                    );
                    let inner = child.attr("childclass").unwrap_or(class);
                    self.check_class(child, inner)?;
                    self.flatten_into(child, x * pose, inner, c)?;
                }
                _ => {}
            }
        }
        Ok(())
    }

    fn check_class(&self, e: &Element, class: &str) -> Result<(), LoadError> {
        if self.defaults.has(class) {
            Ok(())
        } else {
            Err(LoadError::UnknownClass {
                loc: e.loc.clone(),
                element: e.tag.clone(),
                class: class.to_string(),
            })
        }
    }

    /// One `<body>` below link `parent` at `x_parent_frame` (its enclosing frame's pose).
    fn body(
        &mut self,
        e: &Element,
        parent: usize,
        x_parent_frame: Transform,
        class: &str,
    ) -> Result<(), LoadError> {
        let id = self.next_body;
        self.next_body += 1;
        let a = Attrs::plain(e);
        let name = a.text("name").map_or_else(|| format!("body{id}"), str::to_string);
        let class = e.attr("childclass").unwrap_or(class).to_string();
        self.check_class(e, &class)?;
        let x_frame_body =
            Transform::new(rotation(&a, &self.compiler.angles)?, a.vec3("pos")?.unwrap_or_default());
        let x_parent_body = x_parent_frame * x_frame_body;
        let content = self.flatten(e, Transform::identity(), &class)?;

        // Joints, in order, with their anchors and axes in the body frame.
        let mut joints = Vec::with_capacity(content.joints.len());
        for (je, x, jclass) in &content.joints {
            joints.push(self.joint(je, x, jclass)?);
        }
        if let Some(ball) = joints.iter().position(|j| j.0.jtype == JointType::Ball) {
            if let Some((later, _)) =
                joints[ball + 1..].iter().find(|j| matches!(j.0.jtype, JointType::Ball | JointType::Revolute))
            {
                return Err(LoadError::Invalid {
                    loc: later.loc.clone(),
                    element: "joint".into(),
                    detail: format!(
                        "body '{name}': joint '{}' rotates after ball joint '{}' in the same body, which MuJoCo forbids; put it in a child body or before the ball joint",
                        later.name, joints[ball].0.name
                    ),
                });
            }
        }
        let free = joints.iter().any(|j| j.0.jtype == JointType::Floating);
        if free && (joints.len() > 1 || parent != 0) {
            return Err(LoadError::Invalid {
                loc: e.loc.clone(),
                element: "body".into(),
                detail: format!(
                    "body '{name}': a free joint must be the only joint of a top-level body (a child of the world), as in MuJoCo"
                ),
            });
        }
        let mocap = a.bool("mocap")?.unwrap_or(false);
        if mocap && (!joints.is_empty() || parent != 0) {
            return Err(a.error("mocap", "is only allowed on a top-level body without joints"));
        }
        let gravcomp = a.real("gravcomp")?.unwrap_or(0.0);
        let sleep = match a.keyword("sleep", &["auto", "never", "allowed", "init"])? {
            Some(w) => crate::model::sleep::SleepPolicy::from_mjcf(&w),
            None => None,
        };

        // The link chain: the body link hangs from `parent` directly or from its joint links.
        let mut chain_parent = parent;
        let mut x_chain_body = x_parent_body; // body frame relative to `chain_parent`
        let single_at_origin = joints.len() == 1 && (free || joints[0].1 == Vec3::zeros());
        let mut body_joint = JointSpec::new("", JointType::Fixed, e.loc.clone());
        if single_at_origin {
            let (mut j, _) = joints.pop().expect("one joint");
            if free {
                j.qpos0 = free_qpos0(&x_parent_body);
                j.x_parent_joint = Transform::identity();
            } else {
                j.x_parent_joint = x_parent_body * j.x_parent_joint;
            }
            body_joint = j;
        } else if !joints.is_empty() {
            let mut prev_anchor = Vec3::zeros();
            let mut x_origin = x_parent_body;
            for (j, anchor) in joints.into_iter() {
                let mut j = j;
                j.x_parent_joint =
                    x_origin * Transform::from_translation(anchor - prev_anchor) * j.x_parent_joint;
                let link_name = format!("{name}/{}", j.name);
                self.links.push(LinkSpec {
                    name: link_name,
                    loc: j.loc.clone(),
                    parent: Some(chain_parent),
                    joint: j,
                    inertial: None,
                    inertia_from_geoms: false,
                    geoms: Vec::new(),
                    kind: FrameKind::Joint,
                    frames: Vec::new(),
                    mocap: false,
                });
                chain_parent = self.links.len() - 1;
                x_origin = Transform::identity();
                prev_anchor = anchor;
            }
            x_chain_body = Transform::from_translation(-prev_anchor);
        }
        if !single_at_origin {
            body_joint.x_parent_joint = x_chain_body;
        }

        // Mass: <inertial>, or the geoms' when the compiler says so.
        let inertial = match content.inertial {
            Some((ie, x)) => Some(inertial(ie, &x, &self.compiler.angles)?),
            None => None,
        };
        let from_geoms = match self.compiler.inertia_from_geom {
            InertiaFromGeom::True => true,
            InertiaFromGeom::False => false,
            InertiaFromGeom::Auto => inertial.is_none(),
        };
        // A body with no mass at all gets MuJoCo's default inertial frame: its own `pos` and
        // `quat` reused as if they were body-frame coordinates (`mjCBody::Compile`, "ipos
        // undefined"), which matters when `boundmass`/`boundinertia` give it mass.
        let inertial = inertial.or_else(|| {
            Some(InertialSpec {
                mass: 0.0,
                x_link_inertial: x_frame_body,
                inertia: Mat3::zeros(),
                loc: e.loc.clone(),
            })
        });
        self.links.push(LinkSpec {
            name,
            loc: e.loc.clone(),
            parent: Some(chain_parent),
            joint: body_joint,
            inertial,
            inertia_from_geoms: from_geoms,
            geoms: Vec::new(),
            kind: FrameKind::Link,
            frames: Vec::new(),
            mocap,
        });
        let link = self.links.len() - 1;
        if gravcomp != 0.0 {
            self.gravcomp.push((link, gravcomp));
        }
        if let Some(p) = sleep.filter(|p| *p != crate::model::sleep::SleepPolicy::Auto) {
            self.sleep.push((link, p));
        }
        self.attach_geoms_and_sites(link, &content, Transform::identity(), from_geoms)?;
        for (b, x, bclass) in &content.bodies {
            self.body(b, link, *x, bclass)?;
        }
        Ok(())
    }

    /// Adds the geoms (as link geoms) and sites (as frames) of `content` to link `link`.
    fn attach_geoms_and_sites(
        &mut self,
        link: usize,
        content: &Content,
        x: Transform,
        infer_inertia: bool,
    ) -> Result<(), LoadError> {
        for (ge, xf, class) in &content.geoms {
            let a = self.defaults.resolve(ge, class)?;
            let g = geom(&a, &(x * *xf), self.compiler, self.meshes, self.materials, infer_inertia)?;
            self.links[link].geoms.push(g);
        }
        for (se, xf, class) in &content.sites {
            let a = self.defaults.resolve(se, class)?;
            let class_attrs = self.defaults.class_defaults_under(se, "site", class)?;
            let (pose, shape) = site(&a, &class_attrs, &self.compiler.angles)?;
            let Some(name) = a.text("name") else { continue };
            if shape.is_none() {
                self.warnings.push(format!(
                    "{}: site '{name}' is a mesh site: its shape is not kept (a touch sensor, insidesite or contact-sensor filter on it is not computed)",
                    se.loc
                ));
            }
            self.links[link].frames.push(FrameSpec {
                name: name.to_string(),
                loc: se.loc.clone(),
                kind: FrameKind::Site,
                x_link_frame: x * *xf * pose,
                site: shape,
            });
        }
        Ok(())
    }

    /// Records a passive element that is parsed, not simulated.
    fn keep(&mut self, category: &str, kind: &str, name: &str, a: &Attrs) {
        self.kept.push(crate::model::Element {
            category: category.to_string(),
            kind: kind.to_string(),
            name: name.to_string(),
            targets: vec![name.to_string()],
            attributes: a.values.clone(),
            loc: a.loc.clone(),
        });
    }

    /// A `<joint>` or `<freejoint>` as a spec joint whose `x_parent_joint` holds only the `ref`
    /// shift (the caller adds the placement), with its anchor in the body frame.
    fn joint(
        &mut self,
        e: &Element,
        x_frame: &Transform,
        class: &str,
    ) -> Result<(JointSpec, Vec3), LoadError> {
        let id = self.next_joint;
        self.next_joint += 1;
        let a = if e.tag == "freejoint" { Attrs::plain(e) } else { self.defaults.resolve(e, class)? };
        let name = a.text("name").map_or_else(|| format!("joint{id}"), str::to_string);
        let jtype = if e.tag == "freejoint" {
            "free".to_string()
        } else {
            a.keyword("type", &["free", "ball", "slide", "hinge"])?.unwrap_or_else(|| "hinge".into())
        };
        let deg = self.compiler.angles.to_radians;
        let angular = jtype == "hinge";
        let scale = if angular { deg } else { 1.0 };
        let mut j = JointSpec::new(
            &name,
            match jtype.as_str() {
                "free" => JointType::Floating,
                "ball" => JointType::Ball,
                "slide" => JointType::Prismatic,
                _ => JointType::Revolute,
            },
            e.loc.clone(),
        );
        let anchor = x_frame.act_point(&a.vec3("pos")?.unwrap_or_default());
        let axis = x_frame.rot * a.vec3("axis")?.unwrap_or(Vec3::z());
        if matches!(jtype.as_str(), "hinge" | "slide") && axis.norm() < 1e-14 {
            return Err(LoadError::ZeroAxis { loc: e.loc.clone(), joint: name });
        }
        j.axis = axis;
        let range = a.array::<2>("range")?;
        let limited = match a.keyword("limited", &["false", "true", "auto"])?.as_deref() {
            Some("true") => true,
            Some("false") => false,
            _ => self.compiler.autolimits && range.is_some_and(|r| r != [0.0, 0.0]),
        };
        if limited && matches!(jtype.as_str(), "hinge" | "slide") {
            let r = range.unwrap_or_default();
            if r[0] >= r[1] {
                return Err(a.error(
                    "range",
                    format!("is [{}, {}]; the lower limit must be below the upper", r[0], r[1]),
                ));
            }
            j.limits = Some([r[0] * scale, r[1] * scale]);
        }
        if limited && jtype == "ball" {
            // MuJoCo: the cone's half-angle is range[1]; range[0] must be 0.
            let r = range.unwrap_or_default();
            if r[0] != 0.0 || r[1] < 0.0 {
                return Err(a.error(
                    "range",
                    format!("is [{}, {}]; a ball joint's range is [0, max angle] (range[0] must be 0, as MuJoCo requires)", r[0], r[1]),
                ));
            }
            j.limits = Some([0.0, r[1] * deg]);
        }
        j.actuator_force_range = a.limited_range(
            "actuatorfrclimited",
            "actuatorfrcrange",
            self.compiler.autolimits,
            &mut self.warnings,
        )?;
        let reference = a.real("ref")?.unwrap_or(0.0) * scale;
        let first =
            |name: &str| -> Result<f64, LoadError> { Ok(a.some_numbers(name, 1, 3)?.map_or(0.0, |v| v[0])) };
        j.damping = first("damping")?;
        j.stiffness = first("stiffness")?;
        j.armature = a.real("armature")?.unwrap_or(0.0);
        j.friction = a.real("frictionloss")?.unwrap_or(0.0);
        j.soft = soft_params(&a)?;
        j.actuator_gravcomp = a.bool("actuatorgravcomp")?.unwrap_or(false);
        if let Some(sd) = a.array::<2>("springdamper")? {
            // MuJoCo: "when defined, springdamper values must be positive"; 0 0 is undefined.
            if sd != [0.0, 0.0] {
                if !(sd[0] > 0.0 && sd[1] > 0.0 && sd.iter().all(|x| x.is_finite())) {
                    return Err(a.error(
                        "springdamper",
                        "when defined, both values (timeconst, dampratio) must be positive and finite, as MuJoCo requires",
                    ));
                }
                j.springdamper = Some(sd);
            }
        }
        for poly in ["stiffness", "damping"] {
            if a.some_numbers(poly, 1, 3)?.is_some_and(|v| v[1..].iter().any(|&c| c != 0.0)) {
                self.keep("joint", &format!("{poly} polynomial"), &name, &a);
            }
        }
        match jtype.as_str() {
            "hinge" => {
                j.spring_ref = a.real("springref")?.unwrap_or(0.0) * scale;
                j.qpos0 = vec![reference];
                let unit = axis.normalize();
                j.x_parent_joint = Transform::new(axis_angle_matrix(&unit, -reference), Vec3::zeros());
            }
            "slide" => {
                j.spring_ref = a.real("springref")?.unwrap_or(0.0);
                j.qpos0 = vec![reference];
                j.x_parent_joint = Transform::from_translation(-axis.normalize() * reference);
            }
            _ => {}
        }
        Ok((j, anchor))
    }
}

/// A free body's reference configuration: its pose in the file, [x y z qw qx qy qz].
fn free_qpos0(x: &Transform) -> Vec<f64> {
    let q = x.quat_wxyz();
    vec![x.pos.x, x.pos.y, x.pos.z, q[0], q[1], q[2], q[3]]
}

/// `<inertial pos mass diaginertia|fullinertia + orientation>` in the body frame.
fn inertial(
    e: &Element,
    x_frame: &Transform,
    angles: &super::orientation::AngleConvention,
) -> Result<InertialSpec, LoadError> {
    let a = Attrs::plain(e);
    let Some(mass) = a.real("mass")? else {
        return Err(a.error("mass", "is missing: <inertial> needs mass and pos"));
    };
    let Some(pos) = a.vec3("pos")? else {
        return Err(a.error("pos", "is missing: <inertial> needs mass and pos"));
    };
    let (rot, inertia) = if let Some(f) = a.array::<6>("fullinertia")? {
        if ["quat", "axisangle", "euler", "xyaxes", "zaxis"].iter().any(|o| a.has(o)) {
            return Err(
                a.error("fullinertia", "cannot be combined with an orientation: the tensor is in body axes")
            );
        }
        // fullinertia = Ixx Iyy Izz Ixy Ixz Iyz.
        (Mat3::identity(), Mat3::new(f[0], f[3], f[4], f[3], f[1], f[5], f[4], f[5], f[2]))
    } else {
        let d = a.vec3("diaginertia")?.unwrap_or_default();
        (rotation(&a, angles)?, Mat3::from_diagonal(&d))
    };
    let x_body_inertial = *x_frame * Transform::new(rot, pos);
    Ok(InertialSpec { mass, x_link_inertial: x_body_inertial, inertia, loc: e.loc.clone() })
}

/// A joint's or tendon's soft-constraint parameters (`solreflimit`, `solimplimit`,
/// `solreffriction`, `solimpfriction`, `margin`), over MuJoCo's defaults; `solimp` may give its first 1 to 5 values.
pub(super) fn soft_params(a: &Attrs) -> Result<crate::model::spec::SoftParams, LoadError> {
    let mut soft = crate::model::spec::SoftParams::default();
    for (name, out) in
        [("solreflimit", &mut soft.solref_limit), ("solreffriction", &mut soft.solref_friction)]
    {
        if let Some(r) = a.some_numbers(name, 2, 2)? {
            out.copy_from_slice(&r[..2]);
        }
    }
    for (name, out) in
        [("solimplimit", &mut soft.solimp_limit), ("solimpfriction", &mut soft.solimp_friction)]
    {
        if let Some(i) = a.some_numbers(name, 1, 5)? {
            out[..i.len()].copy_from_slice(&i);
        }
    }
    soft.margin = a.real("margin")?.unwrap_or(0.0);
    Ok(soft)
}
