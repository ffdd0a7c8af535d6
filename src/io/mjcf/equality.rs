//! `<equality>` → [`EqualitySpec`]s (MuJoCo documentation, "XML Reference → equality"), with the
//! defaults of `<default><equality>` (`active`, `solref`, `solimp`).
//!
//! - `connect`: `body1` + `anchor` (a point in body1 coordinates; `body2` absent = the world), or
//!   `site1` + `site2` (the two site origins coincide).
//! - `weld`: `body1` (+ `body2`, `anchor` in body2 coordinates, `relpose` = pos + quat of body2's
//!   anchor frame in body1; MuJoCo's default `0 1 0 0 0 0 0` has an all-zero quaternion, which
//!   means "take it at `qpos0`"), or `site1` + `site2`; `torquescale` (default 1).
//! - `joint`: `joint1`, `joint2`, `polycoef` (default `0 1 0 0 0`; fewer values keep the
//!   defaults of the rest, as MuJoCo reads it).
//! - `tendon`: `tendon1`, `tendon2`, `polycoef`.
//!
//! The names are resolved, and the objects checked, by the compile step. Flex equalities are
//! kept as listed elements with a warning: flexes are not built.

use super::attrs::Attrs;
use super::defaults::{Defaults, MAIN};
use super::xml::Element;
use crate::io::LoadError;
use crate::model::equality::{DEFAULT_SOLIMP, DEFAULT_SOLREF};
use crate::model::spec::{EqualitySpec, EqualitySpecKind};
use crate::model::Element as KeptElement;
use crate::spatial::{quat_to_matrix, Transform, Vec3};

/// MuJoCo's default `polycoef`: the identity coupling `y = x`.
const DEFAULT_POLYCOEF: [f64; 5] = [0.0, 1.0, 0.0, 0.0, 0.0];

/// Reads every `<equality>` section: typed constraints, and the flex equalities (kept, listed,
/// with a warning each).
pub(crate) fn equalities(
    root: &Element,
    defaults: &Defaults,
    kept: &mut Vec<KeptElement>,
    warnings: &mut Vec<String>,
) -> Result<Vec<EqualitySpec>, LoadError> {
    let mut out = Vec::new();
    for section in root.children_named("equality") {
        for e in &section.children {
            let a = defaults.resolve_as(e, "equality", MAIN)?;
            let kind = match e.tag.as_str() {
                "connect" => connect(&a)?,
                "weld" => weld(&a)?,
                "joint" => {
                    let polycoef = polycoef(&a, defaults, e)?;
                    EqualitySpecKind::Joint {
                        joint1: required(&a, "joint1")?,
                        joint2: a.text("joint2").map(str::to_string),
                        polycoef,
                    }
                }
                "tendon" => {
                    let polycoef = polycoef(&a, defaults, e)?;
                    EqualitySpecKind::Tendon {
                        tendon1: required(&a, "tendon1")?,
                        tendon2: a.text("tendon2").map(str::to_string),
                        polycoef,
                    }
                }
                other => {
                    warnings.push(format!(
                        "{}: <{other}>: flex equality constraints are not simulated (flexes are not built); kept as a listed element",
                        e.loc
                    ));
                    kept.push(KeptElement {
                        category: "equality".into(),
                        kind: other.to_string(),
                        name: a.text("name").unwrap_or("").to_string(),
                        targets: a.text("flex").map(str::to_string).into_iter().collect(),
                        attributes: a.values.clone(),
                        loc: e.loc.clone(),
                    });
                    continue;
                }
            };
            let class = defaults.class_defaults(e, "equality")?;
            let mut solref = DEFAULT_SOLREF;
            a.fill_over(&class, "solref", &mut solref)?;
            let mut solimp = DEFAULT_SOLIMP;
            a.fill_over(&class, "solimp", &mut solimp)?;
            out.push(EqualitySpec {
                name: a.text("name").unwrap_or("").to_string(),
                kind,
                active: a.bool("active")?.unwrap_or(true),
                solref,
                solimp,
                loc: e.loc.clone(),
            });
        }
    }
    Ok(out)
}

/// A required name attribute.
fn required(a: &Attrs, name: &str) -> Result<String, LoadError> {
    a.text(name).map(str::to_string).ok_or_else(|| a.error(name, "is missing; name the object it constrains"))
}

/// `polycoef` over MuJoCo's default `0 1 0 0 0`, 1 to 5 values.
fn polycoef(a: &Attrs, defaults: &Defaults, e: &Element) -> Result<[f64; 5], LoadError> {
    let mut c = DEFAULT_POLYCOEF;
    a.fill_over(&defaults.class_defaults(e, "equality")?, "polycoef", &mut c)?;
    Ok(c)
}

/// Whether the element uses the site form (`site1`/`site2`) or the body form; mixing them is an
/// error, as in MuJoCo's schema.
fn uses_sites(a: &Attrs, body_attrs: &[&str]) -> Result<bool, LoadError> {
    let site = ["site1", "site2"].into_iter().find(|n| a.has(n));
    let body = body_attrs.iter().copied().find(|n| a.has(n));
    match (site, body) {
        (Some(s), Some(b)) => Err(a.error(
            b,
            format!(
                "cannot be combined with '{s}': use the site form (site1, site2) or the body form ({})",
                body_attrs.join(", ")
            ),
        )),
        (Some(_), None) => Ok(true),
        _ => Ok(false),
    }
}

/// Both sites of the site form.
fn sites(a: &Attrs) -> Result<(String, String), LoadError> {
    let get = |n: &str| {
        a.text(n)
            .map(str::to_string)
            .ok_or_else(|| a.error(n, "is missing: the site form needs site1 and site2"))
    };
    Ok((get("site1")?, get("site2")?))
}

fn connect(a: &Attrs) -> Result<EqualitySpecKind, LoadError> {
    if uses_sites(a, &["body1", "body2", "anchor"])? {
        let (site1, site2) = sites(a)?;
        return Ok(EqualitySpecKind::ConnectSites { site1, site2 });
    }
    let missing = |n: &str| {
        a.error(n, "is missing: give body1 and anchor (body2 defaults to the world), or site1 and site2")
    };
    let body1 = a.text("body1").ok_or_else(|| missing("body1"))?.to_string();
    let anchor = a.array::<3>("anchor")?.ok_or_else(|| missing("anchor"))?;
    Ok(EqualitySpecKind::ConnectBodies { body1, body2: a.text("body2").map(str::to_string), anchor })
}

fn weld(a: &Attrs) -> Result<EqualitySpecKind, LoadError> {
    let torquescale = a.real("torquescale")?.unwrap_or(1.0);
    if uses_sites(a, &["body1", "body2", "anchor", "relpose"])? {
        let (site1, site2) = sites(a)?;
        return Ok(EqualitySpecKind::WeldSites { site1, site2, torquescale });
    }
    let body1 = a
        .text("body1")
        .ok_or_else(|| {
            a.error("body1", "is missing: give body1 (body2 defaults to the world), or site1 and site2")
        })?
        .to_string();
    let anchor = a.array::<3>("anchor")?.unwrap_or([0.0; 3]);
    // An all-zero quaternion (MuJoCo's default) means: the relative pose at qpos0; the
    // position part is then ignored, as in MuJoCo.
    let relpose = match a.array::<7>("relpose")? {
        Some(r) => super::orientation::unit_quaternion([r[3], r[4], r[5], r[6]])
            .map(|[w, x, y, z]| Transform::new(quat_to_matrix(w, x, y, z), Vec3::new(r[0], r[1], r[2]))),
        None => None,
    };
    Ok(EqualitySpecKind::WeldBodies {
        body1,
        body2: a.text("body2").map(str::to_string),
        anchor,
        relpose,
        torquescale,
    })
}
