//! The MJCF sections around the tree: `<compiler>`, `<option>`, `<keyframe>`, and `<sensor>`s,
//! which are kept as listed elements, not evaluated.

use super::attrs::Attrs;
use super::orientation::AngleConvention;
use super::xml::Element;
use super::{Compiler, InertiaFromGeom};
use crate::io::LoadError;
use crate::model::options::{Cone, Integrator, JacobianStorage, Solver};
use crate::model::spec::MassRules;
use crate::model::{Element as KeptElement, Keyframe, Options};
use crate::spatial::Vec3;
use std::path::Path;

/// Reads every `<compiler>` (later ones override earlier ones, as MuJoCo applies them in order).
pub(crate) fn compiler(root: &Element, dir: &Path) -> Result<Compiler, LoadError> {
    let mut c = Compiler {
        angles: AngleConvention::default(),
        meshdir: dir.to_path_buf(),
        autolimits: true,
        inertia_from_geom: InertiaFromGeom::Auto,
        inertia_groups: [0, 5],
        mass_rules: MassRules { require_moving_mass: true, ..MassRules::default() },
    };
    for e in root.children_named("compiler") {
        let a = Attrs::plain(e);
        if let Some(angle) = a.keyword("angle", &["radian", "degree"])? {
            c.angles.to_radians = if angle == "radian" { 1.0 } else { std::f64::consts::PI / 180.0 };
        }
        if let Some(seq) = a.text("eulerseq") {
            let bytes = seq.as_bytes();
            if bytes.len() != 3 || !bytes.iter().all(|b| b"xyzXYZ".contains(b)) {
                return Err(a.error("eulerseq", format!("is '{seq}'; give three of x y z X Y Z (lower case: rotating axes, upper case: fixed axes)")));
            }
            c.angles.eulerseq = [bytes[0], bytes[1], bytes[2]];
        }
        // `assetdir` sets the mesh folder unless `meshdir` is given too.
        for attr in ["assetdir", "meshdir"] {
            if let Some(d) = a.text(attr) {
                c.meshdir = dir.join(d);
            }
        }
        if let Some(v) = a.bool("autolimits")? {
            c.autolimits = v;
        }
        if let Some(v) = a.keyword("inertiafromgeom", &["false", "true", "auto"])? {
            c.inertia_from_geom = match v.as_str() {
                "false" => InertiaFromGeom::False,
                "true" => InertiaFromGeom::True,
                _ => InertiaFromGeom::Auto,
            };
        }
        if let Some(v) = a.array::<2>("inertiagrouprange")? {
            c.inertia_groups = [v[0] as i64, v[1] as i64];
        }
        if let Some(v) = a.real("boundmass")? {
            c.mass_rules.bound_mass = v;
        }
        if let Some(v) = a.real("boundinertia")? {
            c.mass_rules.bound_inertia = v;
        }
        if let Some(v) = a.bool("balanceinertia")? {
            c.mass_rules.balance_inertia = v;
        }
        if let Some(v) = a.real("settotalmass")? {
            c.mass_rules.total_mass = (v > 0.0).then_some(v);
        }
        if a.text("coordinate") == Some("global") {
            return Err(a.error(
                "coordinate",
                "is 'global', which MuJoCo no longer supports; convert the model to local coordinates (MuJoCo ≤ 2.3.3 can re-save it)",
            ));
        }
    }
    Ok(c)
}

/// Reads `<option>`: time step, integrator, flags, and gravity (zero when `<flag gravity="disable">`).
pub(crate) fn options(root: &Element) -> Result<(Options, Vec3), LoadError> {
    let mut o = Options::default();
    let mut gravity = Vec3::new(0.0, 0.0, -9.81);
    for e in root.children_named("option") {
        let a = Attrs::plain(e);
        if let Some(v) = a.real("timestep")? {
            if v <= 0.0 {
                return Err(a.error("timestep", format!("is {v}; the time step must be positive")));
            }
            o.timestep = v;
        }
        if let Some(v) = a.vec3("gravity")? {
            gravity = v;
        }
        if let Some(v) = a.vec3("wind")? {
            o.wind = [v.x, v.y, v.z];
        }
        if let Some(v) = a.vec3("magnetic")? {
            o.magnetic = [v.x, v.y, v.z];
        }
        if let Some(v) = a.keyword("integrator", &["Euler", "RK4", "implicit", "implicitfast"])? {
            o.integrator = match v.as_str() {
                "Euler" => Integrator::Euler,
                "RK4" => Integrator::Rk4,
                "implicit" => Integrator::Implicit,
                _ => Integrator::ImplicitFast,
            };
        }
        if let Some(v) = a.keyword("cone", &["pyramidal", "elliptic"])? {
            o.cone = if v == "pyramidal" { Cone::Pyramidal } else { Cone::Elliptic };
        }
        if let Some(v) = a.keyword("solver", &["PGS", "CG", "Newton"])? {
            o.solver = match v.as_str() {
                "PGS" => Solver::Pgs,
                "CG" => Solver::Cg,
                _ => Solver::Newton,
            };
        }
        if let Some(v) = a.keyword("jacobian", &["dense", "sparse", "auto"])? {
            o.jacobian = match v.as_str() {
                "dense" => JacobianStorage::Dense,
                "sparse" => JacobianStorage::Sparse,
                _ => JacobianStorage::Auto,
            };
        }
        for (attr, slot) in [
            ("iterations", &mut o.iterations),
            ("ls_iterations", &mut o.ls_iterations),
            ("noslip_iterations", &mut o.noslip_iterations),
            ("ccd_iterations", &mut o.ccd_iterations),
        ] {
            if let Some(v) = a.real(attr)? {
                if v < 0.0 || v.fract() != 0.0 {
                    return Err(a.error(attr, format!("is {v}; give a non-negative whole number")));
                }
                *slot = v as u32;
            }
        }
        for (attr, slot) in [
            ("tolerance", &mut o.tolerance),
            ("ls_tolerance", &mut o.ls_tolerance),
            ("noslip_tolerance", &mut o.noslip_tolerance),
            ("impratio", &mut o.impratio),
            ("density", &mut o.density),
            ("viscosity", &mut o.viscosity),
            ("ccd_tolerance", &mut o.ccd_tolerance),
            ("sleep_tolerance", &mut o.sleep_tolerance),
        ] {
            if let Some(v) = a.real(attr)? {
                if v < 0.0 {
                    return Err(a.error(attr, format!("is {v}; it must be ≥ 0")));
                }
                *slot = v;
            }
        }
        if let Some(v) = a.real("o_margin")? {
            o.o_margin = v;
        }
        a.fill("o_solref", &mut o.o_solref)?;
        a.fill("o_solimp", &mut o.o_solimp)?;
        a.fill("o_friction", &mut o.o_friction)?;
        for f in e.children_named("flag") {
            for (name, value) in &f.attrs {
                let on = match value.as_str() {
                    "enable" => true,
                    "disable" => false,
                    other => {
                        return Err(
                            Attrs::plain(f).error(name, format!("is '{other}'; use enable or disable"))
                        );
                    }
                };
                match o.flags.get_mut(name) {
                    Some(flag) => *flag = on,
                    None => {
                        return Err(Attrs::plain(f).error(
                            name,
                            "is not a MuJoCo <flag>; see the MJCF reference for the flag names".to_string(),
                        ));
                    }
                }
            }
        }
    }
    if !o.flags.gravity {
        gravity = Vec3::zeros();
    }
    Ok((o, gravity))
}

/// Reads `<keyframe>`: each `<key>` with its name, time and state vectors (sizes are checked by
/// the compile step against nq and nv).
pub(crate) fn keyframes(root: &Element) -> Result<Vec<Keyframe>, LoadError> {
    let mut keys = Vec::new();
    for section in root.children_named("keyframe") {
        for (i, k) in section.children_named("key").enumerate() {
            let a = Attrs::plain(k);
            keys.push(Keyframe {
                name: a.text("name").map_or_else(|| format!("key{i}"), str::to_string),
                loc: k.loc.clone(),
                time: a.real("time")?.unwrap_or(0.0),
                qpos: a.numbers("qpos")?,
                qvel: a.numbers("qvel")?,
                ctrl: a.numbers("ctrl")?,
                act: a.numbers("act")?,
                mpos: a.numbers("mpos")?,
                mquat: a.numbers("mquat")?,
            });
        }
    }
    Ok(keys)
}

/// Attributes of a sensor that name the objects it measures.
const SENSOR_TARGETS: [&str; 8] =
    ["joint", "site", "tendon", "actuator", "body", "geom", "objname", "refname"];

/// Reads the `<sensor>` sections: each sensor listed with the objects it names.
pub(crate) fn sensors(root: &Element) -> Result<Vec<KeptElement>, LoadError> {
    let mut out = Vec::new();
    for section in root.children_named("sensor") {
        for e in &section.children {
            let a = Attrs::plain(e);
            out.push(KeptElement {
                category: "sensor".to_string(),
                kind: e.tag.clone(),
                name: a.text("name").unwrap_or("").to_string(),
                targets: SENSOR_TARGETS.iter().filter_map(|t| a.text(t)).map(str::to_string).collect(),
                attributes: a.values.clone(),
                loc: e.loc.clone(),
            });
        }
    }
    Ok(out)
}
