//! URDF loader: text → [`ModelSpec`] (docs/architecture.md, "Layers").
//!
//! One parse with `roxmltree` (its errors carry line and column). The loader first indexes every
//! `<link>` and `<joint>` (with their `<inertial>`, `<visual>`, `<collision>`, `<mesh>` and
//! `<axis>`) by source line, catching what needs a line to be reported well: missing names,
//! unknown joint types, joints without `<parent>`/`<child>`, duplicate names; then checks every
//! value it will read (`values`: missing or unreadable attributes, the URDF version's rules) and
//! reads them from the same tree. Finally the tree is checked (one root, no cycles, every link has
//! at most one parent joint) and the links are laid out in depth-first pre-order from the root, children in file order of their joints —
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
use crate::spatial::{Mat3, Vec3};
use roxmltree::{Document, Node, NodeId, ParsingOptions};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use values::{child, number, numbers, origin, Version};

mod values;

/// URDF joint type names and what they become. `spherical` is an extension (urdf-rs and some
/// exporters write it): a ball joint.
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
    if let Some(e) = values::check_values(doc.root_element(), &ctx, index.version_1_2) {
        return Err(e);
    }
    let tree = Tree::build(&index, &ctx)?;
    let mut spec = build_spec(&doc, &ctx, &index, &tree, path, options)?;
    spec.elements.extend(transmissions(&doc, &ctx));
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
    node: NodeId,
    collision: bool,
    loc: SourceLoc,
    /// Location of its `<mesh>`, if the geometry is a mesh.
    mesh_loc: Option<SourceLoc>,
}

/// What the first pass learned about a `<link>`.
struct LinkIndex {
    node: NodeId,
    name: String,
    loc: SourceLoc,
    inertial_loc: Option<SourceLoc>,
    /// Visuals and collisions in file order.
    geoms: Vec<GeomIndex>,
}

/// What the first pass learned about a `<joint>`.
struct JointIndex {
    node: NodeId,
    name: String,
    loc: SourceLoc,
    jtype: JointType,
    parent: String,
    child: String,
    axis_loc: Option<SourceLoc>,
    /// Location of its `<mimic>`, if any.
    mimic_loc: Option<SourceLoc>,
}

/// The positions of all links and joints (first pass, roxmltree).
struct Index {
    links: Vec<LinkIndex>,
    joints: Vec<JointIndex>,
    /// `version` of `<robot>`.
    version: Version,
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
        let version = Version::of(robot);
        let version_1_2 = version >= Version(1, 2);
        let mut index = Index { links: Vec::new(), joints: Vec::new(), version, version_1_2 };
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
    let mut link = LinkIndex {
        node: node.id(),
        name: name.to_string(),
        loc: ctx.loc(node),
        inertial_loc: None,
        geoms: Vec::new(),
    };
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
                    node: child.id(),
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
        node: node.id(),
        name: name.to_string(),
        loc,
        jtype,
        parent,
        child,
        axis_loc: elements(node).find(|c| is(c, "axis")).map(|a| ctx.loc(a)),
        mimic_loc: elements(node).find(|c| is(c, "mimic")).map(|m| ctx.loc(m)),
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

/// Reads the links and joints into the spec, in tree order.
fn build_spec(
    doc: &Document,
    ctx: &Ctx,
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
    let node = |id: NodeId| doc.get_node(id).expect("index of this document");

    let mut links = Vec::with_capacity(tree.order.len());
    for &li in &tree.order {
        let link_index = &index.links[li];
        let (parent, joint) = match tree.parent_joint[li] {
            Some(ji) => {
                let parent = spec_index[tree.joint_parent[ji]];
                let ji = &index.joints[ji];
                (Some(parent), joint_spec(ctx, node(ji.node), ji, index, options)?)
            }
            None => (None, root_joint(link_index, index, options)?),
        };
        let link_node = node(link_index.node);
        let inertial = match (&link_index.inertial_loc, child(link_node, "inertial")) {
            (Some(loc), Some(inertial)) => {
                Some(inertial_spec(ctx, inertial, index.version, &link_index.name, loc)?)
            }
            _ => None,
        };
        let geoms = geom_specs(ctx, doc, link_index, index.version, &base, &search_dirs, &mut warnings)?;
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
        name: doc.root_element().attribute("name").unwrap_or("").to_string(),
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

fn joint_spec(
    ctx: &Ctx,
    node: Node,
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
    let mut spec = JointSpec::new(name, ji.jtype, ji.loc.clone());
    spec.x_parent_joint = origin(ctx, node, index.version, &format!("joint '{name}'"))?;
    let axis = child(node, "axis").and_then(|a| numbers::<3>(a, "xyz")).unwrap_or([1.0, 0.0, 0.0]);
    spec.axis = Vec3::new(axis[0], axis[1], axis[2]);
    let limit = match child(node, "limit") {
        Some(l) => Some(values::limit(ctx, node, l, index.version, name)?),
        None => None,
    };
    if let (Some(limit), JointType::Revolute | JointType::Prismatic) = (&limit, ji.jtype) {
        let (lower, upper) = (limit.lower, limit.upper);
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
    if let Some(limit) =
        limit.as_ref().filter(|l| options.clamp_effort && l.effort.is_finite() && l.effort > 0.0)
    {
        spec.effort_limit = Some(limit.effort);
    }
    if let Some(d) = child(node, "dynamics") {
        for (what, slot) in [("damping", &mut spec.damping), ("friction", &mut spec.friction)] {
            let v = number(d, what).unwrap_or(0.0);
            if !v.is_finite() || v < 0.0 {
                return Err(invalid(
                    &ji.loc,
                    "joint",
                    format!("joint '{name}': <dynamics {what}=\"{v}\"> must be a finite number ≥ 0; fix it"),
                ));
            }
            *slot = v;
        }
    }
    // The leader is resolved, and mimic chains checked, by the compile step.
    if let Some(m) = child(node, "mimic") {
        let mimic = MimicSpec {
            leader: m.attribute("joint").unwrap_or("").to_string(),
            multiplier: number(m, "multiplier").unwrap_or(1.0),
            offset: number(m, "offset").unwrap_or(0.0),
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

fn inertial_spec(
    ctx: &Ctx,
    node: Node,
    version: Version,
    link: &str,
    loc: &SourceLoc,
) -> Result<InertialSpec, LoadError> {
    let x_link_inertial = origin(ctx, node, version, &format!("link '{link}': <inertial>"))?;
    let mass = child(node, "mass").and_then(|m| number(m, "value")).unwrap_or(0.0);
    let i = |name: &str| child(node, "inertia").and_then(|n| number(n, name)).unwrap_or(0.0);
    let (ixx, ixy, ixz, iyy, iyz, izz) = (i("ixx"), i("ixy"), i("ixz"), i("iyy"), i("iyz"), i("izz"));
    let inertia = Mat3::new(ixx, ixy, ixz, ixy, iyy, iyz, ixz, iyz, izz);
    Ok(InertialSpec { mass, x_link_inertial, inertia, loc: loc.clone() })
}

/// Visuals and collisions of a link in file order, meshes resolved to existing files. A visual
/// whose mesh cannot be found (missing file, unresolved `package://`) is dropped with a warning:
/// the engine never uses visual geometry for dynamics (as Pinocchio's kinematic model ignores it).
fn geom_specs(
    ctx: &Ctx,
    doc: &Document,
    li: &LinkIndex,
    version: Version,
    base: &Path,
    search_dirs: &[PathBuf],
    warnings: &mut Vec<String>,
) -> Result<Vec<GeomSpec>, LoadError> {
    let mut geoms = Vec::with_capacity(li.geoms.len());
    for g in &li.geoms {
        let node = doc.get_node(g.node).expect("index of this document");
        let element = if g.collision { "collision" } else { "visual" };
        let bad = |detail: String| LoadError::Invalid {
            loc: g.loc.clone(),
            element: element.into(),
            detail: format!("link '{}': {detail}", li.name),
        };
        let x_link_geom = origin(ctx, node, version, &format!("link '{}': <{element}>", li.name))?;
        // `check_values` made sure of exactly one known shape with readable sizes.
        let Some(shape_node) = child(node, "geometry").and_then(|g| elements(g).next()) else {
            return Err(bad("<geometry> holds no shape".into()));
        };
        let n = |name: &str| number(shape_node, name).unwrap_or(f64::NAN);
        let shape = match shape_node.tag_name().name() {
            "box" => {
                let size = numbers::<3>(shape_node, "size").unwrap_or([f64::NAN; 3]);
                Shape::Box { size: Vec3::new(size[0], size[1], size[2]) }
            }
            "cylinder" => Shape::Cylinder { radius: n("radius"), length: n("length") },
            "capsule" => Shape::Capsule { radius: n("radius"), length: n("length") },
            "sphere" => Shape::Sphere { radius: n("radius") },
            "mesh" => {
                let filename = shape_node.attribute("filename").unwrap_or("");
                let scale = numbers::<3>(shape_node, "scale").unwrap_or([1.0; 3]);
                if !scale.iter().all(|s| s.is_finite()) {
                    return Err(bad(format!(
                        "the <mesh> scale {scale:?} has a non-finite value; give finite numbers"
                    )));
                }
                let loc = g.mesh_loc.clone().unwrap_or_else(|| g.loc.clone());
                let path = match resolve_mesh(filename, &li.name, &loc, base, search_dirs) {
                    Err(e) if !g.collision => {
                        warnings.push(format!("{e} [visual dropped]"));
                        continue;
                    }
                    other => other?,
                };
                Shape::Mesh {
                    source: crate::mass::MeshSource::File(path),
                    scale: Vec3::new(scale[0], scale[1], scale[2]),
                }
            }
            other => return Err(bad(format!("unknown geometry <{other}>"))),
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
        if !dims.iter().all(|v| v.is_finite() && *v >= 0.0) {
            return Err(bad(format!(
                "the geometry has a negative or non-finite size {dims:?}; sizes must be ≥ 0"
            )));
        }
        geoms.push(GeomSpec { collision: g.collision, ..GeomSpec::new(shape, x_link_geom, g.loc.clone()) });
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
