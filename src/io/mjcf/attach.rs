//! Model composition before the readers run: `<replicate>`s expanded ([`super::replicate`]) and
//! every `<attach model body prefix>` replaced by the sub-model it names (`<asset><model name
//! file>`), as MuJoCo 4.0's `mjs_attach` merges a child spec (user_api.cc; xml_native_reader.cc,
//! "attachment"):
//!
//! - the child file is read, checked and composed on its own (its includes, replicates and
//!   attaches), with its own `<compiler>` (mesh folder; its angle unit must agree with the
//!   parent's, see below);
//! - the attached body's subtree (or, without `body`, everything in the child's `<worldbody>`)
//!   takes the `<attach>`'s place, inside a frame at the attach point;
//! - every name and every reference in what is copied gets the prefix (bodies, joints, geoms,
//!   sites, tendons, actuators, sensors, meshes, materials, textures, default classes); `world`
//!   stays `world`; unnamed elements stay unnamed;
//! - the child's default classes come along under the prefix, its top-level class as
//!   `{prefix}main`, which starts from MuJoCo's built-in defaults (not the parent's `main`): the
//!   copied elements resolve their attributes exactly as in the child model;
//! - the child's assets, tendons, equalities, contact pairs and exclusions, actuators and sensors
//!   are appended after the parent's (MuJoCo's order), each only when every object it names is
//!   in the attached subtree (or is the world), as MuJoCo drops the others.
//!
//! Not merged (warned): the child's keyframes (MuJoCo would add them under the prefix, laid out
//! on the merged qpos), and its `<option>`/`<size>` (MuJoCo's default conflict policy keeps the
//! parent's values, with a warning, as here). A child whose `<compiler angle/eulerseq>` differs
//! from the parent's is refused (its angles would need converting). Self-attach (no `model`) and
//! attaching a `frame` are refused with the fix.

use super::orientation::AngleConvention;
use super::replicate;
use super::xml::{self, Element};
use super::{check, sections, Compiler};
use crate::io::LoadError;
use crate::model::SourceLoc;
use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};

/// The tag under which an attached model's default class tree is handed to
/// [`super::defaults::Defaults::build`]: a root class (`{prefix}main`) over MuJoCo's built-in
/// defaults. (Not an MJCF tag: it cannot come from a file.)
pub(crate) const ATTACHED_DEFAULTS: &str = "default:attached";

/// Resource limit: how deep attached models may nest (a model attaching itself is caught here).
pub const MAX_ATTACH_DEPTH: usize = 16;

/// Attributes that name another element (or a class, or the element itself): prefixed on attach.
const NAME_ATTRS: [&str; 31] = [
    "name",
    "class",
    "childclass",
    "joint",
    "body",
    "geom",
    "site",
    "tendon",
    "actuator",
    "mesh",
    "material",
    "texture",
    "hfield",
    "objname",
    "refname",
    "body1",
    "body2",
    "geom1",
    "geom2",
    "joint1",
    "joint2",
    "site1",
    "site2",
    "tendon1",
    "tendon2",
    "cranksite",
    "slidersite",
    "jointinparent",
    "refsite",
    "sidesite",
    "target",
];

/// Of [`NAME_ATTRS`], those naming objects of the body tree or of the model's sections (an
/// element is copied only when all of these are in the attached subtree).
const OBJECT_ATTRS: [&str; 25] = [
    "joint",
    "body",
    "geom",
    "site",
    "tendon",
    "actuator",
    "objname",
    "refname",
    "body1",
    "body2",
    "geom1",
    "geom2",
    "joint1",
    "joint2",
    "site1",
    "site2",
    "tendon1",
    "tendon2",
    "cranksite",
    "slidersite",
    "jointinparent",
    "refsite",
    "sidesite",
    "target",
    "flex",
];

/// Elements that take a default class (`class`, else the class they inherit): a copied one without
/// `class` is given the child's top-level class.
const CLASSED: [&str; 26] = [
    "joint",
    "geom",
    "site",
    "camera",
    "light",
    "mesh",
    "material",
    "pair",
    "connect",
    "weld",
    "tendon",
    "distance",
    "fixed",
    "spatial",
    "general",
    "motor",
    "position",
    "velocity",
    "intvelocity",
    "damper",
    "cylinder",
    "muscle",
    "adhesion",
    "dcmotor",
    "pid",
    "orientation",
];

/// Sections of the child appended after the parent's, in the order their references need
/// (actuators name tendons, sensors name actuators).
const SECTIONS: [&str; 5] = ["tendon", "equality", "contact", "actuator", "sensor"];

/// Whether `root` uses composition (`<replicate>`, `<attach>` or a `<model>` asset).
pub(crate) fn needed(root: &Element) -> bool {
    fn any(e: &Element) -> bool {
        e.children.iter().any(|c| matches!(c.tag.as_str(), "replicate" | "attach" | "model") || any(c))
    }
    any(root)
}

/// `root` (the model file at `dir`, with `compiler`) with its replicates expanded and attaches
/// merged; warnings for what is not merged go to `warnings`.
pub(crate) fn expand(
    root: &Element,
    compiler: &Compiler,
    dir: &Path,
    warnings: &mut Vec<String>,
) -> Result<Element, LoadError> {
    expand_at(root, compiler, dir, 0, warnings)
}

fn expand_at(
    root: &Element,
    compiler: &Compiler,
    dir: &Path,
    depth: usize,
    warnings: &mut Vec<String>,
) -> Result<Element, LoadError> {
    let mut root = root.clone();
    replicate::expand(&mut root, &compiler.angles)?;
    let models = sub_models(&mut root, dir)?;
    let mut ctx = Ctx {
        models,
        compiler,
        depth,
        warnings,
        cache: HashMap::new(),
        shared: HashSet::new(),
        merged: Vec::new(),
    };
    for wb in root.children.iter_mut().filter(|c| c.tag == "worldbody") {
        ctx.walk(wb)?;
    }
    let merged = std::mem::take(&mut ctx.merged);
    root.children.extend(merged);
    Ok(root)
}

/// The `<model>` assets by name (file relative to the model's folder), removed from `<asset>`.
fn sub_models(root: &mut Element, dir: &Path) -> Result<HashMap<String, (PathBuf, SourceLoc)>, LoadError> {
    let mut out = HashMap::new();
    for section in root.children.iter_mut().filter(|c| c.tag == "asset") {
        for m in section.children.iter().filter(|c| c.tag == "model") {
            let (Some(name), Some(file)) = (m.attr("name"), m.attr("file")) else {
                return Err(LoadError::Invalid {
                    loc: m.loc.clone(),
                    element: "model".into(),
                    detail: "a sub-model asset needs 'name' and 'file': <model name=\"gripper\" file=\"gripper.xml\"/>"
                        .into(),
                });
            };
            if out.insert(name.to_string(), (dir.join(file), m.loc.clone())).is_some() {
                return Err(LoadError::DuplicateName {
                    loc: m.loc.clone(),
                    element: "model",
                    name: name.into(),
                });
            }
        }
        section.children.retain(|c| c.tag != "model");
    }
    Ok(out)
}

/// A composed child model: its root (replicates and its own attaches merged) and compiler.
struct Child {
    root: Element,
    compiler: Compiler,
    dir: PathBuf,
}

struct Ctx<'a> {
    models: HashMap<String, (PathBuf, SourceLoc)>,
    compiler: &'a Compiler,
    depth: usize,
    warnings: &'a mut Vec<String>,
    cache: HashMap<String, std::rc::Rc<Child>>,
    /// The (model, prefix) already attached: their classes and assets are merged once (the
    /// copies of a replicated `<attach>` share them, as in MuJoCo).
    shared: HashSet<(String, String)>,
    /// Root-level elements to append (per attach: its default classes, assets and sections).
    merged: Vec<Element>,
}

impl Ctx<'_> {
    /// Replaces the `<attach>`es below `e` (bodies and frames, in file order).
    fn walk(&mut self, e: &mut Element) -> Result<(), LoadError> {
        for c in e.children.iter_mut() {
            if c.tag == "attach" {
                *c = self.attach(c)?;
            } else if matches!(c.tag.as_str(), "body" | "frame") {
                self.walk(c)?;
            }
        }
        Ok(())
    }

    fn child(&mut self, model: &str, at: &Element) -> Result<std::rc::Rc<Child>, LoadError> {
        if let Some(c) = self.cache.get(model) {
            return Ok(c.clone());
        }
        let Some((path, _)) = self.models.get(model) else {
            return Err(LoadError::UnknownReference {
                loc: at.loc.clone(),
                element: "attach".into(),
                kind: "sub-model (<asset><model name>)",
                target: model.to_string(),
            });
        };
        if self.depth >= MAX_ATTACH_DEPTH {
            return Err(LoadError::Invalid {
                loc: at.loc.clone(),
                element: "attach".into(),
                detail: format!(
                    "attached models nest more than {MAX_ATTACH_DEPTH} deep (does '{}' attach itself?)",
                    path.display()
                ),
            });
        }
        let raw = xml::read_document(path)?;
        self.warnings.extend(check::check_tree(&raw)?);
        let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        let compiler = sections::compiler(&raw, &dir)?;
        if !same_angles(&compiler.angles, &self.compiler.angles) {
            return Err(LoadError::Unsupported {
                loc: at.loc.clone(),
                element: "attach".into(),
                what: format!(
                    "attaching '{}', whose <compiler angle/eulerseq> differ from this model's,",
                    path.display()
                ),
                fix: "MuJoCo would convert the child's angles; give both files the same <compiler angle=... eulerseq=...>".into(),
            });
        }
        if compiler.autolimits != self.compiler.autolimits
            || compiler.inertia_from_geom != self.compiler.inertia_from_geom
            || compiler.inertia_groups != self.compiler.inertia_groups
        {
            self.warnings.push(format!(
                "{}: <attach model=\"{model}\">: the attached model's <compiler> autolimits/inertiafromgeom/inertiagrouprange differ from this model's; this model's apply to it",
                at.loc
            ));
        }
        let root = expand_at(&raw, &compiler, &dir, self.depth + 1, self.warnings)?;
        for e in &root.children {
            let set: Vec<&str> = match e.tag.as_str() {
                "option" | "size" => e.attrs.iter().map(|(k, _)| k.as_str()).collect(),
                _ => continue,
            };
            if !set.is_empty() || !e.children.is_empty() {
                self.warnings.push(format!(
                    "{}: <{}> of the attached model '{model}' is not merged: this model's values apply (MuJoCo's default conflict policy keeps the parent's)",
                    e.loc, e.tag
                ));
            }
        }
        let c = std::rc::Rc::new(Child { root, compiler, dir });
        self.cache.insert(model.to_string(), c.clone());
        Ok(c)
    }

    /// The frame that replaces `<attach>` `at`; queues the child's classes, assets and sections.
    fn attach(&mut self, at: &Element) -> Result<Element, LoadError> {
        let invalid = |detail: &str| LoadError::Invalid {
            loc: at.loc.clone(),
            element: "attach".into(),
            detail: detail.to_string(),
        };
        let Some(model) = at.attr("model") else {
            return Err(LoadError::Unsupported {
                loc: at.loc.clone(),
                element: "attach".into(),
                what: "self-attach (an <attach> without 'model')".into(),
                fix: "MuJoCo would copy a subtree of this model; put the subtree in a file of its own and attach it with <asset><model>".into(),
            });
        };
        if at.attr("frame").is_some() {
            return Err(LoadError::Unsupported {
                loc: at.loc.clone(),
                element: "attach".into(),
                what: "attaching a <frame> of the sub-model".into(),
                fix: "MuJoCo would copy the frame's contents; attach a body (body=...) or the whole model (no body)".into(),
            });
        }
        let Some(prefix) = at.attr("prefix") else {
            return Err(invalid(
                "missing attribute 'prefix' (MuJoCo requires it; it is prepended to every name copied)",
            ));
        };
        let prefix = prefix.to_string();
        // The suffixes of the replicates around this attach (`replicate::ATTACH_SUFFIX`).
        let suffix = at.attr(replicate::ATTACH_SUFFIX).unwrap_or("").to_string();
        let first = self.shared.insert((model.to_string(), prefix.clone()));
        let child = self.child(model, at)?;

        // The subtree and the class it inherits in the child.
        let (subtree, inherited): (Vec<Element>, String) = match at.attr("body") {
            Some(body) => {
                let found = child
                    .root
                    .children
                    .iter()
                    .filter(|c| c.tag == "worldbody")
                    .find_map(|wb| find_body(wb, body, super::defaults::MAIN));
                let Some((b, class)) = found else {
                    return Err(LoadError::UnknownReference {
                        loc: at.loc.clone(),
                        element: "attach".into(),
                        kind: "body of the sub-model",
                        target: body.to_string(),
                    });
                };
                (vec![b.clone()], class)
            }
            None => (
                child
                    .root
                    .children
                    .iter()
                    .filter(|c| c.tag == "worldbody")
                    .flat_map(|wb| wb.children.iter().cloned())
                    .collect(),
                super::defaults::MAIN.to_string(),
            ),
        };
        let mut inside: HashSet<String> = HashSet::new();
        for e in &subtree {
            collect_names(e, &mut inside);
        }
        inside.insert("world".into());

        // Default classes: the child's top level becomes `{prefix}main`; classes of models it
        // attached itself come along.
        let mut defaults = Element {
            tag: ATTACHED_DEFAULTS.into(),
            attrs: vec![("class".into(), super::defaults::MAIN.into())],
            children: Vec::new(),
            loc: at.loc.clone(),
        };
        let mut queued = Vec::new();
        for e in child.root.children.iter().filter(|_| first) {
            match e.tag.as_str() {
                "default" => defaults.children.extend(e.children.iter().cloned()),
                ATTACHED_DEFAULTS => queued.push(e.clone()),
                _ => {}
            }
        }
        if first {
            queued.insert(0, defaults);
        }

        // Assets: all of them, files made absolute (the child's mesh folder).
        let mut assets =
            Element { tag: "asset".into(), attrs: vec![], children: vec![], loc: at.loc.clone() };
        for section in child.root.children.iter().filter(|c| first && c.tag == "asset") {
            for a in &section.children {
                let mut a = a.clone();
                if let Some(file) = a.attr("file").map(str::to_string) {
                    let base = if a.tag == "mesh" { &child.compiler.meshdir } else { &child.dir };
                    let abs = base.join(&file);
                    if a.tag == "mesh" && a.attr("name").is_none() {
                        let stem = Path::new(&file).file_stem().and_then(|s| s.to_str()).unwrap_or(&file);
                        a.attrs.push(("name".into(), stem.to_string()));
                    }
                    set_attr(&mut a, "file", abs.to_string_lossy().into_owned());
                }
                assets.children.push(a);
            }
        }
        queued.push(assets);

        // Sections: the elements whose objects were all copied.
        for tag in SECTIONS {
            let mut out = Element { tag: tag.into(), attrs: vec![], children: vec![], loc: at.loc.clone() };
            for section in child.root.children.iter().filter(|c| c.tag == tag) {
                for e in &section.children {
                    if refs_inside(e, &inside) {
                        if let Some(n) = e.attr("name") {
                            inside.insert(n.to_string());
                        }
                        out.children.push(e.clone());
                    }
                }
            }
            queued.push(out);
        }
        for k in child
            .root
            .children
            .iter()
            .filter(|c| first && c.tag == "keyframe")
            .flat_map(|s| s.children.iter())
        {
            self.warnings.push(format!(
                "{}: keyframe '{}' of the attached model '{model}' is not merged (MuJoCo 4.0 would add it as '{prefix}{}' on the merged qpos); write the key in this model",
                k.loc,
                k.attr("name").unwrap_or(""),
                k.attr("name").unwrap_or("")
            ));
        }

        // Classes of the copies, then the prefix on every name.
        for q in &mut queued {
            if q.tag != ATTACHED_DEFAULTS {
                for e in &mut q.children {
                    give_class(e);
                }
            }
            prefix_names(q, &prefix);
            if !SHARED_TAGS.contains(&q.tag.as_str()) {
                suffix_names(q, &suffix);
            }
        }
        self.merged.extend(queued);
        let mut frame = Element {
            tag: "frame".into(),
            attrs: vec![("childclass".into(), inherited)],
            children: subtree,
            loc: at.loc.clone(),
        };
        prefix_names(&mut frame, &prefix);
        suffix_names(&mut frame, &suffix);
        Ok(frame)
    }
}

fn same_angles(a: &AngleConvention, b: &AngleConvention) -> bool {
    a.to_radians == b.to_radians && a.eulerseq == b.eulerseq
}

/// The body named `name` below `e` and the class it inherits (the nearest enclosing `childclass`).
fn find_body<'e>(e: &'e Element, name: &str, class: &str) -> Option<(&'e Element, String)> {
    for c in &e.children {
        if !matches!(c.tag.as_str(), "body" | "frame") {
            continue;
        }
        if c.tag == "body" && c.attr("name") == Some(name) {
            return Some((c, class.to_string()));
        }
        let inner = c.attr("childclass").unwrap_or(class);
        if let Some(found) = find_body(c, name, inner) {
            return Some(found);
        }
    }
    None
}

fn collect_names(e: &Element, out: &mut HashSet<String>) {
    if let Some(n) = e.attr("name") {
        out.insert(n.to_string());
    }
    for c in &e.children {
        collect_names(c, out);
    }
}

/// Whether every object `e` (and its children: a tendon's path) names is in `inside`.
fn refs_inside(e: &Element, inside: &HashSet<String>) -> bool {
    e.attrs.iter().all(|(k, v)| !OBJECT_ATTRS.contains(&k.as_str()) || v.is_empty() || inside.contains(v))
        && e.children.iter().all(|c| refs_inside(c, inside))
}

/// Gives a copied element that takes a default class the child's top-level class when it has none.
fn give_class(e: &mut Element) {
    if CLASSED.contains(&e.tag.as_str()) && e.attr("class").is_none() {
        e.attrs.push(("class".into(), super::defaults::MAIN.into()));
    }
}

/// Prefixes every name and reference in the subtree (`world` excepted).
fn prefix_names(e: &mut Element, prefix: &str) {
    for (k, v) in &mut e.attrs {
        if NAME_ATTRS.contains(&k.as_str()) && !v.is_empty() && !(v == "world" && k != "name") {
            *v = format!("{prefix}{v}");
        }
    }
    for c in &mut e.children {
        prefix_names(c, prefix);
    }
}

/// The merged sections a replicated attach shares among its copies (no suffix).
const SHARED_TAGS: [&str; 2] = [ATTACHED_DEFAULTS, "asset"];

/// Names that a replicate's suffix leaves alone: classes and assets are shared by the copies.
const SHARED_REFS: [&str; 6] = ["class", "childclass", "mesh", "material", "texture", "hfield"];

/// Appends a replicate's `suffix` to every name and reference of the copied elements (`world`,
/// classes and assets excepted).
fn suffix_names(e: &mut Element, suffix: &str) {
    if suffix.is_empty() {
        return;
    }
    for (k, v) in &mut e.attrs {
        let named = NAME_ATTRS.contains(&k.as_str()) && !SHARED_REFS.contains(&k.as_str());
        if named && !v.is_empty() && !(v == "world" && k != "name") {
            v.push_str(suffix);
        }
    }
    for c in &mut e.children {
        suffix_names(c, suffix);
    }
}

fn set_attr(e: &mut Element, name: &str, value: String) {
    match e.attrs.iter_mut().find(|(k, _)| k == name) {
        Some(slot) => slot.1 = value,
        None => e.attrs.push((name.to_string(), value)),
    }
}
