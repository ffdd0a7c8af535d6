//! The exact mode's polish: the exact solve of the active set that the Coulomb solver's
//! Gauss–Seidel iterate has found ([`super::coulomb`]; the "polish" of active-set methods, Cottle,
//! Pang & Stone, *The Linear Complementarity Problem*, §4). Sticking rows get w = 0, the others
//! keep their force; a slipping contact's friction (on its cone, against the slip) is substituted
//! into the reduced system — one LU solve with complete pivoting for a contact already moving,
//! Newton's method on the maximal-dissipation law for one whose slip direction is the solution's
//! own — and the result is kept only if every row's law holds (docs/constraints.md, exact mode);
//! a row that breaks its law changes sides (a principal pivot) and the set is solved again.

use super::coulomb::{
    column_dot, max_dissipation, mu, separating, Level, MAX_DIM, POLISH_ROUNDS, SLIP_VELOCITY,
};
use super::ExactWork;
use crate::model::{Data, EfcType, Model};

/// The exact solve of the active set the Gauss–Seidel iterate has found (the "polish" of
/// active-set methods, Cottle, Pang & Stone §4): equality rows, normals carrying force, sticking
/// friction rows and friction-loss rows inside their bounds have w = 0; every other row keeps its
/// force (0, a friction-loss bound, a sliding friction). The reduced system is solved for the
/// correction of the iterate's forces, minimum-norm: rows that are parallel (a limit and a
/// friction loss on one dof, two contacts with one Jacobian) make it singular, and along its null
/// space the forces keep the iterate's split, which respects every row's bounds. The result is
/// kept only if every row's law holds (λ_n ≥ 0, w ≥ 0 off contact, friction inside its cone or
/// box, w opposing a friction at its bound); when one does not, the row that breaks its law the
/// most changes sides (a friction loss outside its box goes to that bound, a normal pulling leaves,
/// a friction leaving its cone slips, …: one principal pivot) and the system is solved again, at
/// most [`PIVOTS`] times, before the iteration goes on.
pub(crate) fn polish(model: &Model, data: &mut Data, level: Level) -> bool {
    let n = data.nefc;
    data.exact.active.clear();
    data.exact.slipping[..n].fill(false);
    let mut any_sliding = false;
    // Classify rows: Free rows go into `exact.active`; every other row keeps its force.
    let mut i = 0;
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
                if !dof_sliding(data, i, level)
                    && l > lo + TOL * (hi - lo).abs()
                    && l < hi - TOL * (hi - lo).abs()
                {
                    data.exact.active.push(i);
                }
            }
            EfcType::ContactElliptic => {
                if data.exact.rhs[i] > 0.0 || data.exact.pressing[i] {
                    data.exact.active.push(i);
                    let friction = data.contacts[data.efc_id[i]].friction;
                    let (radius, spent) = cone_of(data, i, len, level);
                    let y2: f64 = (1..len)
                        .filter(|&k| mu(&friction, k) > 0.0)
                        .map(|k| ((data.exact.rhs[i + k] + spent[k - 1]) / mu(&friction, k)).powi(2))
                        .sum();
                    // Moving (friction fixed by the slip, c · λ_n, updated in the rounds below)
                    // or starting to slip (friction on the cone, opposing the slip acceleration;
                    // at the velocity level, the post-step slip velocity).
                    if contact_moving(data, i, len, level)
                        || (y2.sqrt() >= radius * (1.0 - TOL) && radius > 0.0)
                    {
                        data.exact.slipping[i] = true;
                        any_sliding = true;
                    } else {
                        push_sticking_friction(data, i, len);
                    }
                }
            }
        }
        i += len;
    }
    if data.exact.active.is_empty() {
        return false;
    }
    // A set this solve's polish has tried (and failed on) is not tried again.
    let set = set_hash(data);
    if set == data.exact.polish_set {
        return false;
    }
    data.exact.polish_set = set;
    // The candidate starts at the iterate, friction-loss rows kept at a bound exactly on it.
    for j in 0..n {
        data.exact.lambda_prev[j] = data.exact.rhs[j];
    }
    set_in_active(data);
    snap_friction_dof_bounds(model, data, level);
    let mut pivoted = [(usize::MAX, 0u8); 2 * PIVOTS as usize];
    for pivot in 0..=PIVOTS {
        let k = data.exact.active.len();
        // Larger systems keep the symmetric rounds, and give up at the velocity level: the LU
        // with complete pivoting, and Newton's repeated ones, cost several times the Cholesky
        // there (bin_50 2.3× slower with them).
        let substitute = k <= SUBSTITUTE_MAX;
        if any_sliding && !substitute && level != Level::Acceleration {
            return false;
        }
        if pivot > 0 {
            restart_from_iterate(data);
        }
        let Some(redundant) = solve_active_set(data, level, any_sliding, substitute, false) else {
            return false;
        };
        let mut verdict = verify(model, data, level, &pivoted[..2 * pivot as usize]);
        if redundant && !matches!(verdict, Verdict::Holds) {
            // Redundant free rows: their minimum-norm forces (an even split) broke a law; the
            // iterate's split, corrected by the minimum-norm change, respects each row's bounds
            // (a limit and a friction loss on one dof).
            restart_from_iterate(data);
            if solve_active_set(data, level, any_sliding, substitute, true).is_none() {
                return false;
            }
            verdict = verify(model, data, level, &pivoted[..2 * pivot as usize]);
        }
        match verdict {
            Verdict::Holds => {
                for j in 0..n {
                    data.exact.rhs[j] = data.exact.lambda_prev[j];
                }
                return true;
            }
            Verdict::Fails => return false,
            Verdict::Pivot(p) => {
                if pivot == PIVOTS {
                    return false;
                }
                pivoted[2 * pivot as usize] = p.source(data);
                pivoted[2 * pivot as usize + 1] = p.target();
                any_sliding |= apply_pivot(data, p, level);
            }
        }
    }
    false
}

/// The candidate's free rows (and slipping contacts' friction) back at the iterate's forces; the
/// fixed rows keep the forces the pivots gave them.
fn restart_from_iterate(data: &mut Data) {
    let n = data.nefc;
    let mut j = 0;
    while j < n {
        let len = data.efc_block_len(j);
        let slipping = data.exact.slipping[j];
        for q in j..j + len {
            if data.exact.in_active[q] || (slipping && q > j) {
                data.exact.lambda_prev[q] = data.exact.rhs[q];
            }
        }
        j += len;
    }
}

/// A hash (FNV-1a) of the polish's active set: its free rows and its slipping contacts; never 0.
fn set_hash(data: &Data) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut mix = |x: usize| {
        h ^= x as u64;
        h = h.wrapping_mul(0x0100_0000_01b3);
    };
    for &r in &data.exact.active {
        mix(r);
    }
    mix(usize::MAX);
    for i in 0..data.nefc {
        if data.exact.slipping[i] {
            mix(i);
        }
    }
    h.max(1)
}

/// A row's place in the polish's active set is decided with this relative margin (of a box's
/// width, or of a cone's radius).
const TOL: f64 = 1e-9;

/// Principal pivots one polish may take after its first solve.
const PIVOTS: u32 = 8;

/// Whether friction-loss row i slides (its force fixed at −f sign(q̇); acceleration level only).
fn dof_sliding(data: &Data, i: usize, level: Level) -> bool {
    level == Level::Acceleration && data.efc_vel[i].abs() > SLIP_VELOCITY && !data.efc_frozen_at_rest(i)
}

/// Whether contact i slips at the acceleration level (its friction fixed by its slip velocity).
fn contact_moving(data: &Data, i: usize, len: usize, level: Level) -> bool {
    level == Level::Acceleration
        && (1..len).any(|k| data.efc_vel[i + k].abs() > SLIP_VELOCITY)
        && !data.efc_frozen_at_rest(i)
}

/// Whether some contact that is not separating slips at the acceleration level: its friction is
/// then fixed by its slip velocity, and the rows' problem is no longer the convex one of sticking
/// and static friction (whose row accelerations are unique: any active set that satisfies every
/// law gives the same motion) — with maximal dissipation along a given slip, two active sets may
/// both satisfy every law and move differently.
pub(super) fn any_contact_moving(data: &Data, level: Level) -> bool {
    let n = data.nefc;
    let mut i = 0;
    while i < n {
        let len = data.efc_block_len(i);
        if data.efc_type[i] == EfcType::ContactElliptic
            && !separating(data, i, level)
            && contact_moving(data, i, len, level)
        {
            return true;
        }
        i += len;
    }
    false
}

/// Adds contact i's friction rows (those with μ > 0) to the active set: the contact sticks.
fn push_sticking_friction(data: &mut Data, i: usize, len: usize) {
    let friction = data.contacts[data.efc_id[i]].friction;
    for k in 1..len {
        if mu(&friction, k) > 0.0 {
            insert_active(data, i + k);
        }
    }
}

/// Inserts row r into the (ascending) active set.
fn insert_active(data: &mut Data, r: usize) {
    let active = &mut data.exact.active;
    if let Err(at) = active.binary_search(&r) {
        active.insert(at, r);
    }
    data.exact.in_active[r] = true;
}

/// Removes row r from the active set.
fn remove_active(data: &mut Data, r: usize) {
    if let Ok(at) = data.exact.active.binary_search(&r) {
        data.exact.active.remove(at);
    }
    data.exact.in_active[r] = false;
}

/// `exact.in_active` from `exact.active`.
fn set_in_active(data: &mut Data) {
    let n = data.nefc;
    let ExactWork { active, in_active, .. } = &mut data.exact;
    in_active[..n].fill(false);
    for &r in active.iter() {
        in_active[r] = true;
    }
}

/// The candidate for the current active set (`exact.lambda_prev`, from its starting forces):
/// slipping contacts substituted (LU, Newton) or, for larger systems, symmetric rounds with their
/// friction fixed. The symmetric solve takes, for redundant free rows, the minimum-norm forces,
/// or with `from_candidate` the candidate's forces changed by the minimum-norm correction. None
/// when the rounds or Newton's method fail; else whether the symmetric system was redundant.
fn solve_active_set(
    data: &mut Data,
    level: Level,
    any_sliding: bool,
    substitute: bool,
    from_candidate: bool,
) -> Option<bool> {
    let n = data.nefc;
    let k = data.exact.active.len();
    let mut last_change = f64::INFINITY;
    let mut redundant = false;
    for round in 0..POLISH_ROUNDS {
        // Slipping contacts: their friction, direction times the cone's radius, substituted into
        // the normal's column (one non-symmetric solve); the symmetric solve with their friction
        // fixed at the candidate's when that system is inconsistent.
        if any_sliding && substitute && !all_moving(data, level) {
            // A contact whose slip direction is the solution's own: Newton from the iterate
            // (a direction taken from a candidate's slip near the stick–slip boundary is noise).
            return newton_slipping(data, level).then_some(false);
        }
        if any_sliding && substitute {
            slip_directions(data, level);
            if solve_substituted(data, level) {
                let change = update_sliding_friction(data, level);
                let scale = 1.0 + (0..n).map(|j| data.exact.lambda_prev[j].abs()).fold(0.0, f64::max);
                if change <= 1e-15 * scale {
                    return Some(false);
                }
                // The slip directions moved with the solution (a contact starting to slip, or
                // slipping after the step): Newton on the whole system, directions included
                // (fixed-point rounds on them diverge near sticking, measured on go1).
                return newton_slipping(data, level).then_some(false);
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
                    polish_work,
                    lu,
                    pattern_ptr,
                    pattern_rows,
                    pattern_n,
                    pattern_full,
                    ..
                },
            ..
        } = &mut *data;
        let sparse = !*pattern_full && *pattern_n == n;
        // A_FF λ_F = b_F − A_F,X λ_X, the fixed forces λ_X the candidate's; minimum-norm for
        // redundant rows (a box's corners share its load evenly). From the candidate: the
        // correction δ_F of its free forces, A_FF δ_F = −w_F (w = A λ − b), minimum-norm.
        for (a, &r) in efc_active.iter().enumerate() {
            let col = &efc_delassus.as_slice()[r * efc_delassus.nrows()..r * efc_delassus.nrows() + n];
            let mut rhs = efc_force[r];
            // Over the Delassus pattern when there is one (the other terms are exact zeros).
            let subtract = |rhs: &mut f64, j: usize| {
                if from_candidate || !in_active[j] {
                    *rhs -= col[j] * efc_lambda_prev[j];
                }
            };
            if sparse {
                for &j in &pattern_rows[pattern_ptr[r]..pattern_ptr[r + 1]] {
                    subtract(&mut rhs, j);
                }
            } else {
                for j in 0..n {
                    subtract(&mut rhs, j);
                }
            }
            efc_sub_rhs[a] = rhs;
            for (c, &q) in efc_active.iter().enumerate() {
                efc_sub[(a, c)] = col[q];
            }
        }
        *polish_work += (k * k * k) as f64 / 3.0;
        // Block by block over the islands of the active rows (a pile's separate groups).
        redundant |= lu.solve_psd(efc_sub, &mut efc_sub_rhs.as_mut_slice()[..k], efc_factor, efc_eig) < k;
        for (a, &r) in efc_active.iter().enumerate() {
            if from_candidate {
                efc_lambda_prev[r] += efc_sub_rhs[a];
            } else {
                efc_lambda_prev[r] = efc_sub_rhs[a];
            }
        }
        if !any_sliding {
            return Some(redundant);
        }
        let change = update_sliding_friction(data, level);
        let scale = 1.0 + (0..n).map(|j| data.exact.lambda_prev[j].abs()).fold(0.0, f64::max);
        if change <= 1e-15 * scale {
            return Some(redundant);
        }
        if round == POLISH_ROUNDS - 1 {
            return None;
        }
        // Rounds left at this round's rate of contraction: a fixed point the remaining rounds
        // cannot reach (or a round that did not contract) is abandoned now rather than at the
        // last round (the iteration goes on either way).
        let rate = change / last_change;
        if round > 0 {
            let needed = (1e-15 * scale / change).ln() / rate.ln();
            if rate >= 1.0 || needed.is_nan() || needed > f64::from(POLISH_ROUNDS - 1 - round) {
                return None;
            }
        }
        last_change = change;
    }
    None
}

/// Whether every slipping contact moves (acceleration level): their friction is then fixed by
/// their velocity and one substituted solve is exact.
fn all_moving(data: &Data, level: Level) -> bool {
    let n = data.nefc;
    let mut i = 0;
    while i < n {
        let len = data.efc_block_len(i);
        if data.exact.slipping[i] && !contact_moving(data, i, len, level) {
            return false;
        }
        i += len;
    }
    true
}

/// The outcome of checking a polish candidate against every row's law.
enum Verdict {
    /// Every law holds: the candidate is the solution.
    Holds,
    /// A law fails in a way no pivot mends (a contact moving against its own friction).
    Fails,
    /// The row breaking its law the most, and how it changes sides.
    Pivot(Pivot),
}

/// One principal pivot of the polish's active set.
#[derive(Clone, Copy, Debug)]
enum Pivot {
    /// A free friction-loss row left its box: held at that bound.
    FixDof(usize, f64),
    /// A friction-loss row held at a bound pushes into its box: free.
    FreeDof(usize),
    /// A free limit or contact normal pulls: it (and a contact's friction) leaves, with no force.
    DropNormal(usize),
    /// A limit or contact normal with no force is penetrating: it (and a sticking contact's
    /// friction) joins.
    AddNormal(usize),
    /// A sticking contact's friction left its cone: it slips.
    Slip(usize),
    /// A slipping contact's friction does not oppose its slip: it sticks.
    Stick(usize),
}

/// Checks the candidate (`exact.lambda_prev`) against every row's law with w = A λ − b; the
/// violation kept is the largest, forces relative to the largest force, row motions w to the
/// largest b, among the pivots that do not return a row to a side it had in this polish
/// (`pivoted`: that would be a cycle; when only such pivots are left, the polish fails).
fn verify(model: &Model, data: &Data, level: Level, pivoted: &[(usize, u8)]) -> Verdict {
    let n = data.nefc;
    let scale = 1.0 + (0..n).map(|j| data.efc_force[j].abs()).fold(0.0, f64::max);
    let w = |r: usize| -> f64 {
        column_dot(data, r, &data.exact.lambda_prev.as_slice()[..n]) - data.efc_force[r]
    };
    let force_scale = 1.0 + (0..n).map(|j| data.exact.lambda_prev[j].abs()).fold(0.0, f64::max);
    let mut worst: Option<(f64, Pivot)> = None;
    let mut blocked = false;
    let mut note = |size: f64, p: Pivot| {
        if pivoted.contains(&p.target()) {
            blocked = true;
        } else if worst.is_none_or(|(s, _)| size > s) {
            worst = Some((size, p));
        }
    };
    let mut i = 0;
    while i < n {
        let len = data.efc_block_len(i);
        let l = data.exact.lambda_prev[i];
        match data.efc_type[i] {
            EfcType::Equality | EfcType::FrictionTendon => {}
            EfcType::LimitJoint
            | EfcType::LimitTendon
            | EfcType::ContactFrictionless
            | EfcType::ContactElliptic
            | EfcType::ContactPyramidal => {
                let free = data.exact.in_active[i];
                if data.exact.pressing[i] {
                    // Held closed: its force has no sign.
                } else if free {
                    if l < -1e-12 * force_scale {
                        note(-l / force_scale, Pivot::DropNormal(i));
                        i += len;
                        continue;
                    }
                } else if !separating(data, i, level) {
                    let wi = w(i);
                    if wi < -1e-12 * scale {
                        note(-wi / scale, Pivot::AddNormal(i));
                    }
                }
                if data.efc_type[i] == EfcType::ContactElliptic && free {
                    let friction = data.contacts[data.efc_id[i]].friction;
                    let (_, spent) = cone_of(data, i, len, level);
                    let radius = match level {
                        Level::Acceleration => l,
                        Level::Velocity { dt } => l.max(0.0) + dt * data.exact.previous[i].max(0.0),
                    };
                    let y2: f64 = (1..len)
                        .filter(|&k| mu(&friction, k) > 0.0)
                        .map(|k| ((data.exact.lambda_prev[i + k] + spent[k - 1]) / mu(&friction, k)).powi(2))
                        .sum();
                    let excess = y2.sqrt() - radius * (1.0 + 1e-12) - 1e-12 * force_scale;
                    if data.exact.slipping[i] {
                        if !slip_opposed(data, i, len, level, force_scale) {
                            if contact_moving(data, i, len, level) {
                                return Verdict::Fails;
                            }
                            note(0.0, Pivot::Stick(i));
                        }
                    } else if excess > 0.0 {
                        note(excess / force_scale, Pivot::Slip(i));
                    }
                }
            }
            EfcType::FrictionDof => {
                let (lo, hi) = friction_dof_bounds(model, data, i, level);
                let slack = 1e-12 * force_scale;
                if data.exact.in_active[i] {
                    if l > hi + slack {
                        note((l - hi) / force_scale, Pivot::FixDof(i, hi));
                    } else if l < lo - slack {
                        note((lo - l) / force_scale, Pivot::FixDof(i, lo));
                    }
                } else if !dof_sliding(data, i, level) {
                    // At the upper bound the dof must be accelerating the other way, and back.
                    let wi = w(i);
                    let at_hi = l >= hi - slack;
                    let at_lo = l <= lo + slack;
                    if !((at_hi && wi <= 1e-12 * scale) || (at_lo && wi >= -1e-12 * scale)) {
                        note(wi.abs() / scale, Pivot::FreeDof(i));
                    }
                }
            }
        }
        i += len;
    }
    match worst {
        None if blocked => Verdict::Fails,
        None => Verdict::Holds,
        Some((_, p)) => Verdict::Pivot(p),
    }
}

impl Pivot {
    /// The row (a contact's normal row) that changes sides and the side it leaves: a friction
    /// loss at a bound or free, a normal with or without force, a contact sticking or slipping.
    fn source(self, data: &Data) -> (usize, u8) {
        match self {
            Pivot::FixDof(i, _) => (i, SIDE_FREE),
            Pivot::FreeDof(i) => (i, if data.exact.lambda_prev[i] > 0.0 { SIDE_HIGH } else { SIDE_LOW }),
            Pivot::DropNormal(i) => (i, SIDE_ON),
            Pivot::AddNormal(i) => (i, SIDE_OFF),
            Pivot::Slip(i) => (i, SIDE_STICK),
            Pivot::Stick(i) => (i, SIDE_SLIP),
        }
    }

    /// The row that changes sides and the side it takes.
    fn target(self) -> (usize, u8) {
        match self {
            Pivot::FixDof(i, bound) => (i, if bound > 0.0 { SIDE_HIGH } else { SIDE_LOW }),
            Pivot::FreeDof(i) => (i, SIDE_FREE),
            Pivot::DropNormal(i) => (i, SIDE_OFF),
            Pivot::AddNormal(i) => (i, SIDE_ON),
            Pivot::Slip(i) => (i, SIDE_SLIP),
            Pivot::Stick(i) => (i, SIDE_STICK),
        }
    }
}

/// The sides of a row in the polish's active set ([`Pivot::source`]).
const SIDE_LOW: u8 = 0;
const SIDE_HIGH: u8 = 1;
const SIDE_FREE: u8 = 2;
const SIDE_OFF: u8 = 3;
const SIDE_ON: u8 = 4;
const SIDE_STICK: u8 = 5;
const SIDE_SLIP: u8 = 6;

/// Applies pivot `p` to the active set and the candidate's fixed forces; returns whether a
/// contact now slips.
fn apply_pivot(data: &mut Data, p: Pivot, level: Level) -> bool {
    match p {
        Pivot::FixDof(i, bound) => {
            remove_active(data, i);
            data.exact.lambda_prev[i] = bound;
        }
        Pivot::FreeDof(i) => insert_active(data, i),
        Pivot::DropNormal(i) => {
            let len = data.efc_block_len(i);
            for r in i..i + len {
                remove_active(data, r);
                data.exact.lambda_prev[r] = 0.0;
            }
            data.exact.slipping[i] = false;
        }
        Pivot::AddNormal(i) => {
            insert_active(data, i);
            if data.efc_type[i] == EfcType::ContactElliptic {
                let len = data.efc_block_len(i);
                if contact_moving(data, i, len, level) {
                    data.exact.slipping[i] = true;
                    return true;
                }
                push_sticking_friction(data, i, len);
            }
        }
        Pivot::Slip(i) => {
            let len = data.efc_block_len(i);
            for r in i + 1..i + len {
                remove_active(data, r);
            }
            data.exact.slipping[i] = true;
            return true;
        }
        Pivot::Stick(i) => {
            let len = data.efc_block_len(i);
            data.exact.slipping[i] = false;
            push_sticking_friction(data, i, len);
        }
    }
    false
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
            column_dot(data, i + k, &data.exact.lambda_prev.as_slice()[..n]) - data.efc_force[i + k]
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
/// untouched) when the system is inconsistent.
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
        lu,
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
    exact.polish_work += (2 * k * k * k) as f64 / 3.0;
    if !lu.solve(sub, &mut sub_rhs.as_mut_slice()[..k], 0.0) {
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

/// Step halvings of one Newton iteration's backtracking before [`newton_slipping`] gives up.
const HALVINGS: u32 = 6;

/// [`newton_slipping`]'s residual at convergence: each equation's, relative to 1 + the largest b
/// (rows held at w = 0) or 1 + the largest force (slipping friction).
const NEWTON_TOLERANCE: f64 = 1e-14;

/// The polish's system with its slipping contacts solved by Newton's method (the semismooth
/// Newton of the active set, e.g. Acary & Brogliato §13.4, on the maximal-dissipation law),
/// started from the candidate (`exact.lambda_prev`, updated; the other rows keep its forces):
/// the unknowns are the active rows' forces, with w_r = (A λ − b)_r = 0, and the slipping
/// contacts' friction ([`newton_assemble`] gives each law). Each iteration solves the Jacobian
/// system by LU and backtracks until the largest residual falls; true when it reaches
/// [`NEWTON_TOLERANCE`].
fn newton_slipping(data: &mut Data, level: Level) -> bool {
    let n = data.nefc;
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
    let Some(mut worst) = newton_assemble(data, level, m, b_scale) else {
        return false;
    };
    for _ in 0..NEWTON_ITERATIONS {
        if worst <= NEWTON_TOLERANCE {
            return true;
        }
        {
            let ExactWork { sub, sub_rhs, lu, eig, polish_work, .. } = &mut data.exact;
            *polish_work += (2 * m * m * m) as f64 / 3.0;
            if !lu.solve(sub, &mut sub_rhs.as_mut_slice()[..m], NEWTON_TOLERANCE) {
                return false;
            }
            eig.as_mut_slice()[..m].copy_from_slice(&sub_rhs.as_slice()[..m]);
        }
        // Backtracking on the largest residual (Armijo): far from the solution a full step can
        // overshoot the law's curvature.
        let (mut alpha, mut applied) = (1.0, 0.0);
        let mut accepted = false;
        for _ in 0..=HALVINGS {
            let ExactWork { newton_rows, lambda_prev, eig, .. } = &mut data.exact;
            for c in 0..m {
                lambda_prev[newton_rows[c]] += (alpha - applied) * eig[c];
            }
            applied = alpha;
            match newton_assemble(data, level, m, b_scale) {
                Some(w) if w <= (1.0 - 1e-4 * alpha) * worst => {
                    worst = w;
                    accepted = true;
                    break;
                }
                _ => alpha *= 0.5,
            }
        }
        if !accepted {
            return false;
        }
    }
    worst <= NEWTON_TOLERANCE
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

/// The Newton system of [`newton_slipping`] at the candidate: the Jacobian into `exact.sub`
/// (m × m), minus the residual into `exact.sub_rhs`; returns the largest scaled residual, or None
/// when a slip direction is undefined. A slipping contact's friction law, with R = λ_n + c and s
/// the normal and friction impulses the step already spent (velocity level; 0 at the
/// acceleration level): for a contact moving at the acceleration level, λ_f + s = R φ(u) with
/// φ_k(u) = −μ_k² u_k / ‖μ ∘ u‖ of its slip velocity u (fixed); otherwise, in the scaled friction
/// y = (λ_f + s)/μ and slip ũ = μ ∘ u (u the rows' w), y = R z/‖z‖ with z = y − ρ ũ — the
/// projection form of maximal dissipation, which stays regular where the slip vanishes.
fn newton_assemble(data: &mut Data, level: Level, m: usize, b_scale: f64) -> Option<f64> {
    let n = data.nefc;
    let dt = match level {
        Level::Acceleration => 0.0,
        Level::Velocity { dt } => dt,
    };
    let l_scale = 1.0 + (0..n).map(|j| data.exact.lambda_prev[j].abs()).fold(0.0, f64::max);
    let mut worst = 0.0f64;
    // The slip of the contact whose friction rows are being assembled (consecutive unknowns).
    let mut slip: (usize, [f64; MAX_DIM]) = (usize::MAX, [0.0; MAX_DIM]);
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
        let mk = mu(&friction, k);
        let c0 = dt * data.exact.previous[s].max(0.0);
        let spent = dt * data.exact.previous[r];
        let radius = data.exact.lambda_prev[s] + c0;
        for c in 0..m {
            data.exact.sub[(a, c)] = 0.0;
        }
        data.exact.sub[(a, a)] = 1.0;
        let cs = data.exact.newton_pos[s];
        if mk == 0.0 {
            // No friction along this row: its whole impulse stays 0.
            let f = data.exact.lambda_prev[r] + spent;
            worst = worst.max(f.abs() / l_scale);
            data.exact.sub_rhs[a] = -f;
            continue;
        }
        if slip.0 != s {
            slip_of(data, s, len, level, &mut slip.1);
            slip.0 = s;
        }
        let u = slip.1;
        if contact_moving(data, s, len, level) {
            // The direction is the slip velocity's: λ_k = R φ_k(u), φ_k = −μ_k² u_k / ‖μ ∘ u‖.
            let norm = (1..len).map(|q| (mu(&friction, q) * u[q - 1]).powi(2)).sum::<f64>().sqrt();
            if !(norm > 0.0 && norm.is_finite()) {
                return None;
            }
            let phi = -mk * mk * u[k - 1] / norm;
            let f = data.exact.lambda_prev[r] + spent - radius * phi;
            worst = worst.max(f.abs() / l_scale);
            data.exact.sub_rhs[a] = -f;
            data.exact.sub[(a, cs)] -= phi;
            continue;
        }
        // The direction is the solution's own: in the scaled friction y_q = (λ_q + s_q)/μ_q
        // and slip ũ_q = μ_q u_q, y = R z/‖z‖ with z = y − ρ ũ (ρ > 0: the projection of
        // y − ρ ũ onto the cone's boundary). It holds exactly when ‖y‖ = R and ũ = −t y, t ≥ 0
        // (maximal dissipation, t checked by the verification), and stays regular as the slip
        // vanishes, where −μ² u/‖μ ∘ u‖ has no direction (a contact at the stick–slip
        // boundary). ρ = 1 / the mean diagonal of the scaled block.
        let mut z = [0.0; MAX_DIM];
        let (mut diag, mut count) = (0.0, 0.0);
        for q in 1..len {
            let mq = mu(&friction, q);
            if mq > 0.0 {
                diag += mq * mq * data.exact.delassus[(s + q, s + q)];
                count += 1.0;
            }
        }
        let rho = if diag > 0.0 { count / diag } else { 0.0 };
        for q in 1..len {
            let mq = mu(&friction, q);
            if mq > 0.0 {
                let y = (data.exact.lambda_prev[s + q] + dt * data.exact.previous[s + q]) / mq;
                z[q - 1] = y - rho * mq * u[q - 1];
            }
        }
        let norm = z.iter().map(|x| x * x).sum::<f64>().sqrt();
        if !(norm > 0.0 && norm.is_finite()) {
            return None;
        }
        let ek = z[k - 1] / norm;
        let f = data.exact.lambda_prev[r] + spent - radius * mk * ek;
        worst = worst.max(f.abs() / l_scale);
        data.exact.sub_rhs[a] = -f;
        data.exact.sub[(a, cs)] -= mk * ek;
        // −R μ_k Σ_l ∂e_k/∂z_l ∂z_l/∂λ, ∂e_k/∂z_l = (δ_kl − e_k e_l)/‖z‖,
        // ∂z_l/∂λ_j = [j = s + l]/μ_l − ρ μ_l A_(s+l) j.
        for l in 1..len {
            let ml = mu(&friction, l);
            if ml == 0.0 {
                continue;
            }
            let el = z[l - 1] / norm;
            let coef = -radius * mk * ((if l == k { 1.0 } else { 0.0 }) - ek * el) / norm;
            if coef == 0.0 {
                continue;
            }
            let pl = data.exact.newton_pos[s + l];
            if pl != usize::MAX {
                data.exact.sub[(a, pl)] += coef / ml;
            }
            for c in 0..m {
                let q = data.exact.newton_rows[c];
                let v = data.exact.delassus[(q, s + l)];
                data.exact.sub[(a, c)] -= coef * rho * ml * v;
            }
        }
    }
    Some(worst)
}
