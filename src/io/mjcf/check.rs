//! Checks the element tree against MuJoCo's MJCF schema ([`super::schema`]): value counts and
//! keywords of known attributes are errors when wrong (as in MuJoCo); unknown attributes and
//! elements are warnings with file:line; known elements this engine does not build and that would
//! change the dynamics (`replicate`, `attach`, `composite`, `flexcomp`, `<deformable>` flexes,
//! sub-model assets) are errors that say so.

use super::attrs::Attrs;
use super::schema_types::ElementSchema;
use super::xml::Element;
use crate::io::LoadError;

/// Elements MuJoCo knows that change the model's bodies or dynamics and are not built here.
const UNSUPPORTED: [(&str, &str); 6] = [
    ("replicate", "write the repeated bodies out"),
    ("attach", "paste the attached model's bodies into this file"),
    ("composite", "expand the composite into bodies and joints"),
    ("flexcomp", "flexible bodies are not simulated; remove it"),
    ("flex", "flexible bodies are not simulated; remove it"),
    ("model", "paste the sub-model's bodies into this file"),
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
        match child_decl {
            Some(d) => check(child, d, warnings)?,
            None => warnings
                .push(format!("{}: unknown element <{}> in <{}> ignored", child.loc, child.tag, e.tag)),
        }
    }
    Ok(())
}
