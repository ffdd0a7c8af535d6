//! Projected Gauss–Seidel on the dual of the soft problem (MuJoCo's `PGS` solver; MuJoCo
//! documentation, "Computation → Solver"): minimize ½ fᵀ (A + R) f + fᵀ (J a₀ − aref) over the
//! row forces f, with A = J M⁻¹ Jᵀ, a₀ = `qacc_smooth`, subject to: equality rows free, friction
//! loss |f| ≤ frictionloss, limits and frictionless or pyramidal contacts f ≥ 0, and elliptic
//! contacts in the cone f_n ≥ |(f_i / μ_i)| (μ_i the contact's friction coefficients). The dual
//! is strictly convex (R > 0), so its minimizer is unique and gives the same forces and
//! acceleration a = a₀ + M⁻¹ Jᵀ f as the primal solvers.
//!
//! Scalar rows are updated in closed form; an elliptic contact's block is minimized over its cone
//! (`elliptic_block`) in the coordinates x = (f_n, f_i / μ_i), where the cone is the standard
//! second-order cone and its projection has a closed form.

use super::primal::Settings;
use crate::dynamics::solve_with_factor_unchecked;
use crate::model::{Data, EfcType, Model};
use nalgebra::DMatrix;

/// The minimizer of the dual over one elliptic contact's forces, the others fixed: in
/// x = (f_n, f_i / μ_i) the block is a small QP ½ xᵀ B x + gᵀ x over the second-order cone K
/// (B positive definite since R > 0). Its unconstrained minimizer is taken if it lies in K; the
/// apex x = 0 if g lies in K (K is self-dual: no direction into K descends). Otherwise the
/// minimizer lies on K's surface x = r (1, u), |u| = 1: for a direction w = (1, u) the best r is
/// max(0, −g·w / wᵀBw) in closed form, leaving a search over u — for condim 3 one angle (sampled,
/// then refined by golden sections to round-off), for condim 4 and 6 accelerated projected
/// gradient (FISTA) iterations from the current forces.
fn elliptic_block(
    data: &mut Data,
    i: usize,
    dim: usize,
    friction: &[f64; 5],
    residual: impl Fn(&Data, usize) -> f64,
) {
    let scale = |k: usize| if k == 0 { 1.0 } else { friction[k - 1] };
    let mut b = [[0.0; 6]; 6];
    for r in 0..dim {
        for c in 0..dim {
            b[r][c] = data.soft.ar[(i + r, i + c)] * scale(r) * scale(c);
        }
    }
    // g: the gradient at x = 0 within the block (the residual without the block's own forces).
    let mut x_now = [0.0; 6];
    for k in 0..dim {
        x_now[k] = data.efc_force[i + k] / scale(k);
    }
    let mut g = [0.0; 6];
    for k in 0..dim {
        let bx: f64 = (0..dim).map(|c| b[k][c] * x_now[c]).sum();
        g[k] = residual(data, i + k) * scale(k) - bx;
    }
    let tangent = |x: &[f64; 6]| x[1..dim].iter().map(|v| v * v).sum::<f64>().sqrt();
    let x = match unconstrained(&b, &g, dim) {
        Some(x) if x[0] >= tangent(&x) => x,
        _ if g[0] >= tangent(&g) => [0.0; 6],
        _ if dim == 3 => surface_angle(&b, &g),
        _ => surface_fista(&b, &g, dim, x_now),
    };
    for k in 0..dim {
        data.efc_force[i + k] = x[k] * scale(k);
    }
}

/// −B⁻¹ g by Cholesky (None if B is not positive definite).
fn unconstrained(b: &[[f64; 6]; 6], g: &[f64; 6], dim: usize) -> Option<[f64; 6]> {
    let mut l = [[0.0; 6]; 6];
    for c in 0..dim {
        let d = b[c][c] - (0..c).map(|k| l[c][k] * l[c][k]).sum::<f64>();
        if d <= 0.0 {
            return None;
        }
        let d = d.sqrt();
        l[c][c] = d;
        for r in c + 1..dim {
            l[r][c] = (b[r][c] - (0..c).map(|k| l[r][k] * l[c][k]).sum::<f64>()) / d;
        }
    }
    let (mut y, mut x) = ([0.0; 6], [0.0; 6]);
    for r in 0..dim {
        y[r] = (-g[r] - (0..r).map(|k| l[r][k] * y[k]).sum::<f64>()) / l[r][r];
    }
    for r in (0..dim).rev() {
        x[r] = (y[r] - (r + 1..dim).map(|k| l[k][r] * x[k]).sum::<f64>()) / l[r][r];
    }
    Some(x)
}

/// The best point r (1, cos φ, sin φ) on a condim-3 cone's surface: F(φ) = min over r ≥ 0 is
/// −(g·w)²/(2 wᵀBw) where g·w < 0; 72 samples of φ, then golden sections around the best.
fn surface_angle(b: &[[f64; 6]; 6], g: &[f64; 6]) -> [f64; 6] {
    let point = |phi: f64| -> ([f64; 6], f64) {
        let w = [1.0, phi.cos(), phi.sin()];
        let gw: f64 = (0..3).map(|k| g[k] * w[k]).sum();
        let wbw: f64 = (0..3).map(|r| (0..3).map(|c| w[r] * b[r][c] * w[c]).sum::<f64>()).sum();
        let r = if gw < 0.0 { -gw / wbw } else { 0.0 };
        let mut x = [0.0; 6];
        for k in 0..3 {
            x[k] = r * w[k];
        }
        (x, if gw < 0.0 { -0.5 * gw * gw / wbw } else { 0.0 })
    };
    const SAMPLES: usize = 72;
    let step = std::f64::consts::TAU / SAMPLES as f64;
    let best = (0..SAMPLES)
        .map(|k| k as f64 * step)
        .min_by(|a, b| point(*a).1.total_cmp(&point(*b).1))
        .unwrap_or(0.0);
    let (mut a, mut c) = (best - step, best + step);
    let ratio = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..80 {
        let (x1, x2) = (c - ratio * (c - a), a + ratio * (c - a));
        if point(x1).1 < point(x2).1 {
            c = x2;
        } else {
            a = x1;
        }
    }
    point(0.5 * (a + c)).0
}

/// Projection of x (length dim) onto the second-order cone x₀ ≥ |x_t|.
fn project_cone(x: &mut [f64]) {
    let t = x[1..].iter().map(|v| v * v).sum::<f64>().sqrt();
    if t <= x[0] {
        return;
    }
    if t <= -x[0] {
        x.fill(0.0);
        return;
    }
    let a = 0.5 * (x[0] + t);
    x[0] = a;
    for v in &mut x[1..] {
        *v *= a / t;
    }
}

/// FISTA on the cone (condim 4 and 6) from `start`, step 1/λ_max(B).
fn surface_fista(b: &[[f64; 6]; 6], g: &[f64; 6], dim: usize, start: [f64; 6]) -> [f64; 6] {
    let mut v = [1.0; 6];
    let mut lmax = 0.0;
    for _ in 0..30 {
        let mut w = [0.0; 6];
        for r in 0..dim {
            w[r] = (0..dim).map(|c| b[r][c] * v[c]).sum();
        }
        lmax = w[..dim].iter().map(|a| a * a).sum::<f64>().sqrt();
        if lmax == 0.0 {
            break;
        }
        for r in 0..dim {
            v[r] = w[r] / lmax;
        }
    }
    let step = 1.0 / (1.01 * lmax).max(f64::MIN_POSITIVE);
    let mut x = start;
    project_cone(&mut x[..dim]);
    let (mut y, mut t) = (x, 1.0_f64);
    for _ in 0..300 {
        let mut next = [0.0; 6];
        for r in 0..dim {
            let grad: f64 = (0..dim).map(|c| b[r][c] * y[c]).sum::<f64>() + g[r];
            next[r] = y[r] - step * grad;
        }
        project_cone(&mut next[..dim]);
        let t_next = 0.5 * (1.0 + (1.0 + 4.0 * t * t).sqrt());
        for r in 0..dim {
            y[r] = next[r] + (t - 1.0) / t_next * (next[r] - x[r]);
        }
        x = next;
        t = t_next;
    }
    x
}

/// M⁻¹ Jᵀ into `soft.minv_jt` and the dual matrix J M⁻¹ Jᵀ of the rows into `soft.ar` (both
/// grown once for larger problems): what PGS (with R added) and the no-slip sweeps work on.
pub(crate) fn dual_matrix(model: &Model, data: &mut Data) {
    let nv = model.nv;
    let n = data.nefc;
    if data.soft.ar.nrows() < n {
        data.soft.ar = DMatrix::zeros(n, n);
        data.soft.minv_jt = DMatrix::zeros(nv, n);
    }
    for i in 0..n {
        let mut col = data.soft.minv_jt.column_mut(i);
        for k in 0..nv {
            col[k] = data.efc_j[(i, k)];
        }
        solve_with_factor_unchecked(model, &data.mass_factor, data.soft.minv_jt.column_mut(i).as_mut_slice());
    }
    for i in 0..n {
        for j in 0..=i {
            let a: f64 = (0..nv).map(|k| data.efc_j[(i, k)] * data.soft.minv_jt[(k, j)]).sum();
            data.soft.ar[(i, j)] = a;
            data.soft.ar[(j, i)] = a;
        }
    }
}

/// Solves the soft problem by PGS; writes the same outputs as
/// `solve_primal` (the unconverged count included).
pub fn solve_pgs(model: &Model, data: &mut Data, s: Settings) {
    let nv = model.nv;
    let n = data.nefc;
    // AR = J M⁻¹ Jᵀ + diag(R).
    dual_matrix(model, data);
    for i in 0..n {
        data.soft.ar[(i, i)] += data.efc_r[i];
    }
    // b = J a₀ − aref in `jar`; forces from the warm start's rows are not kept: start at 0.
    for i in 0..n {
        let ja: f64 = (0..nv).map(|k| data.efc_j[(i, k)] * data.qacc_smooth[k]).sum();
        data.soft.jar[i] = ja - data.efc_aref[i];
    }
    data.efc_force.rows_mut(0, n).fill(0.0);
    let dual_cost = |data: &Data| -> f64 {
        let f = &data.efc_force;
        let mut c = 0.0;
        for i in 0..n {
            let af: f64 = (0..n).map(|j| data.soft.ar[(i, j)] * f[j]).sum();
            c += f[i] * (0.5 * af + data.soft.jar[i]);
        }
        c
    };
    let mut cost = 0.0;
    let mut iter = 0;
    let mut improvement = f64::INFINITY;
    while iter < s.iterations {
        iter += 1;
        // The forces at the sweep's start (in `jv`, free in the dual solve).
        for i in 0..n {
            data.soft.jv[i] = data.efc_force[i];
        }
        let mut i = 0;
        while i < n {
            let kind = data.efc_type[i];
            let residual = |data: &Data, r: usize| -> f64 {
                let af: f64 = (0..n).map(|j| data.soft.ar[(r, j)] * data.efc_force[j]).sum();
                af + data.soft.jar[r]
            };
            if kind == EfcType::ContactElliptic && i >= data.ne + data.nf {
                let c = data.contacts[data.efc_id[i]];
                let dim = c.condim.clamp(1, 6) as usize;
                elliptic_block(data, i, dim, &c.friction, residual);
                i += dim;
                continue;
            }
            let f = data.efc_force[i] - residual(data, i) / data.soft.ar[(i, i)];
            data.efc_force[i] = if i < data.ne {
                f
            } else if i < data.ne + data.nf {
                let b = data.efc_frictionloss[i];
                f.clamp(-b, b)
            } else {
                f.max(0.0)
            };
            i += 1;
        }
        let new_cost = dual_cost(data);
        improvement = s.scale * (cost - new_cost);
        cost = new_cost;
        // MuJoCo's test on the scaled improvement of the cost, and a sweep that no longer moves
        // the forces (Gauss–Seidel creeps on ill-conditioned cones: a small improvement per sweep
        // alone does not mean convergence).
        let moved = (0..n).fold(0.0_f64, |m, i| m.max((data.efc_force[i] - data.soft.jv[i]).abs()));
        let size = data.efc_force.rows(0, n).amax().max(f64::MIN_POSITIVE);
        if improvement.abs() < s.tolerance && moved <= s.tolerance * size {
            break;
        }
    }
    // a = a₀ + M⁻¹ Jᵀ f, qfrc_constraint = Jᵀ f.
    data.qacc.copy_from(&data.qacc_smooth);
    data.qfrc_constraint.fill(0.0);
    for i in 0..n {
        let f = data.efc_force[i];
        if f != 0.0 {
            for k in 0..nv {
                data.qacc[k] += data.soft.minv_jt[(k, i)] * f;
                data.qfrc_constraint[k] += data.efc_j[(i, k)] * f;
            }
        }
    }
    data.solver_niter = iter;
    data.solver_improvement = improvement.abs();
    data.solver_gradient = 0.0;
    // MuJoCo's criterion (the last sweep's scaled improvement below the tolerance; the creep test
    // above only makes more sweeps): a solve that swept to its limit without meeting it is
    // counted, with that improvement as the residual (none to count with no sweep: iterations 0).
    let converged = improvement.abs() < s.tolerance;
    data.efc_converged = converged;
    if !converged && iter > 0 {
        data.efc_unconverged += 1;
        data.efc_unconverged_residual = data.efc_unconverged_residual.max(improvement.abs());
    }
}
