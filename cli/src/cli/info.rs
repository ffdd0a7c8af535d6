//! `lagrange info MODEL [--json]`: the compiled tree, sizes and the simulation plan.

use super::CliError;
use lagrange::constraint::ConstraintMode;
use lagrange::forward::Plan;
use lagrange::io::{load, LoadOptions};
use lagrange::model::actuator::Transmission;
use lagrange::model::{EqualityKind, TendonKind};
use lagrange::sensor::SensorObject;
use lagrange::Model;
use serde_json::{json, Map, Value};
use std::path::Path;

/// One element of the model beyond the tree, as `info` lists it.
struct Listed {
    category: String,
    kind: String,
    name: String,
    /// The names of the objects it acts on.
    targets: Vec<String>,
    source: String,
    status: String,
}

/// Status of elements the engine keeps without simulating them.
const NOT_SIMULATED: &str = "parsed, not simulated";
/// Status of URDF `<transmission>`s: ros_control hardware descriptions; torques act on the joints.
const TRANSMISSION: &str = "listed: joint torques act directly (--clamp-effort bounds them)";

/// Every equality constraint, tendon, actuator, contact pair and exclusion, then the untyped
/// elements (sensors, ...), with what the engine does with each.
fn listing(model: &Model) -> Vec<Listed> {
    let frame = |f: usize| model.frames[f].name.clone();
    let joint = |j: usize| model.joints[j].name.clone();
    let tendon = |t: usize| model.tendons[t].name.clone();
    let mut out = Vec::new();
    for e in &model.equalities {
        let targets = match &e.kind {
            EqualityKind::Connect { frame1, frame2, .. } | EqualityKind::Weld { frame1, frame2, .. } => {
                vec![frame(*frame1), frame(*frame2)]
            }
            EqualityKind::Joint { joint1, joint2, .. } => {
                std::iter::once(joint(*joint1)).chain(joint2.map(joint)).collect()
            }
            EqualityKind::Tendon { tendon1, tendon2, .. } => {
                std::iter::once(tendon(*tendon1)).chain(tendon2.map(tendon)).collect()
            }
            EqualityKind::Mimic { joint: follower, leader, .. } => vec![joint(*follower), joint(*leader)],
        };
        out.push(Listed {
            category: "equality".into(),
            kind: e.kind.name().to_string(),
            name: e.name.clone(),
            targets,
            source: e.loc.to_string(),
            status: "simulated (exact mode)".into(),
        });
    }
    for (i, t) in model.tendons.iter().enumerate() {
        let coupled = model.equalities.iter().any(|e| {
            matches!(e.kind, EqualityKind::Tendon { tendon1, tendon2, .. } if tendon1 == i || tendon2 == Some(i))
        });
        let (kind, targets, status) = match &t.kind {
            TendonKind::Fixed { joints } => (
                "fixed",
                joints.iter().map(|&(j, _)| joint(j)).collect(),
                if coupled { "simulated (equality rows)" } else { "parsed" },
            ),
            TendonKind::Spatial { path, .. } => ("spatial", path.clone(), "simulated"),
        };
        out.push(Listed {
            category: "tendon".into(),
            kind: kind.to_string(),
            name: t.name.clone(),
            targets,
            source: t.loc.to_string(),
            status: status.into(),
        });
    }
    for a in &model.actuators {
        let targets = match &a.transmission {
            Transmission::Joint(j) | Transmission::JointInParent(j) => vec![joint(*j)],
            Transmission::Tendon(t) => vec![tendon(*t)],
            Transmission::Site { site, refsite } => {
                std::iter::once(frame(*site)).chain(refsite.map(frame)).collect()
            }
            Transmission::Body(b) => vec![model.bodies[*b].name.clone()],
            Transmission::SliderCrank { cranksite, slidersite, .. } => {
                vec![frame(*cranksite), frame(*slidersite)]
            }
        };
        let status = if lagrange::forward::unsimulated_reason(model, a).is_none() {
            "simulated"
        } else {
            NOT_SIMULATED
        };
        out.push(Listed {
            category: "actuator".into(),
            kind: a.shortcut.name().to_string(),
            name: a.name.clone(),
            targets,
            source: a.loc.to_string(),
            status: status.into(),
        });
    }
    for p in &model.contact_pairs {
        out.push(Listed {
            category: "contact".into(),
            kind: "pair".into(),
            name: p.name.clone(),
            targets: vec![model.geoms[p.geom1].name.clone(), model.geoms[p.geom2].name.clone()],
            source: p.loc.to_string(),
            status: "simulated (exact mode)".into(),
        });
    }
    for x in &model.contact_excludes {
        out.push(Listed {
            category: "contact".into(),
            kind: "exclude".into(),
            name: x.name.clone(),
            targets: vec![model.bodies[x.body1].name.clone(), model.bodies[x.body2].name.clone()],
            source: x.loc.to_string(),
            status: "simulated (exact mode)".into(),
        });
    }
    for e in &model.elements {
        out.push(Listed {
            category: e.category.clone(),
            kind: e.kind.clone(),
            name: e.name.clone(),
            targets: e.targets.clone(),
            source: e.loc.to_string(),
            status: if e.category == "transmission" { TRANSMISSION } else { NOT_SIMULATED }.into(),
        });
    }
    for sensor in &model.sensors {
        let object = |o: SensorObject| -> Option<String> {
            match o {
                SensorObject::None => None,
                SensorObject::Body(b) | SensorObject::XBody(b) => Some(frame(model.links.frame[b])),
                SensorObject::Site(f) => Some(frame(f)),
                SensorObject::Geom(g) => Some(model.geoms[g].name.clone()),
                SensorObject::Joint(j) => Some(joint(j)),
                SensorObject::Tendon(t) => Some(tendon(t)),
                SensorObject::Actuator(a) => Some(model.actuators[a].name.clone()),
            }
        };
        let status = match &sensor.not_computed {
            None if model.options.flags.sensor => "computed".to_string(),
            None => "not computed: <flag sensor=\"disable\">".to_string(),
            Some(why) => format!("not computed: {why}"),
        };
        out.push(Listed {
            category: "sensor".into(),
            kind: sensor.kind.tag().to_string(),
            name: sensor.label(),
            targets: object(sensor.object).into_iter().chain(object(sensor.reference)).collect(),
            source: sensor.loc.to_string(),
            status,
        });
    }
    out
}

/// The URDF mimic a joint follows: (leader name, multiplier, offset, equality name).
fn mimic_of(model: &Model, j: usize) -> Option<(&str, f64, f64, &str)> {
    model.equalities.iter().find_map(|e| match e.kind {
        EqualityKind::Mimic { joint, leader, multiplier, offset } if joint == j => {
            Some((model.joints[leader].name.as_str(), multiplier, offset, e.name.as_str()))
        }
        _ => None,
    })
}

/// The plan `info` describes: the model's own (its inverse weights took a pass over the bodies
/// at compile), or a new one when `--constraints` asks for a mode.
fn plan_of(model: &Model, mode: Option<ConstraintMode>) -> std::borrow::Cow<'_, Plan> {
    match mode {
        Some(m) => std::borrow::Cow::Owned(Plan::new(model, Some(m))),
        None => std::borrow::Cow::Borrowed(&model.plan),
    }
}

/// The `info` JSON document: keys `nq`, `nv`, `total_mass`, `bodies`, `joints`, `stages`.
/// `com` is in the body frame, `inertia` is the 3×3 tensor about the centre of mass in body axes.
/// Body 0 is `world` (with any links welded to it); `total_mass` counts the moving bodies only.
pub fn to_json(model: &Model, mode: Option<ConstraintMode>) -> Value {
    let plan = plan_of(model, mode);
    let bodies: Vec<Value> = model
        .bodies
        .iter()
        .enumerate()
        .map(|(b, body)| {
            let i = body.inertia_com();
            json!({
                "name": body.name,
                "parent": if b == 0 { Value::Null } else { Value::from(model.bodies[body.parent].name.clone()) },
                "mass": body.mass(),
                "com": body.com().as_slice(),
                "inertia": [[i[(0, 0)], i[(0, 1)], i[(0, 2)]], [i[(1, 0)], i[(1, 1)], i[(1, 2)]], [i[(2, 0)], i[(2, 1)], i[(2, 2)]]],
            })
        })
        .collect();
    let joints: Vec<Value> = model
        .joints
        .iter()
        .enumerate()
        .map(|(i, j)| {
            let mut v = json!({
                "name": j.name,
                "type": j.kind.type_name(),
                "parent": model.bodies[j.parent].name,
                "child": model.bodies[j.body].name,
                "qposadr": j.qpos_adr,
                "dofadr": j.dof_adr,
                "nq": j.kind.nq(),
                "nv": j.kind.nv(),
            });
            if let Some((leader, multiplier, offset, equality)) = mimic_of(model, i) {
                v["mimic"] = json!({"joint": leader, "multiplier": multiplier, "offset": offset, "equality": equality});
            }
            v
        })
        .collect();
    let mut stages = Map::new();
    for s in &plan.stages {
        stages.insert(s.name.to_string(), json!({"status": s.status.as_str(), "reason": s.reason}));
    }
    let elements: Vec<Value> = listing(model)
        .into_iter()
        .map(|e| {
            json!({"category": e.category, "kind": e.kind, "name": e.name, "targets": e.targets,
                   "source": e.source, "status": e.status})
        })
        .collect();
    let keyframes: Vec<Value> =
        model.keyframes.iter().map(|k| json!({"name": k.name, "time": k.time})).collect();
    let frames: Vec<Value> = model
        .frames
        .iter()
        .map(|f| {
            json!({"name": f.name, "kind": format!("{:?}", f.kind).to_lowercase(), "body": model.bodies[f.body].name})
        })
        .collect();
    // MuJoCo's actuator_* compile-time constants, by actuator.
    let actuators: Vec<Value> = model
        .actuators
        .iter()
        .map(|a| {
            let history =
                a.history.map(|h| json!({"nsample": h.nsample, "delay": h.delay, "interp": h.interp.name()}));
            json!({"name": a.name, "kind": a.shortcut.name(), "lengthrange": a.lengthrange, "acc0": a.acc0,
                   "gear": a.gear, "ctrlrange": a.ctrlrange, "forcerange": a.forcerange, "history": history})
        })
        .collect();
    json!({
        "nq": model.nq,
        "nv": model.nv,
        "nu": model.actuators.len(),
        "na": model.na(),
        "total_mass": model.total_mass(),
        "bodies": bodies,
        "joints": joints,
        "actuators": actuators,
        "frames": frames,
        "qpos0": model.qpos0,
        "options": {"timestep": model.options.timestep, "integrator": model.options.integrator.mjcf_name(),
                    "gravity": model.gravity.as_slice(),
                    "flags": model.options.flags.changed().into_iter().map(|(n, on)| (n.to_string(), json!(if on { "enable" } else { "disable" }))).collect::<Map<String, Value>>()},
        "keyframes": keyframes,
        "elements": elements,
        "warnings": model.warnings.iter().map(|w| super::in_cli_terms(w)).collect::<Vec<_>>(),
        "stages": stages,
        "constraints": {"mode": plan.mode().name(), "reason": plan.mode_reason},
    })
}

/// Human-readable summary of a model.
pub fn to_text(model: &Model, mode: Option<ConstraintMode>) -> String {
    let plan = plan_of(model, mode);
    use std::fmt::Write;
    let mut s = String::new();
    let src = model.source.as_ref().map(|p| p.display().to_string()).unwrap_or_else(|| "(embedded)".into());
    let _ = writeln!(s, "model '{}' from {src}", model.name);
    let _ = writeln!(
        s,
        "nq = {}, nv = {}, {} moving bodies, {} frames, total mass {:.6} kg",
        model.nq,
        model.nv,
        model.nbody() - 1,
        model.frames.len(),
        model.total_mass()
    );
    if !model.actuators.is_empty() {
        let _ = writeln!(
            s,
            "nu = {} actuators (ctrl), na = {} activation states (act)",
            model.actuators.len(),
            model.na()
        );
    }
    let _ = writeln!(s, "\nbodies (com in body frame; inertia about com, body axes):");
    let _ = writeln!(s, "  {:<28} {:<24} {:>10}  {:<30} diag(I)", "name", "parent", "mass", "com");
    for (b, body) in model.bodies.iter().enumerate() {
        let parent = if b == 0 { "-" } else { model.bodies[body.parent].name.as_str() };
        let c = body.com();
        let i = body.inertia_com();
        let _ = writeln!(
            s,
            "  {:<28} {:<24} {:>10.5}  [{:>8.4} {:>8.4} {:>8.4}]  [{:.4e} {:.4e} {:.4e}]",
            body.name,
            parent,
            body.mass(),
            c.x,
            c.y,
            c.z,
            i[(0, 0)],
            i[(1, 1)],
            i[(2, 2)]
        );
    }
    let _ = writeln!(s, "\njoints (depth-first file order):");
    let _ = writeln!(
        s,
        "  {:<26} {:<10} {:<22} {:<22} {:>7} {:>6} {:>3} {:>3}  limits",
        "name", "type", "parent", "child", "qposadr", "dofadr", "nq", "nv"
    );
    for (i, j) in model.joints.iter().enumerate() {
        let limits = match j.limits {
            Some([lo, hi]) => format!("[{lo:.4}, {hi:.4}]"),
            None => "-".into(),
        };
        let mimic = mimic_of(model, i)
            .map(|(leader, multiplier, offset, _)| format!("  mimic {leader} (× {multiplier} + {offset})"))
            .unwrap_or_default();
        let effort = j.effort_limit.map(|e| format!("  |torque| ≤ {e} (--clamp-effort)")).unwrap_or_default();
        let _ = writeln!(
            s,
            "  {:<26} {:<10} {:<22} {:<22} {:>7} {:>6} {:>3} {:>3}  {limits}{mimic}{effort}",
            j.name,
            j.kind.type_name(),
            model.bodies[j.parent].name,
            model.bodies[j.body].name,
            j.qpos_adr,
            j.dof_adr,
            j.kind.nq(),
            j.kind.nv()
        );
    }
    if !model.keyframes.is_empty() {
        let names: Vec<&str> = model.keyframes.iter().map(|k| k.name.as_str()).collect();
        let _ = writeln!(s, "\nkeyframes (simulate --keyframe NAME): {}", names.join(", "));
    }
    let listed = listing(model);
    if !listed.is_empty() {
        let _ = writeln!(s, "\nelements ({}):", listed.len());
        let mut by_kind: Vec<(String, &str, usize)> = Vec::new();
        for e in &listed {
            let key = format!("{} <{}>", e.category, e.kind);
            match by_kind.iter_mut().find(|(k, st, _)| *k == key && *st == e.status) {
                Some(entry) => entry.2 += 1,
                None => by_kind.push((key, &e.status, 1)),
            }
        }
        for (k, status, n) in by_kind {
            let _ = writeln!(s, "  {n:>4} × {k:<28} {status}");
        }
    }
    let _ = writeln!(s, "\nforward plan (constraint mode: {}; {}):", plan.mode().name(), plan.mode_reason);
    for st in &plan.stages {
        let _ = writeln!(s, "  {:<22} {:<22} {}", st.name, st.status.as_str(), st.reason);
    }
    if !model.warnings.is_empty() {
        let _ = writeln!(s, "\nwarnings ({}):", model.warnings.len());
        for w in &model.warnings {
            let _ = writeln!(s, "  {}", super::in_cli_terms(w));
        }
    }
    s
}

/// Runs `info`.
pub fn run(
    path: &Path,
    options: &LoadOptions,
    json: bool,
    mode: Option<ConstraintMode>,
) -> Result<(), CliError> {
    let model = load(path, options)?;
    if json {
        let text = serde_json::to_string_pretty(&to_json(&model, mode)).expect("JSON values serialize");
        super::stdout::print(&(text + "\n"))
    } else {
        super::stdout::print(&to_text(&model, mode))
    }
}
