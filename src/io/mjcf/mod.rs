//! MJCF loader (MuJoCo's XML format): file → [`ModelSpec`] (docs/architecture.md, "Layers"), with MuJoCo's
//! semantics.
//!
//! Passes: read the file into one element tree with `<include>`s spliced (`xml`); check every
//! element and attribute against MuJoCo's schema (`check`: unknown ones are warnings, elements
//! that would change the dynamics and are not supported are errors); read `<compiler>`; expand
//! `<replicate>`s and merge `<attach>`ed sub-models (`replicate`, `attach`); read `<option>`;
//! build the default classes (`defaults`); read the mesh assets (`assets`); walk `<worldbody>`
//! depth-first in file order into links (`body`, `geom`); read keyframes and
//! sensors (`sections`), equality constraints (`equality`), tendons (`tendon`), actuators
//! (`actuator`) and contact pairs and exclusions (`contact`), whose names the compile step
//! resolves.

mod actuator;
mod assets;
mod attach;
mod attrs;
mod body;
mod check;
mod contact;
mod defaults;
mod equality;
mod geom;
mod hfield;
mod mesh_builtin;
mod mesh_builtin_solid;
mod mesh_builtin_super;
mod mesh_inline;
mod orientation;
mod replicate;
mod schema;
mod schema_types;
mod sections;
mod tendon;
mod xml;

pub use replicate::{MAX_COPIES, MAX_SEP};

use super::{LoadError, LoadOptions};
use crate::model::spec::{MassRules, ModelSpec};
use orientation::AngleConvention;
use std::path::{Path, PathBuf};

/// `<compiler inertiafromgeom>`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum InertiaFromGeom {
    False,
    True,
    Auto,
}

/// What `<compiler>` says, as the loader needs it.
#[derive(Clone, Debug)]
pub(crate) struct Compiler {
    pub angles: AngleConvention,
    pub meshdir: PathBuf,
    pub autolimits: bool,
    pub inertia_from_geom: InertiaFromGeom,
    pub inertia_groups: [i64; 2],
    pub mass_rules: MassRules,
}

/// Parses an MJCF file into a spec.
pub fn parse_file(path: &Path, options: &LoadOptions) -> Result<ModelSpec, LoadError> {
    let root = xml::read_document(path)?;
    parse_root(&root, path, options)
}

/// Parses MJCF text (e.g. an embedded model); `path` names it and anchors relative paths.
pub fn parse_str(text: &str, path: &Path, options: &LoadOptions) -> Result<ModelSpec, LoadError> {
    let root = xml::read_text(text, path)?;
    parse_root(&root, path, options)
}

/// Actuators kept untyped must still name objects that exist (as MuJoCo requires); their names
/// are checked against all bodies, joints, geoms, sites and tendons. (Typed elements are resolved
/// by the compile step.)
fn check_targets(
    elements: &[crate::model::Element],
    links: &[crate::model::spec::LinkSpec],
    tendons: &[crate::model::spec::TendonSpec],
) -> Result<(), LoadError> {
    let mut names: std::collections::HashSet<&str> = std::collections::HashSet::new();
    for l in links {
        names.insert(&l.name);
        names.insert(&l.joint.name);
        names.extend(l.geoms.iter().map(|g| g.name.as_str()));
        names.extend(l.frames.iter().map(|f| f.name.as_str()));
    }
    names.extend(tendons.iter().map(|t| t.name.as_str()));
    for e in elements.iter().filter(|e| e.category == "actuator") {
        if let Some(t) = e.targets.iter().find(|t| !names.contains(t.as_str())) {
            return Err(LoadError::UnknownReference {
                loc: e.loc.clone(),
                element: e.kind.clone(),
                kind: "object (body, joint, geom, site or tendon)",
                target: t.clone(),
            });
        }
    }
    Ok(())
}

fn parse_root(root: &xml::Element, path: &Path, load: &LoadOptions) -> Result<ModelSpec, LoadError> {
    let mut warnings = check::check_tree(root)?;
    // The shared load options: each acts on MJCF too, or says that it does not apply.
    if load.floating {
        warnings.push(format!(
            "{}: LoadOptions::floating applies to URDF only: an MJCF model says which bodies float with <freejoint> (ignored)",
            path.display()
        ));
    }
    if load.clamp_effort {
        warnings.push(format!(
            "{}: LoadOptions::clamp_effort applies to URDF <limit effort> only: MJCF joints bound actuator forces with actuatorfrcrange (ignored)",
            path.display()
        ));
    }
    if !load.package_dirs.is_empty() {
        warnings.push(format!(
            "{}: LoadOptions::package_dirs applies to URDF package:// paths only: MJCF paths are relative to the model file or <compiler meshdir/assetdir> (ignored)",
            path.display()
        ));
    }
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let compiler = sections::compiler(root, &dir)?;
    // Composition (`<replicate>`, `<attach>`): expanded into plain elements first.
    let composed;
    let root = if attach::needed(root) {
        composed = attach::expand(root, &compiler, &dir, &mut warnings)?;
        &composed
    } else {
        root
    };
    let (options, gravity) = sections::options(root)?;
    let defaults = defaults::Defaults::build(root)?;
    let meshes = assets::meshes(root, &defaults, &compiler, &root.loc.file)?;
    let materials = assets::materials(root, &defaults)?;
    let mut builder = body::TreeBuilder::new(&compiler, &defaults, &meshes, &materials);
    builder.worldbody(root)?;
    hfield::resolve(&mut builder.links, &hfield::hfields(root, &compiler, &root.loc.file)?)?;
    warnings.append(&mut builder.warnings);
    let keyframes = sections::keyframes(root)?;
    let mut elements = sections::sensors(root)?;
    let equalities = equality::equalities(root, &defaults, &mut elements, &mut warnings)?;
    let tendons = tendon::tendons(root, &defaults, compiler.autolimits, &mut warnings)?;
    let actuators = actuator::actuators(root, &defaults, compiler.autolimits, &mut elements, &mut warnings)?;
    let lengthrange = actuator::lengthrange_options(root)?;
    let (contact_pairs, contact_excludes) = contact::contacts(root, &defaults)?;
    check_targets(&elements, &builder.links, &tendons)?;
    elements.append(&mut builder.kept);
    let name = root.attr("model").unwrap_or("MuJoCo Model").to_string();
    Ok(ModelSpec {
        name,
        source: Some(path.to_path_buf()),
        gravity,
        links: builder.links,
        mass_rules: MassRules {
            accept_nonphysical: load.accept_nonphysical_inertia,
            ..compiler.mass_rules.clone()
        },
        options,
        lengthrange,
        keyframes,
        equalities,
        tendons,
        actuators,
        contact_pairs,
        contact_excludes,
        elements,
        warnings,
        gravcomp: builder.gravcomp,
        sleep: builder.sleep,
    })
}
