//! Semi-implicit (symplectic) Euler: v ← v + h·v̇(q, v); q ← q ⊕ h·v (first order; MuJoCo's
//! default `Euler`). As MuJoCo's (`<flag eulerdamp>`, on by default; MuJoCo documentation,
//! "Computation → Numerical integration"), joint damping is integrated implicitly:
//! v ← v + h (M + h·diag(damping))⁻¹ M v̇, which keeps strongly damped joints stable. As
//! MuJoCo's `mj_forward` does, the evaluation then forms M and its factor also where no
//! constraint row exists (the M path instead of ABA), since the step needs M anyway.

use super::{correct_drift, Advance, State, StepReport, Stepper};
use crate::constraint::ConstraintSolver;
use crate::dynamics::{crba_unchecked, factorize_mass_matrix_damped, solve_with_factor_unchecked};
use crate::forward::{advance_activations, forward_at};
use crate::model::{Data, Model};
use nalgebra::{DMatrix, DVector};

/// Semi-implicit Euler stepper, with its buffer for the implicitly damped acceleration.
pub struct SemiImplicitEuler {
    /// The activations `forward` reads in a stage (`data.act` while the state is moved out).
    stage_act: DVector<f64>,
    damped: DVector<f64>,
}

impl SemiImplicitEuler {
    /// The stepper with its buffers sized for `model`.
    pub fn new(model: &Model) -> Self {
        let nv = model.nv;
        Self { stage_act: DVector::zeros(model.na()), damped: DVector::zeros(nv) }
    }
}

impl Stepper for SemiImplicitEuler {
    fn name(&self) -> &'static str {
        "euler"
    }
    fn order(&self) -> u32 {
        1
    }
    fn step(&mut self, model: &Model, data: &mut Data, h: f64) -> StepReport {
        self.step_moved(model, data, h)
    }
}

impl Advance for SemiImplicitEuler {
    fn stage_act(&mut self) -> &mut DVector<f64> {
        &mut self.stage_act
    }

    fn advance(&mut self, model: &Model, data: &mut Data, state: &mut State, h: f64) -> StepReport {
        data.act.copy_from(&state.act);
        let flags = &model.options.flags;
        let damped = flags.eulerdamp && flags.damper && model.has_damping();
        // The damped step factors M at q anyway: `forward` forms it (and RNEA's bias) where no
        // row exists too, instead of ABA and CRBA again below (`ForwardSkip::mass_wanted`).
        data.forward_skip.mass_wanted = damped;
        forward_at(model, data, state.q.as_slice(), state.v.as_slice());
        data.forward_skip.mass_wanted = false;
        // MuJoCo's mj_step: the sensors of the state the step starts from.
        crate::sensor::compute_at(model, data, state.q.as_slice(), state.v.as_slice(), state.time);
        advance_activations(model, state.act.as_mut_slice(), data.act_dot.as_slice(), h);
        // MuJoCo's mj_advance: islands at rest fall asleep (their v zeroed) before v advances.
        crate::forward::sleep::sleep_islands(model, data, state.q.as_slice(), state.v.as_mut_slice());
        if damped {
            damped_acceleration(model, data, state.q.as_slice(), &mut self.damped, h);
            state.v.axpy(h, &self.damped, 1.0);
        } else {
            state.v.axpy(h, &data.qacc, 1.0);
        }
        crate::forward::sleep::hold_velocities(model, data, state.v.as_mut_slice());
        crate::forward::sleep::integrate_awake(model, data, state.q.as_mut_slice(), state.v.as_slice(), h);
        state.time += h;
        StepReport::fixed_step(h, correct_drift(model, data, state, h))
    }
}

/// The implicitly damped acceleration (M + h·diag(damping))⁻¹ M qacc after `forward` at
/// configuration `q`, into `out` (MuJoCo's `mj_EulerSkip`, which solves with
/// qfrc_smooth + qfrc_constraint: the same in the soft mode where `forward` formed M). M + h·diag(damping) is factored in
/// the factor's storage (`factorize_mass_matrix_damped`), so M itself stays as CRBA gave it and
/// `data.mass_factor` holds the factor of the damped matrix afterwards.
fn damped_acceleration(model: &Model, data: &mut Data, q: &[f64], out: &mut DVector<f64>, h: f64) {
    // M qacc: in the soft mode on the M path, MuJoCo's sum qfrc_smooth + qfrc_constraint (the
    // forces M qacc balances, the same to round-off, without the product by M: `forward` formed
    // both); else the product, with M the position stage's own when `forward` formed it there
    // (CRBA again would give the same bits), or formed here.
    let soft = matches!(model.plan.solver, ConstraintSolver::Soft(_));
    if soft && data.forward_skip.mass_formed {
        let (smooth, constraint) = (data.qfrc_smooth.as_slice(), data.qfrc_constraint.as_slice());
        for ((o, s), c) in out.as_mut_slice().iter_mut().zip(smooth).zip(constraint) {
            *o = s + c;
        }
    } else {
        if !data.forward_skip.mass_formed {
            crba_unchecked(model, data, q);
        }
        mass_times(out, &data.mass_matrix, &data.qacc);
    }
    factorize_mass_matrix_damped(model, data, h, &model.dof_damping);
    solve_with_factor_unchecked(model, &data.mass_factor, out.as_mut_slice());
}

/// `out` ← M `qacc` (nalgebra's `gemv`), compiled for AVX2 where the CPU has it: the same
/// products and sums in the same order, four entries per instruction instead of two (Rust fuses
/// no multiply–add unasked), so the same bits.
fn mass_times(out: &mut DVector<f64>, mass_matrix: &DMatrix<f64>, qacc: &DVector<f64>) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2 (checked just above), all `mass_times_avx2` requires.
        unsafe { mass_times_avx2(out, mass_matrix, qacc) };
        return;
    }
    out.gemv(1.0, mass_matrix, qacc, 0.0);
}

/// [`mass_times`] compiled for AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn mass_times_avx2(out: &mut DVector<f64>, mass_matrix: &DMatrix<f64>, qacc: &DVector<f64>) {
    out.gemv(1.0, mass_matrix, qacc, 0.0);
}
