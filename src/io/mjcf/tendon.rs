//! `<tendon>` → [`TendonSpec`]s in file order, MuJoCo's tendon order (MuJoCo documentation,
//! "XML Reference → tendon"), with the defaults of `<default><tendon>`.
//!
//! A `<fixed>` tendon is the linear combination `L = Σ coef · q[joint]` of its `<joint joint coef>`
//! children (`coef` is required, a joint may appear once); a `<spatial>` tendon keeps its path
//! (`site`, `geom` with `sidesite`, `pulley divisor`), resolved and checked at compile time.
//! `limited`/`range` follow `<compiler autolimits>`; `stiffness`, `springlength` (one or two
//! values), `damping` and `frictionloss` are read; `armature` is not simulated (said).

use super::defaults::{Defaults, MAIN};
use super::xml::Element;
use crate::io::LoadError;
use crate::model::spec::{TendonSpec, TendonSpecKind};

/// Reads every `<tendon>` section.
pub(crate) fn tendons(
    root: &Element,
    defaults: &Defaults,
    autolimits: bool,
    warnings: &mut Vec<String>,
) -> Result<Vec<TendonSpec>, LoadError> {
    let mut out = Vec::new();
    for section in root.children_named("tendon") {
        for e in section.children.iter().filter(|e| matches!(e.tag.as_str(), "fixed" | "spatial")) {
            let a = defaults.resolve_as(e, "tendon", MAIN)?;
            let name = a.text("name").unwrap_or("").to_string();
            let kind = if e.tag == "fixed" {
                let mut joints: Vec<(String, f64, crate::model::SourceLoc)> = Vec::new();
                for j in e.children_named("joint") {
                    let ja = super::attrs::Attrs::plain(j);
                    let Some(joint) = ja.text("joint") else {
                        return Err(ja.error("joint", "is missing: name the joint of this term"));
                    };
                    let Some(coef) = ja.real("coef")? else {
                        return Err(
                            ja.error("coef", "is missing: give the joint's coefficient in the tendon length")
                        );
                    };
                    if joints.iter().any(|(n, _, _)| n == joint) {
                        return Err(ja.error(
                            "joint",
                            format!("'{joint}' appears twice in tendon '{name}'; add the coefficients into one term"),
                        ));
                    }
                    joints.push((joint.to_string(), coef, j.loc.clone()));
                }
                if joints.is_empty() {
                    return Err(LoadError::Invalid {
                        loc: e.loc.clone(),
                        element: e.tag.clone(),
                        detail: format!(
                            "tendon '{name}' has no <joint>; a fixed tendon needs at least one joint term"
                        ),
                    });
                }
                TendonSpecKind::Fixed { joints }
            } else {
                let path = e
                    .children
                    .iter()
                    .map(|c| {
                        let attr = if c.tag == "pulley" { "divisor" } else { c.tag.as_str() };
                        let side = (c.tag == "geom").then(|| c.attr("sidesite")).flatten();
                        (c.tag.clone(), c.attr(attr).unwrap_or("").to_string(), side.map(str::to_string))
                    })
                    .collect();
                TendonSpecKind::Spatial { path }
            };
            // Tendon armature: not simulated yet, so a nonzero value is said, never silently dropped.
            for (attr, what) in [
                ("armature", "an inertia added along the tendon to M"),
                ("stiffnesspoly", "a polynomial spring along the tendon"),
                ("dampingpoly", "a polynomial damper along the tendon"),
            ] {
                if let Some(values) = a.numbers(attr)? {
                    if values.iter().any(|&x| x != 0.0) {
                        let shown: Vec<String> = values.iter().map(f64::to_string).collect();
                        warnings.push(format!(
                            "{}: <{}> '{name}': {attr}=\"{}\" is not simulated (MuJoCo applies {what}); lagrange's motion will differ from MuJoCo's",
                            e.loc,
                            e.tag,
                            shown.join(" ")
                        ));
                    }
                }
            }
            let range = a.limited_range("limited", "range", autolimits, warnings)?;
            let soft = super::body::soft_params(&a)?;
            let actuator_force_range =
                a.limited_range("actuatorfrclimited", "actuatorfrcrange", autolimits, warnings)?;
            let scalar = |attr: &str| -> Result<f64, LoadError> { Ok(a.real(attr)?.unwrap_or(0.0)) };
            let (stiffness, damping, frictionloss) =
                (scalar("stiffness")?, scalar("damping")?, scalar("frictionloss")?);
            let spring_length = match a.numbers("springlength")?.as_deref() {
                None => [-1.0, -1.0],
                Some([x]) => [*x, *x],
                Some([lo, hi]) if lo <= hi => [*lo, *hi],
                Some([_, _]) => {
                    return Err(a.error(
                        "springlength",
                        "has its lower value above its upper one; give \"lower upper\"",
                    ))
                }
                Some(_) => return Err(a.error("springlength", "takes one or two values")),
            };
            out.push(TendonSpec {
                name,
                kind,
                range,
                soft,
                actuator_force_range,
                stiffness,
                spring_length,
                damping,
                frictionloss,
                loc: e.loc.clone(),
            });
        }
    }
    Ok(out)
}
