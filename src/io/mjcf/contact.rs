//! `<contact>` → [`ContactPairSpec`]s and [`ContactExcludeSpec`]s (MuJoCo documentation, "XML
//! Reference → contact"). A `<pair>` takes the defaults of `<default><pair>` over MuJoCo's own
//! (`mjs_defaultPair`: condim 3, friction `1 1 0.005 0.0001 0.0001`, solref `0.02 1`, solimp
//! `0.9 0.95 0.001 0.5 2`, solreffriction `0 0`, margin and gap 0); partial vectors keep the
//! defaults of the entries not given. `<exclude>` has no defaults.

use super::attrs::Attrs;
use super::defaults::{Defaults, MAIN};
use super::xml::Element;
use crate::io::LoadError;
use crate::model::equality::{DEFAULT_SOLIMP, DEFAULT_SOLREF};
use crate::model::spec::{ContactExcludeSpec, ContactPairSpec};

/// MuJoCo's default pair friction: sliding (2), torsional, rolling (2).
const DEFAULT_FRICTION: [f64; 5] = [1.0, 1.0, 0.005, 0.0001, 0.0001];

/// Reads every `<contact>` section.
pub(crate) fn contacts(
    root: &Element,
    defaults: &Defaults,
) -> Result<(Vec<ContactPairSpec>, Vec<ContactExcludeSpec>), LoadError> {
    let (mut pairs, mut excludes) = (Vec::new(), Vec::new());
    for section in root.children_named("contact") {
        for e in &section.children {
            match e.tag.as_str() {
                "pair" => pairs.push(pair(e, defaults)?),
                "exclude" => {
                    let a = Attrs::plain(e);
                    excludes.push(ContactExcludeSpec {
                        name: a.text("name").unwrap_or("").to_string(),
                        body1: required(&a, "body1", "a body")?,
                        body2: required(&a, "body2", "a body")?,
                        loc: e.loc.clone(),
                    });
                }
                _ => {}
            }
        }
    }
    Ok((pairs, excludes))
}

fn required(a: &Attrs, name: &str, what: &str) -> Result<String, LoadError> {
    a.text(name).map(str::to_string).ok_or_else(|| a.error(name, format!("is missing; name {what}")))
}

fn pair(e: &Element, defaults: &Defaults) -> Result<ContactPairSpec, LoadError> {
    let a = defaults.resolve_as(e, "pair", MAIN)?;
    let class = defaults.class_defaults(e, "pair")?;
    let condim = a.int("condim")?.unwrap_or(3);
    if ![1, 3, 4, 6].contains(&condim) {
        return Err(a.error(
            "condim",
            format!("is {condim}; use 1 (frictionless), 3 (sliding), 4 (+ torsional) or 6 (+ rolling)"),
        ));
    }
    let mut friction = DEFAULT_FRICTION;
    a.fill_over(&class, "friction", &mut friction)?;
    let mut solref = DEFAULT_SOLREF;
    a.fill_over(&class, "solref", &mut solref)?;
    let mut solreffriction = [0.0; 2];
    a.fill_over(&class, "solreffriction", &mut solreffriction)?;
    let mut solimp = DEFAULT_SOLIMP;
    a.fill_over(&class, "solimp", &mut solimp)?;
    Ok(ContactPairSpec {
        name: a.text("name").unwrap_or("").to_string(),
        geom1: required(&a, "geom1", "a geom")?,
        geom2: required(&a, "geom2", "a geom")?,
        condim: condim as u32,
        friction,
        solref,
        solreffriction,
        solimp,
        margin: a.real("margin")?.unwrap_or(0.0),
        gap: a.real("gap")?.unwrap_or(0.0),
        loc: e.loc.clone(),
    })
}
