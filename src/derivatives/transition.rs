//! Transition Jacobians of one step by finite differences (MuJoCo's `mjd_transitionFD`,
//! engine_derivative_fd.c): for x = (q in its tangent space, v, act) and u = ctrl,
//! A = ∂x′/∂x ((2 nv + na)²) and B = ∂x′/∂u ((2 nv + na) × nu) of one [`step`] of the model's
//! integrator, constraints (contacts, limits, equalities) included as the step has them.
//!
//! Done as MuJoCo does: each input nudged by ±ε (forward or centred), q along each tangent
//! direction (`mj_integratePos`), the outputs' q difference taken in the tangent space
//! (`mj_differentiatePos`); every nudged step starts from the same saved state; a control at its
//! `ctrlrange` bound is nudged inward only (a one-sided difference); sensors are not computed.
//!
//! With [`TransitionOptions::skip`] (the default) the nudged steps skip the stages that do not
//! depend on the nudged input, as MuJoCo's `mj_stepSkip`, in MuJoCo's order: ctrl and act nudges
//! reuse the position, velocity and passive stages of the nominal step (body poses, collision
//! and contacts, the rows' J and pos, M and its factor, `qfrc_bias`, `efc_vel`, `efc_jdotv`,
//! `qfrc_passive`) and run actuation, the smooth acceleration and the soft solve; velocity nudges
//! reuse the position stage (collision included) and run the rest; position nudges run the whole
//! step (collision included: the contact set, its points and frames all move with q). With
//! [`TransitionOptions::nominal_warmstart`] (the default) each nudged soft solve is warm-started
//! from the nominal step's solution, so that Newton typically needs one iteration. Skipping applies to the single-evaluation integrators (Euler,
//! implicitfast, implicit) in soft mode or without rows; RK4 and the exact mode run every stage
//! (the RK4 stages and the exact mode's drift projection evaluate other configurations). From
//! the same warm start, the skipped and the plain differences agree to round-off
//! (tests/transition.rs).

use super::transition_analytic::{self, AnalyticWork};
use crate::dynamics::{crba_unchecked, factorize_mass_matrix};
use crate::error::InputError;
use crate::forward::SkipStage;
use crate::integrate::step;
use crate::model::options::Integrator;
use crate::model::{difference_configuration_unchecked, integrate_configuration_unchecked};
use crate::sim::SimError;
use crate::{Data, Model};
use nalgebra::{DMatrix, DVector};

/// How [`transition_jacobians`] computes the columns.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TransitionMethod {
    /// Every column by finite differences (MuJoCo's `mjd_transitionFD`).
    #[default]
    FiniteDifference,
    /// The velocity and control columns analytic — the smooth dynamics' derivatives and the soft
    /// solve's by the implicit function theorem (docs/physics.md) — and the position and
    /// activation columns by finite differences (the position columns analytic too when no
    /// constraint row is active and every force's q-derivative is known: docs/derivatives.md). Applies to the Euler and implicitfast
    /// integrators with the Newton or CG solver and no activations; columns it cannot do
    /// (module `transition_analytic`: a control at a clamp, connect or weld rows for the velocity
    /// columns) and other models fall back to differences.
    Hybrid,
}

/// How [`transition_jacobians`] differences.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TransitionOptions {
    /// The nudge ε (MuJoCo's `eps`); 1e-6 by default.
    pub eps: f64,
    /// Centred differences (two steps per input) rather than forward ones (one), as MuJoCo's
    /// `flg_centered`; true by default.
    pub centered: bool,
    /// Skip the stages that do not depend on the nudged input (module doc); true by default.
    /// False: every nudge runs the whole step (the plain differences, for checking).
    pub skip: bool,
    /// Start every nudged soft solve from the nominal step's solution (true by default: Newton
    /// then needs about one iteration; go1 walking 1.7 ms instead of 3.7) rather than from the
    /// input's warm start as MuJoCo does. The nudged solves then stop at other points within the
    /// solver's tolerance: with the tight solver of the tests [A B] moves by up to 2.9e-6
    /// relative (the gripper holding a box), 1.3e-9 on the humanoid, 2e-11 on the go1.
    pub nominal_warmstart: bool,
    /// Finite differences only (default) or analytic velocity and control columns.
    pub method: TransitionMethod,
}

impl Default for TransitionOptions {
    fn default() -> Self {
        Self {
            eps: 1e-6,
            centered: true,
            skip: true,
            nominal_warmstart: true,
            method: TransitionMethod::FiniteDifference,
        }
    }
}

/// Buffers and results of [`transition_jacobians`] for one model.
pub struct TransitionWork {
    /// A = ∂x′/∂x, (2 nv + na) × (2 nv + na): rows and columns (dq tangent, dv, dact).
    pub a: DMatrix<f64>,
    /// B = ∂x′/∂u, (2 nv + na) × nu.
    pub b: DMatrix<f64>,
    saved: Saved,
    next: Next,
    plus: Next,
    minus: Next,
    dq: DVector<f64>,
    /// M and its factor at the nominal state, restored before each step that skips the
    /// position stage (the implicit integrators overwrite the factor with that of M − h D).
    mass_matrix: DMatrix<f64>,
    mass_factor: DMatrix<f64>,
    analytic: AnalyticWork,
}

/// The inputs every nudged step starts from.
struct Saved {
    qpos: DVector<f64>,
    qvel: DVector<f64>,
    act: DVector<f64>,
    ctrl: DVector<f64>,
    warmstart: DVector<f64>,
    /// The warm start of the nudged steps: the input's, or the nominal solution when skipping.
    nudge_warmstart: DVector<f64>,
    time: f64,
    steps: u64,
    /// The sleeping islands (`Data::sleep`): every nudged step starts from the nominal's.
    sleep: crate::model::sleep::SleepState,
}

/// A step's result: the next (q, v, act).
struct Next {
    qpos: DVector<f64>,
    qvel: DVector<f64>,
    act: DVector<f64>,
}

impl Next {
    fn new(model: &Model) -> Self {
        Self {
            qpos: DVector::zeros(model.nq),
            qvel: DVector::zeros(model.nv),
            act: DVector::zeros(model.na()),
        }
    }
    fn take(&mut self, data: &Data) {
        self.qpos.copy_from(&data.qpos);
        self.qvel.copy_from(&data.qvel);
        self.act.copy_from(&data.act);
    }
}

impl TransitionWork {
    /// Buffers sized for `model`.
    pub fn new(model: &Model) -> Self {
        let (nv, na, nu) = (model.nv, model.na(), model.actuators.len());
        let n = 2 * nv + na;
        Self {
            a: DMatrix::zeros(n, n),
            b: DMatrix::zeros(n, nu),
            saved: Saved {
                qpos: DVector::zeros(model.nq),
                qvel: DVector::zeros(nv),
                act: DVector::zeros(na),
                ctrl: DVector::zeros(nu),
                warmstart: DVector::zeros(nv),
                nudge_warmstart: DVector::zeros(nv),
                time: 0.0,
                steps: 0,
                sleep: crate::model::sleep::SleepState::new(model),
            },
            next: Next::new(model),
            plus: Next::new(model),
            minus: Next::new(model),
            dq: DVector::zeros(nv),
            mass_matrix: DMatrix::zeros(nv, nv),
            mass_factor: DMatrix::zeros(nv, nv),
            analytic: AnalyticWork::new(model),
        }
    }

    /// How many columns of [A B] the last [`transition_jacobians`] computed analytically
    /// ([`TransitionMethod::Hybrid`]: nv velocity columns, nv position columns when no
    /// constraint row is active and every force's q-derivative is known, and one per control
    /// whose force is affine in it away from its clamps; 0 with finite differences).
    pub fn analytic_columns(&self) -> usize {
        let v = if self.analytic.v_done { self.dq.len() } else { 0 };
        let q = if self.analytic.q_done { self.dq.len() } else { 0 };
        v + q + self.analytic.ctrl_done.iter().filter(|&&d| d).count()
    }

    fn save(&mut self, data: &Data) {
        let s = &mut self.saved;
        s.qpos.copy_from(&data.qpos);
        s.qvel.copy_from(&data.qvel);
        s.act.copy_from(&data.act);
        s.ctrl.copy_from(&data.ctrl);
        s.warmstart.copy_from(&data.qacc_warmstart);
        s.nudge_warmstart.copy_from(&data.qacc_warmstart);
        s.time = data.time;
        s.steps = data.stepper.steps;
        s.sleep.copy_from(&data.sleep);
    }

    fn restore(&self, data: &mut Data) {
        let s = &self.saved;
        data.qpos.copy_from(&s.qpos);
        data.qvel.copy_from(&s.qvel);
        data.act.copy_from(&s.act);
        data.ctrl.copy_from(&s.ctrl);
        data.qacc_warmstart.copy_from(&s.nudge_warmstart);
        data.time = s.time;
        data.stepper.steps = s.steps;
        data.stepper.failed = None;
        data.sleep.copy_from(&s.sleep);
    }

    /// Column `col` of `out` from the nudged results: centred (plus − minus) / 2ε when both are
    /// given, else one-sided against the nominal `next`.
    fn difference(
        &mut self,
        model: &Model,
        out: &mut DMatrix<f64>,
        col: usize,
        plus: bool,
        minus: bool,
        eps: f64,
    ) {
        let (nv, na) = (model.nv, model.na());
        let Self { plus: p, minus: m, next, dq, .. } = self;
        let (hi, lo, scale) = match (plus, minus) {
            (true, true) => (&*p, &*m, 0.5 / eps),
            (true, false) => (&*p, &*next, 1.0 / eps),
            _ => (&*next, &*m, 1.0 / eps),
        };
        difference_configuration_unchecked(model, lo.qpos.as_slice(), hi.qpos.as_slice(), dq.as_mut_slice());
        for i in 0..nv {
            out[(i, col)] = dq[i] * scale;
            out[(nv + i, col)] = (hi.qvel[i] - lo.qvel[i]) * scale;
        }
        for i in 0..na {
            out[(2 * nv + i, col)] = (hi.act[i] - lo.act[i]) * scale;
        }
    }
}

/// Which input a column nudges.
#[derive(Clone, Copy)]
enum Input {
    Q(usize),
    V(usize),
    Act(usize),
    Ctrl(usize),
}

/// One nudged step from the saved state, reusing the stages `skip` says (M and its factor
/// restored first when the position stage is reused), its result into `work.plus` (`by` > 0) or
/// `work.minus`, the state restored.
fn nudged_step(
    model: &Model,
    data: &mut Data,
    work: &mut TransitionWork,
    input: Input,
    by: f64,
    skip: SkipStage,
) -> Result<(), SimError> {
    match input {
        Input::Q(k) => {
            work.dq.fill(0.0);
            work.dq[k] = 1.0;
            integrate_configuration_unchecked(model, data.qpos.as_mut_slice(), work.dq.as_slice(), by);
        }
        Input::V(k) => data.qvel[k] += by,
        Input::Act(k) => data.act[k] += by,
        Input::Ctrl(k) => data.ctrl[k] += by,
    }
    if skip != SkipStage::None {
        data.mass_matrix.copy_from(&work.mass_matrix);
        data.mass_factor.copy_from(&work.mass_factor);
    }
    data.forward_skip.stage = skip;
    let result = step(model, data);
    data.forward_skip.stage = SkipStage::None;
    if by > 0.0 {
        work.plus.take(data);
    } else {
        work.minus.take(data);
    }
    work.restore(data);
    result.map(|_| ())
}

/// Whether `model`'s steps can skip stages: one forward evaluation per step (Euler,
/// implicitfast, implicit) and nothing recomputed after it (soft mode or no rows).
fn skippable(model: &Model) -> bool {
    let single = matches!(
        model.options.integrator,
        Integrator::Euler | Integrator::ImplicitFast | Integrator::Implicit
    );
    let plan = &model.plan;
    let soft = plan.constraints.is_empty() || plan.solver.soft_weights().is_some();
    single && soft
}

/// A = ∂x′/∂x and B = ∂x′/∂u of one [`step`] from the state in `data`, into `work.a` and
/// `work.b` (MuJoCo's `mjd_transitionFD` layout: x = (dq in the tangent space, v, act),
/// u = ctrl). `data`'s state, controls and warm start are left as they were (its other buffers
/// hold the last nudged step's; sensors are not computed). Cost: 1 + (2 nv + na + nu) steps
/// forward, twice that centred, most of them skipping stages ([`TransitionOptions::skip`]).
///
/// # Errors
/// [`SimError::Input`] when `data` or `work` was made for another model, ε is not finite and
/// positive, or an actuator keeps a control history (`nsample`; as MuJoCo's); the error of a step that fails (diverges) at the nominal or a nudged state.
pub fn transition_jacobians(
    model: &Model,
    data: &mut Data,
    work: &mut TransitionWork,
    options: &TransitionOptions,
) -> Result<(), SimError> {
    data.check_sizes(model, "transition_jacobians")?;
    let n = 2 * model.nv + model.na();
    InputError::check_len("transition_jacobians", "work (rows)", work.a.nrows(), n, "2 nv + na")?;
    InputError::check_len(
        "transition_jacobians",
        "work (controls)",
        work.b.ncols(),
        model.actuators.len(),
        "nu",
    )?;
    let eps = options.eps;
    if !(eps.is_finite() && eps > 0.0) {
        return Err(InputError::Value {
            function: "transition_jacobians",
            argument: "options.eps",
            detail: format!("{eps} is not a finite positive nudge"),
        }
        .into());
    }
    if let Some(f) = &data.stepper.failed {
        return Err(f.refusal());
    }
    if let Some(a) = model.actuators.iter().find(|a| a.history.is_some()) {
        // A step records the controls into the history, which x does not hold.
        return Err(InputError::Value {
            function: "transition_jacobians",
            argument: "model",
            detail: format!(
                "actuator '{}' keeps a control history (nsample, delay), which is part of the state but not of x = (q, v, act); \
                 MuJoCo's mjd_transitionFD refuses delays too. Differentiate a copy of the model without nsample/delay",
                a.name
            ),
        }
        .into());
    }
    work.save(data);
    data.forward_skip.sensors = true;
    let result = differences(model, data, work, options);
    data.forward_skip = Default::default();
    data.qacc_warmstart.copy_from(&work.saved.warmstart);
    result
}

/// The nominal step and the nudged ones of [`transition_jacobians`], into `work`.
fn differences(
    model: &Model,
    data: &mut Data,
    work: &mut TransitionWork,
    options: &TransitionOptions,
) -> Result<(), SimError> {
    let nominal = step(model, data);
    work.next.take(data);
    let skip = options.skip && skippable(model);
    if options.nominal_warmstart {
        // Every nudged solve starts from the nominal solution.
        work.saved.nudge_warmstart.copy_from(&data.qacc);
    }
    if skip {
        // M and its factor at the nominal state, as its position stage left them (the
        // integrator may have overwritten the factor); the rest of the position and velocity
        // stages' outputs are still the nominal state's.
        crba_unchecked(model, data, work.saved.qpos.as_slice());
        factorize_mass_matrix(model, data);
        work.mass_matrix.copy_from(&data.mass_matrix);
        work.mass_factor.copy_from(&data.mass_factor);
    }
    work.restore(data);
    nominal?;
    let stage = |s: SkipStage| if skip { s } else { SkipStage::None };
    let (eps, centered) = (options.eps, options.centered);
    let mut a = std::mem::take(&mut work.a);
    let mut b = std::mem::take(&mut work.b);
    // The analytic columns, at the nominal forward evaluation still in `data` (its stages'
    // buffers; M is CRBA's again after the nominal step).
    let hybrid = options.method == TransitionMethod::Hybrid && transition_analytic::supported(model);
    let analytic = hybrid && {
        let TransitionWork { analytic, next, .. } = &mut *work;
        transition_analytic::columns(model, data, analytic, &next.qvel, &mut a, &mut b)
    };
    if !analytic {
        work.analytic.v_done = false;
        work.analytic.q_done = false;
        work.analytic.ctrl_done.fill(false);
    }
    let result = (|| {
        // MuJoCo's order: ctrl and act (position and velocity stages reused), v (position stage
        // reused), q (nothing reused), so that each reuses what the nominal step left.
        for i in 0..model.actuators.len() {
            if work.analytic.ctrl_done[i] {
                continue;
            }
            let ctrl = work.saved.ctrl[i];
            let within = |x0: f64, x1: f64| match model.actuators[i].ctrlrange {
                Some([lo, hi]) => x0 >= lo && x1 <= hi,
                _ => true,
            };
            let fwd = within(ctrl, ctrl + eps);
            if fwd {
                nudged_step(model, data, work, Input::Ctrl(i), eps, stage(SkipStage::Velocity))?;
            }
            let back = (centered || !fwd) && within(ctrl - eps, ctrl);
            if back {
                nudged_step(model, data, work, Input::Ctrl(i), -eps, stage(SkipStage::Velocity))?;
            }
            if fwd || back {
                work.difference(model, &mut b, i, fwd, back, eps);
            } else {
                b.column_mut(i).fill(0.0);
            }
        }
        let (nv, na) = (model.nv, model.na());
        let inputs = (0..na)
            .map(|k| (2 * nv + k, Input::Act(k), SkipStage::Velocity))
            .chain((0..nv).map(|k| (nv + k, Input::V(k), SkipStage::Position)))
            .chain((0..nv).map(|k| (k, Input::Q(k), SkipStage::None)));
        for (col, input, s) in inputs {
            if (work.analytic.v_done && matches!(input, Input::V(_)))
                || (work.analytic.q_done && matches!(input, Input::Q(_)))
            {
                continue;
            }
            nudged_step(model, data, work, input, eps, stage(s))?;
            if centered {
                nudged_step(model, data, work, input, -eps, stage(s))?;
            }
            work.difference(model, &mut a, col, true, centered, eps);
        }
        Ok::<(), SimError>(())
    })();
    work.a = a;
    work.b = b;
    result
}
