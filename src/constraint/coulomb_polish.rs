//! The exact mode's polish: the exact solve of the active set that the Coulomb solver's
//! Gauss–Seidel iterate has found ([`super::coulomb`]; the "polish" of active-set methods, Cottle,
//! Pang & Stone, *The Linear Complementarity Problem*, §4). Sticking rows get w = 0, the others
//! keep their force; a slipping contact's friction (on its cone, against the slip) is substituted
//! into the reduced system — one LU solve with complete pivoting for a contact already moving,
//! Newton's method on the maximal-dissipation law for one whose slip direction is the solution's
//! own — and the result is kept only if every row's law holds (docs/constraints.md, exact mode).

use super::coulomb::{
    column_dot, max_dissipation, mu, separating, Level, MAX_DIM, POLISH_ROUNDS, SLIP_VELOCITY,
};
use super::dense::{lu_solve, solve_psd};
use super::ExactWork;
use crate::model::{Data, EfcType, Model};

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
pub(super) fn cone_of(data: &Data, i: usize, len: usize, level: Level) -> (f64, [f64; MAX_DIM]) {
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
