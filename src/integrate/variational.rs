//! A variational integrator: the discrete Euler–Lagrange (DEL) equations of the trapezoidal
//! discrete Lagrangian on the configuration manifold, solved by Newton's method, with holonomic
//! equality constraints held by multipliers (Marsden & West, *Discrete mechanics and variational
//! integrators*, Acta Numerica 10, 2001: the discrete Euler–Lagrange equations and discrete
//! Legendre transforms, discrete Noether's theorem, forced systems by the discrete
//! Lagrange–d'Alembert principle, holonomic constraints and RATTLE; on Lie groups and multibody
//! trees: Lee, Liu, Park & Srinivasa, *A Linear-Time Variational Integrator for Multibody
//! Systems*, WAFR 2016).
//!
//! Configurations step as q_{k+1} = q_k ⊕ h ξ_k (ξ in the model's velocity layout: the curve
//! q_k ⊕ t ξ has the constant velocity ξ on every joint type, ball and free joints included), and
//!
//!   L_d(q_k, q_{k+1}) = h/2 [L(q_k, ξ_k) + L(q_{k+1}, ξ_k)],   L(q, ξ) = ½ ξᵀ M(q) ξ − V(q).
//!
//! With the right-trivialized derivatives (perturbations q ⊕ η) and J_r the right Jacobian of the
//! exponential of ball/free rotations (identity on flat coordinates; `dexp_inv` is J_r⁻¹):
//!
//!   D₁L_d = h/2 ∂_qL(q_k, ξ) − J_r⁻¹(hξ) μ̄,   D₂L_d = h/2 ∂_qL(q_{k+1}, ξ) + J_r⁻¹(−hξ) μ̄,
//!   μ̄ = ½ [M(q_k) + M(q_{k+1})] ξ,   ∂_qL = ∂T/∂q − g(q)   ([`LagrangianTerms`]).
//!
//! In position–momentum form (the discrete Legendre transforms), one step
//! from (q_k, v_k) with p_k = M(q_k) v_k solves for ξ (and the equality multipliers λ)
//!
//!   p_k + D₁L_d(q_k, q_k ⊕ hξ) + f⁻ + J(q_k)ᵀ λ = 0,   φ(q_k ⊕ hξ) = 0,
//!
//! then p_{k+1} = D₂L_d + f⁺ and v_{k+1} = M(q_{k+1})⁻¹ p_{k+1}, projected onto J(q_{k+1}) v = 0
//! M-orthogonally (RATTLE's second multiplier). The forcing is split h/2, h/2 between the ends:
//! f∓ = h/2 [passive(q_{k|k+1}, ξ) + drive], passive = joint springs and damping at the step's
//! velocity ξ, drive = actuator + applied forces at the step's start (held over the step). Springs
//! evaluated at both ends are exactly a trapezoidal potential, so they keep the method
//! symplectic; damping and drives make it a discrete Lagrange–d'Alembert method.
//!
//! Newton: the chord method with the matrix C = M(q_k) + h/2 diag(damping) (its tree-sparse LᵀDL
//! factor) for ξ, and the Schur complement h J(q_{k+1}) C⁻¹ J(q_k)ᵀ for λ, from the predictor
//! ξ = 2 v_k − ξ_{k−1} + (2 e_{k−1} − e_{k−2}) (below), with Anderson acceleration (without
//! equality rows); iterated until the
//! residual of the momentum balance is at round-off, 4 ε of the momentum scale ([`RESIDUAL_TOL`];
//! `StepReport::solver_iterations` counts the
//! iterations). A step whose iteration does not converge is not taken: the state is left as it
//! was and [`Stepper::failure`] says why (the simulation returns a `SimError`).
//!
//! Properties (tested in `tests/variational.rs` and `tests/stress.rs`): second order; symplectic;
//! the discrete momentum maps of symmetries of L_d are conserved to round-off (discrete Noether
//! theorem): for the heavy symmetric top L_z and L_z′ (docs/physics.md (104)–(106)); the energy error
//! stays bounded, without secular drift. Limits, friction rows and contacts, if the model has
//! them, are left to the drift projection after the step ([`correct_drift`]), outside the
//! variational structure.

use super::lagrangian_terms::LagrangianTerms;
use super::{correct_drift, Advance, State, StepFailure, StepReport, Stepper};
use crate::dynamics::{crba_unchecked, factorize_mass_matrix, solve_with_factor_unchecked};
use crate::forward::{accumulate_xfrc, actuation_unchecked, advance_activations, passive};
use crate::kinematics::forward_kinematics_unchecked;
use crate::model::{
    dexp_inv_configuration_unchecked, integrate_configuration_unchecked, Data, EfcType, JointKind, Model,
};
use nalgebra::{DMatrix, DVector};

/// Newton stops when the residual of the DEL equations is below this relative to the momentum
/// scale: 4 ε, round-off (the residual's evaluation cancels momenta of that scale, and its
/// computed value settles at a few ε; below 4 ε the iteration mostly ends by the stall test,
/// one or two iterations later, at the same accuracy). [`Variational::with_tolerance`] sets
/// another,
pub const RESIDUAL_TOL: f64 = 4.0 * f64::EPSILON;
/// … or its update of ξ below this relative to the velocity scale,
const UPDATE_TOL: f64 = 1e-15;
/// … or the residual stagnates (round-off) below this.
const STALL_TOL: f64 = 1e-12;
/// The equality constraints are held to |φ| ≤ this (m or rad).
pub const CONSTRAINT_TOL: f64 = 1e-12;
/// Newton iterations before a step is given up.
pub const MAX_ITERATIONS: u32 = 50;

/// Pivots below this times the largest diagonal entry count as zero in [`guarded_lu_solve`].
const PIVOT_TOL: f64 = 1e-10;

/// Solves the n × n system in the leading block of the column-major `a` (leading dimension `ld`,
/// overwritten by its factor) in place of `x`, by LU without pivoting in which a pivot below
/// `PIVOT_TOL` times the largest diagonal entry is taken as zero and its unknown set to zero: the
/// multipliers of redundant constraint rows (a planar loop closed by a 3-row connect) are zero,
/// the others solve the consistent system.
fn guarded_lu_solve(a: &mut [f64], n: usize, ld: usize, x: &mut [f64]) {
    let scale = (0..n).map(|k| a[k + k * ld].abs()).fold(0.0, f64::max);
    for k in 0..n {
        let pivot = a[k + k * ld];
        if pivot.abs() <= PIVOT_TOL * scale {
            a[k + k * ld] = 0.0;
            for i in k + 1..n {
                a[i + k * ld] = 0.0;
            }
            continue;
        }
        for i in k + 1..n {
            a[i + k * ld] /= pivot;
        }
        for j in k + 1..n {
            let akj = a[k + j * ld];
            for i in k + 1..n {
                a[i + j * ld] -= a[i + k * ld] * akj;
            }
        }
    }
    for j in 0..n {
        let xj = x[j];
        for i in j + 1..n {
            x[i] -= a[i + j * ld] * xj;
        }
    }
    for j in (0..n).rev() {
        let d = a[j + j * ld];
        x[j] = if d == 0.0 { 0.0 } else { x[j] / d };
        let xj = x[j];
        for i in 0..j {
            x[i] -= a[i + j * ld] * xj;
        }
    }
}

/// The variational stepper with its buffers (allocated once per model).
pub struct Variational {
    /// The activations `forward` reads in a stage (`data.act` while the state is moved out).
    stage_act: DVector<f64>,
    terms0: LagrangianTerms,
    terms1: LagrangianTerms,
    xi: DVector<f64>,
    dxi: DVector<f64>,
    residual: DVector<f64>,
    p_k: DVector<f64>,
    mu_bar: DVector<f64>,
    theta: DVector<f64>,
    tmp: DVector<f64>,
    drive: DVector<f64>,
    q1: DVector<f64>,
    /// M and its factor at `mass_q` (the end of the last step is the start of the next).
    mass_q: DVector<f64>,
    mass_valid: bool,
    mass: DMatrix<f64>,
    mass_factor: DMatrix<f64>,
    chord_factor: DMatrix<f64>,
    /// Equality rows: J(q_k), C⁻¹ J(q_k)ᵀ, the Schur complement, multipliers.
    jac_k: DMatrix<f64>,
    y: DMatrix<f64>,
    schur: DMatrix<f64>,
    lambda: DVector<f64>,
    dlambda: DVector<f64>,
    has_equalities: bool,
    /// Whether the model has ball or free joints (J_r⁻¹ ≠ 1); otherwise `dexp_inv` is skipped.
    has_rotations: bool,
    failure: Option<StepFailure>,
    residual_tol: f64,
    /// The last step's ξ, end configuration, end velocity and step (for the predictor).
    last_xi: DVector<f64>,
    last_q1: DVector<f64>,
    last_v1: DVector<f64>,
    last_h: f64,
    last_valid: bool,
    /// The predictor's base 2 v_k − ξ_{k−1} of this step, and the errors e = ξ − base of the
    /// last two steps (`errors` of them valid: steps that continued each other at the same h).
    base: DVector<f64>,
    error1: DVector<f64>,
    error2: DVector<f64>,
    errors: usize,
    anderson: Anderson,
}

/// Depth of the Anderson acceleration of the chord iteration (on chain30, depth 3 → 5 saves
/// ~0.5 iterations per step; more saves nothing).
const ANDERSON_DEPTH: usize = 5;

/// Anderson acceleration (type II; Walker & Ni, *Anderson acceleration for fixed-point
/// iterations*, SIAM J. Numer. Anal. 49, 2011) of the chord iteration x ← x + f(x),
/// f = C⁻¹ R: with the last differences ΔX, ΔF, γ = argmin ‖f − ΔF γ‖ and
/// x ← x + f − (ΔX + ΔF) γ. The chord method alone converges linearly, slowly when the
/// Coriolis terms are large against the smallest eigenvalues of M (long light chains); the
/// acceleration recovers most of Newton's rate at O(n) cost per iteration.
struct Anderson {
    x_prev: DVector<f64>,
    f_prev: DVector<f64>,
    dx: [DVector<f64>; ANDERSON_DEPTH],
    df: [DVector<f64>; ANDERSON_DEPTH],
    /// The Gram matrix df_i · df_j of the stored differences (column-major, updated by slot).
    gram: [f64; ANDERSON_DEPTH * ANDERSON_DEPTH],
    /// Differences stored (≤ depth) and the slot of the next one.
    count: usize,
    next: usize,
    started: bool,
}

impl Anderson {
    fn new(nv: usize) -> Self {
        let z = || DVector::zeros(nv);
        Self {
            x_prev: z(),
            f_prev: z(),
            dx: std::array::from_fn(|_| z()),
            df: std::array::from_fn(|_| z()),
            gram: [0.0; ANDERSON_DEPTH * ANDERSON_DEPTH],
            count: 0,
            next: 0,
            started: false,
        }
    }

    fn reset(&mut self) {
        self.count = 0;
        self.next = 0;
        self.started = false;
    }

    /// x ← the accelerated next iterate, given f = f(x).
    fn update(&mut self, x: &mut DVector<f64>, f: &DVector<f64>) {
        if self.started {
            let slot = self.next;
            self.dx[slot].copy_from(x);
            self.dx[slot] -= &self.x_prev;
            self.df[slot].copy_from(f);
            self.df[slot] -= &self.f_prev;
            self.next = (slot + 1) % ANDERSON_DEPTH;
            self.count = (self.count + 1).min(ANDERSON_DEPTH);
            // Only the new difference's row and column of the Gram matrix change.
            for j in 0..self.count {
                let g = self.df[slot].dot(&self.df[j]);
                self.gram[slot + j * ANDERSON_DEPTH] = g;
                self.gram[j + slot * ANDERSON_DEPTH] = g;
            }
        }
        self.x_prev.copy_from(x);
        self.f_prev.copy_from(f);
        self.started = true;
        let mk = self.count;
        let mut gamma = [0.0; ANDERSON_DEPTH];
        if mk > 0 {
            let mut normal = self.gram;
            for i in 0..mk {
                gamma[i] = self.df[i].dot(f);
            }
            guarded_lu_solve(&mut normal, mk, ANDERSON_DEPTH, &mut gamma[..mk]);
            if gamma[..mk].iter().any(|g| !g.is_finite()) {
                gamma = [0.0; ANDERSON_DEPTH];
                self.reset();
            }
        }
        *x += f;
        for i in 0..mk {
            x.axpy(-gamma[i], &self.dx[i], 1.0);
            x.axpy(-gamma[i], &self.df[i], 1.0);
        }
    }
}

impl Variational {
    /// The stepper with its buffers sized for `model`.
    pub fn new(model: &Model) -> Self {
        let (nq, nv) = (model.nq, model.nv);
        // At most 6 rows per equality (a weld).
        let rows = 6 * crate::constraint::ConstraintModel::new(model).equalities.len();
        let z = || DVector::zeros(nv);
        Self {
            stage_act: DVector::zeros(model.na()),
            terms0: LagrangianTerms::new(model),
            terms1: LagrangianTerms::new(model),
            xi: z(),
            dxi: z(),
            residual: z(),
            p_k: z(),
            mu_bar: z(),
            theta: z(),
            tmp: z(),
            drive: z(),
            q1: DVector::zeros(nq),
            mass_q: DVector::zeros(nq),
            mass_valid: false,
            mass: DMatrix::zeros(nv, nv),
            mass_factor: DMatrix::zeros(nv, nv),
            chord_factor: DMatrix::zeros(nv, nv),
            jac_k: DMatrix::zeros(rows, nv),
            y: DMatrix::zeros(nv, rows),
            schur: DMatrix::zeros(rows, rows),
            lambda: DVector::zeros(rows),
            dlambda: DVector::zeros(rows),
            has_equalities: rows > 0,
            has_rotations: model.joints.iter().any(|j| matches!(j.kind, JointKind::Free | JointKind::Ball)),
            failure: None,
            residual_tol: RESIDUAL_TOL,
            last_xi: z(),
            last_q1: DVector::zeros(nq),
            last_v1: z(),
            last_h: 0.0,
            last_valid: false,
            base: z(),
            error1: z(),
            error2: z(),
            errors: 0,
            anderson: Anderson::new(nv),
        }
    }

    /// The stepper with Newton's residual tolerance `tol` relative to the momentum scale instead
    /// of round-off ([`RESIDUAL_TOL`]): fewer iterations, but the discrete momenta are then
    /// conserved only to about `tol` per step.
    pub fn with_tolerance(model: &Model, tol: f64) -> Self {
        Self { residual_tol: tol.max(RESIDUAL_TOL), ..Self::new(model) }
    }

    /// `tmp` = J_r⁻¹(θ) μ̄ (`theta`, `mu_bar`): the identity on models without ball or free joints.
    fn dexp_inv_mu_bar(&mut self, model: &Model) {
        if self.has_rotations {
            dexp_inv_configuration_unchecked(
                model,
                self.theta.as_slice(),
                self.mu_bar.as_slice(),
                self.tmp.as_mut_slice(),
            );
        } else {
            self.tmp.copy_from(&self.mu_bar);
        }
    }

    /// M(q) and its factor, reused when q is the configuration of the last call.
    fn ensure_mass(&mut self, model: &Model, data: &mut Data, q: &DVector<f64>) {
        if self.mass_valid && self.mass_q == *q {
            return;
        }
        crba_unchecked(model, data, q.as_slice());
        factorize_mass_matrix(model, data);
        self.mass.copy_from(&data.mass_matrix);
        self.mass_factor.copy_from(&data.mass_factor);
        self.mass_q.copy_from(q);
        self.mass_valid = true;
    }

    /// The active equality rows at q into `data.efc_j`, `data.efc_pos` (rows 0..m); returns m.
    fn equality_rows(&self, model: &Model, data: &mut Data, q: &[f64]) -> usize {
        let plan = &model.plan;
        if !self.has_equalities || !plan.has_constraints() {
            return 0;
        }
        forward_kinematics_unchecked(model, data, q);
        plan.constraints.positions_unchecked(model, data, q, false);
        (0..data.nefc).take_while(|&i| data.efc_type[i] == EfcType::Equality).count()
    }
}

impl Stepper for Variational {
    fn name(&self) -> &'static str {
        "variational"
    }
    fn order(&self) -> u32 {
        2
    }
    fn failure(&self) -> Option<StepFailure> {
        self.failure
    }
    fn step(&mut self, model: &Model, data: &mut Data, h: f64) -> StepReport {
        self.step_moved(model, data, h)
    }
}

impl Advance for Variational {
    fn stage_act(&mut self) -> &mut DVector<f64> {
        &mut self.stage_act
    }

    fn advance(&mut self, model: &Model, data: &mut Data, state: &mut State, h: f64) -> StepReport {
        self.failure = None;
        let nv = model.nv;
        let q0 = state.q.as_slice();
        // The bodies' applied wrenches at q_k, held over the step with the drive.
        accumulate_xfrc(model, data, q0);
        self.ensure_mass(model, data, &state.q);
        self.p_k.gemv(1.0, &self.mass, &state.v, 0.0);
        // The drive, held over the step (with the activations at the step's start).
        if !model.actuators.is_empty() {
            data.act.copy_from(&state.act);
            crate::tendon::compute(model, data, q0, state.v.as_slice());
            actuation_unchecked(model, data, q0, state.v.as_slice(), &model.plan.actuator_bias_velocity);
        }
        for k in 0..nv {
            let limit = model.dof_effort_limit[k];
            let f = if model.actuators.is_empty() { 0.0 } else { data.qfrc_actuator[k] };
            self.drive[k] = (f + data.qfrc_applied[k]).clamp(-limit, limit) + data.qfrc_xfrc[k];
        }
        // The chord matrix C = M(q_k) + h/2 diag(damping).
        if model.has_damping() {
            data.mass_matrix.copy_from(&self.mass);
            for k in 0..nv {
                data.mass_matrix[(k, k)] += 0.5 * h * model.dof_damping[k];
            }
            factorize_mass_matrix(model, data);
            self.chord_factor.copy_from(&data.mass_factor);
        } else {
            self.chord_factor.copy_from(&self.mass_factor);
        }
        // Equality rows at q_k: J_k and Y = C⁻¹ J_kᵀ.
        let m = self.equality_rows(model, data, q0);
        for i in 0..m {
            for k in 0..nv {
                self.jac_k[(i, k)] = data.efc_j[(i, k)];
                self.y[(k, i)] = data.efc_j[(i, k)];
            }
            solve_with_factor_unchecked(
                model,
                &self.chord_factor,
                &mut self.y.as_mut_slice()[i * nv..(i + 1) * nv],
            );
        }
        self.lambda.fill(0.0);

        // Predictor: ξ ≈ v_k + h/2 a ≈ 2 v_k − ξ_{k−1} when this step continues the last one
        // (exact for a constant M and forces of q alone: M ξ_{k−1} = p_k − h/2 F(q_k),
        // M ξ_k = p_k + h/2 F(q_k)). Its error e_k = ξ_k − (2 v_k − ξ_{k−1}), from the
        // velocity-dependent terms, is O(h²) and smooth along the trajectory, so it is
        // extrapolated linearly from the last two steps when they continued each other at the
        // same h with the velocity this stepper left (error O(h⁴)): on chain30, 11.7 → 10.2
        // iterations per step at round-off, 7.7 → 6.2 at 1e-10.
        self.xi.copy_from(&state.v);
        let continuing = self.last_valid && self.last_q1 == state.q;
        if !(continuing && self.last_v1 == state.v && self.last_h == h) {
            self.errors = 0;
        }
        if continuing {
            self.xi.axpy(-1.0, &self.last_xi, 2.0);
            self.base.copy_from(&self.xi);
            if self.errors >= 1 {
                self.xi += &self.error1;
            }
            if self.errors >= 2 {
                self.xi += &self.error1;
                self.xi -= &self.error2;
            }
        }
        self.anderson.reset();
        let mut previous = f64::INFINITY;
        // The parts of the convergence scales that are fixed over the step: max |p_k|, the
        // impulse of gravity at q_k and of the drive, max |v_k|.
        let mut fixed_scales = (0.0, 0.0);
        let v_scale = state.v.amax();
        let mut iterations = 0;
        let mut phi_max = 0.0;
        loop {
            iterations += 1;
            self.q1.copy_from(&state.q);
            integrate_configuration_unchecked(model, self.q1.as_mut_slice(), self.xi.as_slice(), h);
            if iterations == 1 {
                self.terms0.compute_unchecked(model, data, q0, self.xi.as_slice());
            } else {
                self.terms0.pass(model, self.xi.as_slice(), false);
            }
            self.terms1.compute_unchecked(model, data, self.q1.as_slice(), self.xi.as_slice());
            crate::tendon::compute(model, data, q0, self.xi.as_slice());
            passive(model, data, q0, self.xi.as_slice());
            for k in 0..nv {
                self.mu_bar[k] = 0.5 * (self.terms0.momentum_gen[k] + self.terms1.momentum_gen[k]);
                self.theta[k] = h * self.xi[k];
            }
            self.dexp_inv_mu_bar(model);
            let t0 = &self.terms0;
            for k in 0..nv {
                let mut r = self.p_k[k]
                    + 0.5
                        * h
                        * (t0.dkinetic_dq[k] - t0.gravity_gen[k] + data.qfrc_passive[k] + self.drive[k])
                    - self.tmp[k];
                for i in 0..m {
                    r += self.jac_k[(i, k)] * self.lambda[i];
                }
                self.residual[k] = r;
            }
            self.dxi.copy_from(&self.residual);
            solve_with_factor_unchecked(model, &self.chord_factor, self.dxi.as_mut_slice());
            if m > 0 {
                self.equality_rows(model, data, self.q1.as_slice());
                phi_max = data.efc_pos.rows(0, m).amax();
                // S = h J₁ Y, rhs = −φ − h J₁ C⁻¹ R.
                for i in 0..m {
                    let mut rhs = -data.efc_pos[i];
                    for k in 0..nv {
                        rhs -= h * data.efc_j[(i, k)] * self.dxi[k];
                    }
                    self.dlambda[i] = rhs;
                    for l in 0..m {
                        let mut s = 0.0;
                        for k in 0..nv {
                            s += data.efc_j[(i, k)] * self.y[(k, l)];
                        }
                        self.schur[(i, l)] = h * s;
                    }
                }
                let ld = self.schur.nrows();
                guarded_lu_solve(self.schur.as_mut_slice(), m, ld, &mut self.dlambda.as_mut_slice()[..m]);
                for i in 0..m {
                    for k in 0..nv {
                        self.dxi[k] += self.y[(k, i)] * self.dlambda[i];
                    }
                }
            }
            // Converged when the residual of the DEL equations (the discrete momentum balance) is
            // at round-off, or stagnates near it, or the update of ξ is; and φ is within tolerance.
            let update = self.dxi.amax();
            let residual = self.residual.amax();
            // The momentum scale: the momenta and the impulse of the forces over the step (so
            // that a state at rest under round-off forces converges too).
            if iterations == 1 {
                fixed_scales =
                    (self.p_k.amax(), 0.5 * h * (self.terms0.gravity_gen.amax() + self.drive.amax()));
            }
            let impulse = fixed_scales.1 + 0.5 * h * data.qfrc_passive.amax();
            let p_scale = fixed_scales.0.max(self.tmp.amax()).max(impulse);
            let scale = self.xi.amax().max(v_scale);
            let finite = self.residual.iter().chain(self.dxi.iter()).all(|x| x.is_finite());
            let converged = finite
                && (residual <= self.residual_tol * p_scale
                    || update <= UPDATE_TOL * scale
                    || (iterations > 2 && residual >= 0.5 * previous && residual <= STALL_TOL * p_scale))
                && phi_max <= CONSTRAINT_TOL;
            if converged {
                break;
            }
            if !finite || iterations >= MAX_ITERATIONS {
                self.failure = Some(StepFailure {
                    iterations,
                    residual: if finite { residual } else { f64::NAN },
                    constraint: phi_max,
                    update,
                });
                return StepReport {
                    accepted: false,
                    h_used: h,
                    h_next: h,
                    error_estimate: None,
                    solver_iterations: iterations,
                    solver_improvement: 0.0,
                    constraint_violation: [phi_max, 0.0],
                    substeps: 0,
                    rejected: 1,
                };
            }
            if m == 0 {
                self.anderson.update(&mut self.xi, &self.dxi);
            } else {
                self.xi += &self.dxi;
            }
            for i in 0..m {
                self.lambda[i] += self.dlambda[i];
            }
            previous = residual;
        }
        if continuing {
            std::mem::swap(&mut self.error1, &mut self.error2);
            self.error1.copy_from(&self.xi);
            self.error1 -= &self.base;
            self.errors = (self.errors + 1).min(2);
        }
        self.last_xi.copy_from(&self.xi);
        self.last_q1.copy_from(&self.q1);
        self.last_h = h;
        self.last_valid = true;
        // p_{k+1} = h/2 [∂_qL(q_{k+1}, ξ) + passive(q_{k+1}, ξ) + drive] + J_r⁻¹(−hξ) μ̄.
        crate::tendon::compute(model, data, self.q1.as_slice(), self.xi.as_slice());
        passive(model, data, self.q1.as_slice(), self.xi.as_slice());
        self.theta.neg_mut();
        self.dexp_inv_mu_bar(model);
        let t1 = &self.terms1;
        for k in 0..nv {
            self.residual[k] =
                0.5 * h * (t1.dkinetic_dq[k] - t1.gravity_gen[k] + data.qfrc_passive[k] + self.drive[k])
                    + self.tmp[k];
        }
        // The equality rows at q_{k+1} are in data (last evaluated there); CRBA leaves them.
        state.q.copy_from(&self.q1);
        self.ensure_mass(model, data, &state.q);
        state.v.copy_from(&self.residual);
        solve_with_factor_unchecked(model, &self.mass_factor, state.v.as_mut_slice());
        let mut jv_max = 0.0;
        if m > 0 {
            // v ← v − Z (J Z)⁻¹ J v with Z = M⁻¹ Jᵀ (RATTLE's velocity multiplier).
            for i in 0..m {
                for k in 0..nv {
                    self.y[(k, i)] = data.efc_j[(i, k)];
                }
                solve_with_factor_unchecked(
                    model,
                    &self.mass_factor,
                    &mut self.y.as_mut_slice()[i * nv..(i + 1) * nv],
                );
            }
            for i in 0..m {
                let mut jv = 0.0;
                for k in 0..nv {
                    jv += data.efc_j[(i, k)] * state.v[k];
                }
                self.dlambda[i] = jv;
                for l in 0..m {
                    let mut s = 0.0;
                    for k in 0..nv {
                        s += data.efc_j[(i, k)] * self.y[(k, l)];
                    }
                    self.schur[(i, l)] = s;
                }
            }
            let ld = self.schur.nrows();
            guarded_lu_solve(self.schur.as_mut_slice(), m, ld, &mut self.dlambda.as_mut_slice()[..m]);
            for i in 0..m {
                for k in 0..nv {
                    state.v[k] -= self.y[(k, i)] * self.dlambda[i];
                }
            }
            for i in 0..m {
                let mut jv: f64 = 0.0;
                for k in 0..nv {
                    jv += data.efc_j[(i, k)] * state.v[k];
                }
                jv_max = f64::max(jv_max, jv.abs());
            }
        }
        state.time += h;
        // Activations as in MuJoCo's `mj_advance`, from their rates at the step's start.
        if !model.actuators.is_empty() {
            advance_activations(model, state.act.as_mut_slice(), data.act_dot.as_slice(), h);
        }
        let plan = &model.plan;
        let others = plan.has_constraints()
            && (!plan.constraints.limits.is_empty()
                || !plan.constraints.friction.is_empty()
                || plan.constraints.has_collision());
        let (extra_iterations, violation) =
            if others { correct_drift(model, data, state, h) } else { (0, [phi_max, jv_max]) };
        self.last_v1.copy_from(&state.v);
        StepReport::fixed_step(h, (iterations + extra_iterations, violation))
    }
}
