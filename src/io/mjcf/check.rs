//! Checks the element tree against MuJoCo's MJCF schema ([`super::schema`]): value counts and
//! keywords of known attributes are errors when wrong (as in MuJoCo); unknown attributes and
//! elements are warnings with file:line; known elements this engine does not build and that would
//! change the dynamics (`composite`, `flexcomp`, `<deformable>` flexes, engine plugins on bodies,
//! geoms and meshes) are errors
//! that name the element, its line and what MuJoCo would do with it. (`replicate`, `attach` and
//! sub-model assets are composed by [`super::attach`]; skins only draw.)

use super::attrs::Attrs;
use super::schema_types::ElementSchema;
use super::xml::Element;
use crate::io::LoadError;

/// Elements MuJoCo knows that change the model's bodies or dynamics and are not built here: what
/// MuJoCo would do, and how to rewrite the model without them.
const UNSUPPORTED: [(&str, &str); 3] = [
    (
        "composite",
        "MuJoCo 4.0 rejects it too (\"unrecognized element\"; MuJoCo 3 generated a cable, rope or grid of bodies, joints and tendons from it); write those bodies out, or compile the model with MuJoCo 3 and save it (mj_saveLastXML)",
    ),
    (
        "flexcomp",
        "MuJoCo would generate a deformable flex with its vertex bodies; flexible bodies are not simulated here: remove it",
    ),
    (
        "flex",
        "MuJoCo would simulate a deformable flex between bodies; flexible bodies are not simulated here: remove it",
    ),
];

/// Checks the whole tree; returns the warnings.
pub(crate) fn check_tree(root: &Element) -> Result<Vec<String>, LoadError> {
    let mut warnings = Vec::new();
    let decl = ElementSchema::get("mujoco").expect("the schema has <mujoco>");
    check(root, decl, &mut warnings)?;
    Ok(warnings)
}

fn check(e: &Element, decl: &ElementSchema, warnings: &mut Vec<String>) -> Result<(), LoadError> {
    let a = Attrs::plain(e);
    for name in a.check(decl)? {
        warnings.push(format!("{}: <{}>: unknown attribute '{name}' ignored", e.loc, e.tag));
    }
    for child in &e.children {
        let child_decl = if decl.name == "mujoco" && child.tag == "worldbody" {
            ElementSchema::get("worldbody")
        } else {
            decl.child(&child.tag)
        };
        // A flex equality is kept as a listed element (see `equality`); the flex it names is the
        // error.
        let flex_equality = e.tag == "equality" && child.tag == "flex";
        if let Some((_, fix)) = UNSUPPORTED.iter().find(|(t, _)| *t == child.tag) {
            if child_decl.is_some() && !flex_equality {
                return Err(LoadError::Unsupported {
                    loc: child.loc.clone(),
                    element: child.tag.clone(),
                    what: format!("<{}>", child.tag),
                    fix: fix.to_string(),
                });
            }
        }
        if child.tag == "plugin" && matches!(e.tag.as_str(), "body" | "worldbody" | "frame" | "geom" | "mesh")
        {
            return Err(LoadError::Unsupported {
                loc: child.loc.clone(),
                element: child.tag.clone(),
                what: format!("an engine plugin in <{}>", e.tag),
                fix: format!(
                    "MuJoCo would run plugin '{}' ({}); plugins are not run here: remove the <plugin> (and its <extension>)",
                    child.attr("plugin").or(child.attr("instance")).unwrap_or("?"),
                    if e.tag == "mesh" || e.tag == "geom" { "a signed-distance shape" } else { "forces on the body" }
                ),
            });
        }
        match child_decl {
            Some(d) => check(child, d, warnings)?,
            None => warnings
                .push(format!("{}: unknown element <{}> in <{}> ignored", child.loc, child.tag, e.tag)),
        }
    }
    Ok(())
}
