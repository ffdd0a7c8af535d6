//! `<actuator>` → [`ActuatorSpec`]s in MuJoCo's general form (MuJoCo documentation, "XML
//! Reference → actuator" and "Modeling → Actuators"): every shortcut is expanded into the gain,
//! bias and activation-dynamics parameters MuJoCo gives it (`mjs_setTo*`), with `x` the control
//! or activation, `L` the actuator length and `V` its velocity:
//!
//! | shortcut | dyntype, dynprm | gaintype, gainprm | biastype, biasprm |
//! | --- | --- | --- | --- |
//! | `motor` | none | fixed `[1]` | none |
//! | `position` | none, or filterexact `[timeconst]` | fixed `[kp]` | affine `[0, −kp, −kv]` |
//! | `intvelocity` | integrator | fixed `[kp]` | affine `[0, −kp, −kv]` |
//! | `velocity` | none | fixed `[kv]` | affine `[0, 0, −kv]` |
//! | `damper` | none | affine `[0, 0, −kv]` | none (control limited) |
//! | `cylinder` | filter `[timeconst]` | fixed `[area]` (or π/4·diameter²) | affine `bias` |
//! | `muscle` | muscle `[timeconst(2), tausmooth]` | muscle (range, force, scale, lmin, lmax, vmax, fpmax, fvmax) | muscle (the same) |
//! | `adhesion` | none | fixed `[gain]` | none (control limited) |
//!
//! `dampratio` is stored as MuJoCo stores it before `mj_setConst` resolves it: a *positive*
//! `biasprm[2]` is a damping ratio, a negative one a damping coefficient −kv.
//!
//! Default classes: all actuator tags share one set of parameters per class, which each actuator
//! element in a `<default>` expands into in order (a `<position>` default sets kp, bias, ...).
//! Replayed here as MuJoCo 4.0.0 does it (checked against `MjModel.actuator_*`): a `<general>`
//! element starts from the class's parameters as they are; a shortcut inherits its own parameters
//! (kp, kv, timeconst, ...) from the class only when the class's last actuator default was the
//! same shortcut, or a `<general>` with the shortcut's gain type, and starts from MuJoCo's
//! defaults otherwise. Ranges, limits, gear and `actearly` are inherited as written.
//!
//! `dcmotor`, `pid`, `orientation`, plugin actuators and general actuators with gain, bias or
//! dynamics types outside the typed set are kept as listed elements with a warning.

use super::attrs::Attrs;
use super::defaults::{Defaults, MAIN};
use super::xml::Element;
use crate::io::LoadError;
use crate::model::actuator::{ActuatorHistory, ActuatorShortcut, BiasType, DynType, GainType, Interp};
use crate::model::lengthrange::{LengthRangeMode, LengthRangeOptions};
use crate::model::spec::{ActuatorSpec, TransmissionSpec};
use crate::model::Element as KeptElement;

/// The parameters an actuator element expands into while defaults and then the element itself
/// are read (the part of MuJoCo's `mjsActuator` that shortcuts write).
#[derive(Clone, Debug)]
struct Params {
    dyntype: DynType,
    gaintype: GainType,
    biastype: BiasType,
    dynprm: [f64; 10],
    gainprm: [f64; 10],
    biasprm: [f64; 10],
    /// `damper` and `adhesion` force `ctrllimited="true"`.
    ctrl_limited: bool,
    inheritrange: Option<f64>,
    /// The tag of the last element expanded into these parameters (`None`: MuJoCo's defaults).
    last_tag: Option<String>,
    /// Why the parameters are outside the typed set: a dynamics, gain or bias type keyword not
    /// typed here (one slot each, as a later `<general>` may set a typed one), or a shortcut.
    untyped: [Option<String>; 3],
}

impl Params {
    /// MuJoCo's default actuator (`mjs_defaultActuator`): a unit-gain motor.
    fn mujoco_default() -> Self {
        let mut p = Params {
            dyntype: DynType::None,
            gaintype: GainType::Fixed,
            biastype: BiasType::None,
            dynprm: [0.0; 10],
            gainprm: [0.0; 10],
            biasprm: [0.0; 10],
            ctrl_limited: false,
            inheritrange: None,
            last_tag: None,
            untyped: [None, None, None],
        };
        p.dynprm[0] = 1.0;
        p.gainprm[0] = 1.0;
        p
    }
}

/// The gain type a shortcut expands to (what a `<general>` default must have for the shortcut to
/// inherit its parameters).
fn natural_gaintype(tag: &str) -> GainType {
    match tag {
        "damper" => GainType::Affine,
        "muscle" => GainType::Muscle,
        _ => GainType::Fixed,
    }
}

/// Reads every `<actuator>` section in file order.
pub(crate) fn actuators(
    root: &Element,
    defaults: &Defaults,
    autolimits: bool,
    kept: &mut Vec<KeptElement>,
    warnings: &mut Vec<String>,
) -> Result<Vec<ActuatorSpec>, LoadError> {
    let mut out = Vec::new();
    for section in root.children_named("actuator") {
        for e in &section.children {
            let a = defaults.resolve(e, MAIN)?;
            let Some(shortcut) = shortcut(&e.tag) else {
                keep_untyped(e, &a, &format!("<{}> actuators are not typed here", e.tag), kept, warnings);
                continue;
            };
            let mut p = Params::mujoco_default();
            for d in defaults.actuator_defaults(e)? {
                p = expand(&d.tag, d, p)?;
            }
            let p = expand(&e.tag, &Attrs::plain(e), p)?;
            if let Some(why) = p.untyped.iter().flatten().next() {
                keep_untyped(e, &a, why, kept, warnings);
                continue;
            }
            out.push(finish(e, &a, defaults, shortcut, p, autolimits, warnings)?);
        }
    }
    Ok(out)
}

fn shortcut(tag: &str) -> Option<ActuatorShortcut> {
    Some(match tag {
        "general" => ActuatorShortcut::General,
        "motor" => ActuatorShortcut::Motor,
        "position" => ActuatorShortcut::Position,
        "velocity" => ActuatorShortcut::Velocity,
        "intvelocity" => ActuatorShortcut::IntVelocity,
        "damper" => ActuatorShortcut::Damper,
        "cylinder" => ActuatorShortcut::Cylinder,
        "muscle" => ActuatorShortcut::Muscle,
        "adhesion" => ActuatorShortcut::Adhesion,
        _ => return None,
    })
}

/// Lists an actuator this loader does not type, with a warning.
fn keep_untyped(e: &Element, a: &Attrs, why: &str, kept: &mut Vec<KeptElement>, warnings: &mut Vec<String>) {
    warnings.push(format!(
        "{}: <{}>: {why}; kept as a listed element, not in the model's actuators (so the control indices of later actuators differ from MuJoCo's)",
        e.loc, e.tag
    ));
    let targets = ["joint", "jointinparent", "tendon", "site", "refsite", "body", "cranksite", "slidersite"]
        .iter()
        .filter_map(|t| a.text(t))
        .map(str::to_string)
        .collect();
    kept.push(KeptElement {
        category: "actuator".into(),
        kind: e.tag.clone(),
        name: a.text("name").unwrap_or("").to_string(),
        targets,
        attributes: a.values.clone(),
        loc: e.loc.clone(),
    });
}

/// The parameters after expanding element `tag` with its own attributes `a` over `p` (the class's
/// parameters so far), as MuJoCo's XML reader does (`OneActuator`, `mjs_setTo*`).
fn expand(tag: &str, a: &Attrs, mut p: Params) -> Result<Params, LoadError> {
    if tag == "general" {
        let keyword = |attr: &str, allowed: &[&str]| -> Option<Result<usize, String>> {
            a.text(attr).map(|t| {
                let t = t.trim();
                allowed.iter().position(|k| *k == t).ok_or_else(|| format!("{attr} '{t}' is not typed here"))
            })
        };
        const DYN: [&str; 6] = ["none", "integrator", "filter", "filterexact", "muscle", "user"];
        const GAIN: [&str; 4] = ["fixed", "affine", "muscle", "user"];
        const BIAS: [&str; 4] = ["none", "affine", "muscle", "user"];
        let types = [DYN.as_slice(), GAIN.as_slice(), BIAS.as_slice()];
        for (slot, (attr, allowed)) in ["dyntype", "gaintype", "biastype"].into_iter().zip(types).enumerate()
        {
            match keyword(attr, allowed) {
                None => {}
                Some(Err(why)) => p.untyped[slot] = Some(why),
                Some(Ok(k)) => match attr {
                    "dyntype" => {
                        p.untyped[slot] = None;
                        p.dyntype = [
                            DynType::None,
                            DynType::Integrator,
                            DynType::Filter,
                            DynType::FilterExact,
                            DynType::Muscle,
                            DynType::User,
                        ][k]
                    }
                    "gaintype" => {
                        p.untyped[slot] = None;
                        p.gaintype = [GainType::Fixed, GainType::Affine, GainType::Muscle, GainType::User][k];
                    }
                    _ => {
                        p.untyped[slot] = None;
                        p.biastype = [BiasType::None, BiasType::Affine, BiasType::Muscle, BiasType::User][k];
                    }
                },
            }
        }
        a.fill("dynprm", &mut p.dynprm)?;
        a.fill("gainprm", &mut p.gainprm)?;
        a.fill("biasprm", &mut p.biasprm)?;
        p.last_tag = Some(tag.to_string());
        return Ok(p);
    }
    if shortcut(tag).is_none() {
        // dcmotor, pid, orientation, plugin: they set types this loader does not type.
        p.untyped = [Some(format!("<{tag}> actuators are not typed here")), None, None];
        p.last_tag = Some(tag.to_string());
        return Ok(p);
    }
    // A shortcut inherits its own parameters only from a default of the same shortcut, or from a
    // `<general>` default of its gain type (MuJoCo 4.0.0's behaviour); else MuJoCo's defaults.
    let inherit = match p.last_tag.as_deref() {
        Some(t) if t == tag => true,
        Some("general") | None => p.gaintype == natural_gaintype(tag),
        _ => false,
    };
    let old = p.clone();
    let fresh = Params::mujoco_default();
    p.dynprm = fresh.dynprm;
    p.gainprm = fresh.gainprm;
    p.biasprm = fresh.biasprm;
    p.inheritrange = if inherit { old.inheritrange } else { None };
    p.untyped = [None, None, None];
    let real = |name: &str| a.real(name);
    let nonnegative = |name: &str, v: f64| -> Result<f64, LoadError> {
        if v < 0.0 {
            Err(a.error(name, format!("is {v}; it cannot be negative")))
        } else {
            Ok(v)
        }
    };
    match tag {
        "motor" => {
            p.dyntype = DynType::None;
            p.gaintype = GainType::Fixed;
            p.biastype = BiasType::None;
        }
        "position" | "intvelocity" => {
            let kp = real("kp")?.unwrap_or(if inherit { old.gainprm[0] } else { 1.0 });
            let (kv, dampratio) = (real("kv")?, real("dampratio")?);
            if kv.is_some() && dampratio.is_some() {
                return Err(a.error("dampratio", "cannot be given together with 'kv': give one of them"));
            }
            // biasprm[2]: −kv, or a positive damping ratio resolved later (as MuJoCo stores it).
            p.biasprm[2] = match (kv, dampratio) {
                (Some(kv), _) => -nonnegative("kv", kv)?,
                (_, Some(r)) => nonnegative("dampratio", r)?,
                _ if inherit => old.biasprm[2],
                _ => 0.0,
            };
            if kp < 0.0 && p.biasprm[2] > 0.0 {
                return Err(a.error(
                    "kp",
                    format!("is {kp} with a 'dampratio': the damping 2·dampratio·√(kp·m) needs kp ≥ 0 (MuJoCo computes NaN); give a non-negative kp, or 'kv' instead of 'dampratio'"),
                ));
            }
            p.gainprm[0] = kp;
            p.biasprm[1] = -kp;
            match real("timeconst")? {
                Some(tc) => {
                    p.dynprm[0] = nonnegative("timeconst", tc)?;
                    p.dyntype = if tc == 0.0 { DynType::None } else { DynType::FilterExact };
                }
                None if inherit && old.dyntype == DynType::FilterExact => {
                    p.dynprm[0] = old.dynprm[0];
                    p.dyntype = DynType::FilterExact;
                }
                None => p.dyntype = DynType::None,
            }
            if let Some(r) = real("inheritrange")? {
                p.inheritrange = (r > 0.0).then_some(r);
            }
            if tag == "intvelocity" {
                p.dyntype = DynType::Integrator;
            }
            p.gaintype = GainType::Fixed;
            p.biastype = BiasType::Affine;
        }
        "velocity" => {
            let kv = real("kv")?.unwrap_or(if inherit { old.gainprm[0] } else { 1.0 });
            p.gainprm[0] = kv;
            p.biasprm[2] = -kv;
            p.dyntype = DynType::None;
            p.gaintype = GainType::Fixed;
            p.biastype = BiasType::Affine;
        }
        "damper" => {
            let kv = real("kv")?.unwrap_or(if inherit { -old.gainprm[2] } else { 0.0 });
            p.gainprm = [0.0; 10];
            p.gainprm[2] = -nonnegative("kv", kv)?;
            p.ctrl_limited = true;
            p.dyntype = DynType::None;
            p.gaintype = GainType::Affine;
            p.biastype = BiasType::None;
        }
        "cylinder" => {
            let timeconst = real("timeconst")?.unwrap_or(if inherit { old.dynprm[0] } else { 1.0 });
            let bias = match a.array::<3>("bias")? {
                Some(b) => b,
                None if inherit => [old.biasprm[0], old.biasprm[1], old.biasprm[2]],
                None => [0.0; 3],
            };
            let mut area = real("area")?.unwrap_or(if inherit { old.gainprm[0] } else { 1.0 });
            if let Some(d) = real("diameter")? {
                area = std::f64::consts::PI / 4.0 * d * d;
            }
            p.dynprm[0] = timeconst;
            p.biasprm[..3].copy_from_slice(&bias);
            p.gainprm[0] = area;
            p.dyntype = DynType::Filter;
            p.gaintype = GainType::Fixed;
            p.biastype = BiasType::Affine;
        }
        "muscle" => muscle(a, &mut p, if inherit { Some(&old) } else { None })?,
        _ => {
            // adhesion
            let gain = real("gain")?.unwrap_or(if inherit { old.gainprm[0] } else { 1.0 });
            p.gainprm[0] = nonnegative("gain", gain)?;
            p.ctrl_limited = true;
            p.dyntype = DynType::None;
            p.gaintype = GainType::Fixed;
            p.biastype = BiasType::None;
        }
    }
    p.last_tag = Some(tag.to_string());
    Ok(p)
}

/// MuJoCo's `mjs_setToMuscle`: defaults for parameters still at the default actuator's values,
/// then the attributes given; `biasprm` repeats `gainprm`.
fn muscle(a: &Attrs, p: &mut Params, inherited: Option<&Params>) -> Result<(), LoadError> {
    if let Some(old) = inherited {
        p.dynprm = old.dynprm;
        p.gainprm = old.gainprm;
    }
    let defaults_if_unset = [
        (0, 1.0, 0.75),
        (1, 0.0, 1.05),
        (2, 0.0, -1.0),
        (3, 0.0, 200.0),
        (4, 0.0, 0.5),
        (5, 0.0, 1.6),
        (6, 0.0, 1.5),
        (7, 0.0, 1.3),
        (8, 0.0, 1.2),
    ];
    if p.dynprm[0] == 1.0 {
        p.dynprm[0] = 0.01;
    }
    if p.dynprm[1] == 0.0 {
        p.dynprm[1] = 0.04;
    }
    for (i, unset, default) in defaults_if_unset {
        if p.gainprm[i] == unset {
            p.gainprm[i] = default;
        }
    }
    if let Some(t) = a.array::<2>("timeconst")? {
        p.dynprm[0] = t[0];
        p.dynprm[1] = t[1];
    }
    if let Some(t) = a.real("tausmooth")? {
        if t < 0.0 {
            return Err(a.error("tausmooth", format!("is {t}; it cannot be negative")));
        }
        p.dynprm[2] = t;
    } else if inherited.is_none() {
        p.dynprm[2] = 0.0;
    }
    if let Some(r) = a.array::<2>("range")? {
        p.gainprm[0] = r[0];
        p.gainprm[1] = r[1];
    }
    for (i, name) in
        [(2, "force"), (3, "scale"), (4, "lmin"), (5, "lmax"), (6, "vmax"), (7, "fpmax"), (8, "fvmax")]
    {
        if let Some(v) = a.real(name)? {
            p.gainprm[i] = v;
        }
    }
    p.biasprm = [0.0; 10];
    p.biasprm[..9].copy_from_slice(&p.gainprm[..9]);
    p.dyntype = DynType::Muscle;
    p.gaintype = GainType::Muscle;
    p.biastype = BiasType::Muscle;
    Ok(())
}

/// The actuator from its expanded parameters and the attributes every actuator shares (its
/// transmission, gear, ranges and limits, `actearly`), with MuJoCo's compile-time checks.
fn finish(
    e: &Element,
    a: &Attrs,
    defaults: &Defaults,
    shortcut: ActuatorShortcut,
    p: Params,
    autolimits: bool,
    warnings: &mut Vec<String>,
) -> Result<ActuatorSpec, LoadError> {
    let transmission = transmission(a, warnings)?;
    let mut gear = [1.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    a.fill_over(&defaults.class_defaults(e, "actuator")?, "gear", &mut gear)?;
    // `damper` and `adhesion` are control-limited whatever `ctrllimited` says; other actuators of
    // a class with such a default are too, unless they say otherwise.
    let own_switch = a.explicit.iter().any(|n| n == "ctrllimited");
    let ctrl_forced = p.ctrl_limited
        && (matches!(shortcut, ActuatorShortcut::Damper | ActuatorShortcut::Adhesion) || !own_switch);
    let ctrlrange = if ctrl_forced {
        let r = a.array::<2>("ctrlrange")?.unwrap_or([0.0, 0.0]);
        if r[0] >= r[1] {
            return Err(a.error(
                "ctrlrange",
                format!(
                    "is [{}, {}]; this actuator is control-limited: give ctrlrange with lower < upper",
                    r[0], r[1]
                ),
            ));
        }
        Some(r)
    } else {
        a.limited_range("ctrllimited", "ctrlrange", autolimits, warnings)?
    };
    if matches!(shortcut, ActuatorShortcut::Damper | ActuatorShortcut::Adhesion)
        && ctrlrange.is_some_and(|r| r[0] < 0.0 || r[1] < 0.0)
    {
        return Err(a.error("ctrlrange", format!("cannot be negative for <{}>: the control scales a dissipative or adhesive force; use a range in [0, ∞)", e.tag)));
    }
    let forcerange = a.limited_range("forcelimited", "forcerange", autolimits, warnings)?;
    let actrange = a.limited_range("actlimited", "actrange", autolimits, warnings)?;
    if actrange.is_some() && p.dyntype == DynType::None {
        return Err(a.error(
            "actrange",
            "is given but the actuator has no activation (dyntype 'none'); remove it or give a dyntype",
        ));
    }
    // `actdim`: the number of activations, one with activation dynamics and none without (the
    // larger counts of `user` dynamics are not typed here).
    if let Some(n) = a.int("actdim")?.filter(|&n| n >= 0) {
        let stateful = p.dyntype != DynType::None;
        if n != i64::from(stateful) && !(n > 1 && p.dyntype == DynType::User) {
            return Err(a.error(
                "actdim",
                format!(
                    "is {n}; an actuator with dyntype '{}' has {} activation: give actdim=\"{}\" or remove it",
                    match p.dyntype {
                        DynType::None => "none",
                        DynType::Integrator => "integrator",
                        DynType::Filter => "filter",
                        DynType::FilterExact => "filterexact",
                        DynType::Muscle => "muscle",
                        DynType::User => "user",
                    },
                    if stateful { "one" } else { "no" },
                    i64::from(stateful)
                ),
            ));
        }
        if n > 1 {
            return Err(a.error(
                "actdim",
                format!("is {n}; user dynamics with several activations are not supported: use actdim=\"1\""),
            ));
        }
    }
    if p.inheritrange.is_some() {
        let (range, attr) = if shortcut == ActuatorShortcut::IntVelocity {
            (actrange, "actrange")
        } else {
            (ctrlrange, "ctrlrange")
        };
        if range.is_some() {
            return Err(a.error(
                "inheritrange",
                format!("cannot be given together with '{attr}': it sets {attr} from the target's range"),
            ));
        }
    }
    Ok(ActuatorSpec {
        name: a.text("name").unwrap_or("").to_string(),
        shortcut,
        transmission,
        gear,
        dyntype: p.dyntype,
        gaintype: p.gaintype,
        biastype: p.biastype,
        dynprm: p.dynprm,
        gainprm: p.gainprm,
        biasprm: p.biasprm,
        ctrlrange,
        forcerange,
        actrange,
        actearly: a.bool("actearly")?.unwrap_or(false),
        inheritrange: p.inheritrange,
        damping: damping(a, warnings)?,
        armature: nonnegative_attr(a, "armature")?,
        lengthrange: a.array::<2>("lengthrange")?.unwrap_or([0.0; 2]),
        history: history(a)?,
        loc: e.loc.clone(),
    })
}

/// The control history (`nsample`, `delay`, `interp`; MuJoCo 4.0, `forward::history`): None
/// without samples. As MuJoCo's compiler: a positive `delay` needs `nsample` > 0; a zero or
/// negative `nsample` keeps no history; a negative `delay` reads the newest sample.
fn history(a: &Attrs) -> Result<Option<ActuatorHistory>, LoadError> {
    let nsample = a.int("nsample")?.unwrap_or(0);
    let delay = a.real("delay")?.unwrap_or(0.0);
    if nsample <= 0 {
        if delay > 0.0 {
            return Err(a.error(
                "delay",
                format!("is {delay} without a history buffer (MuJoCo: \"setting delay > 0 without a history buffer\"); give nsample > 0 samples to keep"),
            ));
        }
        return Ok(None);
    }
    // MuJoCo allocates the buffer for any count; a bound keeps a typo from allocating gigabytes.
    const MAX_SAMPLES: i64 = 1 << 20;
    if nsample > MAX_SAMPLES {
        return Err(a.error("nsample", format!("is {nsample}; at most {MAX_SAMPLES} samples are kept")));
    }
    let interp = match a.keyword("interp", &["zoh", "linear", "cubic"])?.as_deref() {
        Some("linear") => Interp::Linear,
        Some("cubic") => Interp::Cubic,
        _ => Interp::ZeroOrderHold,
    };
    Ok(Some(ActuatorHistory { nsample: nsample as usize, interp, delay, adr: 0 }))
}

/// An attribute that cannot be negative (0 if absent).
fn nonnegative_attr(a: &Attrs, name: &str) -> Result<f64, LoadError> {
    match a.real(name)? {
        Some(v) if v < 0.0 => Err(a.error(name, format!("is {v}; it cannot be negative"))),
        v => Ok(v.unwrap_or(0.0)),
    }
}

/// The linear actuator damping (`damping`'s first value); higher polynomial terms are not
/// simulated and warned about.
fn damping(a: &Attrs, warnings: &mut Vec<String>) -> Result<f64, LoadError> {
    let Some(d) = a.some_numbers("damping", 1, 3)? else { return Ok(0.0) };
    if d[0] < 0.0 {
        return Err(a.error("damping", format!("is {}; it cannot be negative", d[0])));
    }
    if d[1..].iter().any(|&c| c != 0.0) {
        warnings.push(format!(
            "{}: <{}>: the polynomial terms of 'damping' are not simulated (only the linear coefficient {})",
            a.loc, a.tag, d[0]
        ));
    }
    Ok(d[0])
}

/// The transmission: MuJoCo reads `joint`, `jointinparent`, `tendon`, `cranksite`, `site`, `body`
/// in this order and the last one given wins (a warning says so when there are several).
fn transmission(a: &Attrs, warnings: &mut Vec<String>) -> Result<TransmissionSpec, LoadError> {
    const TARGETS: [&str; 6] = ["joint", "jointinparent", "tendon", "cranksite", "site", "body"];
    let given: Vec<&str> = TARGETS.iter().copied().filter(|t| a.has(t)).collect();
    let Some(&kind) = given.last() else {
        return Err(LoadError::Invalid {
            loc: a.loc.clone(),
            element: a.tag.clone(),
            detail: "the actuator has no transmission target; give one of joint, jointinparent, tendon, site, body or cranksite (with slidersite)".into(),
        });
    };
    if given.len() > 1 {
        warnings.push(format!(
            "{}: <{}>: several transmission targets ({}); '{kind}' is used, as in MuJoCo",
            a.loc,
            a.tag,
            given.join(", ")
        ));
    }
    let target = a.text(kind).unwrap_or("").to_string();
    if kind != "cranksite" {
        if let Some(attr) = ["slidersite", "cranklength"].into_iter().find(|n| a.has(n)) {
            return Err(a.error(attr, "is only used by a slider-crank transmission (cranksite)"));
        }
    }
    if kind != "site" && a.has("refsite") {
        return Err(a.error("refsite", "is only used by a site transmission"));
    }
    Ok(match kind {
        "joint" => TransmissionSpec::Joint(target),
        "jointinparent" => TransmissionSpec::JointInParent(target),
        "tendon" => TransmissionSpec::Tendon(target),
        "site" => TransmissionSpec::Site { site: target, refsite: a.text("refsite").map(str::to_string) },
        "body" => TransmissionSpec::Body(target),
        _ => {
            let Some(slidersite) = a.text("slidersite") else {
                return Err(
                    a.error("slidersite", "is missing: a slider-crank (cranksite) needs its slider site")
                );
            };
            let cranklength = a.real("cranklength")?.unwrap_or(0.0);
            if cranklength <= 0.0 {
                return Err(a.error(
                    "cranklength",
                    format!("is {cranklength}; a slider-crank needs a positive crank length"),
                ));
            }
            TransmissionSpec::SliderCrank {
                cranksite: target,
                slidersite: slidersite.to_string(),
                cranklength,
            }
        }
    })
}

/// `<compiler><lengthrange>` (MuJoCo's `mjLROpt`; every attribute, MuJoCo's defaults where absent).
pub(crate) fn lengthrange_options(root: &Element) -> Result<LengthRangeOptions, LoadError> {
    let mut o = LengthRangeOptions::default();
    for c in root.children_named("compiler") {
        for e in c.children_named("lengthrange") {
            let at = Attrs::plain(e);
            if let Some(m) = at.keyword("mode", &["none", "muscle", "muscleuser", "all"])? {
                o.mode = match m.as_str() {
                    "none" => LengthRangeMode::None,
                    "muscleuser" => LengthRangeMode::MuscleUser,
                    "all" => LengthRangeMode::All,
                    _ => LengthRangeMode::Muscle,
                };
            }
            o.useexisting = at.bool("useexisting")?.unwrap_or(o.useexisting);
            o.uselimit = at.bool("uselimit")?.unwrap_or(o.uselimit);
            for (name, field) in [
                ("accel", &mut o.accel),
                ("maxforce", &mut o.maxforce),
                ("timeconst", &mut o.timeconst),
                ("timestep", &mut o.timestep),
                ("inttotal", &mut o.inttotal),
                ("interval", &mut o.interval),
                ("tolrange", &mut o.tolrange),
            ] {
                if let Some(x) = at.real(name)? {
                    if !x.is_finite() || x < 0.0 {
                        return Err(at.error(name, format!("{x} is not a finite non-negative number")));
                    }
                    *field = x;
                }
            }
        }
    }
    Ok(o)
}
