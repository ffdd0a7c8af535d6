//! The exact (rigid) constraint solver: the KKT system of Lagrangian mechanics with multipliers
//! (notes §1.6, eq. 20: M q̈ + c − τ = Jᵀλ together with the acceleration form of the constraints,
//! J q̈ + J̇v = 0), solved by the range-space method with the tree-sparse LᵀDL factor of M
//! (RBDA §6.3): Y = M⁻¹Jᵀ, the Delassus matrix A = J Y, then A λ = −(J q̈_smooth + J̇v) and
//! q̈ = q̈_smooth + Y λ. Redundant rows give the minimum-norm multipliers ([`solve_psd`]).
//!
//! Drift correction for steppers: [`project_positions`] (Gauss–Newton onto φ(q) = 0 along
//! M⁻¹Jᵀ, on the configuration manifold) and [`project_velocities`] (the M-orthogonal projection
//! of v onto J v = 0).

use super::{solve_psd, ConstraintModel};
use crate::dynamics::{crba, factorize_mass_matrix, solve_with_factor};
use crate::kinematics::body_poses;
use crate::model::{integrate_configuration, Data, Model};

/// Y = M⁻¹Jᵀ into `efc_minv_jt` and A = J M⁻¹ Jᵀ into `efc_delassus` for the current rows (needs
/// the factor of M in `mass_factor`).
fn delassus(model: &Model, data: &mut Data) {
    let n = data.nefc;
    let nv = model.nv;
    let Data { efc_j, efc_minv_jt, efc_delassus, mass_factor, .. } = data;
    for i in 0..n {
        let mut col = efc_minv_jt.column_mut(i);
        for k in 0..nv {
            col[k] = efc_j[(i, k)];
        }
        solve_with_factor(model, mass_factor, col.as_mut_slice());
    }
    for i in 0..n {
        for j in i..n {
            let a: f64 = (0..nv).map(|k| efc_j[(i, k)] * efc_minv_jt[(k, j)]).sum();
            efc_delassus[(i, j)] = a;
            efc_delassus[(j, i)] = a;
        }
    }
}

/// Solves A μ = `efc_rhs` (first nefc entries) in place; returns the rank of A.
fn solve_delassus(data: &mut Data) -> usize {
    let n = data.nefc;
    let Data { efc_delassus, efc_rhs, efc_factor, efc_eig, .. } = data;
    solve_psd(efc_delassus, &mut efc_rhs.as_mut_slice()[..n], efc_factor, efc_eig)
}

/// J_i · x for row `i` of the current rows.
fn row_dot(data: &Data, nv: usize, i: usize, x: &[f64]) -> f64 {
    (0..nv).map(|k| data.efc_j[(i, k)] * x[k]).sum()
}

/// x += s · M⁻¹Jᵀ μ with μ the first nefc entries of `efc_rhs` (the result of a Delassus solve).
fn add_minv_jt_mu(data: &Data, nv: usize, s: f64, x: &mut [f64]) {
    for i in 0..data.nefc {
        let mu = s * data.efc_rhs[i];
        for k in 0..nv {
            x[k] += data.efc_minv_jt[(k, i)] * mu;
        }
    }
}

/// The mixed complementarity problem of bilateral and unilateral rows on A = J M⁻¹ Jᵀ (in
/// `efc_delassus`) with b in `efc_rhs`: find μ with w = A μ − b and, per row, w = 0 (bilateral),
/// or μ ≥ 0, w ≥ 0, μ w = 0 (unilateral: joint limits) — the KKT conditions of Signorini's law
/// (notes §1.6 with inequality constraints; Cottle, Pang & Stone, *The Linear Complementarity
/// Problem*, §4.1, the principal pivoting / active-set method). Unilateral rows whose `skip` is
/// true (separating at the acceleration level) carry no force. Solves each active set exactly
/// (minimum-norm for redundant rows), dropping the most negative force or adding the most violated
/// row until both sign conditions hold; returns the number of active-set changes. μ is left in
/// `efc_rhs`; without unilateral rows this is the plain solve.
fn solve_mixed(data: &mut Data, skip: impl Fn(&Data, usize) -> bool) -> u32 {
    let n = data.nefc;
    if !(0..n).any(|i| data.efc_type[i].is_unilateral()) {
        data.efc_active.clear();
        data.efc_active.extend(0..n);
        data.efc_rank = solve_delassus(data);
        return 0;
    }
    let scale = 1.0 + (0..n).map(|i| data.efc_rhs[i].abs()).fold(0.0, f64::max);
    let tol = 1e-11 * scale;
    // b stays in efc_force during the iterations; μ is built in efc_rhs.
    for i in 0..n {
        data.efc_force[i] = data.efc_rhs[i];
    }
    data.efc_active.clear();
    for i in 0..n {
        if !(data.efc_type[i].is_unilateral() && skip(data, i)) {
            data.efc_active.push(i);
        }
    }
    let mut changes = 0;
    for _ in 0..(4 * n + 10) {
        // Solve the active block exactly.
        let k = data.efc_active.len();
        {
            let Data {
                efc_delassus, efc_sub, efc_sub_rhs, efc_active, efc_force, efc_factor, efc_eig, ..
            } = data;
            for (a, &i) in efc_active.iter().enumerate() {
                efc_sub_rhs[a] = efc_force[i];
                for (c, &j) in efc_active.iter().enumerate() {
                    efc_sub[(a, c)] = efc_delassus[(i, j)];
                }
            }
            data.efc_rank = solve_psd(efc_sub, &mut efc_sub_rhs.as_mut_slice()[..k], efc_factor, efc_eig);
        }
        data.efc_rhs.rows_mut(0, n).fill(0.0);
        for (a, &i) in data.efc_active.iter().enumerate() {
            data.efc_rhs[i] = data.efc_sub_rhs[a];
        }
        // The most negative force of an active unilateral row leaves the set.
        let drop = data
            .efc_active
            .iter()
            .enumerate()
            .filter(|(_, &i)| data.efc_type[i].is_unilateral() && data.efc_rhs[i] < -tol)
            .min_by(|a, b| data.efc_rhs[*a.1].total_cmp(&data.efc_rhs[*b.1]))
            .map(|(a, _)| a);
        if let Some(a) = drop {
            data.efc_active.remove(a);
            changes += 1;
            continue;
        }
        // The most violated inactive unilateral row (w < 0) joins it.
        let mut worst: Option<(usize, f64)> = None;
        for i in 0..n {
            if !data.efc_type[i].is_unilateral() || data.efc_active.contains(&i) || skip(data, i) {
                continue;
            }
            let w: f64 =
                (0..n).map(|j| data.efc_delassus[(i, j)] * data.efc_rhs[j]).sum::<f64>() - data.efc_force[i];
            if w < -tol && worst.is_none_or(|(_, ww)| w < ww) {
                worst = Some((i, w));
            }
        }
        match worst {
            Some((i, _)) => {
                let at = data.efc_active.partition_point(|&j| j < i);
                data.efc_active.insert(at, i);
                changes += 1;
            }
            None => break,
        }
    }
    changes
}

/// The constraint stage of the exact mode. Needs, at the same state: the factor of M
/// (`mass_factor`), the rows with `efc_pos`, `efc_vel`, `efc_jdotv`, and `qacc_smooth`. Writes
/// `efc_force` (λ), `qfrc_constraint` (Jᵀλ), `qacc` and `efc_rank`. `baumgarte = [α, β]` adds the
/// stabilization J q̈ + J̇v + α J v + β φ = 0 (Baumgarte 1972); `None` solves the pure KKT system.
pub fn solve_exact(model: &Model, data: &mut Data, baumgarte: Option<[f64; 2]>) {
    let n = data.nefc;
    let nv = model.nv;
    delassus(model, data);
    let [alpha, beta] = baumgarte.unwrap_or([0.0, 0.0]);
    for i in 0..n {
        let j_qacc = row_dot(data, nv, i, data.qacc_smooth.as_slice());
        data.efc_rhs[i] = -(j_qacc + data.efc_jdotv[i]) - alpha * data.efc_vel[i] - beta * data.efc_pos[i];
    }
    // A limit row moving away from its bound (J v > 0) is separating: no force.
    data.efc_iterations = solve_mixed(data, |d, i| d.efc_vel[i] > 0.0);
    data.qacc.copy_from(&data.qacc_smooth);
    let mut qacc = std::mem::take(&mut data.qacc);
    add_minv_jt_mu(data, nv, 1.0, qacc.as_mut_slice());
    data.qacc = qacc;
    data.qfrc_constraint.fill(0.0);
    for i in 0..n {
        let lambda = data.efc_rhs[i];
        data.efc_force[i] = lambda;
        for k in 0..nv {
            data.qfrc_constraint[k] += data.efc_j[(i, k)] * lambda;
        }
    }
}

/// The violation of the current rows: [max |φ| (for a limit row, the penetration), max of |J v|
/// over bilateral rows and max(0, −J v) over unilateral rows (approach speed)].
pub fn row_violation(data: &Data) -> [f64; 2] {
    let n = data.nefc;
    let velocity = (0..n)
        .map(|i| {
            if data.efc_type[i].is_unilateral() {
                (-data.efc_vel[i]).max(0.0)
            } else {
                data.efc_vel[i].abs()
            }
        })
        .fold(0.0, f64::max);
    [data.efc_pos.rows(0, n).amax(), velocity]
}

/// Moves `q` onto the constraint manifold φ(q) = 0 by Gauss–Newton steps Δ = −M⁻¹Jᵀ A⁺ φ applied
/// on the configuration manifold (`q ← q ⊕ Δ`, free and ball joints included), M taken at the
/// starting q. Stops when max |φ| ≤ `tolerance` or after `max_iterations`; returns (iterations,
/// final max |φ|). Leaves the factor of M at the starting q in `data`.
pub fn project_positions(
    model: &Model,
    constraints: &ConstraintModel,
    data: &mut Data,
    q: &mut [f64],
    tolerance: f64,
    max_iterations: u32,
) -> (u32, f64) {
    crba(model, data, q);
    factorize_mass_matrix(model, data);
    let mut iterations = 0;
    loop {
        if iterations > 0 {
            body_poses(model, data, q);
        }
        constraints.positions(model, data, q);
        let n = data.nefc;
        let residual = data.efc_pos.rows(0, n).amax();
        if residual <= tolerance || iterations >= max_iterations || !residual.is_finite() {
            return (iterations, residual);
        }
        delassus(model, data);
        for i in 0..n {
            data.efc_rhs[i] = data.efc_pos[i];
        }
        solve_delassus(data);
        let mut dq = std::mem::take(&mut data.scratch_v);
        dq.fill(0.0);
        add_minv_jt_mu(data, model.nv, -1.0, dq.as_mut_slice());
        integrate_configuration(model, q, dq.as_slice(), 1.0);
        data.scratch_v = dq;
        iterations += 1;
    }
}

/// Replaces `v` by its M-orthogonal projection onto {J v = 0 on bilateral rows, J v ≥ 0 on
/// unilateral rows} at configuration `q`: v ← v + M⁻¹Jᵀ μ with the impulses μ of the mixed
/// complementarity problem (an inelastic impact on a joint limit: restitution 0). Needs the factor
/// of M (e.g. from [`project_positions`]) and the rows at q (`positions`); returns the largest
/// remaining violation (|J v| bilateral, max(0, −J v) unilateral) and leaves J v in `efc_vel`.
pub fn project_velocities(model: &Model, data: &mut Data, v: &mut [f64]) -> f64 {
    let n = data.nefc;
    let nv = model.nv;
    delassus(model, data);
    for i in 0..n {
        data.efc_rhs[i] = -row_dot(data, nv, i, v);
    }
    solve_mixed(data, |_, _| false);
    add_minv_jt_mu(data, nv, 1.0, v);
    // J v of the projected velocity, measured as every row violation is.
    for i in 0..n {
        data.efc_vel[i] = row_dot(data, nv, i, v);
    }
    row_violation(data)[1]
}
