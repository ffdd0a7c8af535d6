//! URDF loader: text → [`ModelSpec`] (docs/architecture.md, "Layers").
//!
//! Two passes over the text. `roxmltree` first checks the XML (its errors carry line and column)
//! and indexes every `<link>` and `<joint>` (with their `<inertial>`, `<visual>`, `<collision>`,
//! `<mesh>` and `<axis>`) by source line, catching what needs a line to be reported well: missing
//! names, unknown joint types, joints without `<parent>`/`<child>`, duplicate names. `urdf-rs` then
//! reads the data; its i-th link/joint is the i-th `<link>`/`<joint>` element of the file. Finally
//! the tree is checked (one root, no cycles, every link has at most one parent joint) and the links
//! are laid out in depth-first pre-order from the root, children in file order of their joints —
//! MuJoCo's order, which the rest of the engine relies on (docs/architecture.md, "Conventions").
//!
//! Semantics follow the URDF specification (<http://wiki.ros.org/urdf/XML>): `<origin rpy>` is a
//! fixed-axis roll–pitch–yaw, `<axis>` defaults to x, `<limit>` is kept for revolute and prismatic
//! joints, a link without `<inertial>` is massless, `<mimic>` defaults to multiplier 1, offset 0.

use super::package::{base_dir, package_search_dirs, resolve_uri, ResolveError};
use super::{LoadError, LoadOptions};
use crate::io::lines::LineIndex;
use crate::model::spec::{
    GeomSpec, InertialSpec, JointSpec, JointType, LinkSpec, MassRules, MimicSpec, ModelSpec, Shape,
};
use crate::model::{FrameKind, SourceLoc};
use crate::spatial::{Mat3, Transform, Vec3};
use roxmltree::{Document, Node, ParsingOptions};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// URDF joint type names and what they become. `spherical` is an extension that urdf-rs reads.
const JOINT_TYPES: [(&str, JointType); 7] = [
    ("revolute", JointType::Revolute),
    ("continuous", JointType::Continuous),
    ("prismatic", JointType::Prismatic),
    ("fixed", JointType::Fixed),
    ("floating", JointType::Floating),
    ("planar", JointType::Planar),
    ("spherical", JointType::Ball),
];

/// Name of the free joint added for the root link with `LoadOptions::floating`.
const ROOT_FREE_JOINT: &str = "root_joint";
/// Name of the fixed joint welding the root link to the world otherwise.
const ROOT_FIXED_JOINT: &str = "world_joint";

/// Parses URDF text into a spec. `path` names the file in messages and anchors relative mesh
/// paths; `options` supplies the `package://` folders and whether the root floats.
pub fn parse(text: &str, path: &Path, options: &LoadOptions) -> Result<ModelSpec, LoadError> {
    let ctx = Ctx::new(text, path);
    let parse_options = ParsingOptions { allow_dtd: true, ..ParsingOptions::default() };
    let doc = Document::parse_with_options(text, parse_options).map_err(|e| LoadError::Xml {
        file: ctx.file.clone(),
        line: e.pos().row,
        col: e.pos().col,
        detail: e.to_string(),
    })?;
    let index = Index::build(&doc, &ctx)?;
    // Resource limits before the second (slower) parse: the link and dof counts.
    let nv = index.joints.iter().map(|j| j.jtype.nv()).sum();
    crate::io::plausibility::check_counts(&ctx.file, crate::io::LinkWord::Link, index.links.len(), nv)?;
    // A material <texture> without a file name (which urdf-rs rejects) only affects drawing: it
    // is blanked out, keeping every byte offset, with a warning.
    let mut warnings = Vec::new();
    let mut cleaned: Option<String> = None;
    for node in doc.descendants().filter(|n| is(n, "texture") && n.attribute("filename").is_none()) {
        let range = node.range();
        let text = cleaned.get_or_insert_with(|| text.to_string());
        text.replace_range(range.clone(), &" ".repeat(range.len()));
        warnings.push(format!(
            "{}: <texture> without a filename ignored (it only affects drawing)",
            ctx.loc(node)
        ));
    }
    let urdf_text = cleaned.as_deref().unwrap_or(text);
    let robot =
        urdf_rs::read_from_string(urdf_text).map_err(|e| diagnose(&doc, &ctx, &index, &e.to_string()))?;
    index.check_matches(&robot, &ctx, &doc)?;
    let tree = Tree::build(&index, &ctx)?;
    let mut spec = build_spec(&robot, &index, &tree, path, options)?;
    spec.elements.extend(transmissions(&doc, &ctx));
    warnings.append(&mut spec.warnings);
    spec.warnings = warnings;
    Ok(spec)
}

/// File name and line table for locating byte offsets.
struct Ctx {
    file: String,
    lines: LineIndex,
}

impl Ctx {
    fn new(text: &str, path: &Path) -> Self {
        Self { file: path.display().to_string(), lines: LineIndex::new(text) }
    }
    /// 1-based line of a byte offset.
    fn line(&self, pos: usize) -> u32 {
        self.lines.line(pos)
    }
    fn loc(&self, node: Node) -> SourceLoc {
        SourceLoc { file: self.file.clone(), line: self.line(node.range().start) }
    }
    /// An [`LoadError::Invalid`] at `node`.
    fn invalid(&self, node: Node, detail: String) -> LoadError {
        LoadError::Invalid { loc: self.loc(node), element: node.tag_name().name().to_string(), detail }
    }
}

/// Where a `<visual>` or `<collision>` is.
struct GeomIndex {
    collision: bool,
    loc: SourceLoc,
    /// Location of its `<mesh>`, if the geometry is a mesh.
    mesh_loc: Option<SourceLoc>,
}

/// What the first pass learned about a `<link>`.
struct LinkIndex {
    name: String,
    loc: SourceLoc,
    inertial_loc: Option<SourceLoc>,
    /// Visuals and collisions in file order.
    geoms: Vec<GeomIndex>,
}

/// What the first pass learned about a `<joint>`.
struct JointIndex {
    name: String,
    loc: SourceLoc,
    jtype: JointType,
    parent: String,
    child: String,
    axis_loc: Option<SourceLoc>,
    /// Location of its `<mimic>`, if any.
    mimic_loc: Option<SourceLoc>,
    has_limit: bool,
}

/// The positions of all links and joints (first pass, roxmltree).
struct Index {
    links: Vec<LinkIndex>,
    joints: Vec<JointIndex>,
    /// `version` of `<robot>` is 1.2 or later (changes limit defaults).
    version_1_2: bool,
}

fn is(node: &Node, name: &str) -> bool {
    node.is_element() && node.tag_name().name() == name
}

fn elements<'a, 'i>(node: Node<'a, 'i>) -> impl Iterator<Item = Node<'a, 'i>> {
    node.children().filter(|c| c.is_element())
}

impl Index {
    fn build(doc: &Document, ctx: &Ctx) -> Result<Self, LoadError> {
        let robot = doc.root_element();
        if robot.tag_name().name() != "robot" {
            return Err(ctx.invalid(
                robot,
                format!(
                    "the root element is <{}>, not <robot>; a URDF file holds one <robot name=\"...\"> \
                     element with the <link>s and <joint>s inside",
                    robot.tag_name().name()
                ),
            ));
        }
        let version_1_2 = robot
            .attribute("version")
            .and_then(|v| v.trim().split_once('.'))
            .and_then(|(a, b)| Some((a.parse::<u32>().ok()?, b.parse::<u32>().ok()?)))
            .is_some_and(|v| v >= (1, 2));
        let mut index = Index { links: Vec::new(), joints: Vec::new(), version_1_2 };
        let mut link_names: HashMap<&str, ()> = HashMap::new();
        let mut joint_names: HashMap<&str, ()> = HashMap::new();
        for node in elements(robot) {
            match node.tag_name().name() {
                "link" => {
                    let name = required_name(ctx, node, "link")?;
                    if link_names.insert(name, ()).is_some() {
                        return Err(LoadError::DuplicateName {
                            loc: ctx.loc(node),
                            element: "link",
                            name: name.to_string(),
                        });
                    }
                    index.links.push(index_link(ctx, node, name)?);
                }
                "joint" => {
                    let name = required_name(ctx, node, "joint")?;
                    if joint_names.insert(name, ()).is_some() {
                        return Err(LoadError::DuplicateName {
                            loc: ctx.loc(node),
                            element: "joint",
                            name: name.to_string(),
                        });
                    }
                    index.joints.push(index_joint(ctx, node, name)?);
                }
                _ => {}
            }
        }
        Ok(index)
    }

    /// Checks that urdf-rs saw the same links and joints in the same order.
    fn check_matches(&self, robot: &urdf_rs::Robot, ctx: &Ctx, doc: &Document) -> Result<(), LoadError> {
        let same_links = robot.links.len() == self.links.len()
            && robot.links.iter().zip(&self.links).all(|(a, b)| a.name == b.name);
        let same_joints = robot.joints.len() == self.joints.len()
            && robot.joints.iter().zip(&self.joints).all(|(a, b)| a.name == b.name);
        if same_links && same_joints {
            return Ok(());
        }
        Err(ctx.invalid(
            doc.root_element(),
            "the URDF reader (urdf-rs) and the XML index disagree on the links and joints of the file \
             (loader bug); please report it with this file"
                .into(),
        ))
    }
}

/// The `name` attribute of a `<link>` or `<joint>`, which must be there and non-empty.
fn required_name<'a>(ctx: &Ctx, node: Node<'a, '_>, what: &str) -> Result<&'a str, LoadError> {
    match node.attribute("name") {
        Some(n) if !n.is_empty() => Ok(n),
        _ => {
            Err(ctx.invalid(node, format!("a <{what}> has no name; give it a unique name=\"...\" attribute")))
        }
    }
}

fn index_link(ctx: &Ctx, node: Node, name: &str) -> Result<LinkIndex, LoadError> {
    let mut link =
        LinkIndex { name: name.to_string(), loc: ctx.loc(node), inertial_loc: None, geoms: Vec::new() };
    for child in elements(node) {
        match child.tag_name().name() {
            "inertial" => {
                if link.inertial_loc.is_some() {
                    return Err(ctx.invalid(
                        child,
                        format!("link '{name}' has a second <inertial>; merge them into one"),
                    ));
                }
                link.inertial_loc = Some(ctx.loc(child));
            }
            tag @ ("visual" | "collision") => {
                let mesh = child
                    .children()
                    .filter(|g| is(g, "geometry"))
                    .flat_map(|g| g.children())
                    .find(|m| is(m, "mesh"));
                link.geoms.push(GeomIndex {
                    collision: tag == "collision",
                    loc: ctx.loc(child),
                    mesh_loc: mesh.map(|m| ctx.loc(m)),
                });
            }
            _ => {}
        }
    }
    Ok(link)
}

fn index_joint(ctx: &Ctx, node: Node, name: &str) -> Result<JointIndex, LoadError> {
    let loc = ctx.loc(node);
    let Some(found) = node.attribute("type") else {
        return Err(ctx.invalid(
            node,
            format!(
                "joint '{name}' has no type attribute; add type=\"...\" with one of revolute, continuous, \
                 prismatic, fixed, floating, planar"
            ),
        ));
    };
    let Some(&(_, jtype)) = JOINT_TYPES.iter().find(|(n, _)| *n == found) else {
        return Err(LoadError::UnknownJointType { loc, joint: name.to_string(), found: found.to_string() });
    };
    let link_of = |role: &str| -> Result<String, LoadError> {
        let Some(el) = elements(node).find(|c| c.tag_name().name() == role) else {
            return Err(ctx.invalid(
                node,
                format!("joint '{name}' has no <{role}>; add <{role} link=\"...\"/> naming its {role} link"),
            ));
        };
        match el.attribute("link") {
            Some(l) => Ok(l.to_string()),
            None => Err(ctx.invalid(
                el,
                format!("joint '{name}': <{role}> has no link attribute; write <{role} link=\"...\"/>"),
            )),
        }
    };
    let parent = link_of("parent")?;
    let child = link_of("child")?;
    Ok(JointIndex {
        name: name.to_string(),
        loc,
        jtype,
        parent,
        child,
        axis_loc: elements(node).find(|c| is(c, "axis")).map(|a| ctx.loc(a)),
        mimic_loc: elements(node).find(|c| is(c, "mimic")).map(|m| ctx.loc(m)),
        has_limit: elements(node).any(|c| is(&c, "limit")),
    })
}

/// The kinematic tree: links in depth-first pre-order and each link's parent joint.
struct Tree {
    /// Link indices (into `Index::links`) in depth-first pre-order from the root.
    order: Vec<usize>,
    /// For each link, the joint (index into `Index::joints`) whose child it is.
    parent_joint: Vec<Option<usize>>,
    /// For each joint, the index of its parent link.
    joint_parent: Vec<usize>,
}

impl Tree {
    fn build(index: &Index, ctx: &Ctx) -> Result<Self, LoadError> {
        let n = index.links.len();
        if n == 0 {
            return Err(LoadError::Empty { file: ctx.file.clone() });
        }
        let by_name: HashMap<&str, usize> =
            index.links.iter().enumerate().map(|(i, l)| (l.name.as_str(), i)).collect();
        let mut parent_joint: Vec<Option<usize>> = vec![None; n];
        let mut children: Vec<Vec<usize>> = vec![Vec::new(); n];
        let mut joint_parent = Vec::with_capacity(index.joints.len());
        let mut joint_child = Vec::with_capacity(index.joints.len());
        for (ji, j) in index.joints.iter().enumerate() {
            let find = |role: &'static str, link: &str| {
                by_name.get(link).copied().ok_or_else(|| LoadError::MissingLink {
                    loc: j.loc.clone(),
                    joint: j.name.clone(),
                    role,
                    link: link.to_string(),
                })
            };
            let p = find("parent", &j.parent)?;
            let c = find("child", &j.child)?;
            if let Some(other) = parent_joint[c] {
                // A second parent that descends from the child closes a loop: report the cycle.
                let mut path = vec![p];
                let mut cur = p;
                while let Some(pj) = parent_joint[cur] {
                    cur = joint_parent[pj];
                    if cur == c || path.len() > n {
                        break;
                    }
                    path.push(cur);
                }
                if cur == c {
                    path.push(c);
                    path.reverse();
                    return Err(LoadError::Cycle {
                        loc: j.loc.clone(),
                        joint: j.name.clone(),
                        links: path.iter().map(|&l| index.links[l].name.clone()).collect(),
                    });
                }
                return Err(LoadError::TwoParents {
                    loc: j.loc.clone(),
                    joint: j.name.clone(),
                    link: j.child.clone(),
                    other: index.joints[other].name.clone(),
                });
            }
            parent_joint[c] = Some(ji);
            children[p].push(ji);
            joint_parent.push(p);
            joint_child.push(c);
        }

        let roots: Vec<usize> = (0..n).filter(|&l| parent_joint[l].is_none()).collect();
        if roots.len() > 1 {
            return Err(LoadError::MultipleRoots {
                file: ctx.file.clone(),
                roots: roots.iter().map(|&l| index.links[l].name.clone()).collect(),
            });
        }
        let mut tree = Tree { order: Vec::with_capacity(n), parent_joint, joint_parent };
        let Some(&root) = roots.first() else {
            return Err(tree.cycle_error(0, index, ctx));
        };
        // Depth-first pre-order; children pushed in reverse so the first joint in the file is
        // visited (and fully recursed into) first.
        let mut visited = vec![false; n];
        let mut stack = vec![root];
        while let Some(l) = stack.pop() {
            visited[l] = true;
            tree.order.push(l);
            stack.extend(children[l].iter().rev().map(|&j| joint_child[j]));
        }
        if let Some(unreached) = visited.iter().position(|v| !v) {
            return Err(tree.cycle_error(unreached, index, ctx));
        }
        Ok(tree)
    }

    /// The cycle reached by walking up parent joints from `start` (a link not reachable from the
    /// root, so every link on the way has a parent joint and the walk must loop).
    fn cycle_error(&self, start: usize, index: &Index, ctx: &Ctx) -> LoadError {
        let mut seen_at = vec![usize::MAX; index.links.len()];
        let mut path = Vec::new();
        let mut cur = start;
        let cycle = loop {
            if seen_at[cur] != usize::MAX {
                break path[seen_at[cur]..].to_vec();
            }
            seen_at[cur] = path.len();
            path.push(cur);
            match self.parent_joint[cur] {
                Some(j) => cur = self.joint_parent[j],
                // Cannot happen for an unreachable link; report what we know.
                None => break path.clone(),
            }
        };
        // Walked child → parent; list parent → child, starting at the loop's first link in the file.
        let mut links: Vec<usize> = cycle.into_iter().rev().collect();
        if let Some(first) = links.iter().enumerate().min_by_key(|(_, &l)| l).map(|(i, _)| i) {
            links.rotate_left(first);
        }
        // Name the joint of the loop that comes last in the file: the one that closes it.
        let joint = links.iter().filter_map(|&l| self.parent_joint[l]).max();
        let (loc, joint) = match joint {
            Some(j) => (index.joints[j].loc.clone(), index.joints[j].name.clone()),
            None => (SourceLoc { file: ctx.file.clone(), line: 0 }, String::new()),
        };
        LoadError::Cycle { loc, joint, links: links.iter().map(|&l| index.links[l].name.clone()).collect() }
    }
}

/// The `<transmission>` elements, kept for `lagrange info` (ros_control hardware descriptions: the
/// engine applies joint torques directly, so they are listed, not simulated): kind from `<type>`
/// (or the old `type` attribute), targets the joints then the actuators, attributes the
/// mechanical reductions and hardware interfaces.
fn transmissions(doc: &Document, ctx: &Ctx) -> Vec<crate::model::Element> {
    let text = |n: Node| n.text().unwrap_or("").trim().to_string();
    let root = doc.root_element();
    elements(root)
        .filter(|n| is(n, "transmission"))
        .map(|t| {
            let kind = elements(t)
                .find(|c| is(c, "type"))
                .map(text)
                .or_else(|| t.attribute("type").map(str::to_string))
                .unwrap_or_default();
            let mut targets = Vec::new();
            let mut attributes = Vec::new();
            for role in ["joint", "actuator"] {
                for c in elements(t).filter(|c| is(c, role)) {
                    let name = c.attribute("name").unwrap_or("").to_string();
                    for detail in elements(c) {
                        attributes
                            .push((format!("{role} {name}: {}", detail.tag_name().name()), text(detail)));
                    }
                    targets.push(name);
                }
            }
            crate::model::Element {
                category: "transmission".into(),
                kind,
                name: t.attribute("name").unwrap_or("").to_string(),
                targets,
                attributes,
                loc: ctx.loc(t),
            }
        })
        .collect()
}

/// Turns the urdf-rs data into the spec, in tree order.
fn build_spec(
    robot: &urdf_rs::Robot,
    index: &Index,
    tree: &Tree,
    path: &Path,
    options: &LoadOptions,
) -> Result<ModelSpec, LoadError> {
    let mut spec_index = vec![usize::MAX; index.links.len()];
    for (si, &li) in tree.order.iter().enumerate() {
        spec_index[li] = si;
    }
    let search_dirs = package_search_dirs(&options.package_dirs);
    let base = base_dir(path);
    let mut warnings = Vec::new();

    let mut links = Vec::with_capacity(tree.order.len());
    for &li in &tree.order {
        let link_index = &index.links[li];
        let (parent, joint) = match tree.parent_joint[li] {
            Some(ji) => {
                let parent = spec_index[tree.joint_parent[ji]];
                (Some(parent), joint_spec(&robot.joints[ji], &index.joints[ji], index, options)?)
            }
            None => (None, root_joint(link_index, index, options)?),
        };
        let urdf_link = &robot.links[li];
        let inertial = match &link_index.inertial_loc {
            Some(loc) => Some(inertial_spec(&urdf_link.inertial, &link_index.name, loc)?),
            None => None,
        };
        let geoms = geom_specs(urdf_link, link_index, &base, &search_dirs, &mut warnings)?;
        links.push(LinkSpec {
            name: link_index.name.clone(),
            loc: link_index.loc.clone(),
            parent,
            joint,
            inertial,
            inertia_from_geoms: false,
            geoms,
            kind: FrameKind::Link,
            frames: Vec::new(),
            mocap: false,
        });
    }
    Ok(ModelSpec {
        name: robot.name.clone(),
        source: Some(path.to_path_buf()),
        gravity: Vec3::new(0.0, 0.0, -9.81),
        links,
        mass_rules: MassRules {
            accept_nonphysical: options.accept_nonphysical_inertia,
            ..MassRules::default()
        },
        warnings,
        ..Default::default()
    })
}

/// The joint attaching the root link to the world: free (`root_joint`) when floating, else fixed.
fn root_joint(root: &LinkIndex, index: &Index, options: &LoadOptions) -> Result<JointSpec, LoadError> {
    let taken = |name: &str| index.joints.iter().find(|j| j.name == name);
    if options.floating {
        if let Some(j) = taken(ROOT_FREE_JOINT) {
            return Err(LoadError::Invalid {
                loc: j.loc.clone(),
                element: "joint".into(),
                detail: format!(
                    "joint '{ROOT_FREE_JOINT}': loading with LoadOptions::floating adds a free joint named \
                     '{ROOT_FREE_JOINT}' for the root link '{}', and this joint has the same name; rename it \
                     or load without LoadOptions::floating",
                    root.name
                ),
            });
        }
        return Ok(JointSpec::new(ROOT_FREE_JOINT, JointType::Floating, root.loc.clone()));
    }
    // The weld is fused away by the compile step; if the file already uses the name, leave it
    // unnamed (the compile step's uniqueness check skips empty names).
    let name = if taken(ROOT_FIXED_JOINT).is_some() { "" } else { ROOT_FIXED_JOINT };
    Ok(JointSpec::new(name, JointType::Fixed, root.loc.clone()))
}

fn pose(p: &urdf_rs::Pose) -> Transform {
    Transform::from_xyz_rpy(p.xyz.0, p.rpy.0)
}

fn finite_pose(p: &urdf_rs::Pose) -> bool {
    p.xyz.iter().chain(p.rpy.iter()).all(|x| x.is_finite())
}

fn joint_spec(
    j: &urdf_rs::Joint,
    ji: &JointIndex,
    index: &Index,
    options: &LoadOptions,
) -> Result<JointSpec, LoadError> {
    let invalid = |loc: &SourceLoc, element: &str, detail: String| LoadError::Invalid {
        loc: loc.clone(),
        element: element.into(),
        detail,
    };
    let name = &ji.name;
    if !finite_pose(&j.origin) {
        return Err(invalid(
            &ji.loc,
            "joint",
            format!(
                "joint '{name}': <origin> has a non-finite value (xyz {:?}, rpy {:?}); give finite numbers",
                j.origin.xyz.0, j.origin.rpy.0
            ),
        ));
    }
    let mut spec = JointSpec::new(name, ji.jtype, ji.loc.clone());
    spec.x_parent_joint = pose(&j.origin);
    let axis = j.axis.xyz.0;
    spec.axis = Vec3::new(axis[0], axis[1], axis[2]);
    if matches!(ji.jtype, JointType::Revolute | JointType::Prismatic) && ji.has_limit {
        let (lower, upper) = (j.limit.lower, j.limit.upper);
        // URDF ≥ 1.2 writes "no limit" as ±inf; both infinite means unlimited.
        let unlimited = index.version_1_2 && lower == f64::NEG_INFINITY && upper == f64::INFINITY;
        if lower.is_nan() || upper.is_nan() {
            return Err(invalid(
                &ji.loc,
                "joint",
                format!("joint '{name}': <limit lower=\"{lower}\" upper=\"{upper}\"> is not a number; give numbers"),
            ));
        }
        if !unlimited {
            spec.limits = Some([lower, upper]);
        }
    }
    // `--clamp-effort`: a positive, finite effort bounds the joint's torque (0 or none: unbounded).
    if options.clamp_effort && ji.has_limit && j.limit.effort.is_finite() && j.limit.effort > 0.0 {
        spec.effort_limit = Some(j.limit.effort);
    }
    if let Some(d) = &j.dynamics {
        for (what, v) in [("damping", d.damping), ("friction", d.friction)] {
            if !v.is_finite() || v < 0.0 {
                return Err(invalid(
                    &ji.loc,
                    "joint",
                    format!("joint '{name}': <dynamics {what}=\"{v}\"> must be a finite number ≥ 0; fix it"),
                ));
            }
        }
        spec.damping = d.damping;
        spec.friction = d.friction;
    }
    // The leader is resolved, and mimic chains checked, by the compile step.
    if let Some(m) = &j.mimic {
        let mimic = MimicSpec {
            leader: m.joint.clone(),
            multiplier: m.multiplier.unwrap_or(1.0),
            offset: m.offset.unwrap_or(0.0),
            loc: ji.mimic_loc.clone().unwrap_or_else(|| ji.loc.clone()),
        };
        if !mimic.multiplier.is_finite() || !mimic.offset.is_finite() {
            return Err(invalid(
                &mimic.loc,
                "mimic",
                format!("joint '{name}': <mimic> multiplier and offset must be finite numbers; fix them"),
            ));
        }
        spec.mimic = Some(mimic);
    }
    if let (Some(axis_loc), false) = (&ji.axis_loc, axis.iter().all(|x| x.is_finite())) {
        return Err(invalid(
            axis_loc,
            "axis",
            format!("joint '{name}': <axis> has a non-finite value ({axis:?}); give a finite nonzero axis"),
        ));
    }
    Ok(spec)
}

fn inertial_spec(i: &urdf_rs::Inertial, link: &str, loc: &SourceLoc) -> Result<InertialSpec, LoadError> {
    if !finite_pose(&i.origin) {
        return Err(LoadError::Invalid {
            loc: loc.clone(),
            element: "inertial".into(),
            detail: format!(
                "link '{link}': the <origin> of <inertial> has a non-finite value; give finite numbers"
            ),
        });
    }
    let t = &i.inertia;
    let inertia = Mat3::new(t.ixx, t.ixy, t.ixz, t.ixy, t.iyy, t.iyz, t.ixz, t.iyz, t.izz);
    Ok(InertialSpec { mass: i.mass.value, x_link_inertial: pose(&i.origin), inertia, loc: loc.clone() })
}

/// Visuals and collisions of a link in file order, meshes resolved to existing files.
fn geom_specs(
    link: &urdf_rs::Link,
    li: &LinkIndex,
    base: &Path,
    search_dirs: &[PathBuf],
    warnings: &mut Vec<String>,
) -> Result<Vec<GeomSpec>, LoadError> {
    let (mut visuals, mut collisions) = (link.visual.iter(), link.collision.iter());
    let mut geoms = Vec::with_capacity(li.geoms.len());
    for g in &li.geoms {
        let next = if g.collision {
            collisions.next().map(|c| (&c.origin, &c.geometry))
        } else {
            visuals.next().map(|v| (&v.origin, &v.geometry))
        };
        let Some((origin, geometry)) = next else {
            return Err(LoadError::Invalid {
                loc: g.loc.clone(),
                element: if g.collision { "collision" } else { "visual" }.into(),
                detail: format!(
                    "link '{}': the URDF reader (urdf-rs) lost this element (loader bug); please report it",
                    li.name
                ),
            });
        };
        let element = if g.collision { "collision" } else { "visual" };
        let bad = |detail: String| LoadError::Invalid {
            loc: g.loc.clone(),
            element: element.into(),
            detail: format!("link '{}': {detail}", li.name),
        };
        if !finite_pose(origin) {
            return Err(bad("the <origin> has a non-finite value; give finite numbers".into()));
        }
        let size_ok = |vals: &[f64]| vals.iter().all(|v| v.is_finite() && *v >= 0.0);
        let shape = match geometry {
            urdf_rs::Geometry::Box { size } => Shape::Box { size: Vec3::new(size[0], size[1], size[2]) },
            urdf_rs::Geometry::Cylinder { radius, length } => {
                Shape::Cylinder { radius: *radius, length: *length }
            }
            urdf_rs::Geometry::Capsule { radius, length } => {
                Shape::Capsule { radius: *radius, length: *length }
            }
            urdf_rs::Geometry::Sphere { radius } => Shape::Sphere { radius: *radius },
            urdf_rs::Geometry::Mesh { filename, scale } => {
                let scale = scale.map_or([1.0; 3], |s| s.0);
                if !scale.iter().all(|s| s.is_finite()) {
                    return Err(bad(format!(
                        "the <mesh> scale {scale:?} has a non-finite value; give finite numbers"
                    )));
                }
                let loc = g.mesh_loc.clone().unwrap_or_else(|| g.loc.clone());
                let path = match resolve_mesh(filename, &li.name, &loc, base, search_dirs) {
                    // A missing file of a visual mesh cannot change the dynamics: the visual is
                    // dropped with a warning (as Pinocchio's kinematic model ignores it).
                    Err(e @ LoadError::MeshNotFound { .. }) if !g.collision => {
                        warnings.push(format!("{e} [visual dropped]"));
                        continue;
                    }
                    other => other?,
                };
                Shape::Mesh { path, scale: Vec3::new(scale[0], scale[1], scale[2]) }
            }
        };
        let dims: Vec<f64> = match &shape {
            Shape::Box { size } => size.iter().copied().collect(),
            Shape::Cylinder { radius, length } | Shape::Capsule { radius, length } => vec![*radius, *length],
            Shape::Sphere { radius } => vec![*radius],
            // URDF has no ellipsoids, planes or height fields.
            Shape::Mesh { .. } | Shape::Ellipsoid { .. } | Shape::Plane { .. } | Shape::Hfield { .. } => {
                Vec::new()
            }
        };
        if !size_ok(&dims) {
            return Err(bad(format!(
                "the geometry has a negative or non-finite size {dims:?}; sizes must be ≥ 0"
            )));
        }
        geoms.push(GeomSpec { collision: g.collision, ..GeomSpec::new(shape, pose(origin), g.loc.clone()) });
    }
    Ok(geoms)
}

/// Resolves a `<mesh filename>` and checks that the file exists.
fn resolve_mesh(
    filename: &str,
    link: &str,
    loc: &SourceLoc,
    base: &Path,
    search_dirs: &[PathBuf],
) -> Result<PathBuf, LoadError> {
    match resolve_uri(filename, base, search_dirs) {
        Ok(path) if path.is_file() => Ok(path),
        Ok(path) => Err(LoadError::MeshNotFound {
            loc: loc.clone(),
            link: link.to_string(),
            path: path.display().to_string(),
        }),
        Err(ResolveError::PackageNotFound { package, searched }) => Err(LoadError::PackageNotFound {
            loc: loc.clone(),
            link: link.to_string(),
            uri: filename.to_string(),
            package,
            searched: searched.into(),
        }),
        Err(ResolveError::BadUri(detail)) => Err(LoadError::Invalid {
            loc: loc.clone(),
            element: "mesh".into(),
            detail: format!("link '{link}': {detail}"),
        }),
    }
}

/// Turns a urdf-rs failure into an error with a location: first look for the element whose
/// values urdf-rs cannot read; else use what the message names (a joint, a quoted value).
fn diagnose(doc: &Document, ctx: &Ctx, index: &Index, message: &str) -> LoadError {
    let robot = doc.root_element();
    if let Some(e) = check_values(robot, ctx, index.version_1_2) {
        return e;
    }
    let message = message.trim();
    let detail = format!("the URDF reader (urdf-rs) rejected the file: {message}; fix the element it names");
    // "joint [NAME]: ..." (urdf-rs's limit checks).
    if let Some(name) = message.split_once("joint [").and_then(|(_, r)| r.split_once(']')).map(|(n, _)| n) {
        if let Some(j) = index.joints.iter().find(|j| j.name == name) {
            return LoadError::Invalid { loc: j.loc.clone(), element: "joint".into(), detail };
        }
    }
    // "... ATTR ... [VALUE]" (urdf-rs's geometry and quat_xyzw checks name the attribute and
    // quote its value): the first element with that attribute and value.
    if let Some(value) = message.rsplit_once('[').and_then(|(_, r)| r.split_once(']')).map(|(v, _)| v.trim())
    {
        let culprit = |n: &Node| {
            n.is_element() && n.attributes().any(|a| a.value().trim() == value && message.contains(a.name()))
        };
        if let Some(node) = robot.descendants().find(culprit) {
            return ctx.invalid(node, detail);
        }
    }
    ctx.invalid(robot, detail)
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

/// Finds the first element (among those urdf-rs reads) with a missing or unreadable value.
fn check_values(robot: Node, ctx: &Ctx, version_1_2: bool) -> Option<LoadError> {
    for top in elements(robot) {
        let owner = format!("{} '{}'", top.tag_name().name(), top.attribute("name").unwrap_or(""));
        let kept: Vec<Node> = match top.tag_name().name() {
            "link" => elements(top)
                .filter(|c| matches!(c.tag_name().name(), "inertial" | "visual" | "collision"))
                .collect(),
            "joint" => elements(top).collect(),
            "material" => vec![top],
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
        "color" => (&[("rgba", 4, true)], &[]),
        "texture" => (&[("filename", 0, true)], &[]),
        "material" => (&[("name", 0, true)], &[]),
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
    for &child in children {
        if !elements(node).any(|c| c.tag_name().name() == child) {
            return Some(ctx.invalid(node, format!("{owner}: <{tag}> has no <{child}>; add one")));
        }
    }
    None
}
