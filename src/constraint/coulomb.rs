//! The exact mode's solver for rows with dry friction — contacts in the Coulomb cone and dof
//! friction loss — together with equality, limit and frictionless contact rows: a projected block
//! Gauss–Seidel iteration on the Delassus matrix A = J M⁻¹ Jᵀ (Jean & Moreau, "Unilaterality and
//! dry friction in the dynamics of rigid body collections", 1992; Acary & Brogliato, *Numerical
//! Methods for Nonsmooth Dynamical Systems*, 2008, §13.3 "nonsmooth Gauss–Seidel"; the same family
//! as Pinocchio's `PGSContactSolver`).
//!
//! With w = A λ − b the row accelerations (or, at the velocity level, the post-impact row
//! velocities), each block of rows is solved exactly with the others fixed:
//! - the equality rows together (w = 0, λ free): A_EE λ_E = b_E − A_E· λ (minimum-norm when
//!   redundant);
//! - a limit or a contact normal (Signorini): λ ≥ 0, w ≥ 0, λ w = 0 — λ = max(0, λ − w/A_ii);
//! - a dof's friction loss: while the dof slides λ = −f sign(q̇); at rest |λ| ≤ f and w = 0 unless
//!   |λ| = f (box projection);
//! - a contact's friction rows (elliptic cone Σ (λ_i/μ_i)² ≤ λ_n²): while the contact slips, the
//!   force of maximal dissipation λ_i = −λ_n μ_i² u_i / ‖μ ∘ u‖ (u the slip velocity); at rest,
//!   the exact minimiser of ½ λᵀ A_ff λ − gᵀ λ over the cone (w_f = 0 inside; on the boundary
//!   w_f ∝ −λ_i/μ_i²), by the stick solve or, when that leaves the cone, Newton on the secular
//!   equation ‖(Ã + νI)⁻¹ g̃‖ = λ_n of the scaled problem (Moré & Sorensen 1983).
//!
//! A fixed point satisfies Signorini's and Coulomb's laws exactly (docs/physics.md §2.5: F_P ≤ μ F_N, and
//! F_P = μ F_N while slipping). The iteration stops when a sweep changes the motion, M⁻¹Jᵀ Δλ
//! (an acceleration, or a velocity at the velocity level), by less than the tolerance relative to
//! the constraints' whole correction M⁻¹Jᵀ λ — redundant rows that still trade force among
//! themselves move nothing — or after the iteration limit; the last change is the residual. At the acceleration level it starts from the previous solve's
//! forces when the rows are the same (warm start; at the velocity level the last step's impulses
//! were measured a worse start: humanoid +18 % instructions, go1 ±1 %).

use super::dense::{lu_solve, solve_psd};
use super::ExactWork;
use crate::model::{Data, EfcType, Model};

/// Iteration limit and tolerance of the Gauss–Seidel solve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolverSettings {
    /// The most Gauss–Seidel sweeps per solve.
    pub max_iterations: u32,
    /// Relative tolerance on the change one sweep makes to the motion, max |M⁻¹Jᵀ Δλ|, against the
    /// constraint forces' whole correction max |M⁻¹Jᵀ λ|.
    pub tolerance: f64,
    /// The algorithm for rows with dry friction at the acceleration level (Gauss–Seidel or
    /// ADMM); the velocity projection always uses Gauss–Seidel.
    pub solver: super::ExactContactSolver,
}

impl Default for SolverSettings {
    fn default() -> Self {
        Self { max_iterations: 1000, tolerance: 1e-13, solver: super::ExactContactSolver::Pgs }
    }
}

pub use crate::model::SLIP_VELOCITY;

/// Separation speed (m/s, rad/s) above which a limit or contact row leaves its bound and carries no
/// force at the acceleration level.
pub const SEPARATING_VELOCITY: f64 = 1e-10;

/// Whether the problem needs this solver: some row has dry friction.
pub fn has_friction(data: &Data) -> bool {
    (0..data.nefc).any(|i| matches!(data.efc_type[i], EfcType::FrictionDof | EfcType::ContactElliptic))
}

/// What the rows' w are.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Level {
    /// Row accelerations (the constraint stage of `forward`): sliding laws from `efc_vel`,
    /// separating rows skipped, warm start.
    Acceleration,
    /// Post-step row velocities (inelastic impacts; Moreau's velocity-level law over the step
    /// `dt`): the friction impulse of the whole step — dt times the force λ̄ of the last
    /// acceleration-level solve plus the projection's impulse p — obeys Coulomb's law: for a dof,
    /// |dt λ̄ + p| ≤ f dt; for a contact, dt λ̄_f + p_f lies in the cone of dt λ̄_n + p_n. A slip that
    /// the step's friction could have stopped thus ends at rest instead of reversing, and a slip
    /// that friction could not stop keeps the velocity the step gave it.
    Velocity {
        /// The step (s).
        dt: f64,
    },
}

/// Solves the rows' conditions on A (`efc_delassus`) and b (`efc_rhs`, first nefc entries); λ is
/// left in `efc_rhs`. `motion_scale` is the size of the motion the rows act on (max |q̈_smooth|,
/// or max |v| at the velocity level): a sweep that changes the motion by less than the tolerance
/// relative to it or to the constraints' correction has converged. Sets `efc_iterations`, `efc_residual`, `efc_converged`. At the acceleration
/// level it starts from `efc_warm` when the rows are those of the last solve (the constraint stage
/// stores it). No allocation.
pub(crate) fn solve_coulomb(
    model: &Model,
    data: &mut Data,
    level: Level,
    settings: SolverSettings,
    motion_scale: f64,
) {
    let n = data.nefc;
    let ne = (0..n).take_while(|&i| data.efc_type[i] == EfcType::Equality).count();
    // A row whose diagonal is round-off next to the others' moves nothing (a contact normal no
    // dof can move along): it gets no force rather than round-off divided by round-off.
    data.exact.a_floor = DIAGONAL_ROUNDOFF * (0..n).map(|i| data.exact.delassus[(i, i)]).fold(0.0, f64::max);
    // b in efc_force during the iterations, λ in efc_rhs.
    for i in 0..n {
        data.efc_force[i] = data.exact.rhs[i];
    }
    if level != Level::Acceleration {
        // Each row's force in the last acceleration-level solve, read by every sweep.
        let mut i = 0;
        while i < n {
            let len = data.efc_block_len(i);
            for k in 0..len {
                data.exact.previous[i + k] = data.efc_previous_force(i, k);
            }
            i += len;
        }
    }
    let warm = level == Level::Acceleration
        && data.exact.warm_rows.len() == n
        && (0..n).all(|i| data.exact.warm_rows[i] == (data.efc_type[i], data.efc_id[i]));
    for i in 0..n {
        data.exact.rhs[i] = if warm { data.exact.warm[i] } else { 0.0 };
    }
    data.exact.nu.as_mut_slice()[..n].fill(0.0);
    let mut change = 0.0;
    let mut iterations = 0;
    data.efc_converged = false;
    // Divergence guard: the sliding law (maximal dissipation) makes the problem non-symmetric, and
    // projected Gauss–Seidel can then grow without bound (a violent state: a body deep in the
    // floor, joints beyond their limits, fast slips). The solve then restarts from zero with the
    // symmetric cone projection for every contact; if that diverges too, the rows get no force
    // and the solve counts as unconverged (reported), never NaN.
    data.efc_safe_friction = false;
    let mut first_total = 0.0f64;
    // A sweep costs about n² + n·nv: large problems get fewer sweeps (a work budget), so that a
    // pile of contacts cannot stall a step; a solve stopped early is counted as unconverged.
    let sweep = (n * n + n * model.nv).max(1) as f64;
    let limit = settings.max_iterations.min((WORK_BUDGET / sweep).max(MIN_SWEEPS as f64) as u32);
    while iterations < limit {
        iterations += 1;
        for i in 0..n {
            data.exact.lambda_prev[i] = data.exact.rhs[i];
        }
        if ne > 0 {
            equality_block(data, ne);
        }
        let mut i = ne;
        while i < n {
            let len = data.efc_block_len(i);
            match data.efc_type[i] {
                // Tendon friction rows are the soft mode's; the exact mode never makes them.
                EfcType::Equality | EfcType::FrictionTendon => {
                    scalar_update(data, i, f64::NEG_INFINITY, f64::INFINITY)
                }
                EfcType::FrictionDof => friction_dof(model, data, i, level),
                // Pyramidal rows are the soft mode's; the exact mode never makes them.
                EfcType::LimitJoint
                | EfcType::LimitTendon
                | EfcType::ContactFrictionless
                | EfcType::ContactPyramidal => {
                    if separating(data, i, level) {
                        set_zero(data, i, 1)
                    } else {
                        scalar_update(data, i, normal_lower_bound(data, i), f64::INFINITY)
                    }
                }
                EfcType::ContactElliptic => contact_block(data, i, len, level),
            };
            i += len;
        }
        // The change of the motion this sweep made, M⁻¹Jᵀ Δλ, against the constraint's whole
        // correction M⁻¹Jᵀ λ: redundant rows may still trade force between them (a box's corners),
        // which moves nothing.
        let (moved, total) = sweep_motion(model.nv, data);
        if iterations == 1 {
            first_total = total;
        }
        if !(total.is_finite() && total <= DIVERGED * first_total.max(motion_scale)) {
            data.exact.rhs.as_mut_slice()[..n].fill(0.0);
            if data.efc_safe_friction {
                change = f64::INFINITY;
                break;
            }
            data.efc_safe_friction = true;
            first_total = 0.0;
            iterations = 0;
            continue;
        }
        change = moved;
        if moved <= settings.tolerance * total.max(motion_scale)
            || moved <= ROUND_OFF_FLOOR
            || !moved.is_finite()
        {
            data.efc_converged = moved.is_finite();
            break;
        }
        // Once the iterate has settled which rows stick, slide or lift, solve that active set
        // exactly; accepted only if every row's law then holds.
        if (iterations == POLISH_AFTER || iterations == limit)
            && !data.efc_safe_friction
            && polish(model, data, level)
        {
            data.efc_converged = true;
            change = 0.0;
            break;
        }
    }
    data.efc_iterations = iterations;
    data.efc_residual = change;
    if !data.efc_converged {
        data.efc_unconverged += 1;
        data.efc_unconverged_residual = data.efc_unconverged_residual.max(change);
    }
}

/// max |M⁻¹Jᵀ Δλ| (the sweep's change, Δλ = λ − `lambda_prev`) and max |M⁻¹Jᵀ λ|. Column by
/// column of M⁻¹Jᵀ, over each row's tree span (`exact.spans`; the column is zero outside it):
/// per dof the same sum, in the same order, as the dense product.
fn sweep_motion(nv: usize, data: &mut Data) -> (f64, f64) {
    let n = data.nefc;
    let ExactWork { minv_jt, rhs, lambda_prev, spans, motion, .. } = &mut data.exact;
    let (change, whole) = motion.as_mut_slice()[..2 * nv].split_at_mut(nv);
    change.fill(0.0);
    whole.fill(0.0);
    let y = minv_jt.as_slice();
    for i in 0..n {
        let (lo, hi) = spans[i];
        let (l, dl) = (rhs[i], rhs[i] - lambda_prev[i]);
        for k in lo..hi {
            let yk = y[k + i * nv];
            change[k] += yk * dl;
            whole[k] += yk * l;
        }
    }
    let moved = change.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let total = whole.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    (moved, total)
}

/// w_i = (A λ)_i − b_i with the current λ (read down column i of the symmetric A: contiguous).
fn row_w(data: &Data, i: usize) -> f64 {
    let n = data.nefc;
    column_dot(data, i, &data.exact.rhs.as_slice()[..n]) - data.efc_force[i]
}

/// Column i of the Delassus matrix, rows 0..nefc (contiguous in its column-major storage).
fn delassus_column(data: &Data, i: usize) -> &[f64] {
    let stride = data.exact.delassus.nrows();
    &data.exact.delassus.as_slice()[i * stride..i * stride + data.nefc]
}

/// Σ_j A_ji x_j over the rows (down column i: contiguous; the same sum, in the same order, as
/// the indexed form).
fn column_dot(data: &Data, i: usize, x: &[f64]) -> f64 {
    delassus_column(data, i).iter().zip(x).map(|(a, x)| a * x).sum()
}

/// Sets λ of rows i..i+len to 0; returns the change (times A_ii).
fn set_zero(data: &mut Data, i: usize, len: usize) -> f64 {
    let mut change = 0.0f64;
    for k in i..i + len {
        change = change.max((data.exact.rhs[k] * data.exact.delassus[(k, k)]).abs());
        data.exact.rhs[k] = 0.0;
    }
    change
}

/// Whether limit/contact row i moves away from its bound (acceleration level only).
fn separating(data: &Data, i: usize, level: Level) -> bool {
    level == Level::Acceleration && !data.rows_frozen() && data.efc_vel[i] > SEPARATING_VELOCITY
}

/// The lower bound of a limit or contact normal force: 0, or none for a row still pressing at the
/// velocity projection (`efc_pressing`: its velocity is held at 0, as a bilateral row's).
fn normal_lower_bound(data: &Data, i: usize) -> f64 {
    if data.exact.pressing[i] {
        f64::NEG_INFINITY
    } else {
        0.0
    }
}

/// λ_i ← clamp(λ_i − w_i / A_ii, lo, hi); returns |Δλ_i| A_ii.
fn scalar_update(data: &mut Data, i: usize, lo: f64, hi: f64) -> f64 {
    let a = data.exact.delassus[(i, i)];
    if a <= data.exact.a_floor {
        return set_zero(data, i, 1);
    }
    let old = data.exact.rhs[i];
    let new = (old - row_w(data, i) / a).clamp(lo, hi);
    data.exact.rhs[i] = new;
    ((new - old) * a).abs()
}

/// The equality rows 0..ne solved together with the other rows fixed (minimum-norm when
/// redundant); returns the largest |Δλ_i| A_ii.
fn equality_block(data: &mut Data, ne: usize) -> f64 {
    let n = data.nefc;
    let Data {
        efc_force,
        exact:
            ExactWork {
                delassus: efc_delassus,
                sub: efc_sub,
                sub_rhs: efc_sub_rhs,
                rhs: efc_rhs,
                factor: efc_factor,
                eig: efc_eig,
                ..
            },
        ..
    } = data;
    for i in 0..ne {
        efc_sub_rhs[i] = efc_force[i] - (ne..n).map(|j| efc_delassus[(i, j)] * efc_rhs[j]).sum::<f64>();
        for j in 0..ne {
            efc_sub[(i, j)] = efc_delassus[(i, j)];
        }
    }
    data.efc_rank = solve_psd(efc_sub, &mut efc_sub_rhs.as_mut_slice()[..ne], efc_factor, efc_eig);
    let mut change = 0.0f64;
    for i in 0..ne {
        change =
            change.max(((data.exact.sub_rhs[i] - data.exact.rhs[i]) * data.exact.delassus[(i, i)]).abs());
        data.exact.rhs[i] = data.exact.sub_rhs[i];
    }
    change
}

/// A dof's friction loss row i.
fn friction_dof(model: &Model, data: &mut Data, i: usize, level: Level) -> f64 {
    let dof = data.efc_id[i];
    let loss = model.joint_of(model.dof_body[dof]).friction;
    if let Level::Velocity { dt } = level {
        let spent = dt * data.exact.previous[i];
        return scalar_update(data, i, -loss * dt - spent, loss * dt - spent);
    }
    let speed = data.efc_vel[i];
    if speed.abs() > SLIP_VELOCITY && !data.efc_frozen_at_rest(i) {
        let a = data.exact.delassus[(i, i)];
        let new = -loss * speed.signum();
        let change = ((new - data.exact.rhs[i]) * a).abs();
        data.exact.rhs[i] = new;
        change
    } else {
        scalar_update(data, i, -loss, loss)
    }
}

/// Friction coefficient of friction row `k` (1-based within the contact: 1, 2 sliding, 3
/// torsional, 4, 5 rolling) from MuJoCo's 5-vector.
fn mu(friction: &[f64; 5], k: usize) -> f64 {
    friction[k - 1]
}

/// A sweep that changes the motion by less than this (m/s², rad/s², or m/s, rad/s at the velocity
/// level) has converged whatever the scale: round-off of motions at rest.
const ROUND_OFF_FLOOR: f64 = 1e-15;
/// A Delassus diagonal at most this fraction of the largest is round-off (see `efc_a_floor`).
const DIAGONAL_ROUNDOFF: f64 = 1e-12;
/// A constraint correction M⁻¹Jᵀλ this many times larger than the first sweep's (or the motion
/// scale) has diverged.
const DIVERGED: f64 = 1e8;

/// Sweeps after which the active set of the iterate is tried as an exact solve ([`polish`]).
const POLISH_AFTER: u32 = 8;

/// Fixed-point rounds of a polish with slipping contacts (their friction from the new normal
/// forces) before it is abandoned.
const POLISH_ROUNDS: u32 = 30;

/// Multiply-adds one iterative solve may spend (sweeps × (n² + n·nv)) before it stops unconverged.
const WORK_BUDGET: f64 = 2e7;
/// Sweeps every solve may take whatever its size.
const MIN_SWEEPS: u32 = 50;

/// Largest contact dimension (condim 6).
const MAX_DIM: usize = 6;

/// A frictional contact's block: rows i (normal) .. i+len (friction).
fn contact_block(data: &mut Data, i: usize, len: usize, level: Level) -> f64 {
    if separating(data, i, level) || data.exact.delassus[(i, i)] <= data.exact.a_floor {
        return set_zero(data, i, len);
    }
    let mut change = scalar_update(data, i, normal_lower_bound(data, i), f64::INFINITY);
    // The cone's radius and, at the velocity level, the friction impulse the step already
    // applied (the cone is then solved for the step's total friction impulse).
    let (lambda_n, spent) = cone_of(data, i, len, level);
    let friction = data.contacts[data.efc_id[i]].friction;
    let nf = len - 1;
    let mut new = [0.0; MAX_DIM];
    if lambda_n > 0.0 {
        let slip: f64 = (1..len).map(|k| data.efc_vel[i + k].powi(2)).sum::<f64>().sqrt();
        let sliding = level == Level::Acceleration && slip > SLIP_VELOCITY && !data.efc_frozen_at_rest(i);
        if sliding && !data.efc_safe_friction {
            // Maximal dissipation against the slip velocity u.
            max_dissipation(lambda_n, &friction, &data.efc_vel.as_slice()[i + 1..i + len], &mut new[..nf]);
        } else {
            let nu = cone_solve(data, i, len, &friction, lambda_n, &spent[..nf], &mut new[..nf]);
            data.exact.nu[i] = nu;
        }
    }
    for k in 1..len {
        let r = i + k;
        change = change.max(((new[k - 1] - data.exact.rhs[r]) * data.exact.delassus[(r, r)]).abs());
        data.exact.rhs[r] = new[k - 1];
    }
    change
}

/// The friction of maximal dissipation against `slip` (the friction rows' velocities or
/// accelerations) on the elliptic cone of radius `lambda_n`: λ_k = −λ_n μ_k² s_k / ‖μ ∘ s‖.
fn max_dissipation(lambda_n: f64, friction: &[f64; 5], slip: &[f64], out: &mut [f64]) {
    let norm = slip.iter().enumerate().map(|(k, s)| (mu(friction, k + 1) * s).powi(2)).sum::<f64>().sqrt();
    for (k, o) in out.iter_mut().enumerate() {
        let m = mu(friction, k + 1);
        *o = if norm > 0.0 { -lambda_n * m * m * slip[k] / norm } else { 0.0 };
    }
}

/// The friction forces `out` of the contact block at row i minimising ½ λᵀ A_ff λ − gᵀ λ with
/// λ + `spent` in the elliptic cone of radius `lambda_n` (`spent` = 0 at the acceleration level),
/// g = b_f − A_f,· λ without the block's own friction. Returns the shift ν of the secular equation
/// (0 when the stick solve lies inside the cone).
#[allow(clippy::too_many_arguments)]
fn cone_solve(
    data: &Data,
    i: usize,
    len: usize,
    friction: &[f64; 5],
    lambda_n: f64,
    spent: &[f64],
    out: &mut [f64],
) -> f64 {
    let n = data.nefc;
    // Scaled problem in y_k = λ_k / μ_k over the friction rows with μ_k > 0.
    let mut idx = [0usize; MAX_DIM];
    let mut m = 0;
    for k in 1..len {
        if mu(friction, k) > 0.0 && data.exact.delassus[(i + k, i + k)] > data.exact.a_floor {
            idx[m] = k;
            m += 1;
        }
    }
    out.fill(0.0);
    if m == 0 {
        return 0.0;
    }
    let mut a = [[0.0; MAX_DIM]; MAX_DIM];
    let mut g = [0.0; MAX_DIM];
    for p in 0..m {
        let rp = i + idx[p];
        let mp = mu(friction, idx[p]);
        // Column rp of the symmetric A (contiguous): A_{rp,j} = A_{j,rp} to the bit.
        let col = delassus_column(data, rp);
        let own: f64 = (1..len).map(|k| col[i + k] * data.exact.rhs[i + k]).sum();
        let w_other: f64 = column_dot(data, rp, &data.exact.rhs.as_slice()[..n]) - own;
        let shift: f64 = (1..len).map(|k| col[i + k] * spent[k - 1]).sum();
        g[p] = mp * (data.efc_force[rp] - w_other + shift);
        for q in 0..m {
            a[p][q] = mp * mu(friction, idx[q]) * col[i + idx[q]];
        }
    }
    let mut y = [0.0; MAX_DIM];
    let trace: f64 = (0..m).map(|p| a[p][p]).sum();
    let regular = shifted_solve(&a, m, 0.0, &g, &mut y, None);
    let inside = regular && (0..m).map(|p| y[p] * y[p]).sum::<f64>().sqrt() <= lambda_n;
    let mut nu = 0.0;
    if !inside {
        // Newton on 1/R − 1/‖y(ν)‖ = 0, ν ≥ 0 (monotone from below; from above, the first step
        // lands below the root, or at 0), started from this contact's ν of the last sweep
        // (`exact.nu`): a converging iteration changes the block's problem little.
        let warm = data.exact.nu[i];
        nu = if warm > 0.0 && warm.is_finite() {
            warm
        } else if regular {
            0.0
        } else {
            1e-14 * trace
        };
        let mut z = [0.0; MAX_DIM];
        for _ in 0..60 {
            if !shifted_solve(&a, m, nu, &g, &mut y, Some(&mut z)) {
                nu = nu.max(1e-14 * trace) * 2.0;
                continue;
            }
            let ny = (0..m).map(|p| y[p] * y[p]).sum::<f64>().sqrt();
            let nz2: f64 = (0..m).map(|p| z[p] * z[p]).sum();
            if ny == 0.0 || (ny - lambda_n).abs() <= 1e-15 * lambda_n || nz2 == 0.0 {
                break;
            }
            let step = (ny * ny / nz2) * (ny - lambda_n) / lambda_n;
            nu = (nu + step).max(0.0);
            if step.abs() <= 1e-16 * nu.max(trace) {
                break;
            }
        }
        // Onto the cone's boundary exactly (round-off of the secular solve).
        let ny = (0..m).map(|p| y[p] * y[p]).sum::<f64>().sqrt();
        if ny > lambda_n {
            for v in y.iter_mut().take(m) {
                *v *= lambda_n / ny;
            }
        }
    }
    for p in 0..m {
        out[idx[p] - 1] = mu(friction, idx[p]) * y[p];
    }
    for (o, s) in out.iter_mut().zip(spent) {
        *o -= s;
    }
    nu
}

/// Solves (A + νI) y = g (m × m, symmetric) by Cholesky; with `z`, also z = L⁻¹ y. False if the
/// shifted matrix is not positive definite.
fn shifted_solve(
    a: &[[f64; MAX_DIM]; MAX_DIM],
    m: usize,
    nu: f64,
    g: &[f64; MAX_DIM],
    y: &mut [f64; MAX_DIM],
    z: Option<&mut [f64; MAX_DIM]>,
) -> bool {
    let mut l = [[0.0; MAX_DIM]; MAX_DIM];
    let scale = (0..m).map(|p| a[p][p]).fold(0.0, f64::max) + nu;
    for j in 0..m {
        let mut d = a[j][j] + nu;
        for k in 0..j {
            d -= l[j][k] * l[j][k];
        }
        if d <= 1e-14 * scale {
            return false;
        }
        let d = d.sqrt();
        l[j][j] = d;
        for p in j + 1..m {
            let mut s = a[p][j];
            for k in 0..j {
                s -= l[p][k] * l[j][k];
            }
            l[p][j] = s / d;
        }
    }
    // L x = g, then Lᵀ y = x.
    let mut x = [0.0; MAX_DIM];
    for p in 0..m {
        let s: f64 = (0..p).map(|k| l[p][k] * x[k]).sum();
        x[p] = (g[p] - s) / l[p][p];
    }
    for p in (0..m).rev() {
        let s: f64 = (p + 1..m).map(|k| l[k][p] * y[k]).sum();
        y[p] = (x[p] - s) / l[p][p];
    }
    if let Some(z) = z {
        for p in 0..m {
            let s: f64 = (0..p).map(|k| l[p][k] * z[k]).sum();
            z[p] = (y[p] - s) / l[p][p];
        }
    }
    true
}

/// The exact solve of the active set the Gauss–Seidel iterate has found (the "polish" of
/// active-set methods, Cottle, Pang & Stone §4): equality rows, normals carrying force, sticking
/// friction rows and friction-loss rows inside their bounds have w = 0; every other row keeps its
/// force (0, a friction-loss bound, a sliding friction). The reduced symmetric system is solved
/// exactly (minimum-norm for redundant rows); the result is kept only if every row's law holds
/// (λ_n ≥ 0, w ≥ 0 off contact, friction inside its cone or box, w opposing a friction at its
/// bound). A contact whose friction is on its cone's boundary makes the system unsymmetric: then
/// there is no polish and the iteration goes on.
pub(crate) fn polish(model: &Model, data: &mut Data, level: Level) -> bool {
    let n = data.nefc;
    const TOL: f64 = 1e-9;
    let mut i = 0;
    let mut any_sliding = false;
    data.exact.active.clear();
    data.exact.slipping[..n].fill(false);
    // Classify rows: Free rows go into efc_active; every other row keeps its force.
    while i < n {
        let len = data.efc_block_len(i);
        match data.efc_type[i] {
            EfcType::Equality | EfcType::FrictionTendon => data.exact.active.push(i),
            EfcType::LimitJoint
            | EfcType::LimitTendon
            | EfcType::ContactFrictionless
            | EfcType::ContactPyramidal => {
                if data.exact.rhs[i] > 0.0 || data.exact.pressing[i] {
                    data.exact.active.push(i);
                }
            }
            EfcType::FrictionDof => {
                let (lo, hi) = friction_dof_bounds(model, data, i, level);
                let l = data.exact.rhs[i];
                let sliding = level == Level::Acceleration
                    && data.efc_vel[i].abs() > SLIP_VELOCITY
                    && !data.efc_frozen_at_rest(i);
                if !sliding && l > lo + TOL * (hi - lo).abs() && l < hi - TOL * (hi - lo).abs() {
                    data.exact.active.push(i);
                }
            }
            EfcType::ContactElliptic => {
                if data.exact.rhs[i] > 0.0 || data.exact.pressing[i] {
                    data.exact.active.push(i);
                    let friction = data.contacts[data.efc_id[i]].friction;
                    let (radius, spent) = cone_of(data, i, len, level);
                    let sliding = level == Level::Acceleration
                        && (1..len).any(|k| data.efc_vel[i + k].abs() > SLIP_VELOCITY)
                        && !data.efc_frozen_at_rest(i);
                    let y2: f64 = (1..len)
                        .filter(|&k| mu(&friction, k) > 0.0)
                        .map(|k| ((data.exact.rhs[i + k] + spent[k - 1]) / mu(&friction, k)).powi(2))
                        .sum();
                    if sliding {
                        // Friction fixed by the slip: c · λ_n, updated in the rounds below.
                        data.exact.slipping[i] = true;
                        any_sliding = true;
                        i += len;
                        continue;
                    }
                    if y2.sqrt() >= radius * (1.0 - TOL) && radius > 0.0 {
                        // Starting to slip: friction on the cone, opposing the slip acceleration
                        // (at the velocity level, the post-step slip velocity).
                        data.exact.slipping[i] = true;
                        any_sliding = true;
                        i += len;
                        continue;
                    }
                    for k in 1..len {
                        if mu(&friction, k) > 0.0 {
                            data.exact.active.push(i + k);
                        }
                    }
                }
            }
        }
        i += len;
    }
    // Reduced system A_FF λ_F = b_F − A_F,X λ_X, the fixed forces λ_X taken from the candidate
    // (efc_lambda_prev; efc_rhs keeps the iterate if the polish fails). A sliding contact's friction
    // is d · λ_n with d = −μ² u / ‖μ ∘ u‖ from its slip u, substituted into the system (then not
    // symmetric: LU, [`solve_substituted`]); a contact moving at the acceleration level has its
    // slip fixed, so one solve is exact; for one starting to slip, u is the slip acceleration of
    // the solution and rounds update d until it settles. Friction-loss rows kept at a bound are
    // set exactly on it.
    let k = data.exact.active.len();
    if k == 0 {
        return false;
    }
    // Larger systems keep the symmetric rounds, and give up at the velocity level: the LU with
    // complete pivoting, and Newton's repeated ones, cost several times the Cholesky there
    // (bin_50 2.3× slower with them).
    let substitute = k <= SUBSTITUTE_MAX;
    if any_sliding && !substitute && level != Level::Acceleration {
        return false;
    }
    data.exact.in_active[..n].fill(false);
    for a in 0..k {
        let r = data.exact.active[a];
        data.exact.in_active[r] = true;
    }
    for j in 0..n {
        data.exact.lambda_prev[j] = data.exact.rhs[j];
    }
    snap_friction_dof_bounds(model, data, level);
    let mut last_change = f64::INFINITY;
    for round in 0..POLISH_ROUNDS {
        // Slipping contacts: their friction, direction times the cone's radius, substituted into
        // the normal's column (one non-symmetric solve); the symmetric solve with their friction
        // fixed at the candidate's when that system is inconsistent.
        if any_sliding && substitute {
            slip_directions(data, level);
            if solve_substituted(data, level) {
                let change = update_sliding_friction(data, level);
                let scale = 1.0 + (0..n).map(|j| data.exact.lambda_prev[j].abs()).fold(0.0, f64::max);
                if change <= 1e-15 * scale {
                    break;
                }
                // The slip directions moved with the solution (a contact starting to slip, or
                // slipping after the step): Newton on the whole system, directions included
                // (fixed-point rounds on them diverge near sticking, measured on go1).
                if newton_slipping(data, level) {
                    break;
                }
                return false;
            }
        }
        let Data {
            efc_force,
            exact:
                ExactWork {
                    delassus: efc_delassus,
                    sub: efc_sub,
                    sub_rhs: efc_sub_rhs,
                    active: efc_active,
                    in_active,
                    lambda_prev: efc_lambda_prev,
                    factor: efc_factor,
                    eig: efc_eig,
                    ..
                },
            ..
        } = &mut *data;
        for (a, &r) in efc_active.iter().enumerate() {
            let mut rhs = efc_force[r];
            for j in 0..n {
                if !in_active[j] {
                    rhs -= efc_delassus[(j, r)] * efc_lambda_prev[j];
                }
            }
            efc_sub_rhs[a] = rhs;
            for (c, &q) in efc_active.iter().enumerate() {
                efc_sub[(a, c)] = efc_delassus[(q, r)];
            }
        }
        solve_psd(efc_sub, &mut efc_sub_rhs.as_mut_slice()[..k], efc_factor, efc_eig);
        for (a, &r) in efc_active.iter().enumerate() {
            efc_lambda_prev[r] = efc_sub_rhs[a];
        }
        if !any_sliding {
            break;
        }
        let change = update_sliding_friction(data, level);
        let scale = 1.0 + (0..n).map(|j| data.exact.lambda_prev[j].abs()).fold(0.0, f64::max);
        if change <= 1e-15 * scale {
            break;
        }
        if round == POLISH_ROUNDS - 1 {
            return false;
        }
        // Rounds left at this round's rate of contraction: a fixed point the remaining rounds
        // cannot reach (or a round that did not contract) is abandoned now rather than at the
        // last round (the iteration goes on either way).
        let rate = change / last_change;
        if round > 0 {
            let needed = (1e-15 * scale / change).ln() / rate.ln();
            if rate >= 1.0 || needed.is_nan() || needed > f64::from(POLISH_ROUNDS - 1 - round) {
                return false;
            }
        }
        last_change = change;
    }
    // Verify every row's law with w = A λ − b.
    let scale = 1.0 + (0..n).map(|j| data.efc_force[j].abs()).fold(0.0, f64::max);
    let w = |data: &Data, r: usize| -> f64 {
        (0..n).map(|j| data.exact.delassus[(j, r)] * data.exact.lambda_prev[j]).sum::<f64>()
            - data.efc_force[r]
    };
    let force_scale = 1.0 + (0..n).map(|j| data.exact.lambda_prev[j].abs()).fold(0.0, f64::max);
    let mut i = 0;
    while i < n {
        let len = data.efc_block_len(i);
        let l = data.exact.lambda_prev[i];
        let ok = match data.efc_type[i] {
            EfcType::Equality | EfcType::FrictionTendon => true,
            EfcType::LimitJoint
            | EfcType::LimitTendon
            | EfcType::ContactFrictionless
            | EfcType::ContactElliptic
            | EfcType::ContactPyramidal => {
                let free = data.exact.in_active[i];
                let normal_ok = if data.exact.pressing[i] {
                    true
                } else if free {
                    l >= -1e-12 * force_scale
                } else {
                    separating(data, i, level) || w(data, i) >= -1e-12 * scale
                };
                normal_ok
                    && (data.efc_type[i] != EfcType::ContactElliptic || !free || {
                        let friction = data.contacts[data.efc_id[i]].friction;
                        let (_, spent) = cone_of(data, i, len, level);
                        let radius = match level {
                            Level::Acceleration => l,
                            Level::Velocity { dt } => l.max(0.0) + dt * data.exact.previous[i].max(0.0),
                        };
                        let y2: f64 = (1..len)
                            .filter(|&k| mu(&friction, k) > 0.0)
                            .map(|k| {
                                ((data.exact.lambda_prev[i + k] + spent[k - 1]) / mu(&friction, k)).powi(2)
                            })
                            .sum();
                        y2.sqrt() <= radius * (1.0 + 1e-12) + 1e-12 * force_scale
                    })
                    && (!data.exact.slipping[i] || slip_opposed(data, i, len, level, force_scale))
            }
            EfcType::FrictionDof => {
                let (lo, hi) = friction_dof_bounds(model, data, i, level);
                let slack = 1e-12 * force_scale;
                if data.exact.in_active[i] {
                    l >= lo - slack && l <= hi + slack
                } else {
                    let wi = w(data, i);
                    // At the upper bound the dof must be accelerating the other way, and back.
                    (l >= hi - slack && wi <= 1e-12 * scale) || (l <= lo + slack && wi >= -1e-12 * scale) || {
                        level == Level::Acceleration && data.efc_vel[i].abs() > SLIP_VELOCITY
                    }
                }
            }
        };
        if !ok {
            return false;
        }
        i += len;
    }
    for j in 0..n {
        data.exact.rhs[j] = data.exact.lambda_prev[j];
    }
    true
}

/// Sets each slipping contact's friction rows in the candidate (`efc_lambda_prev`) to the
/// maximal-dissipation force of its slip (velocity, or acceleration for a contact starting to
/// slip; the post-step velocity at the velocity level) for the candidate's cone radius; returns
/// the largest change.
fn update_sliding_friction(data: &mut Data, level: Level) -> f64 {
    let n = data.nefc;
    let mut change = 0.0f64;
    let mut i = 0;
    while i < n {
        let len = data.efc_block_len(i);
        if data.exact.slipping[i] {
            let friction = data.contacts[data.efc_id[i]].friction;
            let (radius, spent) = candidate_cone(data, i, len, level);
            let mut slip = [0.0; MAX_DIM];
            slip_of(data, i, len, level, &mut slip);
            let mut new = [0.0; MAX_DIM];
            max_dissipation(radius, &friction, &slip[..len - 1], &mut new[..len - 1]);
            for k in 1..len {
                let f = new[k - 1] - spent[k - 1];
                change = change.max((f - data.exact.lambda_prev[i + k]).abs());
                data.exact.lambda_prev[i + k] = f;
            }
        }
        i += len;
    }
    change
}

/// The slip of slipping contact i in the polish: its velocity when it moves (acceleration level),
/// else its friction rows' w = A λ − b of the candidate (the slip acceleration, or at the
/// velocity level the post-step slip velocity).
fn slip_of(data: &Data, i: usize, len: usize, level: Level, slip: &mut [f64; MAX_DIM]) {
    let n = data.nefc;
    let moving = level == Level::Acceleration
        && (1..len).any(|k| data.efc_vel[i + k].abs() > SLIP_VELOCITY)
        && !data.efc_frozen_at_rest(i);
    for k in 1..len {
        slip[k - 1] = if moving {
            data.efc_vel[i + k]
        } else {
            (0..n).map(|j| data.exact.delassus[(j, i + k)] * data.exact.lambda_prev[j]).sum::<f64>()
                - data.efc_force[i + k]
        };
    }
}

/// The cone of slipping contact i for the candidate's normal force: its radius and the friction
/// the step already spent (velocity level; zero at the acceleration level).
fn candidate_cone(data: &Data, i: usize, len: usize, level: Level) -> (f64, [f64; MAX_DIM]) {
    let mut spent = [0.0; MAX_DIM];
    let l = data.exact.lambda_prev[i].max(0.0);
    let radius = match level {
        Level::Acceleration => l,
        Level::Velocity { dt } => {
            for k in 1..len {
                spent[k - 1] = dt * data.exact.previous[i + k];
            }
            l + dt * data.exact.previous[i].max(0.0)
        }
    };
    (radius, spent)
}

/// Each slipping contact's friction per unit cone radius, −μ_k² u_k / ‖μ ∘ u‖ from the
/// candidate's slip u, into `exact.slip_dir` at its friction rows.
fn slip_directions(data: &mut Data, level: Level) {
    let n = data.nefc;
    let mut i = 0;
    while i < n {
        let len = data.efc_block_len(i);
        if data.exact.slipping[i] {
            let friction = data.contacts[data.efc_id[i]].friction;
            let mut slip = [0.0; MAX_DIM];
            slip_of(data, i, len, level, &mut slip);
            let mut dir = [0.0; MAX_DIM];
            max_dissipation(1.0, &friction, &slip[..len - 1], &mut dir[..len - 1]);
            for k in 1..len {
                data.exact.slip_dir[i + k] = dir[k - 1];
            }
        }
        i += len;
    }
}

/// The polish's reduced system with each slipping contact's friction λ_f = d (λ_n + c) − s
/// substituted (d from [`slip_directions`]; c the normal impulse the step already spent and s
/// its friction, velocity level; both 0 at the acceleration level): the rows of `exact.active`
/// solved by LU, the candidate's free rows and slipping friction rows set. False (the candidate
/// untouched) when the system is singular.
fn solve_substituted(data: &mut Data, level: Level) -> bool {
    let n = data.nefc;
    let k = data.exact.active.len();
    let Data { efc_force, efc_type, efc_id, exact, .. } = &mut *data;
    let ExactWork {
        delassus,
        sub,
        sub_rhs,
        active,
        in_active,
        lambda_prev,
        slipping,
        slip_dir,
        previous,
        pivots,
        ..
    } = exact;
    // Per row: whether it is a friction row of a slipping contact (its force substituted).
    // Rows per block, as `Data::efc_block_len`.
    let block = |i: usize| {
        if efc_type[i] != EfcType::ContactElliptic {
            return 1;
        }
        (i + 1..n).take_while(|&q| efc_type[q] == efc_type[i] && efc_id[q] == efc_id[i]).count() + 1
    };
    let dt = match level {
        Level::Acceleration => 0.0,
        Level::Velocity { dt } => dt,
    };
    for (a, &r) in active.iter().enumerate() {
        let mut rhs = efc_force[r];
        for c in 0..k {
            sub[(a, c)] = delassus[(active[c], r)];
        }
        let mut j = 0;
        while j < n {
            let len = block(j);
            if efc_type[j] == EfcType::ContactElliptic && slipping[j] {
                let c0 = dt * previous[j].max(0.0);
                let mut coupling = 0.0;
                for q in 1..len {
                    let arf = delassus[(j + q, r)];
                    coupling += arf * slip_dir[j + q];
                    rhs -= arf * (slip_dir[j + q] * c0 - dt * previous[j + q]);
                }
                let col = active.iter().position(|&x| x == j).expect("a slipping contact's normal is active");
                sub[(a, col)] += coupling;
            } else {
                for q in j..j + len {
                    if !in_active[q] {
                        rhs -= delassus[(q, r)] * lambda_prev[q];
                    }
                }
            }
            j += len;
        }
        sub_rhs[a] = rhs;
    }
    if !lu_solve(sub, &mut sub_rhs.as_mut_slice()[..k], &mut pivots[..2 * k]) {
        return false;
    }
    for (a, &r) in active.iter().enumerate() {
        lambda_prev[r] = sub_rhs[a];
    }
    let mut j = 0;
    while j < n {
        let len = block(j);
        if efc_type[j] == EfcType::ContactElliptic && slipping[j] {
            let c0 = dt * previous[j].max(0.0);
            for q in 1..len {
                lambda_prev[j + q] = slip_dir[j + q] * (lambda_prev[j] + c0) - dt * previous[j + q];
            }
        }
        j += len;
    }
    true
}

/// Whether slipping contact i's friction in the candidate opposes its slip: the cone's radius
/// λ_n + c (c the normal impulse the step already spent, velocity level) is not negative and
/// the whole friction (λ_f + the friction already spent) does no positive work on the slip u.
fn slip_opposed(data: &Data, i: usize, len: usize, level: Level, force_scale: f64) -> bool {
    let (c0, dt) = match level {
        Level::Acceleration => (0.0, 0.0),
        Level::Velocity { dt } => (dt * data.exact.previous[i].max(0.0), dt),
    };
    let mut u = [0.0; MAX_DIM];
    slip_of(data, i, len, level, &mut u);
    let norm = (1..len).map(|k| u[k - 1] * u[k - 1]).sum::<f64>().sqrt();
    let work: f64 =
        (1..len).map(|k| (data.exact.lambda_prev[i + k] + dt * data.exact.previous[i + k]) * u[k - 1]).sum();
    data.exact.lambda_prev[i] + c0 >= -1e-12 * force_scale && work <= 1e-12 * force_scale * norm
}

/// The largest reduced system (rows) whose slipping contacts the polish substitutes
/// ([`solve_substituted`], [`newton_slipping`]).
const SUBSTITUTE_MAX: usize = 64;

/// Newton iterations of [`newton_slipping`] before it gives up.
const NEWTON_ITERATIONS: u32 = 12;

/// The polish's system with its slipping contacts solved by Newton's method (the semismooth
/// Newton of the active set, e.g. Acary & Brogliato §13.4, on the maximal-dissipation law): the
/// unknowns are the active rows' forces, with w_r = (A λ − b)_r = 0, and the slipping contacts'
/// friction, with λ_f + s = R(λ_n) φ(u), φ_k(u) = −μ_k² u_k / ‖μ ∘ u‖, u the slip (the rows' w,
/// or their velocity for a contact moving at the acceleration level), R = λ_n + c and s the
/// normal and friction impulses the step already spent (velocity level; 0 at the acceleration
/// level). Each iteration solves the Jacobian system by LU; the other rows keep the candidate's
/// forces (`exact.lambda_prev`, updated). True when the residual reaches round-off.
fn newton_slipping(data: &mut Data, level: Level) -> bool {
    let n = data.nefc;
    let dt = match level {
        Level::Acceleration => 0.0,
        Level::Velocity { dt } => dt,
    };
    // The unknowns.
    {
        let ExactWork { active, newton_rows, newton_normal, .. } = &mut data.exact;
        newton_rows.clear();
        newton_normal.clear();
        for &r in active.iter() {
            newton_rows.push(r);
            newton_normal.push(usize::MAX);
        }
    }
    let mut i = 0;
    while i < n {
        let len = data.efc_block_len(i);
        if data.exact.slipping[i] {
            for k in 1..len {
                data.exact.newton_rows.push(i + k);
                data.exact.newton_normal.push(i);
            }
        }
        i += len;
    }
    let m = data.exact.newton_rows.len();
    data.exact.newton_pos[..n].fill(usize::MAX);
    for c in 0..m {
        let r = data.exact.newton_rows[c];
        data.exact.newton_pos[r] = c;
    }
    let b_scale = 1.0 + (0..n).map(|j| data.efc_force[j].abs()).fold(0.0, f64::max);
    let mut last_worst = f64::INFINITY;
    for _ in 0..NEWTON_ITERATIONS {
        let l_scale = 1.0 + (0..n).map(|j| data.exact.lambda_prev[j].abs()).fold(0.0, f64::max);
        let mut worst = 0.0f64;
        for a in 0..m {
            let r = data.exact.newton_rows[a];
            let s = data.exact.newton_normal[a];
            if s == usize::MAX {
                // An active row: w_r = 0.
                let w = column_dot(data, r, &data.exact.lambda_prev.as_slice()[..n]) - data.efc_force[r];
                for c in 0..m {
                    let q = data.exact.newton_rows[c];
                    data.exact.sub[(a, c)] = data.exact.delassus[(q, r)];
                }
                data.exact.sub_rhs[a] = -w;
                worst = worst.max(w.abs() / b_scale);
                continue;
            }
            // A friction row k of slipping contact s.
            let len = data.efc_block_len(s);
            let k = r - s;
            let friction = data.contacts[data.efc_id[s]].friction;
            let moving = level == Level::Acceleration
                && (1..len).any(|q| data.efc_vel[s + q].abs() > SLIP_VELOCITY)
                && !data.efc_frozen_at_rest(s);
            let mut u = [0.0; MAX_DIM];
            slip_of(data, s, len, level, &mut u);
            let norm = (1..len).map(|q| (mu(&friction, q) * u[q - 1]).powi(2)).sum::<f64>().sqrt();
            if !(norm > 0.0 && norm.is_finite()) {
                return false;
            }
            let mk2 = mu(&friction, k).powi(2);
            let phi = -mk2 * u[k - 1] / norm;
            let c0 = dt * data.exact.previous[s].max(0.0);
            let spent = dt * data.exact.previous[r];
            let radius = data.exact.lambda_prev[s] + c0;
            let f = data.exact.lambda_prev[r] + spent - radius * phi;
            worst = worst.max(f.abs() / l_scale);
            data.exact.sub_rhs[a] = -f;
            for c in 0..m {
                data.exact.sub[(a, c)] = 0.0;
            }
            data.exact.sub[(a, a)] = 1.0;
            let cs = data.exact.newton_pos[s];
            data.exact.sub[(a, cs)] -= phi;
            if !moving {
                // −R Σ_l ∂φ_k/∂u_l ∂u_l/∂λ, ∂u_l/∂λ_j = A_(s+l) j.
                for l in 1..len {
                    let ml2 = mu(&friction, l).powi(2);
                    let dphi = -mk2
                        * ((if l == k { 1.0 } else { 0.0 }) / norm
                            - u[k - 1] * ml2 * u[l - 1] / norm.powi(3));
                    if dphi == 0.0 {
                        continue;
                    }
                    for c in 0..m {
                        let q = data.exact.newton_rows[c];
                        let v = data.exact.delassus[(q, s + l)];
                        data.exact.sub[(a, c)] -= radius * dphi * v;
                    }
                }
            }
        }
        if worst <= 1e-14 {
            return true;
        }
        // Near a solution Newton's residual falls fast; one that does not is in the wrong
        // active set (the Gauss–Seidel iteration goes on).
        if worst > 0.9 * last_worst {
            return false;
        }
        last_worst = worst;
        let ExactWork { sub, sub_rhs, pivots, newton_rows, lambda_prev, .. } = &mut data.exact;
        if !lu_solve(sub, &mut sub_rhs.as_mut_slice()[..m], &mut pivots[..2 * m]) {
            return false;
        }
        for c in 0..m {
            lambda_prev[newton_rows[c]] += sub_rhs[c];
        }
    }
    false
}

/// Friction-loss rows the polish keeps at a bound (not in `exact.active`, not sliding) exactly at
/// that bound in the candidate: the iterate reaches it only to within the classification's
/// tolerance.
fn snap_friction_dof_bounds(model: &Model, data: &mut Data, level: Level) {
    for i in 0..data.nefc {
        if data.efc_type[i] != EfcType::FrictionDof || data.exact.in_active[i] {
            continue;
        }
        let sliding = level == Level::Acceleration
            && data.efc_vel[i].abs() > SLIP_VELOCITY
            && !data.efc_frozen_at_rest(i);
        if sliding {
            continue;
        }
        let (lo, hi) = friction_dof_bounds(model, data, i, level);
        let l = data.exact.lambda_prev[i];
        data.exact.lambda_prev[i] = if (l - lo).abs() <= (l - hi).abs() { lo } else { hi };
    }
}

/// The box of a friction-loss row's force: ±f at the acceleration level; at the velocity level
/// the step's remaining impulse, ±f dt less what the step already applied.
fn friction_dof_bounds(model: &Model, data: &Data, i: usize, level: Level) -> (f64, f64) {
    let dof = data.efc_id[i];
    let loss = model.joint_of(model.dof_body[dof]).friction;
    match level {
        Level::Acceleration => (-loss, loss),
        Level::Velocity { dt } => {
            let spent = dt * data.exact.previous[i];
            (-loss * dt - spent, loss * dt - spent)
        }
    }
}

/// A contact block's cone radius for the current normal force, and the friction already spent
/// (velocity level).
fn cone_of(data: &Data, i: usize, len: usize, level: Level) -> (f64, [f64; MAX_DIM]) {
    let mut spent = [0.0; MAX_DIM];
    let radius = match level {
        Level::Acceleration => data.exact.rhs[i],
        Level::Velocity { dt } => {
            for k in 1..len {
                spent[k - 1] = dt * data.exact.previous[i + k];
            }
            data.exact.rhs[i].max(0.0) + dt * data.exact.previous[i].max(0.0)
        }
    };
    (radius, spent)
}
