//! Transition Jacobians of one step by finite differences (MuJoCo's `mjd_transitionFD`,
//! engine_derivative_fd.c): for x = (q in its tangent space, v, act) and u = ctrl,
//! A = ∂x′/∂x ((2 nv + na)²) and B = ∂x′/∂u ((2 nv + na) × nu) of one [`step`] of the model's
//! integrator, constraints (contacts, limits, equalities) included as the step has them.
//!
//! Done as MuJoCo does: each input nudged by ±ε (forward or centred), q along each tangent
//! direction (`mj_integratePos`), the outputs' q difference taken in the tangent space
//! (`mj_differentiatePos`); every nudged step starts from the same saved state, warm start
//! (`qacc_warmstart`) included, so that the soft solver starts each from the nominal solution; a
//! control at its `ctrlrange` bound is nudged inward only (a one-sided difference). Not done: the
//! stage skipping of `mj_stepSkip` (every nudged step runs the whole pipeline, collision
//! included).

use crate::error::InputError;
use crate::integrate::step;
use crate::model::{difference_configuration_unchecked, integrate_configuration_unchecked};
use crate::sim::SimError;
use crate::{Data, Model};
use nalgebra::{DMatrix, DVector};

/// How [`transition_jacobians`] differences.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TransitionOptions {
    /// The nudge ε (MuJoCo's `eps`); 1e-6 by default.
    pub eps: f64,
    /// Centred differences (two steps per input) rather than forward ones (one), as MuJoCo's
    /// `flg_centered`; true by default.
    pub centered: bool,
}

impl Default for TransitionOptions {
    fn default() -> Self {
        Self { eps: 1e-6, centered: true }
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
}

/// The inputs every nudged step starts from.
struct Saved {
    qpos: DVector<f64>,
    qvel: DVector<f64>,
    act: DVector<f64>,
    ctrl: DVector<f64>,
    warmstart: DVector<f64>,
    time: f64,
    steps: u64,
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
                time: 0.0,
                steps: 0,
            },
            next: Next::new(model),
            plus: Next::new(model),
            minus: Next::new(model),
            dq: DVector::zeros(nv),
        }
    }

    fn save(&mut self, data: &Data) {
        let s = &mut self.saved;
        s.qpos.copy_from(&data.qpos);
        s.qvel.copy_from(&data.qvel);
        s.act.copy_from(&data.act);
        s.ctrl.copy_from(&data.ctrl);
        s.warmstart.copy_from(&data.qacc_warmstart);
        s.time = data.time;
        s.steps = data.stepper.steps;
    }

    fn restore(&self, data: &mut Data) {
        let s = &self.saved;
        data.qpos.copy_from(&s.qpos);
        data.qvel.copy_from(&s.qvel);
        data.act.copy_from(&s.act);
        data.ctrl.copy_from(&s.ctrl);
        data.qacc_warmstart.copy_from(&s.warmstart);
        data.time = s.time;
        data.stepper.steps = s.steps;
        data.stepper.failed = None;
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

/// One nudged step from the saved state, its result into `work.plus` (`by` > 0) or
/// `work.minus`, the state restored.
fn nudged_step(
    model: &Model,
    data: &mut Data,
    work: &mut TransitionWork,
    input: Input,
    by: f64,
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
    let result = step(model, data);
    if by > 0.0 {
        work.plus.take(data);
    } else {
        work.minus.take(data);
    }
    work.restore(data);
    result.map(|_| ())
}

/// A = ∂x′/∂x and B = ∂x′/∂u of one [`step`] from the state in `data`, into `work.a` and
/// `work.b` (MuJoCo's `mjd_transitionFD` layout: x = (dq in the tangent space, v, act),
/// u = ctrl). `data`'s state, controls and warm start are left as they were (its other buffers
/// hold the last nudged step's). Cost: 1 + (2 nv + na + nu) steps forward, twice that centred.
///
/// # Errors
/// [`SimError::Input`] when `data` or `work` was made for another model or ε is not finite and
/// positive; the error of a step that fails (diverges) at the nominal or a nudged state.
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
    work.save(data);
    let nominal = step(model, data);
    work.next.take(data);
    work.restore(data);
    nominal?;
    let centered = options.centered;
    let mut a = std::mem::take(&mut work.a);
    let mut b = std::mem::take(&mut work.b);
    let result = (|| {
        for i in 0..model.actuators.len() {
            let ctrl = work.saved.ctrl[i];
            let within = |x0: f64, x1: f64| match model.actuators[i].ctrlrange {
                Some([lo, hi]) => x0 >= lo && x1 <= hi,
                _ => true,
            };
            let fwd = within(ctrl, ctrl + eps);
            if fwd {
                nudged_step(model, data, work, Input::Ctrl(i), eps)?;
            }
            let back = (centered || !fwd) && within(ctrl - eps, ctrl);
            if back {
                nudged_step(model, data, work, Input::Ctrl(i), -eps)?;
            }
            if fwd || back {
                work.difference(model, &mut b, i, fwd, back, eps);
            } else {
                b.column_mut(i).fill(0.0);
            }
        }
        let (nv, na) = (model.nv, model.na());
        let inputs = (0..nv).map(Input::Q).chain((0..nv).map(Input::V)).chain((0..na).map(Input::Act));
        for (col, input) in inputs.enumerate() {
            nudged_step(model, data, work, input, eps)?;
            if centered {
                nudged_step(model, data, work, input, -eps)?;
            }
            work.difference(model, &mut a, col, true, centered, eps);
        }
        Ok::<(), SimError>(())
    })();
    work.a = a;
    work.b = b;
    result
}
