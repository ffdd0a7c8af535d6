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
//! were measured a worse start: humanoid +18 % instructions, go1 ±1 %). When that previous solve
//! ended with an exact solve of its active set, no contact slips and that solve was the cheaper
//! (`ExactWork::warm_polish_work` against `warm_sweep_work`), the same set is solved exactly
//! first, and the sweeps run only if a law then fails (two boxes at a mass ratio of 100: 8
//! sweeps and a polish per step before, the polish alone after).
//!
//! The polish, the exact solve of the active set the iterate has found, is
//! [`super::coulomb_polish`].

pub(crate) use super::coulomb_polish::polish;
use super::coulomb_polish::{any_contact_moving, cone_of};
use super::dense::solve_psd;
use super::exact::form_minv_jt;
use super::ExactWork;
use crate::dynamics::solve_with_factor_unchecked;
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
    data.exact.polish_set = 0;
    data.exact.polish_work = 0.0;
    let mut change = 0.0;
    let mut iterations = 0;
    data.efc_converged = false;
    data.efc_safe_friction = false;
    // Warm start from an exact solve: the active set of the last solve (sticking, slipping,
    // lifting rows) is most often this one's too — a resting contact keeps it step after step —
    // and its exact solve, accepted only if every row's law holds, ends the solve before any
    // sweep. Tried first when the last such solve cost less than the sweeps of the last
    // warm-started solve that swept (`ExactWork::warm_sweep_work`): a well-conditioned stack
    // converges in a sweep or two, far cheaper than a factorization of its rows; two boxes at a
    // mass ratio of 100 take 8 sweeps and the polish. Only without slipping contacts: the
    // problem is then convex and any active set whose laws hold gives the one motion the sweeps
    // would reach; a slipping contact's law can hold on several sets (go1's feet), and the
    // sweeps decide which. A set that fails is tried again by the sweeps' polish (from their
    // iterate), its cost not counted against their retries.
    let mut polished = warm
        && data.exact.warm_exact
        && data.exact.warm_polish_work < data.exact.warm_sweep_work
        && !any_contact_moving(data, level)
        && polish(model, data, level);
    data.efc_converged = polished;
    let first_polish = data.exact.polish_work;
    data.exact.polish_work = 0.0;
    data.exact.polish_set = 0;
    // Divergence guard: the sliding law (maximal dissipation) makes the problem non-symmetric, and
    // projected Gauss–Seidel can then grow without bound (a violent state: a body deep in the
    // floor, joints beyond their limits, fast slips). The solve then restarts from zero with the
    // symmetric cone projection for every contact; if that diverges too, the rows get no force
    // and the solve counts as unconverged (reported), never NaN.
    let mut first_total = 0.0f64;
    let mut last_polish = 0.0;
    // The smallest sweep change so far, and whether its iterate is the current one (then not
    // copied: it is saved in `exact.best`, from `lambda_prev`, only once a later sweep changes
    // the motion more — in a converging solve, never).
    let mut best_moved = f64::INFINITY;
    let mut best_is_last = false;
    // A sweep costs about n² + n·nv: large problems get fewer sweeps (a work budget), so that a
    // pile of contacts cannot stall a step; a solve stopped early is counted as unconverged.
    let sweep = (n * n + n * model.nv).max(1) as f64;
    let limit = settings.max_iterations.min((WORK_BUDGET / sweep).max(MIN_SWEEPS as f64) as u32);
    while !data.efc_converged && iterations < limit {
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
        let (moved, total) = sweep_motion(model, data, iterations);
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
            best_moved = f64::INFINITY;
            best_is_last = false;
            continue;
        }
        change = moved;
        if moved < best_moved {
            best_moved = moved;
            best_is_last = true;
        } else if best_is_last {
            // The best iterate is the one this sweep started from.
            let ExactWork { lambda_prev, best, .. } = &mut data.exact;
            best.as_mut_slice()[..n].copy_from_slice(&lambda_prev.as_slice()[..n]);
            best_is_last = false;
        }
        if moved <= settings.tolerance * total.max(motion_scale)
            || moved <= ROUND_OFF_FLOOR
            || !moved.is_finite()
        {
            data.efc_converged = moved.is_finite();
            break;
        }
        // Once the iterate has settled which rows stick, slide or lift, solve that active set
        // exactly; accepted only if every row's law then holds. Tried again after 2, 4, 8, …
        // times as many sweeps if the iterate's active set has changed (the polish skips a set
        // it has tried) and the polishes so far have cost less than the sweeps (a failing
        // polish of a large system, its pivots and Newton iterations, costs hundreds of sweeps:
        // bin_10 1.6× the instructions without this bound), and at the last sweep.
        let retry = iterations > POLISH_AFTER
            && iterations.is_power_of_two()
            && data.exact.polish_work <= f64::from(iterations) * sweep;
        if (iterations == POLISH_AFTER || retry || iterations == limit) && !data.efc_safe_friction {
            let before = data.exact.polish_work;
            if polish(model, data, level) {
                data.efc_converged = true;
                polished = true;
                last_polish = data.exact.polish_work - before;
                change = 0.0;
                break;
            }
        }
    }
    if level == Level::Acceleration {
        let exact = &mut data.exact;
        exact.warm_exact = polished;
        if iterations == 0 {
            exact.warm_polish_work = first_polish;
        } else {
            if polished {
                exact.warm_polish_work = last_polish;
            }
            // What the sweeps cost this time (their polishes included), the price a warm start
            // of the same rows pays without the exact solve first; unknown after a cold start.
            exact.warm_sweep_work =
                if warm { f64::from(iterations) * sweep + exact.polish_work } else { 0.0 };
        }
    }
    // An unconverged solve returns its best iterate, not wherever the last sweep swung to.
    if !data.efc_converged && !best_is_last && best_moved < change {
        let ExactWork { rhs, best, .. } = &mut data.exact;
        rhs.as_mut_slice()[..n].copy_from_slice(&best.as_slice()[..n]);
        change = best_moved;
    }
    data.efc_iterations = iterations;
    data.efc_residual = change;
    if !data.efc_converged {
        data.efc_unconverged += 1;
        data.efc_unconverged_residual = data.efc_unconverged_residual.max(change);
    }
}

/// Σᵢ cᵢ (λᵢ − λ_prev,ᵢ) into `change` and Σᵢ cᵢ λᵢ into `whole`, over the columns cᵢ of
/// `columns` (nv apart: M⁻¹Jᵀ or Jᵀ), each over its nonzero dof ranges `ranges(i)`.
fn add_columns(
    columns: &[f64],
    nv: usize,
    lambda: &[f64],
    lambda_prev: &[f64],
    ranges: impl Fn(usize) -> [(usize, usize); 2],
    change: &mut [f64],
    whole: &mut [f64],
) {
    for (i, (&l, &p)) in lambda.iter().zip(lambda_prev).enumerate() {
        let dl = l - p;
        for (lo, hi) in ranges(i) {
            for k in lo..hi {
                let c = columns[k + i * nv];
                change[k] += c * dl;
                whole[k] += c * l;
            }
        }
    }
}

/// max |M⁻¹Jᵀ Δλ| (the sweep's change, Δλ = λ − `lambda_prev`) and max |M⁻¹Jᵀ λ|, by one of two
/// routes: Jᵀ Δλ and Jᵀ λ over each row's nonzeros (`ExactWork::row_ranges`) and a solve of each
/// with the factor of M; or, once the sweeps of this solve (`sweeps`, this one included) have
/// cost in solves what forming M⁻¹Jᵀ costs (`ExactWork::minv_jt_work`: cheap for many small
/// trees, a pile; dear for a long chain), M⁻¹Jᵀ formed ([`form_minv_jt`]) and its columns summed
/// over each row's trees.
fn sweep_motion(model: &Model, data: &mut Data, sweeps: u32) -> (f64, f64) {
    let (n, nv) = (data.nefc, model.nv);
    let w = &data.exact;
    if !w.minv_jt_ready && f64::from(sweeps) * 2.0 * w.solve_work >= w.minv_jt_work {
        form_minv_jt(model, data);
    }
    let Data { mass_factor, exact, .. } = data;
    let mut motion = std::mem::take(&mut exact.motion);
    let (change, whole) = motion.as_mut_slice()[..2 * nv].split_at_mut(nv);
    change.fill(0.0);
    whole.fill(0.0);
    let (rhs, prev) = (&exact.rhs.as_slice()[..n], &exact.lambda_prev.as_slice()[..n]);
    if exact.minv_jt_ready {
        add_columns(exact.minv_jt.as_slice(), nv, rhs, prev, |i| exact.tree_ranges(i), change, whole);
    } else {
        add_columns(exact.jt.as_slice(), nv, rhs, prev, |i| exact.row_ranges(i), change, whole);
        solve_with_factor_unchecked(model, mass_factor, change);
        solve_with_factor_unchecked(model, mass_factor, whole);
    }
    let moved = change.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let total = whole.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    exact.motion = motion;
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

/// Σ_j A_ji x_j over the rows (down column i: contiguous), over the Delassus matrix's nonzero
/// pattern (`ExactWork::pattern_rows`) when [`delassus`](super::exact) built one for these rows:
/// the same sum, in the same order, as the indexed form without its exact-zero terms.
pub(super) fn column_dot(data: &Data, i: usize, x: &[f64]) -> f64 {
    let col = delassus_column(data, i);
    let w = &data.exact;
    if w.pattern_full || w.pattern_n != data.nefc {
        return col.iter().zip(x).map(|(a, x)| a * x).sum();
    }
    // Over the column's pattern only: the terms left out are exact zeros (rows whose trees do
    // not meet row i's), the others summed in the same, ascending, order.
    w.pattern_rows[w.pattern_ptr[i]..w.pattern_ptr[i + 1]].iter().map(|&r| col[r] * x[r]).sum()
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
pub(super) fn separating(data: &Data, i: usize, level: Level) -> bool {
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
pub(super) fn mu(friction: &[f64; 5], k: usize) -> f64 {
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

/// Sweeps after which the active set of the iterate is first tried as an exact solve
/// ([`polish`]); then after every power of two of sweeps, when that set has changed.
const POLISH_AFTER: u32 = 8;

/// Fixed-point rounds of a polish with slipping contacts (their friction from the new normal
/// forces) before it is abandoned.
pub(super) const POLISH_ROUNDS: u32 = 30;

/// Multiply-adds one iterative solve may spend (sweeps × (n² + n·nv)) before it stops unconverged.
const WORK_BUDGET: f64 = 2e7;
/// Sweeps every solve may take whatever its size.
const MIN_SWEEPS: u32 = 50;

/// Largest contact dimension (condim 6).
pub(super) const MAX_DIM: usize = 6;

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
pub(super) fn max_dissipation(lambda_n: f64, friction: &[f64; 5], slip: &[f64], out: &mut [f64]) {
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
