//! The exact solver for bilateral and frictionless unilateral rows (equalities, joint limits,
//! frictionless contacts): the mixed linear complementarity problem on the Delassus matrix by a
//! principal-pivoting active-set method — exact for these small systems, no iteration tolerance.
//! Rows with dry friction go to [`super::coulomb`] instead.

use super::dense::solve_psd;
use super::ExactWork;
use crate::model::Data;

/// Solves A μ = `efc_rhs` (first nefc entries) in place, island by island of A's pattern
/// (`BlockLu::solve_psd`: the minimum-norm solution where redundant); returns the rank of A.
pub(crate) fn solve_delassus(data: &mut Data) -> usize {
    let n = data.nefc;
    let Data {
        exact: ExactWork { delassus: efc_delassus, rhs: efc_rhs, factor: efc_factor, eig: efc_eig, lu, .. },
        ..
    } = data;
    lu.solve_psd(efc_delassus, &mut efc_rhs.as_mut_slice()[..n], efc_factor, efc_eig)
}

/// The mixed complementarity problem of bilateral and unilateral rows on A = J M⁻¹ Jᵀ (in
/// `efc_delassus`) with b in `efc_rhs`: find μ with w = A μ − b and, per row, w = 0 (bilateral),
/// or μ ≥ 0, w ≥ 0, μ w = 0 (unilateral: joint limits) — the KKT conditions of Signorini's law
/// (docs/physics.md §1.6 with inequality constraints; Cottle, Pang & Stone, *The Linear Complementarity
/// Problem*, §4.1, the principal pivoting / active-set method). Unilateral rows whose `skip` is
/// true (separating at the acceleration level) carry no force. Solves each active set exactly
/// (minimum-norm for redundant rows), dropping the most negative force or adding the most violated
/// row until both sign conditions hold; returns the number of active-set changes. μ is left in
/// `efc_rhs`; without unilateral rows this is the plain solve.
pub(crate) fn solve_mixed(data: &mut Data, skip: impl Fn(&Data, usize) -> bool) -> u32 {
    let n = data.nefc;
    if !(0..n).any(|i| data.efc_signed(i)) {
        data.exact.active.clear();
        data.exact.active.extend(0..n);
        data.efc_rank = solve_delassus(data);
        return 0;
    }
    let scale = 1.0 + (0..n).map(|i| data.exact.rhs[i].abs()).fold(0.0, f64::max);
    let tol = 1e-11 * scale;
    // b stays in efc_force during the iterations; μ is built in efc_rhs.
    for i in 0..n {
        data.efc_force[i] = data.exact.rhs[i];
    }
    data.exact.active.clear();
    for i in 0..n {
        if !(data.efc_signed(i) && skip(data, i)) {
            data.exact.active.push(i);
        }
    }
    let mut changes = 0;
    for _ in 0..(4 * n + 10) {
        // Solve the active block exactly.
        let k = data.exact.active.len();
        {
            let Data {
                efc_force,
                exact:
                    ExactWork {
                        delassus: efc_delassus,
                        sub: efc_sub,
                        sub_rhs: efc_sub_rhs,
                        active: efc_active,
                        factor: efc_factor,
                        eig: efc_eig,
                        ..
                    },
                ..
            } = data;
            for (a, &i) in efc_active.iter().enumerate() {
                efc_sub_rhs[a] = efc_force[i];
                for (c, &j) in efc_active.iter().enumerate() {
                    efc_sub[(a, c)] = efc_delassus[(i, j)];
                }
            }
            data.efc_rank = solve_psd(efc_sub, &mut efc_sub_rhs.as_mut_slice()[..k], efc_factor, efc_eig);
        }
        data.exact.rhs.rows_mut(0, n).fill(0.0);
        for (a, &i) in data.exact.active.iter().enumerate() {
            data.exact.rhs[i] = data.exact.sub_rhs[a];
        }
        // The most negative force of an active unilateral row leaves the set.
        let drop = data
            .exact
            .active
            .iter()
            .enumerate()
            .filter(|(_, &i)| data.efc_signed(i) && data.exact.rhs[i] < -tol)
            .min_by(|a, b| data.exact.rhs[*a.1].total_cmp(&data.exact.rhs[*b.1]))
            .map(|(a, _)| a);
        if let Some(a) = drop {
            data.exact.active.remove(a);
            changes += 1;
            continue;
        }
        // The most violated inactive unilateral row (w < 0) joins it.
        let mut worst: Option<(usize, f64)> = None;
        for i in 0..n {
            if !data.efc_signed(i) || data.exact.active.contains(&i) || skip(data, i) {
                continue;
            }
            let w: f64 = (0..n).map(|j| data.exact.delassus[(i, j)] * data.exact.rhs[j]).sum::<f64>()
                - data.efc_force[i];
            if w < -tol && worst.is_none_or(|(_, ww)| w < ww) {
                worst = Some((i, w));
            }
        }
        match worst {
            Some((i, _)) => {
                let at = data.exact.active.partition_point(|&j| j < i);
                data.exact.active.insert(at, i);
                changes += 1;
            }
            None => break,
        }
    }
    changes
}
