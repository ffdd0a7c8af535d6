//! Resource limits and plausibility of a parsed model, checked before anything is computed from it
//! (hostile inputs, docs/architecture.md "Errors"): counts of links, joints and geoms bounded so that a hostile file
//! cannot exhaust memory; lengths, sizes, mesh scales, masses, densities and inertias that are not
//! finite or are absurd (lengths beyond [`ABSURD_LENGTH`], other quantities beyond [`ABSURD`], in
//! SI units) refused with file and line; and the derived
//! mass properties checked for finiteness, so that no overflow (a huge but finite input squared)
//! loads as NaN.

use crate::io::{LinkWord, LoadError};
use crate::mass::GeomMass;
use crate::model::spec::{EqualitySpecKind, LinkSpec, ModelSpec, Shape, TendonSpecKind};
use crate::model::SourceLoc;
use crate::spatial::{RigidInertia, Transform, Vec3};

/// The largest magnitude accepted for a length (m), mass (kg), density (kg/m³) or inertia entry
/// (kg·m²): beyond it a value is a typo or an attack, and squaring it in mass properties overflows
/// the arithmetic of anything built on it.
pub const ABSURD: f64 = 1e12;
/// The largest length accepted (m): a thousand kilometres. A robot link or anchor 4e9 m long
/// (found by fuzzing) squares into inertias and lever arms that round the dynamics to NaN.
pub const ABSURD_LENGTH: f64 = 1e6;

/// Resource limits: the most links (URDF links, MJCF bodies and joint anchors), and geoms a model
/// may have.
pub const MAX_LINKS: usize = 10_000;
/// Resource limit on the number of geoms a model may have.
pub const MAX_GEOMS: usize = 100_000;
/// Resource limit on degrees of freedom: the mass matrix and its factor are dense nv × nv
/// buffers (72 MB each at this limit).
pub const MAX_DOFS: usize = 3_000;

/// Whether the spec was read from an MJCF file (for wording messages in the file's own terms).
pub fn is_mjcf(spec: &ModelSpec) -> bool {
    spec.source
        .as_ref()
        .and_then(|p| p.extension())
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("xml") || e.eq_ignore_ascii_case("mjcf"))
}

/// What a link is called in its file's terms: "body" (MJCF) or "link" (URDF).
pub fn link_word(spec: &ModelSpec) -> LinkWord {
    if is_mjcf(spec) {
        LinkWord::Body
    } else {
        LinkWord::Link
    }
}

fn invalid(loc: &SourceLoc, element: &str, detail: String) -> LoadError {
    LoadError::Invalid { loc: loc.clone(), element: element.into(), detail }
}

/// `Err` with the reason when `x` is not finite or beyond `limit` in magnitude.
fn plausible(x: f64, limit: f64) -> Result<(), String> {
    if !x.is_finite() {
        Err("is not a finite number".into())
    } else if x.abs() > limit {
        Err(format!("is absurdly large (beyond {limit:e} in SI units)"))
    } else {
        Ok(())
    }
}

fn check_within(
    loc: &SourceLoc,
    element: &str,
    what: impl Fn() -> String,
    values: &[f64],
    limit: f64,
) -> Result<(), LoadError> {
    for &x in values {
        if let Err(why) = plausible(x, limit) {
            return Err(invalid(loc, element, format!("{} {x:e} {why}; fix the value", what())));
        }
    }
    Ok(())
}

/// Masses, densities, inertias, coefficients: finite and within [`ABSURD`].
fn check(loc: &SourceLoc, element: &str, what: impl Fn() -> String, values: &[f64]) -> Result<(), LoadError> {
    check_within(loc, element, what, values, ABSURD)
}

/// Lengths (positions, sizes, anchors): finite and within [`ABSURD_LENGTH`].
fn check_length(
    loc: &SourceLoc,
    element: &str,
    what: impl Fn() -> String,
    values: &[f64],
) -> Result<(), LoadError> {
    check_within(loc, element, what, values, ABSURD_LENGTH)
}

fn check_pose(loc: &SourceLoc, element: &str, owner: &str, x: &Transform) -> Result<(), LoadError> {
    check_length(loc, element, || format!("{owner}: a position coordinate"), x.pos.as_slice())
}

/// The link and degree-of-freedom counts within [`MAX_LINKS`] and [`MAX_DOFS`] (a loader may
/// check them before its slower passes).
pub fn check_counts(file: &str, word: LinkWord, links: usize, nv: usize) -> Result<(), LoadError> {
    let top = SourceLoc { file: file.to_string(), line: 0 };
    if links > MAX_LINKS {
        return Err(invalid(
            &top,
            &word.to_string(),
            format!(
                "the model has {links} {word}s (joint anchors included), more than the limit of {MAX_LINKS} (a resource limit against hostile files); split the model"
            ),
        ));
    }
    if nv > MAX_DOFS {
        return Err(invalid(
            &top,
            "joint",
            format!(
                "the model has {nv} degrees of freedom, more than the limit of {MAX_DOFS} (a resource limit: the mass matrix is stored dense); split the model"
            ),
        ));
    }
    Ok(())
}

/// Counts within the resource limits; every length, size, scale, mass, density and inertia entry
/// finite and within [`ABSURD`].
pub fn check_spec(spec: &ModelSpec) -> Result<(), LoadError> {
    let file = spec.source.as_ref().map(|p| p.display().to_string()).unwrap_or_default();
    let word = link_word(spec);
    let nv = spec.links.iter().map(|l| l.joint.jtype.nv()).sum();
    check_counts(&file, word, spec.links.len(), nv)?;
    let top = SourceLoc { file, line: 0 };
    let r = &spec.mass_rules;
    let rules = [r.bound_mass, r.bound_inertia, r.total_mass.unwrap_or(0.0)];
    check(&top, "compiler", || "boundmass, boundinertia or settotalmass".into(), &rules)?;
    let o = &spec.options;
    check(&top, "option", || "gravity: a component".into(), spec.gravity.as_slice())?;
    check(
        &top,
        "option",
        || "timestep, tolerance, ls_tolerance or impratio".into(),
        &[o.timestep, o.tolerance, o.ls_tolerance, o.impratio],
    )?;
    check(
        &top,
        "option",
        || "density, viscosity or a wind component".into(),
        &[o.density, o.viscosity, o.wind[0], o.wind[1], o.wind[2]],
    )?;
    check(
        &top,
        "option",
        || "o_margin, o_solref, o_solimp or o_friction".into(),
        &[o.o_margin]
            .iter()
            .chain(&o.o_solref)
            .chain(&o.o_solimp)
            .chain(&o.o_friction)
            .copied()
            .collect::<Vec<_>>(),
    )?;
    if o.timestep <= 0.0 {
        return Err(invalid(
            &top,
            "option",
            format!("timestep {} must be positive; e.g. timestep=\"0.002\"", o.timestep),
        ));
    }
    let geoms: usize = spec.links.iter().map(|l| l.geoms.len()).sum();
    if geoms > MAX_GEOMS {
        return Err(invalid(
            &top,
            "geom",
            format!("the model has {geoms} geoms, more than the limit of {MAX_GEOMS} (a resource limit against hostile files)"),
        ));
    }
    for link in &spec.links {
        check_link(link, word)?;
    }
    check_elements(spec)
}

/// The coefficients of equalities, fixed tendons and actuators, and keyframes' activations: finite
/// and within [`ABSURD`] (ranges may be as wide as they like but finite).
fn check_elements(spec: &ModelSpec) -> Result<(), LoadError> {
    for e in &spec.equalities {
        let what = || format!("equality '{}': a coefficient", e.name);
        match &e.kind {
            EqualitySpecKind::ConnectBodies { anchor, .. } => check_length(&e.loc, "connect", what, anchor)?,
            EqualitySpecKind::WeldBodies { anchor, torquescale, relpose, .. } => {
                check_length(&e.loc, "weld", what, anchor)?;
                check(&e.loc, "weld", what, &[*torquescale])?;
                if let Some(x) = relpose {
                    check_pose(&e.loc, "weld", &format!("equality '{}'", e.name), x)?;
                }
            }
            EqualitySpecKind::WeldSites { torquescale, .. } => check(&e.loc, "weld", what, &[*torquescale])?,
            EqualitySpecKind::Joint { polycoef, .. } => check(&e.loc, "joint", what, polycoef)?,
            EqualitySpecKind::Tendon { polycoef, .. } => check(&e.loc, "tendon", what, polycoef)?,
            EqualitySpecKind::ConnectSites { .. } => {}
        }
    }
    for k in &spec.keyframes {
        if let Some(act) = &k.act {
            check(&k.loc, "key", || format!("keyframe '{}': an activation (act)", k.name), act)?;
        }
    }
    for t in &spec.tendons {
        if let Some(range) = t.actuator_force_range.filter(|r| !r.iter().all(|x| x.is_finite())) {
            return Err(invalid(
                &t.loc,
                "tendon",
                format!("tendon '{}': actuatorfrcrange {range:?} is not finite; fix the value", t.name),
            ));
        }
        check(
            &t.loc,
            "tendon",
            || format!("tendon '{}': stiffness, damping or frictionloss", t.name),
            &[t.stiffness, t.damping, t.frictionloss],
        )?;
        check_length(&t.loc, "tendon", || format!("tendon '{}': springlength", t.name), &t.spring_length)?;
        if let TendonSpecKind::Fixed { joints } = &t.kind {
            for (joint, coef, loc) in joints {
                check(
                    loc,
                    "joint",
                    || format!("tendon '{}', joint '{joint}': the coefficient", t.name),
                    &[*coef],
                )?;
            }
        }
    }
    for a in &spec.actuators {
        let what = || format!("actuator '{}': a gear, gain, bias or dynamics parameter", a.name);
        for values in [&a.gear[..], &a.gainprm[..], &a.biasprm[..], &a.dynprm[..], &[a.damping, a.armature]] {
            check(&a.loc, "actuator", what, values)?;
        }
        for range in [a.ctrlrange, a.forcerange, a.actrange].into_iter().flatten() {
            if !range.iter().all(|x| x.is_finite()) {
                return Err(invalid(
                    &a.loc,
                    "actuator",
                    format!("actuator '{}': a range {range:?} is not finite; fix the value", a.name),
                ));
            }
        }
    }
    Ok(())
}

fn check_link(link: &LinkSpec, word: LinkWord) -> Result<(), LoadError> {
    let owner = format!("{word} '{}'", link.name);
    let j = &link.joint;
    // MJCF: the body's pos (with its joint's); URDF: the joint's <origin>.
    check_pose(&j.loc, if word == LinkWord::Body { "body" } else { "joint" }, &owner, &j.x_parent_joint)?;
    let joint = || format!("joint '{}'", j.name);
    if let Some([lower, upper]) = j.limits {
        // MuJoCo: "range[0] should be smaller than range[1]"; a bound may be infinite on its own
        // side only (URDF 1.2's "no limit").
        if lower.is_nan()
            || upper.is_nan()
            || lower > upper
            || lower == f64::INFINITY
            || upper == f64::NEG_INFINITY
        {
            return Err(invalid(
                &j.loc,
                "joint",
                format!(
                    "{}: the lower limit {lower} is not below the upper limit {upper}; give lower < upper (an infinite bound only on its own side)",
                    joint()
                ),
            ));
        }
    }
    let scalars = [j.damping, j.friction, j.armature, j.stiffness, j.spring_ref];
    check(
        &j.loc,
        "joint",
        || format!("{}: a damping, friction, armature or stiffness value", joint()),
        &scalars,
    )?;
    if let Some(m) = &j.mimic {
        check(
            &m.loc,
            "mimic",
            || format!("{}: the mimic multiplier or offset", joint()),
            &[m.multiplier, m.offset],
        )?;
    }
    if let Some(i) = &link.inertial {
        check_pose(&i.loc, "inertial", &owner, &i.x_link_inertial)?;
        check(&i.loc, "inertial", || format!("{owner}: the mass"), &[i.mass])?;
        check(&i.loc, "inertial", || format!("{owner}: an inertia entry"), i.inertia.as_slice())?;
    }
    for f in &link.frames {
        check_pose(&f.loc, "frame", &owner, &f.x_link_frame)?;
    }
    for g in &link.geoms {
        let element = "geom";
        let name = if g.name.is_empty() { owner.clone() } else { format!("{owner}, geom '{}'", g.name) };
        check_pose(&g.loc, element, &name, &g.x_link_geom)?;
        let size = || format!("{name}: a size");
        let sizes: &[f64] = match &g.shape {
            Shape::Box { size: s } | Shape::Ellipsoid { radii: s } => s.as_slice(),
            Shape::Cylinder { radius, length } | Shape::Capsule { radius, length } => &[*radius, *length],
            Shape::Sphere { radius } => std::slice::from_ref(radius),
            _ => &[],
        };
        if let Some(x) = sizes.iter().find(|&&x| x < 0.0) {
            return Err(invalid(
                &g.loc,
                element,
                format!("{}: a size {x} is negative; sizes are lengths ≥ 0", size()),
            ));
        }
        match &g.shape {
            Shape::Box { size: s } | Shape::Ellipsoid { radii: s } => {
                check_length(&g.loc, element, size, s.as_slice())?
            }
            // A plane's size is for drawing only.
            Shape::Plane { size: s } => check(&g.loc, element, size, s.as_slice())?,
            Shape::Cylinder { radius, length } | Shape::Capsule { radius, length } => {
                check_length(&g.loc, element, size, &[*radius, *length])?
            }
            Shape::Sphere { radius } => check_length(&g.loc, element, size, &[*radius])?,
            Shape::Mesh { scale, .. } => {
                check(&g.loc, element, || format!("{name}: its mesh's scale"), scale.as_slice())?
            }
            Shape::Hfield { .. } => {}
        }
        let c = &g.contact;
        let contact =
            [c.friction.as_slice(), c.solref.as_slice(), c.solimp.as_slice(), &[c.solmix, c.margin, c.gap]]
                .concat();
        check(
            &g.loc,
            element,
            || format!("{name}: a contact parameter (friction, solref, solimp, solmix, margin, gap)"),
            &contact,
        )?;
        if let Some(coef) = &g.fluid {
            check(&g.loc, element, || format!("{name}: a fluidcoef entry"), coef)?;
        }
        match g.mass {
            GeomMass::Mass(m) => check(&g.loc, element, || format!("{name}: the mass"), &[m])?,
            GeomMass::Density(d) => check(&g.loc, element, || format!("{name}: the density"), &[d])?,
            GeomMass::None => {}
        }
    }
    Ok(())
}

/// The mass properties computed for a link are finite (an input can pass [`check_spec`] and still
/// overflow when the parallel-axis shift squares an offset, or a mesh's volume integral sums).
pub fn check_derived(link: &LinkSpec, word: LinkWord, inertia: &RigidInertia) -> Result<(), LoadError> {
    let numbers =
        [inertia.mass].into_iter().chain(inertia.h.iter().copied()).chain(inertia.i_origin.iter().copied());
    let com: Vec3 = if inertia.mass > 0.0 { inertia.h / inertia.mass } else { Vec3::zeros() };
    let finite = numbers.clone().all(f64::is_finite) && com.iter().all(|x| x.is_finite());
    if finite && numbers.map(f64::abs).fold(0.0, f64::max) <= ABSURD * ABSURD {
        return Ok(());
    }
    Err(LoadError::NonPhysicalInertia {
        loc: link.loc.clone(),
        what: word,
        link: link.name.clone(),
        detail: format!(
            "its computed mass properties overflow (mass {:e} kg, inertia entries up to {:e} kg·m²); check the sizes, positions and mesh scales of its geoms and <inertial>",
            inertia.mass,
            inertia.i_origin.abs().max()
        ),
    })
}
