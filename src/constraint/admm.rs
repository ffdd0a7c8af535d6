//! The exact mode's alternative solver for rows with dry friction: the proximal ADMM of
//! Carpentier, Montaut & Le Lidec ("From compliant to rigid contact simulation: a unified and
//! efficient approach", RSS 2024; Pinocchio 4.1's `ADMMConstraintSolver`), written from the
//! paper's algorithm on the Delassus problem the exact mode forms (A = J M⁻¹ Jᵀ in
//! `ExactWork::delassus`, b in `ExactWork::rhs`, w = A λ − b the row accelerations).
//!
//! Each contact's friction rows are scaled by their coefficients (λ̂_k = λ_k / μ_k), which turns
//! the elliptic cone Σ (λ_k/μ_k)² ≤ λ_n² into the circular second-order cone K. With the De Saxcé
//! correction s (per contact s_n = ‖σ̂_t‖, σ̂ = Â λ̂ − b̂) the Coulomb problem becomes the cone
//! complementarity problem K ∋ λ̂ ⊥ Â λ̂ − b̂ + s ∈ K* whose solution is the maximal-dissipation
//! friction. ADMM splits λ̂ = x = y:
//! - x ← (Â + (ρ + η) I)⁻¹ (b̂ − s + ρ (y − u) + η x)   (proximal step, η the prox weight),
//! - y ← Π_K(x + u)   (per block: identity for equalities, a box for friction loss and
//!   limits, the second-order cone for a sticking contact, the ray λ_t = λ_n d for a sliding
//!   contact, d the maximal-dissipation direction against the slip velocity),
//! - u ← u + x − y   (scaled dual: σ = −ρ u at the fixed point).
//!
//! ρ follows the spectral rule ρ = √(m L) (L/m)^p (L the largest eigenvalue of Â by power
//! iteration, m = η), p raised or lowered by 0.05 when the primal and dual residuals are more than
//! 10× apart (then Â + (ρ + η) I is refactored). It stops when the primal residual L ‖x − y‖∞,
//! the dual residual ‖Â y − b̂ + s + ρ u‖∞ and the complementarity max |⟨y, σ⟩| per block are all
//! below [`ADMM_TOLERANCE`] (relative to 1 + ‖b̂‖∞); the active set it found is then solved
//! exactly by the Gauss–Seidel solver's polish, kept when every row's law holds.

use super::coulomb::{polish, solve_coulomb, Level, SolverSettings, SEPARATING_VELOCITY, SLIP_VELOCITY};
use super::dense::{cholesky, cholesky_solve};
use super::ExactWork;
use crate::model::{Data, EfcType, Model};

/// Which algorithm the exact mode uses for rows with dry friction.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ExactContactSolver {
    /// Projected block Gauss–Seidel with polish (`constraint::coulomb`).
    #[default]
    Pgs,
    /// The proximal ADMM of Carpentier, Montaut & Le Lidec (this module); the velocity-level
    /// projection keeps Gauss–Seidel.
    Admm,
}

/// Relative stopping tolerance of the ADMM residuals (primal, dual, complementarity), against
/// 1 + ‖b̂‖∞ (an acceleration).
pub const ADMM_TOLERANCE: f64 = 1e-8;

/// A row's constraint set in the ADMM projection.
#[derive(Clone, Copy, Debug, PartialEq)]
enum RowSet {
    /// Equality: λ free.
    Free,
    /// No force (separating, or a diagonal that is round-off).
    Zero,
    /// lo ≤ λ ≤ hi (limits and frictionless normals: [0, ∞); friction loss: [−f, f] or the
    /// sliding value).
    Bounded,
    /// The normal of a sticking contact with this many rows (second-order cone).
    Cone(usize),
    /// The normal of a sliding contact with this many rows (the ray λ̂_t = λ̂_n d).
    Slide(usize),
    /// A friction row (handled with its normal).
    Tangent,
}

/// Buffers of the ADMM solve, one entry per row (grown with the rows; no allocation per step).
#[derive(Clone, Debug, Default)]
pub(crate) struct AdmmWork {
    set: Vec<RowSet>,
    scale: Vec<f64>,
    lo: Vec<f64>,
    hi: Vec<f64>,
    dir: Vec<f64>,
    b: Vec<f64>,
    x: Vec<f64>,
    y: Vec<f64>,
    u: Vec<f64>,
    sigma: Vec<f64>,
    desaxce: Vec<f64>,
    work: Vec<f64>,
    diag: Vec<f64>,
}

impl AdmmWork {
    /// Sizes every buffer for `nefc` rows.
    pub fn grow(&mut self, nefc: usize) {
        self.set.resize(nefc, RowSet::Zero);
        for v in [
            &mut self.scale,
            &mut self.lo,
            &mut self.hi,
            &mut self.dir,
            &mut self.b,
            &mut self.x,
            &mut self.y,
            &mut self.u,
            &mut self.sigma,
            &mut self.desaxce,
            &mut self.work,
            &mut self.diag,
        ] {
            v.resize(nefc, 0.0);
        }
    }
}

/// Prox weight η relative to the largest eigenvalue of Â.
const PROX: f64 = 1e-6;
/// Initial exponent p of the spectral ρ rule, and its step.
const RHO_POWER: f64 = 0.2;
const RHO_POWER_STEP: f64 = 0.05;
/// Residual ratio that triggers a ρ update, checked every this many iterations.
const RHO_RATIO: f64 = 10.0;
const RHO_CHECK_EVERY: u32 = 5;
/// A Delassus diagonal at most this fraction of the largest is round-off.
const DIAGONAL_ROUNDOFF: f64 = 1e-12;
/// Multiply-adds one solve may spend before it stops unconverged.
const WORK_BUDGET: f64 = 4e7;
const MIN_ITERATIONS: u32 = 50;

/// Classifies the rows and fills the scaling, bounds and sliding directions.
fn classify(model: &Model, data: &mut Data, a_floor: f64) {
    let n = data.nefc;
    let mut i = 0;
    while i < n {
        let len = data.efc_block_len(i);
        let aii = data.exact.delassus[(i, i)];
        let separating = !data.rows_frozen() && data.efc_vel[i] > SEPARATING_VELOCITY;
        let at_rest = data.efc_frozen_at_rest(i);
        let w = &mut data.exact.admm;
        match data.efc_type[i] {
            EfcType::Equality | EfcType::FrictionTendon => {
                w.set[i] = RowSet::Free;
                w.scale[i] = 1.0;
            }
            EfcType::FrictionDof => {
                let dof = data.efc_id[i];
                let loss = model.joint_of(model.dof_body[dof]).friction;
                let speed = data.efc_vel[i];
                w.set[i] = RowSet::Bounded;
                w.scale[i] = 1.0;
                if speed.abs() > SLIP_VELOCITY && !at_rest {
                    w.lo[i] = -loss * speed.signum();
                    w.hi[i] = w.lo[i];
                } else {
                    w.lo[i] = -loss;
                    w.hi[i] = loss;
                }
            }
            EfcType::LimitJoint
            | EfcType::LimitTendon
            | EfcType::ContactFrictionless
            | EfcType::ContactPyramidal => {
                if separating || aii <= a_floor {
                    w.set[i] = RowSet::Zero;
                    w.scale[i] = 0.0;
                } else {
                    w.set[i] = RowSet::Bounded;
                    w.scale[i] = 1.0;
                    w.lo[i] = 0.0;
                    w.hi[i] = f64::INFINITY;
                }
            }
            EfcType::ContactElliptic => {
                if separating || aii <= a_floor {
                    for k in i..i + len {
                        w.set[k] = RowSet::Zero;
                        w.scale[k] = 0.0;
                    }
                } else {
                    let friction = data.contacts[data.efc_id[i]].friction;
                    let slip: f64 = (1..len).map(|k| data.efc_vel[i + k].powi(2)).sum::<f64>().sqrt();
                    let sliding = slip > SLIP_VELOCITY && !at_rest;
                    let norm: f64 =
                        (1..len).map(|k| (friction[k - 1] * data.efc_vel[i + k]).powi(2)).sum::<f64>().sqrt();
                    let w = &mut data.exact.admm;
                    w.set[i] = if sliding && norm > 0.0 { RowSet::Slide(len) } else { RowSet::Cone(len) };
                    w.scale[i] = 1.0;
                    for k in 1..len {
                        let r = i + k;
                        let m = friction[k - 1];
                        w.set[r] = RowSet::Tangent;
                        w.scale[r] = if m > 0.0 && data.exact.delassus[(r, r)] > a_floor { m } else { 0.0 };
                        // λ_k = −λ_n μ_k² v_k / ‖μ ∘ v‖, so λ̂_k = λ_n (−μ_k v_k / ‖μ ∘ v‖).
                        w.dir[r] = if norm > 0.0 { -m * data.efc_vel[r] / norm } else { 0.0 };
                    }
                }
            }
        }
        i += len;
    }
}

/// y ← Π_K(z) with z = x + u, block by block.
fn project(w: &mut AdmmWork, n: usize) {
    let mut i = 0;
    while i < n {
        let z = |k: usize| if w.scale[k] > 0.0 { w.x[k] + w.u[k] } else { 0.0 };
        match w.set[i] {
            RowSet::Free => {
                w.y[i] = z(i);
                i += 1;
            }
            RowSet::Zero | RowSet::Tangent => {
                w.y[i] = 0.0;
                i += 1;
            }
            RowSet::Bounded => {
                w.y[i] = z(i).clamp(w.lo[i], w.hi[i]);
                i += 1;
            }
            RowSet::Slide(len) => {
                let yn = z(i).max(0.0);
                w.y[i] = yn;
                for k in i + 1..i + len {
                    w.y[k] = if w.scale[k] > 0.0 { yn * w.dir[k] } else { 0.0 };
                }
                i += len;
            }
            RowSet::Cone(len) => {
                let zn = z(i);
                let zt: f64 = (i + 1..i + len).map(|k| z(k).powi(2)).sum::<f64>().sqrt();
                if zt <= zn {
                    for k in i..i + len {
                        w.y[k] = z(k);
                    }
                } else if zt <= -zn {
                    w.y[i..i + len].fill(0.0);
                } else {
                    let alpha = 0.5 * (zn + zt);
                    let t = alpha / zt;
                    w.y[i] = alpha;
                    for k in i + 1..i + len {
                        w.y[k] = z(k) * t;
                    }
                }
                i += len;
            }
        }
    }
}

/// Factors Â + shift·I (Â in `sub`, its diagonal kept in `admm.diag`) into `factor`.
fn factor(work: &mut ExactWork, n: usize, shift: f64) -> bool {
    for i in 0..n {
        work.sub[(i, i)] = work.admm.diag[i] + shift;
    }
    let ok = cholesky(&work.sub, n, &mut work.factor, 0.0);
    for i in 0..n {
        work.sub[(i, i)] = work.admm.diag[i];
    }
    ok
}

/// σ ← Â y − b̂ and the De Saxcé correction of the sticking contacts; returns the
/// complementarity max |⟨y, σ + s⟩| over the unilateral blocks.
fn dual(work: &mut ExactWork, n: usize) -> f64 {
    let ExactWork { sub, admm: w, .. } = work;
    for i in 0..n {
        w.sigma[i] = -w.b[i];
    }
    for j in 0..n {
        let yj = w.y[j];
        if yj == 0.0 {
            continue;
        }
        let col = sub.column(j);
        for i in 0..n {
            w.sigma[i] += col[i] * yj;
        }
    }
    w.desaxce[..n].fill(0.0);
    let mut comp = 0.0f64;
    let mut i = 0;
    while i < n {
        match w.set[i] {
            RowSet::Cone(len) => {
                let st: f64 = (i + 1..i + len).map(|k| w.sigma[k].powi(2)).sum::<f64>().sqrt();
                w.desaxce[i] = st;
                let dot: f64 = (i..i + len).map(|k| w.y[k] * (w.sigma[k] + w.desaxce[k])).sum();
                comp = comp.max(dot.abs());
                i += len;
            }
            RowSet::Slide(len) => {
                comp = comp.max((w.y[i] * w.sigma[i]).abs());
                i += len;
            }
            RowSet::Bounded if w.lo[i] == 0.0 => {
                comp = comp.max((w.y[i] * w.sigma[i]).abs());
                i += 1;
            }
            _ => i += 1,
        }
    }
    comp
}

/// Solves the rows' conditions on A (`delassus`) and b (`rhs`) by ADMM at the acceleration
/// level; λ is left in `rhs`, as [`super::coulomb::solve_coulomb`] leaves it, and the outputs
/// (`efc_iterations`, `efc_residual`, `efc_converged`, the unconverged counters) are set the same
/// way. Warm-started from the previous solve's forces when the rows are the same. No allocation.
pub(crate) fn solve_admm(model: &Model, data: &mut Data, settings: SolverSettings) {
    let n = data.nefc;
    data.exact.admm.grow(n);
    let a_floor = DIAGONAL_ROUNDOFF * (0..n).map(|i| data.exact.delassus[(i, i)]).fold(0.0, f64::max);
    data.exact.a_floor = a_floor;
    classify(model, data, a_floor);
    let warm = data.exact.warm_rows.len() == n
        && (0..n).all(|i| data.exact.warm_rows[i] == (data.efc_type[i], data.efc_id[i]));
    // b in efc_force (as the Gauss–Seidel solve keeps it, for the polish); the scaled problem
    // Â = S A S in `sub`, b̂ = S b.
    {
        let Data { efc_force, exact, .. } = data;
        let ExactWork { delassus, sub, rhs, warm: warm_force, admm: w, .. } = exact;
        for i in 0..n {
            efc_force[i] = rhs[i];
            w.b[i] = w.scale[i] * rhs[i];
            w.y[i] = if warm && w.scale[i] > 0.0 { warm_force[i] / w.scale[i] } else { 0.0 };
            w.x[i] = w.y[i];
            w.u[i] = 0.0;
        }
        for j in 0..n {
            for i in 0..n {
                sub[(i, j)] = w.scale[i] * w.scale[j] * delassus[(i, j)];
            }
            w.diag[j] = sub[(j, j)];
        }
    }
    // The largest eigenvalue L of Â by power iteration.
    let mut big = 0.0f64;
    {
        let ExactWork { sub, admm: w, .. } = &mut data.exact;
        w.work[..n].fill(1.0);
        for _ in 0..20 {
            for i in 0..n {
                w.sigma[i] = (0..n).map(|j| sub[(i, j)] * w.work[j]).sum();
            }
            let norm = w.sigma[..n].iter().map(|v| v * v).sum::<f64>().sqrt();
            if norm == 0.0 || !norm.is_finite() {
                break;
            }
            big = norm / w.work[..n].iter().map(|v| v * v).sum::<f64>().sqrt();
            for i in 0..n {
                w.work[i] = w.sigma[i] / norm;
            }
        }
    }
    let mut iterations = 0;
    let mut residual = 0.0;
    let mut converged = big == 0.0;
    if big > 0.0 && big.is_finite() {
        let eta = PROX * big;
        let mut power = RHO_POWER;
        let rho_of = |p: f64| (eta * big).sqrt() * (big / eta).powf(p);
        let mut rho = rho_of(power);
        let scale = 1.0 + data.exact.admm.b[..n].iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let tol = ADMM_TOLERANCE * scale;
        let mut ok = factor(&mut data.exact, n, rho + eta);
        let limit = settings
            .max_iterations
            .min((WORK_BUDGET / (3 * n * n).max(1) as f64).max(MIN_ITERATIONS as f64) as u32);
        dual(&mut data.exact, n);
        while ok && iterations < limit {
            iterations += 1;
            let ExactWork { factor: l, admm: w, .. } = &mut data.exact;
            for i in 0..n {
                w.work[i] = w.b[i] - w.desaxce[i] + rho * (w.y[i] - w.u[i]) + eta * w.x[i];
            }
            cholesky_solve(l, n, &mut w.work[..n]);
            w.x[..n].copy_from_slice(&w.work[..n]);
            project(w, n);
            let mut primal = 0.0f64;
            for i in 0..n {
                let d = w.x[i] - w.y[i];
                w.u[i] += d;
                primal = primal.max(d.abs());
            }
            let comp = dual(&mut data.exact, n);
            let w = &data.exact.admm;
            let dual_res =
                (0..n).map(|i| (w.sigma[i] + w.desaxce[i] + rho * w.u[i]).abs()).fold(0.0, f64::max);
            let primal_res = big * primal;
            residual = primal_res.max(dual_res).max(comp);
            if !residual.is_finite() {
                break;
            }
            if residual <= tol {
                converged = true;
                break;
            }
            if iterations % RHO_CHECK_EVERY == 0 {
                let old = power;
                if primal_res > RHO_RATIO * dual_res {
                    power += RHO_POWER_STEP;
                } else if dual_res > RHO_RATIO * primal_res {
                    power -= RHO_POWER_STEP;
                }
                if power != old {
                    let new_rho = rho_of(power);
                    // The scaled dual u = −σ/ρ keeps σ.
                    for v in &mut data.exact.admm.u[..n] {
                        *v *= rho / new_rho;
                    }
                    rho = new_rho;
                    ok = factor(&mut data.exact, n, rho + eta);
                }
            }
        }
    }
    let finite = residual.is_finite();
    {
        let ExactWork { rhs, admm: w, .. } = &mut data.exact;
        for i in 0..n {
            rhs[i] = if finite { w.scale[i] * w.y[i] } else { 0.0 };
        }
    }
    // Solve the active set found exactly when the laws then hold.
    data.efc_safe_friction = false;
    if finite && polish(model, data, Level::Acceleration) {
        converged = true;
        residual = 0.0;
    }
    if !(converged && finite) {
        // Fall back on the Gauss–Seidel solve (b is still in efc_force, the rows unchanged).
        for i in 0..n {
            data.exact.rhs[i] = data.efc_force[i];
        }
        let scale = data.qacc_smooth.amax();
        solve_coulomb(model, data, Level::Acceleration, settings, scale);
        data.efc_iterations += iterations;
        return;
    }
    data.efc_iterations = iterations;
    data.efc_residual = residual;
    data.efc_converged = true;
    if !data.efc_converged {
        data.efc_unconverged += 1;
        data.efc_unconverged_residual = data.efc_unconverged_residual.max(data.efc_residual);
    }
}
