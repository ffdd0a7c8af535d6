//! `lagrange eval MODEL --states FILE`: one process evaluates a batch of states (the interface the
//! validation scripts use; schema in docs/cli.md). The states are read one at a time
//! ([`super::eval_stream`]) and each result is written as soon as it is computed, so memory does not
//! grow with the number of states. A state whose result has a non-finite number gets an
//! `{"error": "..."}` entry in its place (naming the quantity) and the run ends with
//! [`super::EXIT_STATES_FAILED`]; no `null` is ever printed.

use super::eval_stream::for_each_state;
use super::finite_json::{describe, first_null};
use super::stdout::Stdout;
use super::CliError;
use lagrange::constraint::contact_force::contact_force;
use lagrange::constraint::ConstraintMode;
use lagrange::derivatives::{
    aba_derivatives, rnea_derivatives, smooth_derivatives, transition_jacobians, DerivativesWork,
    TransitionMethod, TransitionOptions, TransitionWork,
};
use lagrange::dynamics::{aba, bias_forces, center_of_mass, crba, kinetic_energy, potential_energy};
use lagrange::forward::forward;
use lagrange::io::{load, LoadOptions};
use lagrange::kinematics::{forward_kinematics, frame_jacobian, ReferenceFrame};
use lagrange::model::EfcType;
use lagrange::model::FrameKind;
use lagrange::{Data, Model};
use nalgebra::DMatrix;
use serde::Deserialize;
use serde_json::{json, Map, Value};
use std::path::Path;

/// One input state: q (nq), v (nv, default zero), tau (nv, default zero).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StateIn {
    pub q: Vec<f64>,
    #[serde(default)]
    pub v: Option<Vec<f64>>,
    #[serde(default)]
    pub tau: Option<Vec<f64>>,
    /// Controls, one per actuator (default zero).
    #[serde(default)]
    pub ctrl: Option<Vec<f64>>,
    /// Actuator activations, one per actuator with activation dynamics (MuJoCo's `act`, `na`
    /// values; default zero).
    #[serde(default)]
    pub act: Option<Vec<f64>>,
    /// The simulation time (s) the clock sensor reads (default zero).
    #[serde(default)]
    pub time: Option<f64>,
    /// The actuators' control histories (MuJoCo's `history`, `nhistory` values in its layout;
    /// default: the buffers as a reset leaves them).
    #[serde(default)]
    pub history: Option<Vec<f64>>,
    /// The soft solver's warm start (MuJoCo's `qacc_warmstart`, nv values; default zero): read
    /// by `--step` only.
    #[serde(default)]
    pub qacc_warmstart: Option<Vec<f64>>,
}

/// What `eval --derivatives` adds to each state's result.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Derivatives {
    /// RNEA, ABA and smooth forward-dynamics derivatives and the step's transition Jacobians.
    All,
    /// Without the transition Jacobians.
    Smooth,
    /// As `all`, the transition's velocity and control columns analytic (the library's
    /// `TransitionMethod::Hybrid`; docs/derivatives.md).
    Hybrid,
}

/// Buffers of the derivatives, made once per run.
pub struct DerivativeBuffers {
    which: Derivatives,
    work: DerivativesWork,
    transition: TransitionWork,
}

impl DerivativeBuffers {
    /// Buffers for `model`.
    pub fn new(model: &Model, which: Derivatives) -> Self {
        Self { which, work: DerivativesWork::new(model), transition: TransitionWork::new(model) }
    }
}

/// `"derivatives"` of one state, after [`forward_json`] left the state in `data`: `rnea` at
/// (q, v, forward's qacc), `aba` of the printed ABA `qacc` (τ = the state's tau), `smooth` of
/// `forward.qacc_smooth` (passive, actuator and applied forces differentiated), `transition`
/// (A, B of one step, as MuJoCo's `mjd_transitionFD`, centred, ε = 1e-6; `hybrid`: the velocity
/// and control columns analytic) unless `smooth`.
fn derivatives_json(
    model: &Model,
    data: &mut Data,
    s: &StateIn,
    v: &[f64],
    tau: &[f64],
    d: &mut DerivativeBuffers,
) -> Result<Value, CliError> {
    let qacc = data.qacc.clone();
    let w = &mut d.work;
    rnea_derivatives(model, data, w, &s.q, v, qacc.as_slice())?;
    let rnea = json!({"dtau_dq": rows(&w.dtau_dq), "dtau_dv": rows(&w.dtau_dv)});
    aba_derivatives(model, data, w, &s.q, v, tau)?;
    let aba = json!({"dqacc_dq": rows(&w.dqacc_dq), "dqacc_dv": rows(&w.dqacc_dv), "dqacc_dtau": rows(&w.dqacc_dtau)});
    smooth_derivatives(model, data, w)?;
    let smooth = json!({"dqacc_dq": rows(&w.dqacc_dq), "dqacc_dv": rows(&w.dqacc_dv), "dqacc_dtau": rows(&w.dqacc_dtau)});
    let mut out = json!({"rnea": rnea, "aba": aba, "smooth": smooth});
    if d.which != Derivatives::Smooth {
        data.qacc_warmstart.copy_from(&qacc);
        let method = if d.which == Derivatives::Hybrid {
            TransitionMethod::Hybrid
        } else {
            TransitionMethod::FiniteDifference
        };
        let options = TransitionOptions { method, ..Default::default() };
        out["transition"] = match transition_jacobians(model, data, &mut d.transition, &options) {
            Ok(()) => json!({"A": rows(&d.transition.a), "B": rows(&d.transition.b)}),
            Err(e) => json!({"error": e.to_string()}),
        };
    }
    Ok(out)
}

fn rows(m: &DMatrix<f64>) -> Vec<Vec<f64>> {
    (0..m.nrows()).map(|r| m.row(r).iter().copied().collect()).collect()
}

/// Evaluates one state: M, bias, qacc, poses of every frame, energies, com, and the requested
/// frame Jacobians (world-aligned).
///
/// With `kernels_only`, the smooth kernels alone: no `forward` pipeline and no sensors (what the
/// corpus cross-validation compares; a model loaded with `--accept-nonphysical-inertia` may have a
/// pipeline that is not finite where the kernels are), and an ABA `qacc` that is not finite — M
/// singular at the state — is left out with the reason in `qacc_error` (M, bias and poses are
/// still compared).
pub fn evaluate(
    model: &Model,
    data: &mut Data,
    s: &StateIn,
    jacobians: &[usize],
    kernels_only: bool,
    derivatives: Option<&mut DerivativeBuffers>,
) -> Result<Value, CliError> {
    let zeros = vec![0.0; model.nv];
    let v = s.v.as_deref().unwrap_or(&zeros);
    let tau = s.tau.as_deref().unwrap_or(&zeros);
    let m = rows(crba(model, data, &s.q)?);
    let bias: Vec<f64> = bias_forces(model, data, &s.q, v)?.iter().copied().collect();
    let qacc: Vec<f64> = aba(model, data, &s.q, v, tau)?.iter().copied().collect();
    let kinetic = kinetic_energy(model, data, &s.q, v)?;
    forward_kinematics(model, data, &s.q)?;
    let potential = potential_energy(model, data);
    let com = center_of_mass(model, data);
    // Links/bodies (and joint-anchor frames) in "poses", MJCF sites in "sites": MuJoCo keeps
    // bodies and sites in separate namespaces, and models reuse names across them.
    let (mut poses, mut sites) = (Map::new(), Map::new());
    for (f, frame) in model.frames.iter().enumerate() {
        let x = &data.x_world_frame[f];
        let map = if frame.kind == FrameKind::Site { &mut sites } else { &mut poses };
        map.insert(frame.name.clone(), json!({"pos": x.pos.as_slice(), "quat": x.quat_wxyz()}));
    }
    let mut out = json!({
        "M": m, "bias": bias, "qacc": qacc, "poses": poses, "sites": sites,
        "kinetic": kinetic, "potential": potential, "com": com.as_slice(),
    });
    if !jacobians.is_empty() {
        let mut jac = DMatrix::zeros(6, model.nv);
        let mut jmap = Map::new();
        for &f in jacobians {
            frame_jacobian(model, data, f, ReferenceFrame::LocalWorldAligned, &mut jac)?;
            jmap.insert(model.frames[f].name.clone(), json!(rows(&jac)));
        }
        out["jacobians"] = Value::Object(jmap);
    }
    if kernels_only {
        if out["qacc"].as_array().is_some_and(|a| a.iter().any(|x| !x.as_f64().is_some_and(f64::is_finite))) {
            let map = out.as_object_mut().expect("an object");
            map.remove("qacc");
            map.insert(
                "qacc_error".into(),
                json!("ABA's qacc is not finite: the mass matrix is singular at this state (a massless floating or moving body)"),
            );
        }
    } else {
        out["forward"] = forward_json(model, data, s, v, tau);
        out["sensors"] = super::sensor_columns::to_json(model, data.sensordata.as_slice());
        if let Some(d) = derivatives {
            out["derivatives"] = derivatives_json(model, data, s, v, tau, d)?;
        }
        let warnings = data.warnings.messages(model);
        if !warnings.is_empty() {
            out["warnings"] = json!(warnings);
        }
    }
    Ok(out)
}

/// The sensors not computed, by label, with the reason.
pub fn sensors_not_computed_json(model: &Model) -> Value {
    let mut map = Map::new();
    for s in &model.sensors {
        let why = match &s.not_computed {
            Some(why) => why.clone(),
            None if !model.options.flags.sensor => {
                "sensors are disabled (<flag sensor=\"disable\">)".to_string()
            }
            None => continue,
        };
        map.insert(s.label(), json!(why));
    }
    Value::Object(map)
}

/// The staged forward pipeline at the state: `qacc` (constrained), its parts, and one entry per
/// active constraint with its multipliers and residuals (docs/cli.md, "eval").
fn forward_json(model: &Model, data: &mut Data, s: &StateIn, v: &[f64], tau: &[f64]) -> Value {
    data.qfrc_applied.copy_from_slice(tau);
    data.ctrl.fill(0.0);
    if let Some(ctrl) = &s.ctrl {
        data.ctrl.copy_from_slice(ctrl);
    }
    data.act.fill(0.0);
    if let Some(act) = &s.act {
        data.act.copy_from_slice(act);
    }
    data.qpos.copy_from_slice(&s.q);
    data.qvel.copy_from_slice(v);
    data.time = s.time.unwrap_or(0.0);
    set_history(model, data, s);
    data.warnings.clear();
    forward(model, data);
    let mut constraints = Vec::new();
    let file = model.source.as_ref().map(|p| p.display().to_string()).unwrap_or_default();
    let mut r = 0;
    while r < data.nefc {
        let id = data.efc_id[r];
        let n = data.efc_block_len(r);
        let mut entry = match data.efc_type[r] {
            EfcType::Equality => {
                let eq = &model.equalities[id];
                let n = eq.kind.nrow();
                json!({"name": eq.name, "kind": eq.kind.name(), "source": eq.loc.to_string(), "rows": n})
            }
            EfcType::LimitJoint => json!({"name": model.joints[id].name, "kind": "limit", "source": file}),
            EfcType::LimitTendon => {
                json!({"name": model.tendons[id].name, "kind": "tendon_limit", "source": model.tendons[id].loc.to_string()})
            }
            EfcType::FrictionTendon => {
                json!({"name": model.tendons[id].name, "kind": "tendon_friction", "source": model.tendons[id].loc.to_string()})
            }
            EfcType::FrictionDof => {
                let joint = model.joint_of(model.dof_body[id]);
                json!({"name": joint.name, "kind": "friction", "source": file, "dof": id})
            }
            EfcType::ContactFrictionless | EfcType::ContactElliptic | EfcType::ContactPyramidal => {
                let c = &data.contacts[id];
                let names = c.geom.map(|g| geom_name(model, g));
                json!({
                    "name": format!("{}|{}", names[0], names[1]), "kind": "contact", "source": file,
                    "geoms": names, "pos": c.pos.as_slice(), "normal": c.frame.row(0).transpose().as_slice(),
                    "frame": [c.frame.row(0).transpose().as_slice(), c.frame.row(1).transpose().as_slice(),
                              c.frame.row(2).transpose().as_slice()],
                    "dist": c.dist, "condim": c.condim,
                    "contact_force": contact_force(model, data, id).unwrap_or_default(),
                })
            }
        };
        let n = entry.get("rows").and_then(Value::as_u64).map_or(n, |k| k as usize);
        entry["force"] = json!(data.efc_force.as_slice()[r..r + n]);
        entry["violation"] = json!(data.efc_pos.as_slice()[r..r + n]);
        constraints.push(entry);
        r += n;
    }
    let vec = |x: &nalgebra::DVector<f64>| x.as_slice().to_vec();
    let efc = model.plan.solver.soft_weights().is_some().then(|| soft_rows_json(model, data));
    let mut out = json!({
        "qacc": vec(&data.qacc), "qacc_smooth": vec(&data.qacc_smooth), "qfrc_passive": vec(&data.qfrc_passive),
        "qfrc_actuator": vec(&data.qfrc_actuator), "qfrc_constraint": vec(&data.qfrc_constraint),
        "actuator_force": vec(&data.actuator_force), "actuator_length": vec(&data.actuator_length),
        "actuator_velocity": vec(&data.actuator_velocity), "act_dot": vec(&data.act_dot),
        "actuator_moment": (0..data.actuator_moment.nrows())
            .map(|i| data.actuator_moment.row(i).iter().copied().collect::<Vec<f64>>())
            .collect::<Vec<_>>(),
        "constraints": constraints,
    });
    if let Some(efc) = efc {
        out["efc"] = efc;
    }
    out
}

/// Soft mode: every row with MuJoCo's per-row quantities (`efc_type`, `efc_id` as the element's
/// name, `efc_pos`, `efc_margin`, `efc_vel`, `efc_diagA`, `efc_R`, `efc_D`, `efc_aref`,
/// `efc_force`, `efc_state`, the Jacobian row), the contacts, and the solver's statistics.
fn soft_rows_json(model: &Model, data: &Data) -> Value {
    let n = data.nefc;
    let element = |r: usize| -> String {
        let id = data.efc_id[r];
        match data.efc_type[r] {
            EfcType::Equality => model.equalities[id].name.clone(),
            EfcType::LimitJoint => model.joints[id].name.clone(),
            EfcType::LimitTendon => model.tendons[id].name.clone(),
            EfcType::FrictionDof => format!("dof{id}"),
            _ => {
                let c = &data.contacts[id];
                format!("{}|{}", geom_name(model, c.geom[0]), geom_name(model, c.geom[1]))
            }
        }
    };
    let col = |x: &nalgebra::DVector<f64>| x.as_slice()[..n].to_vec();
    let contacts: Vec<Value> = data
        .contacts
        .iter()
        .enumerate()
        .map(|(i, c)| {
            json!({
                "geoms": c.geom.map(|g| geom_name(model, g)), "geom_ids": c.geom, "pos": c.pos.as_slice(), "dist": c.dist,
                "frame": [c.frame.row(0).transpose().as_slice(), c.frame.row(1).transpose().as_slice(),
                          c.frame.row(2).transpose().as_slice()],
                "condim": c.condim, "includemargin": c.includemargin, "mu": data.contact_mu[i],
                "friction": c.friction,
                "contact_force": contact_force(model, data, i).unwrap_or_default(),
            })
        })
        .collect();
    json!({
        "type": data.efc_type[..n].iter().map(|t| t.name()).collect::<Vec<_>>(),
        "id": data.efc_id[..n].to_vec(),
        "element": (0..n).map(element).collect::<Vec<_>>(),
        "pos": col(&data.efc_pos), "margin": col(&data.efc_margin), "vel": col(&data.efc_vel),
        "diagA": col(&data.efc_diag_a), "R": col(&data.efc_r), "D": col(&data.efc_d),
        "aref": col(&data.efc_aref), "force": col(&data.efc_force),
        "state": data.efc_state[..n].iter().map(|s| s.name()).collect::<Vec<_>>(),
        "J": (0..n).map(|r| data.efc_j.row(r).iter().copied().collect::<Vec<f64>>()).collect::<Vec<_>>(),
        "ne": data.ne, "nf": data.nf, "contacts": contacts,
        "solver_niter": data.solver_niter, "solver_improvement": data.solver_improvement,
        "solver_gradient": data.solver_gradient,
    })
}

/// A geom's name, or `<body>#<index>` for an unnamed one.
pub fn geom_name(model: &Model, g: usize) -> String {
    let geom = &model.geoms[g];
    if geom.name.is_empty() {
        format!("{}#{g}", geom.link)
    } else {
        geom.name.clone()
    }
}

/// The state's control histories, or the reset buffers when it gives none.
pub fn set_history(model: &Model, data: &mut Data, s: &StateIn) {
    match &s.history {
        Some(h) => data.history.copy_from_slice(h),
        None => lagrange::forward::history::reset_buffers(model, data),
    }
}

/// Checks one input state's sizes and values.
fn check_state(model: &Model, file: &str, i: usize, s: &StateIn) -> Result<(), CliError> {
    let err =
        |detail: String| CliError::Input { file: file.to_string(), detail: format!("states[{i}]: {detail}") };
    let check = |name: &str, x: &Option<Vec<f64>>, n: usize| match x {
        Some(x) if x.len() != n => Err(err(format!("'{name}' has {} values, the model needs {n}", x.len()))),
        Some(x) if x.iter().any(|e| !e.is_finite()) => Err(err(format!("'{name}' has a non-finite value"))),
        _ => Ok(()),
    };
    check("q", &Some(s.q.clone()), model.nq)?;
    check("v", &s.v, model.nv)?;
    check("tau", &s.tau, model.nv)?;
    check("ctrl", &s.ctrl, model.actuators.len())?;
    check("act", &s.act, model.na())?;
    check("history", &s.history, model.nhistory())?;
    check("qacc_warmstart", &s.qacc_warmstart, model.nv)?;
    match s.time {
        Some(t) if !t.is_finite() => Err(err("'time' is not finite".to_string())),
        _ => Ok(()),
    }
}

/// Runs `eval`, printing `{"results": [...]}`; with `step` = Some(N), each result is the state
/// after N steps ([`super::eval_step`]).
// One argument per command-line option of `eval`, passed through from clap.
#[allow(clippy::too_many_arguments)]
pub fn run(
    path: &Path,
    options: &LoadOptions,
    states: &Path,
    jacobians: &[String],
    mode: Option<ConstraintMode>,
    kernels_only: bool,
    step: Option<u32>,
    derivatives: Option<Derivatives>,
    dump_problem: Option<&Path>,
) -> Result<(), CliError> {
    let step = step.map(super::eval_step::check_steps).transpose()?;
    if dump_problem.is_some() && step.is_none() {
        return Err(CliError::Usage(
            "--dump-contact-problem writes the problem at the state after --step N: add e.g. --step 1".into(),
        ));
    }
    if kernels_only && derivatives.is_some() {
        return Err(CliError::Usage(
            "--derivatives needs the forward pipeline (its qacc, actuators and step): drop --kernels-only"
                .into(),
        ));
    }
    if step.is_some() && derivatives.is_some() {
        return Err(CliError::Usage(
            "--step prints the states after the steps, --derivatives those of the given states: use one at a time"
                .into(),
        ));
    }
    let mut model = load(path, options)?;
    if let Some(mode) = mode {
        model.set_constraint_mode(mode);
    }
    if dump_problem.is_some() && model.plan.solver.exact().is_none() {
        return Err(CliError::Usage(
            "--dump-contact-problem writes the exact mode's problem: add --constraints exact".into(),
        ));
    }
    let mut problems = Vec::new();
    let file = states.display().to_string();
    let frame_ids = jacobians
        .iter()
        .map(|name| {
            model
                .frame_id(name)
                .ok_or_else(|| CliError::Usage(format!("--jacobian {name}: the model has no frame '{name}'")))
        })
        .collect::<Result<Vec<_>, _>>()?;
    let reader = std::fs::File::open(states)
        .map(|f| std::io::BufReader::with_capacity(1 << 16, f))
        .map_err(|source| CliError::Io { file: file.clone(), source })?;
    let mut data = Data::new(&model);
    let mut buffers = derivatives.map(|which| DerivativeBuffers::new(&model, which));
    let mut out = Stdout::lock();
    // The output is `{"constraints": {...}, "results": [...]}`, keys in serde_json's (sorted)
    // order: byte for byte what serializing the whole object at once gives.
    let constraints = json!({"mode": model.plan.mode().name(), "reason": model.plan.mode_reason});
    out.print("{\"constraints\":")?;
    out.json(&constraints)?;
    out.print(",\"results\":[")?;
    let (mut failed, mut first) = (0usize, Vec::new());
    let expected =
        "{\"states\": [{\"q\": [...], \"v\": [...], \"tau\": [...], \"ctrl\": [...], \"act\": [...]}]}";
    let progress = super::progress::bar(None, "states");
    let total = for_each_state(reader, &file, expected, &mut |i, s: StateIn| {
        if i % 64 == 0 {
            progress.set_position(i as u64);
        }
        check_state(&model, &file, i, &s)?;
        let mut result = match step {
            Some(n) => super::eval_step::evaluate(&model, &mut data, &s, n)?,
            None => evaluate(&model, &mut data, &s, &frame_ids, kernels_only, buffers.as_mut())?,
        };
        if let (Some(n), Some(_)) = (step, dump_problem) {
            problems.push(super::contact_problem::problem_json(&model, &mut data, n)?);
        }
        if let Some(path) = first_null(&result) {
            let reason = format!("states[{i}]: {} is not finite (NaN or infinite)", describe(&path));
            failed += 1;
            if first.len() < 3 {
                first.push(reason.clone());
            }
            result = json!({ "error": reason });
        }
        if i > 0 {
            out.print(",")?;
        }
        out.json(&result)
    })?;
    progress.finish_and_clear();
    // `sensors_not_computed` sorts after `results`: the key order stays serde_json's.
    out.print("],\"sensors_not_computed\":")?;
    out.json(&sensors_not_computed_json(&model))?;
    out.print("}\n")?;
    out.finish()?;
    if let Some(file) = dump_problem {
        let text = serde_json::to_string(&json!({ "problems": problems }))
            .map_err(|e| CliError::Usage(format!("--dump-contact-problem: {e}")))?;
        // Under a temporary name, renamed onto the target once complete (never a destroyed file).
        let mut dump = super::output_file::OutputFile::create(file)?;
        dump.write_all(text.as_bytes())?;
        dump.commit()?;
    }
    if failed > 0 {
        return Err(CliError::StatesFailed {
            failed,
            total,
            first: first.join("; ") + if failed > first.len() { "; …" } else { "" },
        });
    }
    Ok(())
}
