//! The compile step for `<sensor>`s: each MJCF sensor element becomes a [`Sensor`] with its
//! objects resolved to lagrange's indices, its stage, data type, dimension and address in
//! `sensordata`, with MuJoCo 4.0's compile-time checks (`mjCSensor::Compile`,
//! `mjCSensor::ResolveReferences`; the attributes as `mjXReader::Sensor` reads them).
//!
//! A sensor lagrange does not compute keeps its place (and its MuJoCo address and size where they
//! are known) with the reason in [`Sensor::not_computed`]: user sensors (values come from user
//! code), plugins, tactile sensors, camera-attached sensors (cameras are not parsed), sensors on
//! spatial tendons or unsimulated actuators, sensors with a history (`nsample`, `delay`,
//! `interval`).

use crate::io::compile_elements::Names;
use crate::io::LoadError;
use crate::model::{Element, JointKind, Model};
use crate::sensor::{
    ContactSensorSpec, Sensor, SensorDataType, SensorObject, SensorStage, SensorType, CONTACT_FIELDS,
    RAY_FIELDS,
};

/// The attribute `name` of `e`, if written.
fn attr<'e>(e: &'e Element, name: &str) -> Option<&'e str> {
    e.attributes.iter().find(|(k, _)| k == name).map(|(_, v)| v.as_str())
}

fn invalid(e: &Element, detail: impl Into<String>) -> LoadError {
    LoadError::Invalid { loc: e.loc.clone(), element: e.kind.clone(), detail: detail.into() }
}

/// A number attribute (default `default`), with MuJoCo's non-negativity checks for `cutoff` and
/// `noise`.
fn number(e: &Element, name: &str, default: f64) -> Result<f64, LoadError> {
    match attr(e, name) {
        None => Ok(default),
        Some(s) => s.trim().parse::<f64>().map_err(|_| invalid(e, format!("{name}=\"{s}\" is not a number"))),
    }
}

/// The bits of a `data` attribute over `fields` (MuJoCo requires them in the fields' order).
fn dataspec(e: &Element, fields: &[(&str, usize)], default: u32) -> Result<u32, LoadError> {
    let Some(text) = attr(e, "data") else { return Ok(default) };
    let mut bits = 0u32;
    let mut last: Option<usize> = None;
    for word in text.split_whitespace() {
        let Some(i) = fields.iter().position(|(f, _)| *f == word) else {
            let known: Vec<&str> = fields.iter().map(|(f, _)| *f).collect();
            return Err(invalid(e, format!("data field '{word}' is not one of {}", known.join(", "))));
        };
        if last.is_some_and(|l| i <= l) {
            let known: Vec<&str> = fields.iter().map(|(f, _)| *f).collect();
            return Err(invalid(e, format!("data attributes must be in order: {}", known.join(", "))));
        }
        last = Some(i);
        bits |= 1 << i;
    }
    if bits == 0 {
        return Err(invalid(e, "data names no field"));
    }
    Ok(bits)
}

/// The number of values one slot of a `dataspec` over `fields` holds.
pub(crate) fn slot_size(fields: &[(&str, usize)], dataspec: u32) -> usize {
    fields.iter().enumerate().filter(|(i, _)| dataspec & (1 << i) != 0).map(|(_, (_, n))| n).sum()
}

/// The frame-object kinds of `objtype`/`reftype` (MuJoCo's `frameobj_map`).
fn frame_object(
    e: &Element,
    names: &Names,
    kind: Option<&str>,
    name: Option<&str>,
    which: &str,
) -> Result<Result<SensorObject, String>, LoadError> {
    let Some(kind) = kind else { return Ok(Ok(SensorObject::None)) };
    let name = name.ok_or_else(|| invalid(e, format!("{which}type=\"{kind}\" without {which}name")))?;
    Ok(Ok(match kind {
        "body" => SensorObject::Body(names.body_id_of(name, &e.loc, &e.kind)?),
        "xbody" => SensorObject::XBody(names.body_id_of(name, &e.loc, &e.kind)?),
        "geom" => SensorObject::Geom(names.geom_of(name, &e.loc, &e.kind)?),
        "site" => SensorObject::Site(names.site_of(name, &e.loc, &e.kind)?),
        "camera" => return Ok(Err("it is attached to a camera (cameras are not parsed)".into())),
        other => {
            return Err(invalid(
                e,
                format!("{which}type=\"{other}\" must be body, xbody, geom, site or camera"),
            ));
        }
    }))
}

/// The most numbers `sensordata` may hold (128 MiB): a bound on a file's `dim` or `num` that
/// would exhaust memory.
const MAX_SENSORDATA: usize = 1 << 24;

/// Compiles every sensor element of `elements` (category `sensor`, file order) against `model`;
/// returns the sensors and the size of `sensordata`.
pub(crate) fn compile_sensors(
    elements: &[Element],
    names: &Names,
    model: &Model,
) -> Result<(Vec<Sensor>, usize), LoadError> {
    let mut out = Vec::new();
    let mut adr = 0;
    for e in elements.iter().filter(|e| e.category == "sensor") {
        let mut s = sensor(e, names, model, out.len())?;
        s.adr = adr;
        adr = adr.saturating_add(s.dim);
        if adr > MAX_SENSORDATA {
            return Err(invalid(
                e,
                format!(
                    "the sensors take more than {MAX_SENSORDATA} numbers of sensordata ({} MiB) with this one \
                     ({} values): give a smaller 'dim' or 'num'",
                    (MAX_SENSORDATA * 8) >> 20,
                    s.dim
                ),
            ));
        }
        out.push(s);
    }
    Ok((out, adr))
}

fn sensor(e: &Element, names: &Names, model: &Model, id: usize) -> Result<Sensor, LoadError> {
    use SensorType::*;
    let kind = SensorType::from_tag(&e.kind).ok_or_else(|| invalid(e, "unknown sensor type"))?;
    let cutoff = number(e, "cutoff", 0.0)?;
    let noise = number(e, "noise", 0.0)?;
    if cutoff < 0.0 {
        return Err(invalid(e, "negative cutoff in sensor"));
    }
    if noise < 0.0 {
        return Err(invalid(e, "negative noise in sensor"));
    }
    let (loc, tag) = (&e.loc, e.kind.as_str());
    let mut not_computed: Option<String> = None;
    let mut object = SensorObject::None;
    let mut reference = SensorObject::None;
    let mut contact = None;
    let mut ray_dataspec = 0;
    let mut dim = kind.fixed_dim();
    let mut stage = kind.stage();
    let mut datatype = kind.datatype();
    let required = |a: &str| attr(e, a).ok_or_else(|| invalid(e, format!("missing attribute '{a}'")));
    match kind {
        Touch | Accelerometer | Velocimeter | Gyro | Force | Torque | Magnetometer => {
            object = SensorObject::Site(names.site_of(required("site")?, loc, tag)?);
        }
        CamProjection => {
            object = SensorObject::Site(names.site_of(required("site")?, loc, tag)?);
            not_computed = Some("it projects onto a camera (cameras are not parsed)".into());
        }
        Rangefinder => {
            ray_dataspec = dataspec(e, &RAY_FIELDS, 1)?;
            if let Some(site) = attr(e, "site") {
                object = SensorObject::Site(names.site_of(site, loc, tag)?);
                dim = Some(slot_size(&RAY_FIELDS, ray_dataspec));
            } else {
                required("camera")?;
                not_computed = Some(
                    "it is attached to a camera (cameras are not parsed; its size in sensordata is unknown, so later sensors' addresses differ from MuJoCo's)".into(),
                );
                dim = Some(0);
            }
        }
        JointPos | JointVel | JointActuatorFrc | BallQuat | BallAngVel | JointLimitPos | JointLimitVel
        | JointLimitFrc => {
            let name = required("joint")?;
            let j = names.joint_of(name, loc, tag)?;
            let joint = &model.joints[j];
            let ball = matches!(joint.kind, JointKind::Ball);
            let scalar = matches!(joint.kind, JointKind::Revolute { .. } | JointKind::Prismatic { .. });
            match kind {
                BallQuat | BallAngVel if !ball => return Err(invalid(e, "joint must be ball in sensor")),
                JointPos | JointVel | JointActuatorFrc if !scalar => {
                    return Err(invalid(e, "joint must be slide or hinge in sensor"))
                }
                JointLimitPos | JointLimitVel | JointLimitFrc if joint.limits.is_none() => {
                    return Err(invalid(e, "joint must be limited in sensor"))
                }
                _ => {}
            }
            object = SensorObject::Joint(j);
        }
        TendonPos | TendonVel | TendonActuatorFrc | TendonLimitPos | TendonLimitVel | TendonLimitFrc => {
            let t = names.tendon_of(required("tendon")?, loc, tag)?;
            let tendon = &model.tendons[t];
            if matches!(kind, TendonLimitPos | TendonLimitVel | TendonLimitFrc) && tendon.range.is_none() {
                return Err(invalid(e, "tendon must be limited in sensor"));
            }
            object = SensorObject::Tendon(t);
        }
        ActuatorPos | ActuatorVel | ActuatorFrc => {
            let name = required("actuator")?;
            let a = model.actuators.iter().position(|a| a.name == name).ok_or_else(|| {
                LoadError::UnknownReference {
                    loc: loc.clone(),
                    element: tag.to_string(),
                    kind: "actuator",
                    target: name.to_string(),
                }
            })?;
            if let Some(why) = crate::model::actuator::unsimulated_reason(model, &model.actuators[a]) {
                not_computed = Some(format!("its actuator is not simulated ({why})"));
            }
            object = SensorObject::Actuator(a);
            dim = Some(1);
        }
        FramePos | FrameQuat | FrameXAxis | FrameYAxis | FrameZAxis | FrameLinVel | FrameAngVel
        | FrameLinAcc | FrameAngAcc => {
            match frame_object(e, names, Some(required("objtype")?), attr(e, "objname"), "obj")? {
                Ok(o) => object = o,
                Err(why) => not_computed = Some(why),
            }
            match frame_object(e, names, attr(e, "reftype"), attr(e, "refname"), "ref")? {
                Ok(o) => reference = o,
                Err(why) => not_computed = Some(why),
            }
        }
        SubtreeCom | SubtreeLinVel | SubtreeAngMom => {
            object = SensorObject::Body(names.body_id_of(required("body")?, loc, tag)?);
        }
        InsideSite => {
            reference = SensorObject::Site(names.site_of(required("site")?, loc, tag)?);
            match frame_object(e, names, Some(required("objtype")?), attr(e, "objname"), "obj")? {
                Ok(o) => object = o,
                Err(why) => not_computed = Some(why),
            }
        }
        GeomDist | GeomNormal | GeomFromTo => {
            let one = |body: &str, geom: &str| -> Result<SensorObject, LoadError> {
                match (attr(e, body), attr(e, geom)) {
                    (Some(b), _) => Ok(SensorObject::Body(names.body_id_of(b, loc, tag)?)),
                    (None, Some(g)) => Ok(SensorObject::Geom(names.geom_of(g, loc, tag)?)),
                    (None, None) => Err(invalid(e, format!("needs {body} or {geom}"))),
                }
            };
            object = one("body1", "geom1")?;
            reference = one("body2", "geom2")?;
            if object == reference {
                return Err(invalid(e, "1st body/geom must be different from 2nd body/geom"));
            }
        }
        Contact => {
            object = if let Some(s) = attr(e, "site") {
                SensorObject::Site(names.site_of(s, loc, tag)?)
            } else if let Some(b) = attr(e, "body1") {
                SensorObject::Body(names.body_id_of(b, loc, tag)?)
            } else if let Some(b) = attr(e, "subtree1") {
                SensorObject::XBody(names.body_id_of(b, loc, tag)?)
            } else if let Some(g) = attr(e, "geom1") {
                SensorObject::Geom(names.geom_of(g, loc, tag)?)
            } else {
                SensorObject::None
            };
            reference = if let Some(b) = attr(e, "body2") {
                SensorObject::Body(names.body_id_of(b, loc, tag)?)
            } else if let Some(b) = attr(e, "subtree2") {
                SensorObject::XBody(names.body_id_of(b, loc, tag)?)
            } else if let Some(g) = attr(e, "geom2") {
                SensorObject::Geom(names.geom_of(g, loc, tag)?)
            } else {
                SensorObject::None
            };
            let spec = dataspec(e, &CONTACT_FIELDS, 1)?;
            let reduce = match attr(e, "reduce").unwrap_or("none") {
                "none" => 0,
                "mindist" => 1,
                "maxforce" => 2,
                "netforce" => 3,
                other => {
                    return Err(invalid(
                        e,
                        format!("reduce=\"{other}\" must be none, mindist, maxforce or netforce"),
                    ))
                }
            };
            let num = match attr(e, "num") {
                None => 1,
                Some(n) => match n.trim().parse::<i64>() {
                    Ok(n) if n > 0 => n as usize,
                    _ => return Err(invalid(e, "'num' must be positive in sensor")),
                },
            };
            if reduce == 3 && spec >> 7 != 0 {
                return Err(invalid(e, "netforce reduction is incompatible with linvel or angvel"));
            }
            dim = Some(slot_size(&CONTACT_FIELDS, spec).saturating_mul(num));
            contact = Some(ContactSensorSpec { dataspec: spec, reduce, num });
        }
        EPotential | EKinetic | Clock => {}
        User => {
            let n = attr(e, "dim").ok_or_else(|| invalid(e, "missing attribute 'dim'"))?;
            let n: usize =
                n.trim().parse().map_err(|_| invalid(e, "sensor dim must be non-negative in sensor"))?;
            dim = Some(n);
            stage = match attr(e, "needstage").unwrap_or("acc") {
                "pos" => SensorStage::Position,
                "vel" => SensorStage::Velocity,
                _ => SensorStage::Acceleration,
            };
            datatype = match attr(e, "datatype").unwrap_or("real") {
                "positive" => SensorDataType::Positive,
                "axis" => SensorDataType::Axis,
                "quaternion" => SensorDataType::Quaternion,
                _ => SensorDataType::Real,
            };
            not_computed = Some("a user sensor: its values come from user code (they stay 0)".into());
        }
        Tactile => {
            not_computed = Some(
                "tactile sensors are not simulated (its size in sensordata is unknown, so later sensors' addresses differ from MuJoCo's)".into(),
            );
            dim = Some(0);
        }
        Plugin => {
            not_computed = Some(
                "engine plugins are not supported (its size in sensordata is unknown, so later sensors' addresses differ from MuJoCo's)".into(),
            );
            dim = Some(0);
        }
    }
    if cutoff > 0.0
        && (datatype == SensorDataType::Quaternion
            || (datatype == SensorDataType::Axis && kind != GeomNormal))
    {
        return Err(invalid(e, "cutoff applied to axis or quaternion datatype in sensor"));
    }
    let history = ["nsample", "delay", "interval"]
        .iter()
        .filter(|a| {
            attr(e, a).is_some_and(|v| v.split_whitespace().any(|x| x.parse::<f64>().is_ok_and(|x| x != 0.0)))
        })
        .copied()
        .collect::<Vec<_>>();
    if not_computed.is_none() && !history.is_empty() {
        not_computed =
            Some(format!("it has a sensor history ({}), which is not simulated", history.join(", ")));
    }
    Ok(Sensor {
        name: e.name.clone(),
        kind,
        object,
        reference,
        adr: 0,
        dim: dim.unwrap_or(0),
        stage,
        datatype,
        cutoff,
        noise,
        contact,
        ray_dataspec,
        not_computed,
        loc: e.loc.clone(),
        id,
    })
}
