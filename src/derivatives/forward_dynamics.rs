//! Derivatives of forward dynamics q̈ = M(q)⁻¹ (τ − c(q, v)): [`aba_derivatives`] (the
//! quantities of Pinocchio's `computeABADerivatives`) and [`smooth_derivatives`] (of MuJoCo's
//! `qacc_smooth`, with the passive, actuator and applied forces that make τ).
//!
//! Differentiating the identity RNEA(q, v, q̈(q, v, τ)) = τ gives
//! ∂q̈/∂q = −M⁻¹ ∂τ/∂q|ₐ₌q̈, ∂q̈/∂v = −M⁻¹ ∂τ/∂v, ∂q̈/∂τ = M⁻¹ (Carpentier & Mansard, RSS 2018,
//! §IV): one ABA, the RNEA derivatives at a = q̈ ([`rnea_derivatives`](super::rnea_derivatives)),
//! and M's tree-sparse LᵀDL factor applied to 3 nv columns. When τ depends on the state through
//! forces f(q, v) (springs, damping, actuator gains and biases), ∂τ/∂q and ∂τ/∂v above become
//! ∂τ/∂q − ∂f/∂q and ∂τ/∂v − ∂f/∂v.

use super::rnea::rnea_derivatives_unchecked;
use super::DerivativesWork;
use crate::dynamics::{
    aba_unchecked, crba_unchecked, factorize_mass_matrix, solve_transposed_with_factor_unchecked,
};
use crate::error::{check, InputError};
use crate::forward::{
    accumulate_xfrc, actuation_unchecked, add_actuator_length_derivative, add_actuator_velocity_derivative,
    drive, passive, StageKind,
};
use crate::{Data, Model};
use nalgebra::DMatrix;

/// ∂q̈/∂q, ∂q̈/∂v and ∂q̈/∂τ of q̈ = ABA(q, v, τ) into `work.dqacc_dq`, `work.dqacc_dv` and
/// `work.dqacc_dtau`, q̈ into `work.qacc`; on the way `work.dtau_dq` and `work.dtau_dv` hold the
/// RNEA derivatives at a = q̈, and `data.mass_matrix` and its factor M at q. Cost: one ABA, the
/// RNEA derivatives, one CRBA and 3 nv sparse triangular solves; no allocation.
///
/// # Errors
/// [`InputError::Length`] when q is not nq long, v or tau not nv long, or `data` or `work` was
/// made for another model.
pub fn aba_derivatives(
    model: &Model,
    data: &mut Data,
    work: &mut DerivativesWork,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
) -> Result<(), InputError> {
    check::data("aba_derivatives", model, data)?;
    work.check("aba_derivatives", model)?;
    check::q("aba_derivatives", model, q)?;
    check::v("aba_derivatives", "v", model, v)?;
    check::v("aba_derivatives", "tau", model, tau)?;
    work.tau.copy_from_slice(tau);
    aba_unchecked(model, data, q, v, tau);
    work.qacc.copy_from(&data.aba_qacc);
    let qacc = std::mem::take(&mut work.qacc);
    rnea_derivatives_unchecked(model, data, work, q, v, qacc.as_slice());
    work.qacc = qacc;
    solve_columns(model, data, work, q);
    Ok(())
}

/// The derivatives of `qacc_smooth` (forward dynamics without constraints) at the state in
/// `data` (`qpos`, `qvel`, `ctrl`, `act`, `qfrc_applied`, `xfrc_applied`), with the forces that
/// depend on the state differentiated too: joint damping (∂/∂v = −d), hinge and slide springs
/// (∂/∂q = −k), the tendons' springs and dampers (along J = ∂L/∂q; a spatial tendon's path
/// curvature left out) and the actuators' affine gains and biases through their moment arms
/// (∂force/∂velocity = b₂ + g₂ x, ∂force/∂length = b₁ + g₁ x; see
/// `forward::actuation::add_actuator_length_derivative` for what the configuration part leaves out). Not
/// differentiated: the q-dependence of `xfrc_applied`'s Jacobian and of gravity compensation,
/// fluid forces, and the effort-limit and `actuatorfrcrange` clamps (a clamped force's
/// derivative is reported as if unclamped).
/// Results as [`aba_derivatives`], with `work.tau` the total generalized force; runs the passive
/// and actuation stages (their buffers in `data` are left at this state).
///
/// # Errors
/// [`InputError::Length`] when `data`'s state or `work` is sized for another model.
pub fn smooth_derivatives(
    model: &Model,
    data: &mut Data,
    work: &mut DerivativesWork,
) -> Result<(), InputError> {
    check::data("smooth_derivatives", model, data)?;
    work.check("smooth_derivatives", model)?;
    data.check_sizes(model, "smooth_derivatives")?;
    let q = std::mem::take(&mut data.qpos);
    let v = std::mem::take(&mut data.qvel);
    smooth_derivatives_at(model, data, work, q.as_slice(), v.as_slice());
    data.qpos = q;
    data.qvel = v;
    Ok(())
}

/// [`smooth_derivatives`] at (q, v), `data.qpos` and `data.qvel` unused.
fn smooth_derivatives_at(model: &Model, data: &mut Data, work: &mut DerivativesWork, q: &[f64], v: &[f64]) {
    let plan = &model.plan;
    crate::tendon::compute(model, data, q, v);
    if plan.runs(StageKind::Passive) {
        passive(model, data, q, v);
    } else {
        data.qfrc_passive.fill(0.0);
    }
    let actuated = plan.runs(StageKind::Actuation);
    if actuated {
        actuation_unchecked(model, data, q, v, &plan.actuator_bias_velocity);
    } else {
        data.qfrc_actuator.fill(0.0);
    }
    accumulate_xfrc(model, data, q);
    for k in 0..model.nv {
        work.tau[k] = data.qfrc_passive[k] + drive(model, data, k) + data.qfrc_xfrc[k];
    }
    let tau = std::mem::take(&mut work.tau);
    aba_unchecked(model, data, q, v, tau.as_slice());
    work.tau = tau;
    work.qacc.copy_from(&data.aba_qacc);
    let qacc = std::mem::take(&mut work.qacc);
    rnea_derivatives_unchecked(model, data, work, q, v, qacc.as_slice());
    work.qacc = qacc;
    // ∂τ/∂x − ∂f/∂x: the passive and actuator forces' own derivatives.
    if plan.runs(StageKind::Passive) {
        for k in 0..model.nv {
            work.dtau_dv[(k, k)] += model.dof_damping[k];
        }
        for s in &model.springs {
            work.dtau_dq[(s.dof_adr, s.dof_adr)] += s.stiffness;
        }
        add_tendon_passive_derivative(model, data, work);
    }
    if actuated {
        add_actuator_velocity_derivative(
            model,
            data,
            &plan.actuator_bias_velocity,
            work.dtau_dv.as_mut_slice(),
            1.0,
        );
        add_actuator_length_derivative(model, data, work.dtau_dq.as_mut_slice(), 1.0);
    }
    solve_columns(model, data, work, q);
}

/// The tendons' springs and dampers, f = −k (L − L_spring) − b L̇ along J = ∂L/∂q (outside the
/// spring's dead band): −∂f/∂v = b JᵀJ and −∂f/∂q = k JᵀJ (a spatial tendon's path curvature,
/// f ∂²L/∂q², is left out: exact for fixed tendons, whose J is constant).
fn add_tendon_passive_derivative(model: &Model, data: &Data, work: &mut DerivativesWork) {
    let flags = &model.options.flags;
    for (t, tendon) in model.tendons.iter().enumerate() {
        let b = if flags.damper { tendon.damping } else { 0.0 };
        let [lower, upper] = tendon.spring_length;
        let length = data.ten_length[t];
        let stretched = length > upper || length < lower;
        let k = if flags.spring && stretched { tendon.stiffness } else { 0.0 };
        if b == 0.0 && k == 0.0 {
            continue;
        }
        for r in 0..model.nv {
            let j_r = data.ten_j[(t, r)];
            if j_r == 0.0 {
                continue;
            }
            for c in 0..model.nv {
                let jj = j_r * data.ten_j[(t, c)];
                work.dtau_dv[(r, c)] += b * jj;
                work.dtau_dq[(r, c)] += k * jj;
            }
        }
    }
}

/// M at q and its factor, then ∂q̈/∂q = −M⁻¹ ∂τ/∂q, ∂q̈/∂v = −M⁻¹ ∂τ/∂v, ∂q̈/∂τ = M⁻¹: the
/// tree-sparse solve on the transposes, every right-hand side at once (`work.scratch`).
fn solve_columns(model: &Model, data: &mut Data, work: &mut DerivativesWork, q: &[f64]) {
    crba_unchecked(model, data, q);
    factorize_mass_matrix(model, data);
    let factor = &data.mass_factor;
    let y = &mut work.scratch;
    // X = −M⁻¹ B: Y = −Bᵀ in, Y = Xᵀ out.
    let mut minus_solve = |from: &DMatrix<f64>, to: &mut DMatrix<f64>| {
        y.tr_copy_from(from);
        y.neg_mut();
        solve_transposed_with_factor_unchecked(model, factor, y);
        y.transpose_to(to);
    };
    minus_solve(&work.dtau_dq, &mut work.dqacc_dq);
    minus_solve(&work.dtau_dv, &mut work.dqacc_dv);
    // M⁻¹ is symmetric: Yᵀ = Y.
    work.dqacc_dtau.fill_with_identity();
    solve_transposed_with_factor_unchecked(model, factor, &mut work.dqacc_dtau);
}
