//! The analytic velocity and control columns of the transition Jacobians
//! ([`TransitionMethod::Hybrid`](super::TransitionMethod)): the derivative of the soft solve's
//! acceleration by the implicit function theorem on MuJoCo's convex problem at its solution
//! (docs/physics.md, "Derivatives of the soft constraint solve"), composed with the smooth
//! dynamics' derivatives ([`smooth_derivatives`](super::smooth_derivatives)) and the step of the
//! Euler or implicitfast integrator.
//!
//! At the minimizer a of ½ (a − a₀)ᵀ M (a − a₀) + s(J a − aref), M (a − a₀) + Jᵀ ∇s = 0; with the
//! rows' zones fixed (quadratic, satisfied, linear friction loss, an elliptic cone's zone),
//! differentiating gives H da = M da₀ + Jᵀ S daref, H = M + Jᵀ S J (Newton's Hessian at the
//! solution, S = ∂²s/∂jar²). For a velocity, M ∂a₀/∂v = −∂τ/∂v (RNEA's, damping and actuator
//! velocity terms included) and ∂aref/∂v = −B J (B = diag(b) of each row's solref); for a
//! control, M ∂a₀/∂u_i = momentᵢ gainᵢ. The step maps a to v′ = v + h K⁻¹ M a (K = M, or
//! M + h·damping with Euler's implicit damping, minus h ∂qfrc_actuator/∂v with implicitfast) and
//! q′ = q ⊕ h v′, whose tangent moves by J_r(h v′) h dv′ on ball and free rotations (the right
//! Jacobian of SO(3)) and by h dv′ elsewhere.

use super::forward_dynamics::dtau_minus_dforce;
use super::{smooth_derivatives, DerivativesWork};
use crate::constraint::soft::cost::Rows;
use crate::constraint::{cholesky, cholesky_solve};
use crate::forward::add_actuator_velocity_derivative;
use crate::model::actuator::{BiasType, GainType, Transmission};
use crate::model::options::{Integrator, Solver};
use crate::model::tendon::TendonKind;
use crate::model::{Data, EfcType, EqualityKind, JointKind, Model};
use nalgebra::{DMatrix, DVector};

/// Buffers of the analytic columns.
pub(super) struct AnalyticWork {
    deriv: DerivativesWork,
    /// H = M + Jᵀ S J and G = Jᵀ S B J, then H's Cholesky factor.
    h: DMatrix<f64>,
    g: DMatrix<f64>,
    h_factor: DMatrix<f64>,
    /// K of the integrator and its Cholesky factor.
    k: DMatrix<f64>,
    k_factor: DMatrix<f64>,
    /// Union of a block's nonzero columns and S J over them.
    cols: Vec<usize>,
    sj: DMatrix<f64>,
    x: DVector<f64>,
    y: DVector<f64>,
    /// Which controls got analytic columns.
    pub ctrl_done: Vec<bool>,
    /// Whether the velocity columns are analytic.
    pub v_done: bool,
    /// Whether the position columns are analytic ([`position_supported`]).
    pub q_done: bool,
    /// The step's effective acceleration (v′ − v)/h = K⁻¹ M q̈.
    a_step: DVector<f64>,
}

impl AnalyticWork {
    pub fn new(model: &Model) -> Self {
        let nv = model.nv;
        Self {
            deriv: DerivativesWork::new(model),
            h: DMatrix::zeros(nv, nv),
            g: DMatrix::zeros(nv, nv),
            h_factor: DMatrix::zeros(nv, nv),
            k: DMatrix::zeros(nv, nv),
            k_factor: DMatrix::zeros(nv, nv),
            cols: Vec::with_capacity(nv),
            sj: DMatrix::zeros(6, nv),
            x: DVector::zeros(nv),
            y: DVector::zeros(nv),
            ctrl_done: vec![false; model.actuators.len()],
            v_done: false,
            q_done: false,
            a_step: DVector::zeros(nv),
        }
    }
}

/// Whether the analytic columns apply to `model`: the Euler or implicitfast integrator, the
/// soft mode (or no rows) with a primal solver (Newton or CG), no activations, and no fluid
/// forces (their velocity derivative is not in `smooth_derivatives`).
pub(super) fn supported(model: &Model) -> bool {
    let integrator = matches!(model.options.integrator, Integrator::Euler | Integrator::ImplicitFast);
    let plan = &model.plan;
    let soft = plan.constraints.is_empty() || plan.solver.soft_weights().is_some();
    integrator && soft && model.options.solver != Solver::Pgs && model.na() == 0 && plan.fluid.is_none()
}

/// The analytic columns at the nominal state of `data` (its buffers those of the nominal
/// step's forward evaluation; `v_next` the step's v′) into `a` and `b`: the velocity columns
/// unless a connect or weld row is active (their J̇v is not differentiated), and each control
/// whose force is affine in it away from every clamp. Sets `work.v_done` and `work.ctrl_done`;
/// false (nothing written) when H or K is not positive definite.
pub(super) fn columns(
    model: &Model,
    data: &mut Data,
    work: &mut AnalyticWork,
    v_next: &DVector<f64>,
    a: &mut DMatrix<f64>,
    b: &mut DMatrix<f64>,
) -> bool {
    let nv = model.nv;
    work.v_done = false;
    work.q_done = false;
    work.ctrl_done.fill(false);
    // The smooth part: ∂τ/∂v with damping and actuator terms; M at q (CRBA's, which the
    // implicit step perturbed by round-off) and the actuation stage's buffers are left at the
    // nominal state, the rows and the solution untouched.
    if smooth_derivatives(model, data, &mut work.deriv).is_err() {
        return false;
    }
    assemble(model, data, work);
    if !cholesky(&work.h, nv, &mut work.h_factor, 0.0) {
        return false;
    }
    integrator_matrix(model, data, work);
    if !cholesky(&work.k, nv, &mut work.k_factor, 0.0) {
        return false;
    }
    let equality_jdotv = (0..data.ne).any(|r| {
        data.efc_type[r] == EfcType::Equality
            && matches!(
                model.equalities[data.efc_id[r]].kind,
                EqualityKind::Connect { .. } | EqualityKind::Weld { .. }
            )
    });
    if !equality_jdotv {
        for k in 0..nv {
            for i in 0..nv {
                work.x[i] = -work.deriv.dtau_dv[(i, k)] - work.g[(i, k)];
            }
            column(model, data, work, v_next, Some(k), a, nv + k);
        }
        work.v_done = true;
    }
    for i in 0..model.actuators.len() {
        let Some(gain) = control_gain(model, data, i) else { continue };
        for k in 0..nv {
            work.x[k] = data.actuator_moment[(i, k)] * gain;
        }
        column(model, data, work, v_next, None, b, i);
        work.ctrl_done[i] = true;
    }
    if position_supported(model, data) {
        position_columns(model, data, work, v_next, a);
        work.q_done = true;
    }
    true
}

/// Whether the position columns can be analytic at the nominal state in `data`: no constraint
/// rows (the contact set, its points and frames, move with q: those columns are differenced), and
/// no force whose q-dependence [`dtau_minus_dforce`](super::forward_dynamics::dtau_minus_dforce)
/// leaves out — gravity compensation, `xfrc_applied`, effort and `actuatorfrcrange` clamps,
/// springs and dampers on spatial tendons, actuators other than affine ones on hinge or slide
/// joints and fixed tendons (fluid forces and activations are excluded by [`supported`]).
fn position_supported(model: &Model, data: &Data) -> bool {
    if data.nefc != 0 || !model.gravcomp.is_empty() {
        return false;
    }
    if data.xfrc_applied.iter().any(|w| w.iter().any(|&x| x != 0.0)) {
        return false;
    }
    let clamps = model.joints.iter().any(|j| j.actuator_force_range.is_some())
        || model.tendons.iter().any(|t| t.actuator_force_range.is_some())
        || model.dof_effort_limit.iter().any(|l| l.is_finite());
    let fixed = |t: usize| matches!(model.tendons[t].kind, TendonKind::Fixed { .. });
    let tendons = (0..model.tendons.len())
        .all(|t| fixed(t) || (model.tendons[t].stiffness == 0.0 && model.tendons[t].damping == 0.0));
    let actuators = model.actuators.iter().all(|a| {
        let transmission = match &a.transmission {
            Transmission::Joint(j) | Transmission::JointInParent(j) => {
                matches!(model.joints[*j].kind, JointKind::Revolute { .. } | JointKind::Prismatic { .. })
            }
            Transmission::Tendon(t) => fixed(*t),
            _ => false,
        };
        transmission
            && crate::forward::unsimulated_reason(model, a).is_none()
            && matches!(a.gaintype, GainType::Fixed | GainType::Affine)
            && matches!(a.biastype, BiasType::None | BiasType::Affine)
    });
    !clamps && tendons && actuators
}

/// The position columns without rows: v′ = v + h K⁻¹ τ(q, v) with τ the smooth force less the
/// bias, so dv′ = h K⁻¹ (∂τ/∂q − ∂(K ã)/∂q) with ã = K⁻¹ M q̈ the step's acceleration; K's
/// q-dependence is M's, so the bracket is −(∂RNEA/∂q at a = ã − ∂f/∂q), one RNEA sweep. Then
/// dq′ = e_k + h dv′, on ball and free rotations R(h ω′)ᵀ e_k + J_r(h ω′) h dω′
/// (q′ = q ⊗ exp(h ω′)).
fn position_columns(
    model: &Model,
    data: &mut Data,
    work: &mut AnalyticWork,
    v_next: &DVector<f64>,
    a: &mut DMatrix<f64>,
) {
    let (nv, h) = (model.nv, model.options.timestep);
    data.mass_matrix.mul_to(&data.qacc, &mut work.a_step);
    cholesky_solve(&work.k_factor, nv, work.a_step.as_mut_slice());
    let q = std::mem::take(&mut data.qpos);
    let v = std::mem::take(&mut data.qvel);
    dtau_minus_dforce(model, data, &mut work.deriv, q.as_slice(), v.as_slice(), work.a_step.as_slice());
    data.qpos = q;
    data.qvel = v;
    for k in 0..nv {
        for i in 0..nv {
            work.y[i] = -work.deriv.dtau_dq[(i, k)];
        }
        cholesky_solve(&work.k_factor, nv, work.y.as_mut_slice());
        for i in 0..nv {
            let dv = h * work.y[i];
            a[(nv + i, k)] = dv;
            a[(i, k)] = h * dv + if i == k { 1.0 } else { 0.0 };
        }
        for joint in &model.joints {
            let adr = match joint.kind {
                JointKind::Free => joint.dof_adr + 3,
                JointKind::Ball => joint.dof_adr,
                _ => continue,
            };
            let phi = nalgebra::Vector3::new(v_next[adr], v_next[adr + 1], v_next[adr + 2]) * h;
            let w = nalgebra::Vector3::new(a[(nv + adr, k)], a[(nv + adr + 1, k)], a[(nv + adr + 2, k)]) * h;
            let mut t = right_jacobian(&phi, &w);
            if (adr..adr + 3).contains(&k) {
                t += nalgebra::Rotation3::new(-phi) * nalgebra::Vector3::ith(k - adr, 1.0);
            }
            for r in 0..3 {
                a[(adr + r, k)] = t[r];
            }
        }
    }
}

/// H = M + Jᵀ S J and G = Jᵀ S B J at the solution in `data` (S from the rows' zones in
/// `efc_state`, jar = J qacc − aref).
fn assemble(model: &Model, data: &mut Data, work: &mut AnalyticWork) {
    let nefc = data.nefc;
    work.h.copy_from(&data.mass_matrix);
    work.g.fill(0.0);
    if nefc == 0 {
        return;
    }
    let nv = model.nv;
    // jar into the soft solver's scratch (free after the solve).
    let mut jar = std::mem::take(&mut data.soft.jv);
    if jar.len() < nefc {
        jar = DVector::zeros(nefc);
    }
    for i in 0..nefc {
        jar[i] = (0..nv).map(|k| data.efc_j[(i, k)] * data.qacc[k]).sum::<f64>() - data.efc_aref[i];
    }
    let rows = Rows {
        ne: data.ne,
        nf: data.nf,
        nefc,
        kind: &data.efc_type,
        id: &data.efc_id,
        d: &data.efc_d,
        r: &data.efc_r,
        floss: &data.efc_frictionloss,
        contacts: &data.contacts,
        mu: &data.contact_mu,
    };
    let (j, kbip) = (&data.efc_j, &data.efc_kbip);
    let AnalyticWork { h, g, cols, sj, .. } = work;
    rows.hessian(&jar, &data.efc_state, |i, dim, s| {
        cols.clear();
        for r in i..i + dim {
            for p in 0..nv {
                if j[(r, p)] != 0.0 && !cols.contains(&p) {
                    cols.push(p);
                }
            }
        }
        // H += J_Bᵀ S J_B, G += J_Bᵀ S diag(b) J_B.
        for (c, &q) in cols.iter().enumerate() {
            for x in 0..dim {
                sj[(x, c)] = (0..dim).map(|y| s[x][y] * j[(i + y, q)]).sum();
            }
        }
        for &p in cols.iter() {
            for x in 0..dim {
                let jp = j[(i + x, p)];
                if jp == 0.0 {
                    continue;
                }
                for (c, &q) in cols.iter().enumerate() {
                    h[(p, q)] += jp * sj[(x, c)];
                }
            }
        }
        for (c, &q) in cols.iter().enumerate() {
            for x in 0..dim {
                sj[(x, c)] = (0..dim).map(|y| s[x][y] * kbip[i + y][1] * j[(i + y, q)]).sum();
            }
        }
        for &p in cols.iter() {
            for x in 0..dim {
                let jp = j[(i + x, p)];
                if jp == 0.0 {
                    continue;
                }
                for (c, &q) in cols.iter().enumerate() {
                    g[(p, q)] += jp * sj[(x, c)];
                }
            }
        }
    });
    data.soft.jv = jar;
}

/// K of the step v′ = v + h K⁻¹ M a (`integrate::implicit_fast`'s matrix): M, plus h·damping
/// with Euler's implicit damping or implicitfast, minus h ∂qfrc_actuator/∂v with implicitfast
/// on M's tree sparsity.
fn integrator_matrix(model: &Model, data: &Data, work: &mut AnalyticWork) {
    let h = model.options.timestep;
    let flags = &model.options.flags;
    work.k.copy_from(&data.mass_matrix);
    let fast = model.options.integrator == Integrator::ImplicitFast;
    let damped = model.has_damping() && (fast || (flags.eulerdamp && flags.damper));
    if damped {
        for k in 0..model.nv {
            work.k[(k, k)] += h * model.dof_damping[k];
        }
    }
    if fast && !model.actuators.is_empty() && flags.actuation {
        add_actuator_velocity_derivative(
            model,
            data,
            &model.plan.actuator_bias_velocity,
            work.k.as_mut_slice(),
            h,
        );
        // The step factors K with M's tree-sparse LᵀDL, which reads only the entries between a
        // dof and its ancestors: a coupling of sibling dofs (a tendon actuator across two
        // fingers) is dropped there, as in MuJoCo's implicitfast, and so here.
        let nv = model.nv;
        for j in 0..nv {
            for i in 0..j {
                if !is_ancestor(model, i, j) {
                    work.k[(i, j)] = 0.0;
                    work.k[(j, i)] = 0.0;
                }
            }
        }
    }
}

/// Whether dof `i` is dof `j`'s ancestor (i < j).
fn is_ancestor(model: &Model, i: usize, j: usize) -> bool {
    let mut k = j;
    while model.dof_parent[k] != usize::MAX && model.dof_parent[k] >= i {
        k = model.dof_parent[k];
        if k == i {
            return true;
        }
    }
    false
}

/// ∂force/∂ctrl of actuator `i` when its force is gain · ctrl + bias away from every clamp (no
/// activation, ctrl inside `ctrlrange`, force inside `forcerange`, no joint or tendon
/// `actuatorfrcrange` or effort limit, a fixed or affine gain that implicitfast's K does not
/// read); None otherwise (the column is differenced).
fn control_gain(model: &Model, data: &Data, i: usize) -> Option<f64> {
    let a = &model.actuators[i];
    if a.actnum() != 0 || crate::forward::unsimulated_reason(model, a).is_some() {
        return None;
    }
    let inside = |x: f64, range: Option<[f64; 2]>| range.is_none_or(|[lo, hi]| x > lo && x < hi);
    let clamps = model.joints.iter().any(|j| j.actuator_force_range.is_some())
        || model.tendons.iter().any(|t| t.actuator_force_range.is_some())
        || model.dof_effort_limit.iter().any(|l| l.is_finite());
    let ctrl_free = !model.options.flags.clampctrl || inside(data.ctrl[i], a.ctrlrange);
    if clamps || !ctrl_free || !inside(data.actuator_force[i], a.forcerange) {
        return None;
    }
    let fast = model.options.integrator == Integrator::ImplicitFast;
    match a.gaintype {
        GainType::Fixed => Some(a.gainprm[0]),
        GainType::Affine if !(fast && a.gainprm[2] != 0.0) => Some(
            a.gainprm[0] + a.gainprm[1] * data.actuator_length[i] + a.gainprm[2] * data.actuator_velocity[i],
        ),
        _ => None,
    }
}

/// From the right-hand side M ∂a₀/∂θ + Jᵀ S ∂aref/∂θ in `work.x`: da = H⁻¹ x, dv′ = e_k + h K⁻¹ M
/// da (e_k for velocity k), dq′ = T(h v′) h dv′, into column `col` of `out`.
fn column(
    model: &Model,
    data: &Data,
    work: &mut AnalyticWork,
    v_next: &DVector<f64>,
    velocity: Option<usize>,
    out: &mut DMatrix<f64>,
    col: usize,
) {
    let (nv, h) = (model.nv, model.options.timestep);
    cholesky_solve(&work.h_factor, nv, work.x.as_mut_slice());
    data.mass_matrix.mul_to(&work.x, &mut work.y);
    cholesky_solve(&work.k_factor, nv, work.y.as_mut_slice());
    for k in 0..nv {
        work.y[k] *= h;
    }
    if let Some(k) = velocity {
        work.y[k] += 1.0;
    }
    for k in 0..nv {
        out[(nv + k, col)] = work.y[k];
        out[(k, col)] = h * work.y[k];
    }
    // Rotations: J_r(φ) h dω with φ = h ω′.
    for joint in &model.joints {
        let adr = match joint.kind {
            JointKind::Free => joint.dof_adr + 3,
            JointKind::Ball => joint.dof_adr,
            _ => continue,
        };
        let phi = nalgebra::Vector3::new(v_next[adr], v_next[adr + 1], v_next[adr + 2]) * h;
        let w = nalgebra::Vector3::new(work.y[adr], work.y[adr + 1], work.y[adr + 2]) * h;
        let t = right_jacobian(&phi, &w);
        for k in 0..3 {
            out[(adr + k, col)] = t[k];
        }
    }
}

/// J_r(φ) w = w − (1 − cos θ)/θ² φ × w + (θ − sin θ)/θ³ φ × (φ × w), θ = |φ| (series below 1e-4).
fn right_jacobian(phi: &nalgebra::Vector3<f64>, w: &nalgebra::Vector3<f64>) -> nalgebra::Vector3<f64> {
    let t2 = phi.norm_squared();
    let (c1, c2) = if t2 < 1e-8 {
        (0.5 - t2 / 24.0, 1.0 / 6.0 - t2 / 120.0)
    } else {
        let t = t2.sqrt();
        ((1.0 - t.cos()) / t2, (t - t.sin()) / (t2 * t))
    };
    let pw = phi.cross(w);
    w - pw * c1 + phi.cross(&pw) * c2
}
