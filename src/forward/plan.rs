//! The plan of the forward pipeline: which stages run for a model and why (docs/architecture.md, "Layers").
//! It is built once from the model; [`forward`](super::forward) walks its stages, and `lagrange
//! info` prints the same list, so what is reported is what runs. A stage runs only when the model
//! contains what it acts on: a scene without constraint rows never builds M (ABA path), a scene
//! without damping or springs has no passive pass.

use crate::constraint::{ConstraintMode, ConstraintModel, ConstraintSolver, LimitKind};
use crate::model::Model;
use serde::Serialize;

/// What a stage does (MuJoCo's stage names for the pipeline; the rest say where rows come from
/// and what the model holds that is not simulated yet).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum StageKind {
    /// Body poses, M and its factor, constraint rows (MuJoCo's `mj_fwdPosition`).
    Position,
    /// Bias forces and the rows' velocity terms (`mj_fwdVelocity`).
    Velocity,
    /// Joint damping and springs (`mj_passive`).
    Passive,
    /// Actuator forces and activation derivatives (`mj_fwdActuation`).
    Actuation,
    /// Unconstrained acceleration `qacc_smooth` (`mj_fwdAcceleration`), or ABA without rows.
    Acceleration,
    /// The constraint solve (`mj_fwdConstraint`).
    Constraint,
    /// Rows of equality constraints and URDF mimics.
    Equality,
    /// Rows of joint limits (and fixed-tendon limits).
    JointLimits,
    /// Rows of joint friction loss.
    FrictionLoss,
    /// Collision detection and contact rows.
    Collision,
    /// Tendon lengths, Jacobians and wrap points (`mj_tendon`).
    Tendons,
    /// The sensor stage (`sensordata`), after the constraint stage.
    Sensors,
    /// Other passive forces MuJoCo computes (fluid forces, gravity compensation, spring-dampers, …;
    /// not simulated).
    PassiveOther,
    /// MuJoCo's fluid forces (`<option density viscosity wind>`, geom `fluidshape`), part of the
    /// passive stage (`dynamics::fluid`).
    Fluid,
}

/// Whether a stage runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Status {
    /// The stage runs in `forward`.
    Runs,
    /// The model has nothing for it (or a `<flag>` switches it off).
    Skipped,
    /// The model has such elements; they are kept and listed, not simulated yet.
    NotSimulated,
}

impl Status {
    /// The status as `info` prints it.
    pub fn as_str(self) -> &'static str {
        match self {
            Status::Runs => "runs",
            Status::Skipped => "skipped",
            Status::NotSimulated => "parsed, not simulated",
        }
    }
}

/// One stage with its status and the reason.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Stage {
    /// Which stage.
    pub kind: StageKind,
    /// Its name as `info` prints it (`position`, `joint limits`, …).
    pub name: &'static str,
    /// Whether it runs.
    pub status: Status,
    /// What it does for this model, or why it does not run.
    pub reason: String,
}

/// The per-model plan of [`forward`](super::forward): part of the compiled [`Model`]
/// ([`Model::plan`]), built when the model is compiled and rebuilt by
/// [`Model::set_constraint_mode`] and [`Model::rebuild_plan`]. The default is the empty plan of a
/// model without elements (what a model holds while it is being compiled).
#[derive(Clone, Debug, Default)]
pub struct Plan {
    /// Every stage in pipeline order, then the row sources and the elements not simulated.
    pub stages: Vec<Stage>,
    /// Why the constraint mode is what it is (requested, the format's default, or a fallback).
    pub mode_reason: String,
    /// The constraint rows of the model.
    pub constraints: ConstraintModel,
    /// The constraint solver: exact or soft, with its settings ([`Plan::mode`] tells which).
    pub solver: ConstraintSolver,
    /// Each actuator's velocity bias coefficient with `dampratio` resolved at `qpos0`
    /// ([`super::resolved_bias_velocity`]).
    pub actuator_bias_velocity: Vec<f64>,
    /// The actuators' layout for the actuation stage (simulated or not, activation, moment span,
    /// one-dof joint transmissions).
    pub actuators: super::ActuatorLayout,
    /// What the sensor stage computes beside the sensors (body velocities, subtree momenta, …).
    pub sensor_needs: crate::sensor::SensorNeeds,
    /// The fluid forces' bodies and coefficients (None without `<option density>` or `viscosity`).
    pub fluid: Option<crate::dynamics::fluid::FluidModel>,
    /// [`Model::max_dof_depth`], which the contact budget reads at every collision pass.
    pub max_dof_depth: usize,
}

impl Plan {
    /// The plan for `model`, with the constraint mode `requested` (None: MJCF models soft, URDF
    /// models exact, docs/architecture.md, "Conventions").
    pub fn new(model: &Model, requested: Option<ConstraintMode>) -> Self {
        let (mode, mode_reason) = resolve_mode(model, requested);
        let mut constraints = ConstraintModel::new(model);
        // The exact mode has no tendon rows: its fixed-tendon limits are listed as not simulated.
        let exact_tendon_limits = if mode == ConstraintMode::Exact {
            std::mem::take(&mut constraints.tendon_limits).len()
                + std::mem::take(&mut constraints.tendon_friction).len()
        } else {
            0
        };
        let stages = stages(model, &constraints, mode, exact_tendon_limits);
        let solver = ConstraintSolver::new(mode, model, &constraints);
        Self {
            stages,
            mode_reason,
            constraints,
            solver,
            actuator_bias_velocity: super::resolved_bias_velocity(model),
            actuators: super::ActuatorLayout::new(model),
            sensor_needs: crate::sensor::SensorNeeds::of(model),
            fluid: crate::dynamics::fluid::FluidModel::new(model),
            max_dof_depth: model.max_dof_depth(),
        }
    }

    /// The constraint mode of the plan's solver.
    pub fn mode(&self) -> ConstraintMode {
        self.solver.mode()
    }

    /// Whether the stage of `kind` runs.
    pub fn runs(&self, kind: StageKind) -> bool {
        self.stages.iter().any(|s| s.kind == kind && s.status == Status::Runs)
    }

    /// Whether the model has constraint rows (and so the M path and a constraint solve).
    pub fn has_constraints(&self) -> bool {
        !self.constraints.is_empty()
    }
}

fn is_mjcf(model: &Model) -> bool {
    model
        .source
        .as_ref()
        .and_then(|p| p.extension())
        .is_some_and(|e| e.eq_ignore_ascii_case("xml") || e.eq_ignore_ascii_case("mjcf"))
}

fn resolve_mode(model: &Model, requested: Option<ConstraintMode>) -> (ConstraintMode, String) {
    let (wanted, why) = match requested {
        Some(m) => (m, format!("{} requested", m.name())),
        None if is_mjcf(model) => (ConstraintMode::Soft, "soft is the default for MJCF".to_string()),
        None => (ConstraintMode::Exact, "exact is the default for URDF".to_string()),
    };
    (wanted, why)
}

fn stage(kind: StageKind, name: &'static str, status: Status, reason: impl Into<String>) -> Stage {
    Stage { kind, name, status, reason: reason.into() }
}

/// The stages of the plan; `exact_tendon_limits` tendon limits and friction losses are kept but not simulated
/// (exact mode).
fn stages(
    model: &Model,
    constraints: &ConstraintModel,
    mode: ConstraintMode,
    exact_tendon_limits: usize,
) -> Vec<Stage> {
    use StageKind::*;
    use Status::*;
    let nrow: usize = constraints.equalities.iter().map(|e| model.equalities[e.id].kind.nrow()).sum();
    let ntendon = constraints.tendon_limits.len();
    let nlimit = constraints.limits.len() + ntendon;
    let nfriction = constraints.friction.len() + constraints.tendon_friction.len();
    let rows = match (nrow, nlimit) {
        (_, 0) => format!("{nrow} constraint rows"),
        (0, _) => {
            format!("up to {nlimit} limit rows, only while a joint or tendon is at a limit (ABA otherwise)")
        }
        _ => format!("{nrow} equality rows and up to {nlimit} limit rows"),
    };
    let rows = if nfriction > 0 { format!("{rows}, {nfriction} friction-loss rows") } else { rows };
    let rows =
        if constraints.has_collision() { format!("{rows}, contact rows while touching") } else { rows };
    let constrained = !constraints.is_empty();
    let mut out = Vec::with_capacity(13);
    out.push(if constrained {
        stage(
            Position,
            "position",
            Runs,
            format!("body poses, CRBA and the tree-sparse LᵀDL factor of M (nv = {}), {rows}", model.nv),
        )
    } else {
        stage(
            Position,
            "position",
            Skipped,
            "no constraint rows: ABA computes the joint transforms in its first pass",
        )
    });
    out.push(if constrained {
        stage(Velocity, "velocity", Runs, "bias forces qfrc_bias (RNEA), J v and J̇ v of the active rows")
    } else {
        stage(
            Velocity,
            "velocity",
            Skipped,
            "no constraint rows: ABA computes velocities and bias in its passes",
        )
    });
    let damped = model.dof_damping.iter().filter(|&&d| d != 0.0).count();
    let springs = model.springs.len();
    let fluid = crate::dynamics::fluid::FluidModel::new(model);
    let tendon_passive = crate::tendon::passive::count_tendon_passive(model);
    let gravcomp = if crate::dynamics::gravcomp::active(model) { model.gravcomp.len() } else { 0 };
    out.push(if damped + springs + tendon_passive + gravcomp > 0 || fluid.is_some() {
        let tendons = if tendon_passive > 0 {
            format!(", {tendon_passive} tendon spring-dampers (ten_Jᵀ f)")
        } else {
            String::new()
        };
        stage(
            Passive,
            "passive",
            Runs,
            format!(
                "joint damping on {damped} degrees of freedom, {springs} joint springs{tendons}{}{}",
                if fluid.is_some() { ", fluid forces" } else { "" },
                if gravcomp > 0 {
                    format!(", gravity compensation on {gravcomp} bodies")
                } else {
                    String::new()
                }
            ),
        )
    } else {
        stage(Passive, "passive", Skipped, "no joint damping or springs")
    });
    // Typed actuators (simulated or not, and why), and any the loader kept as a listing.
    let listed = model.elements.iter().filter(|e| e.category == "actuator").count();
    let mut reasons: Vec<(&str, usize)> = Vec::new();
    for a in &model.actuators {
        if let Some(why) = super::unsimulated_reason(model, a) {
            match reasons.iter_mut().find(|(w, _)| *w == why) {
                Some(r) => r.1 += 1,
                None => reasons.push((why, 1)),
            }
        }
    }
    let unsimulated: usize = reasons.iter().map(|r| r.1).sum();
    let simulated = model.actuators.len() - unsimulated;
    let mut missing: Vec<String> = reasons.iter().map(|(w, k)| format!("{k} with {w}")).collect();
    if listed > 0 {
        missing.push(format!("{listed} of kinds not typed yet"));
    }
    let missing = if missing.is_empty() {
        String::new()
    } else {
        format!("; not simulated (no force): {}", missing.join(", "))
    };
    out.push(if model.actuators.is_empty() && listed == 0 {
        stage(Actuation, "actuation", Skipped, "no actuators")
    } else if !model.options.flags.actuation {
        stage(Actuation, "actuation", Skipped, "switched off by <option><flag actuation=\"disable\">")
    } else if simulated == 0 {
        stage(Actuation, "actuation", NotSimulated, format!("{} actuators{missing}", unsimulated + listed))
    } else {
        stage(
            Actuation,
            "actuation",
            Runs,
            format!(
                "{simulated} actuators (force = gain·(ctrl or act) + bias on joints, fixed tendons, sites and slider-cranks){}{missing}",
                match model.actuators.iter().filter(|a| a.history.is_some_and(|h| h.delay != 0.0)).count() {
                    0 => String::new(),
                    n => format!("; {n} with delayed controls (history buffers)"),
                }
            ),
        )
    });
    out.push(if constrained {
        stage(Acceleration, "acceleration", Runs, "qacc_smooth = M⁻¹ qfrc_smooth with the LᵀDL factor")
    } else {
        stage(
            Acceleration,
            "acceleration",
            Runs,
            format!("articulated-body algorithm over {} bodies, nv = {}", model.nbody() - 1, model.nv),
        )
    });
    out.push(if constrained && mode == ConstraintMode::Soft {
        stage(Constraint, "constraint", Runs, soft_description(model))
    } else if constrained {
        stage(
            Constraint,
            "constraint",
            Runs,
            format!(
                "{} mode: KKT system on the active rows, λ by the Delassus matrix J M⁻¹ Jᵀ{}{}",
                mode.name(),
                if nlimit > 0 { "; limits: complementarity, λ ≥ 0, by an active-set method" } else { "" },
                if nfriction > 0 {
                    "; rows with dry friction: projected block Gauss–Seidel (Signorini + Coulomb)"
                } else {
                    ""
                }
            ),
        )
    } else {
        stage(Constraint, "constraint", Skipped, "no constraint rows: qacc = qacc_smooth")
    });
    // Row sources and elements kept but not simulated.
    let flags = &model.options.flags;
    out.push(if model.equalities.is_empty() {
        stage(Equality, "equality", Skipped, "no equality constraints or mimic joints")
    } else if !flags.equality || !flags.constraint {
        stage(Equality, "equality", Skipped, "switched off by <option><flag equality|constraint=\"disable\">")
    } else {
        let mut counts: Vec<(&str, usize)> = Vec::new();
        for e in &model.equalities {
            match counts.iter_mut().find(|(k, _)| *k == e.kind.name()) {
                Some(c) => c.1 += 1,
                None => counts.push((e.kind.name(), 1)),
            }
        }
        let inactive = model.equalities.iter().filter(|e| !e.active).count();
        let list: Vec<String> = counts.iter().map(|(k, n)| format!("{n} {k}")).collect();
        let inactive = if inactive > 0 { format!(", {inactive} inactive at start") } else { String::new() };
        stage(Equality, "equality", Runs, format!("{} ({nrow} rows{inactive})", list.join(", ")))
    });
    let tendons_kept = if exact_tendon_limits > 0 {
        format!("; {exact_tendon_limits} tendon length limits and friction losses kept, not simulated in exact mode (soft mode has them)")
    } else {
        String::new()
    };
    out.push(if nlimit > 0 {
        let ball = constraints.limits.iter().filter(|l| matches!(l.kind, LimitKind::Cone { .. })).count();
        let counts = [
            (nlimit - ntendon - ball, "limited hinge/slide joints"),
            (ball, "ball-joint cone limits"),
            (ntendon, "tendon length limits"),
        ];
        let what: Vec<String> =
            counts.iter().filter(|(n, _)| *n > 0).map(|(n, w)| format!("{n} {w}")).collect();
        stage(
            JointLimits,
            "joint limits",
            Runs,
            format!(
                "{}: {}{tendons_kept}",
                what.join(", "),
                if mode == ConstraintMode::Soft {
                    "a soft row per bound within the joint's or tendon's margin (solreflimit, solimplimit)"
                } else {
                    "a unilateral row at a bound (exact mode)"
                }
            ),
        )
    } else if exact_tendon_limits > 0 {
        stage(JointLimits, "joint limits", NotSimulated, format!("no limited joints{tendons_kept}"))
    } else if !flags.limit && model.joints.iter().any(|j| j.limits.is_some()) {
        stage(JointLimits, "joint limits", Skipped, "switched off by <option><flag limit=\"disable\">")
    } else {
        stage(JointLimits, "joint limits", Skipped, "no limited joints")
    });
    let nfriction = constraints.friction.len();
    let ntendon_friction = constraints.tendon_friction.len();
    out.push(if nfriction + ntendon_friction > 0 {
        stage(
            FrictionLoss,
            "friction loss",
            Runs,
            format!("{nfriction} dofs and {ntendon_friction} tendons with dry friction: bounded rows |λ| ≤ frictionloss, always active"),
        )
    } else if !flags.frictionloss && model.joints.iter().any(|j| j.friction > 0.0) {
        stage(
            FrictionLoss,
            "friction loss",
            Skipped,
            "switched off by <option><flag frictionloss=\"disable\">",
        )
    } else {
        stage(FrictionLoss, "friction loss", Skipped, "no joints with friction loss")
    });
    let colliding = model.geoms.iter().filter(|g| g.collision).count();
    let npairs = model.collision_pairs.len();
    let hfields = model
        .geoms
        .iter()
        .filter(|g| g.collision && matches!(g.shape, crate::model::spec::Shape::Hfield { .. }))
        .count();
    let hfield_note = if hfields > 0 {
        format!("; {hfields} height fields (MuJoCo's prisms: exact for spheres, GJK/EPA for the other geoms)")
    } else {
        String::new()
    };
    out.push(if npairs > 0 {
        let bound = model.max_contacts();
        stage(
            Collision,
            "collision",
            Runs,
            format!(
                "{npairs} candidate geom pairs ({} explicit <pair>) among {colliding} collision geoms, up to {bound} contacts: bounding spheres, then closed forms (planes, spheres, capsules, boxes) or GJK/EPA; {}{hfield_note}",
                model.collision_pairs.iter().filter(|p| p.pair.is_some()).count(),
                if mode == ConstraintMode::Soft {
                    "soft mode: rows for contacts closer than their margin (detected to margin + gap)"
                } else {
                    "exact mode: contact rows while touching"
                }
            ),
        )
    } else if colliding > 0 && !(flags.contact && flags.constraint) {
        stage(Collision, "collision", Skipped, "switched off by <option><flag contact|constraint=\"disable\">")
    } else if colliding > 0 {
        stage(
            Collision,
            "collision",
            Skipped,
            format!("{colliding} collision geoms but no candidate pair (same body, parent–child, welded to the world, bit masks or <exclude>){hfield_note}"),
        )
    } else {
        stage(Collision, "collision", Skipped, "no collision geometry")
    });
    let spatial =
        model.tendons.iter().filter(|t| matches!(t.kind, crate::model::TendonKind::Spatial { .. })).count();
    out.push(if model.tendons.is_empty() {
        stage(Tendons, "tendons", Skipped, "no tendons")
    } else {
        stage(
            Tendons,
            "tendons",
            Runs,
            format!(
                "{} tendons ({spatial} spatial: forward kinematics, site paths wrapped around spheres and cylinders, pulleys): ten_length, ten_J, ten_velocity each evaluation",
                model.tendons.len()
            ),
        )
    });
    out.push(sensor_stage(model));
    let multi_dof_springs = model.joints.iter().filter(|j| j.stiffness != 0.0 && j.kind.nq() > 1).count();
    let other = model.elements.iter().filter(|e| matches!(e.category.as_str(), "body" | "joint")).count()
        + multi_dof_springs;
    let o = &model.options;
    if let Some(f) = &fluid {
        out.push(fluid_stage(model, f));
    } else if o.density != 0.0 || o.viscosity != 0.0 {
        out.push(stage(
            Fluid,
            "fluid forces",
            Skipped,
            "switched off with every passive force by <flag spring=\"disable\" damper=\"disable\">",
        ));
    }
    if other > 0 {
        out.push(stage(
            PassiveOther,
            "passive (other)",
            NotSimulated,
            format!(
                "{other} elements (spring-dampers, polynomial or ball/free springs); see `info` elements"
            ),
        ));
    }
    out
}

/// The fluid-forces stage: the medium, how many bodies feel each model, and what is left out.
fn fluid_stage(model: &Model, f: &crate::dynamics::fluid::FluidModel) -> Stage {
    let o = &model.options;
    let (boxes, geoms) = f.counts();
    let mut reason = format!(
        "<option density=\"{}\" viscosity=\"{}\" wind=\"{} {} {}\">: inertia-box model on {boxes} bodies, ellipsoid model on {geoms} geoms, into qfrc_fluid and qfrc_passive; not in the implicit integrators' velocity derivative (MuJoCo's is)",
        o.density, o.viscosity, o.wind[0], o.wind[1], o.wind[2]
    );
    if !f.unsupported.is_empty() {
        reason.push_str(&format!(
            "; {} fluidshape=\"ellipsoid\" geoms without semi-axes here (mesh, plane, height field) feel nothing",
            f.unsupported.len()
        ));
    }
    stage(StageKind::Fluid, "fluid forces", Status::Runs, reason)
}

/// The sensor stage: how many sensors of each stage are computed, what they add to a `forward`,
/// and which are not computed (with `info` listing each with its reason).
fn sensor_stage(model: &Model) -> Stage {
    use crate::sensor::SensorStage;
    let n = model.sensors.len();
    if n == 0 {
        return stage(StageKind::Sensors, "sensors", Status::Skipped, "no sensors");
    }
    if !model.options.flags.sensor {
        return stage(
            StageKind::Sensors,
            "sensors",
            Status::Skipped,
            format!("{n} sensors, disabled by <flag sensor=\"disable\">"),
        );
    }
    let computed =
        |st: SensorStage| model.sensors.iter().filter(|s| s.is_computed() && s.stage == st).count();
    let not = model.sensors.iter().filter(|s| !s.is_computed()).count();
    let needs = crate::sensor::SensorNeeds::of(model);
    let mut extra = vec!["world poses"];
    if needs.velocities {
        extra.push("body velocities");
    }
    if needs.subtree_com {
        extra.push("subtree centres of mass");
    }
    if needs.subtree_velocities {
        extra.push("subtree momenta");
    }
    let mut reason = format!(
        "{} position, {} velocity, {} acceleration-stage sensors into sensordata ({} values); adds {}",
        computed(SensorStage::Position),
        computed(SensorStage::Velocity),
        computed(SensorStage::Acceleration),
        model.nsensordata,
        extra.join(", ")
    );
    if not > 0 {
        reason.push_str(&format!("; {not} not computed (listed with the reason under sensors)"));
    }
    let status = if needs.any { Status::Runs } else { Status::NotSimulated };
    stage(StageKind::Sensors, "sensors", status, reason)
}

/// The constraint stage in soft mode: solver, cone and the `<option>` settings honoured, and the
/// MuJoCo features of the model the soft mode does not simulate yet.
fn soft_description(model: &Model) -> String {
    use crate::model::options::{Cone, Solver};
    let o = &model.options;
    let solver = match o.solver {
        Solver::Newton => "Newton (exact line search)",
        Solver::Cg => "CG (Polak–Ribière, M⁻¹-preconditioned, exact line search)",
        Solver::Pgs => "PGS on the dual",
    };
    let cone = match o.cone {
        Cone::Pyramidal => "pyramidal",
        Cone::Elliptic => "elliptic",
    };
    let mut missing = soft_unsupported(model);
    let missing = if missing.is_empty() {
        String::new()
    } else {
        missing.sort();
        format!("; not simulated in soft mode: {}", missing.join(", "))
    };
    let sleep = if o.flags.sleep {
        let may = model.sleep.policy.iter().filter(|p| p.may_sleep()).count();
        format!(
            "; sleeping islands on (sleep_tolerance {:e}: {may} of {} trees may sleep)",
            o.sleep_tolerance,
            model.sleep.ntree()
        )
    } else {
        String::new()
    };
    format!(
        "soft mode (MuJoCo's convex model): solref/solimp impedance, R from the diagonal approximation, aref = −b·Jv − k·d·r; {solver}, {cone} cones, impratio {}, iterations {}, tolerance {:e}, ls_iterations {}, ls_tolerance {:e}, warm start {}{sleep}{missing}",
        o.impratio,
        o.iterations,
        o.tolerance,
        o.ls_iterations,
        o.ls_tolerance,
        if o.flags.warmstart { "on" } else { "off" }
    )
}

/// MuJoCo features present in `model` that the soft mode does not simulate (listed by `info`).
pub fn soft_unsupported(model: &Model) -> Vec<String> {
    let o = &model.options;
    let mut out = Vec::new();
    if o.noslip_iterations > 0 && o.cone == crate::model::options::Cone::Elliptic {
        out.push(format!(
            "noslip_iterations = {} on elliptic cones (the no-slip post-process runs on friction loss only)",
            o.noslip_iterations
        ));
    }
    if o.flags.island {
        out.push("<flag island> (islands are solved as one problem: same solution)".to_string());
    }
    out
}
