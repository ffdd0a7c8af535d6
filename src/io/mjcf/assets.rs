//! `<asset>`: meshes (files, or inline `vertex`/`face` lists: [`super::mesh_inline`]; with their
//! default class, scale and inertia mode) and material colours
//! (`rgba`, which ray casting filters on) by name. Textures, the other material attributes and
//! height fields are accepted; they do not affect the dynamics.

use super::defaults::{Defaults, MAIN};
use super::xml::Element;
use super::Compiler;
use crate::io::LoadError;
use crate::mass::{MeshInertia, MeshSource};
use crate::spatial::Vec3;
use std::collections::HashMap;

/// A mesh asset: its file on disk or inline triangles, its scale and how MuJoCo computes its
/// inertia.
#[derive(Clone, Debug)]
pub struct MeshAsset {
    pub source: MeshSource,
    pub scale: Vec3,
    pub inertia: MeshInertia,
}

/// All `<mesh>` assets by name (a mesh without a name is named after its file, extension removed).
pub(crate) fn meshes(
    root: &Element,
    defaults: &Defaults,
    compiler: &Compiler,
    main_file: &str,
) -> Result<HashMap<String, MeshAsset>, LoadError> {
    let mut out = HashMap::new();
    for section in root.children_named("asset") {
        for e in section.children_named("mesh") {
            let a = defaults.resolve(e, MAIN)?;
            let mut inertia = match a.keyword("inertia", &["convex", "exact", "legacy", "shell"])?.as_deref()
            {
                Some("convex") => MeshInertia::Convex,
                Some("exact") => MeshInertia::Exact,
                Some("shell") => MeshInertia::Shell,
                _ => MeshInertia::Legacy,
            };
            let Some(file) = a.text("file") else {
                let (name, mesh) = match a.text("builtin") {
                    Some(shape) => {
                        // MuJoCo makes a built-in surface without volume `shell`.
                        let (name, mesh, mode) = super::mesh_builtin::builtin_mesh(e, &a, shape, inertia)?;
                        inertia = mode;
                        (name, mesh)
                    }
                    None => super::mesh_inline::inline_mesh(e, &a)?,
                };
                let scale = a.vec3("scale")?.unwrap_or(Vec3::repeat(1.0));
                out.insert(
                    name.clone(),
                    MeshAsset { source: MeshSource::Inline { name, mesh }, scale, inertia },
                );
                continue;
            };
            // MuJoCo looks in the mesh folder first, then (for a file pulled in by <include>)
            // next to the including file.
            let mut path = compiler.meshdir.join(file);
            if !path.is_file() && e.loc.file != main_file {
                if let Some(dir) = std::path::Path::new(&e.loc.file).parent() {
                    if dir.join(file).is_file() {
                        path = dir.join(file);
                    }
                }
            }
            if !path.is_file() {
                return Err(LoadError::AssetNotFound {
                    loc: e.loc.clone(),
                    element: "mesh".into(),
                    path: path.display().to_string(),
                });
            }
            let name = match a.text("name") {
                Some(n) => n.to_string(),
                None => {
                    let stem =
                        std::path::Path::new(file).file_stem().and_then(|s| s.to_str()).unwrap_or(file);
                    stem.to_string()
                }
            };
            for moved in ["refpos", "refquat"] {
                if a.has(moved) {
                    return Err(LoadError::Unsupported {
                        loc: e.loc.clone(),
                        element: "mesh".into(),
                        what: format!("'{moved}'"),
                        fix: "transform the mesh file instead, or place the geom with pos/quat".into(),
                    });
                }
            }
            let scale = a.vec3("scale")?.unwrap_or(Vec3::repeat(1.0));
            out.insert(name, MeshAsset { source: MeshSource::File(path), scale, inertia });
        }
    }
    Ok(out)
}

/// MuJoCo's default material colour (`mat_rgba`).
const DEFAULT_MATERIAL_RGBA: [f32; 4] = [1.0, 1.0, 1.0, 1.0];

/// The `rgba` of every named `<material>` (over its default class; MuJoCo's default 1 1 1 1).
pub(crate) fn materials(root: &Element, defaults: &Defaults) -> Result<HashMap<String, [f32; 4]>, LoadError> {
    let mut out = HashMap::new();
    for section in root.children_named("asset") {
        for e in section.children_named("material") {
            let a = defaults.resolve(e, MAIN)?;
            let Some(name) = a.text("name") else { continue };
            let rgba = a.array::<4>("rgba")?.map_or(DEFAULT_MATERIAL_RGBA, |c| c.map(|x| x as f32));
            out.insert(name.to_string(), rgba);
        }
    }
    Ok(out)
}
