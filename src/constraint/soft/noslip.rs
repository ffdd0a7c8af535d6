//! MuJoCo's no-slip post-process (`<option noslip_iterations noslip_tolerance>`; MuJoCo's
//! `mj_solNoSlip`, engine_solver.c, called by engine_forward.c after the main solver): projected
//! Gauss–Seidel sweeps on the dual without regularisation (A = J M⁻¹ Jᵀ, R = 0) over the
//! friction-loss rows (clamped to ±frictionloss) and the pyramidal contacts' opposing edge pairs
//! (their sum, the normal force, fixed; the split minimised on [0, sum]), the other rows' forces
//! fixed; then qacc = qacc_smooth + M⁻¹ Jᵀ f and qfrc_constraint = Jᵀ f. A sweep's change that
//! raises the cost is undone; the sweeps stop when the scaled improvement is below
//! `noslip_tolerance`. Elliptic cones' friction rows are left as the main solver set them (not
//! done yet: MuJoCo's QCQP on the cone of the fixed normal force).

use crate::model::{Data, EfcType, Model};

/// MuJoCo's guard against a vanishing diagonal (mjMINVAL).
const MIN_VAL: f64 = 1e-15;

/// The cost change ½ δᵀ A δ + δᵀ res of a block's update; a rise above 1e-10 restores the old
/// forces (MuJoCo's costChange).
fn cost_change(data: &mut Data, rows: &[usize], old: &[f64], res: &[f64]) -> f64 {
    let mut change = 0.0;
    for (a, &i) in rows.iter().enumerate() {
        let da = data.efc_force[i] - old[a];
        change += da * res[a];
        for (b, &j) in rows.iter().enumerate() {
            change += 0.5 * da * data.soft.ar[(i, j)] * (data.efc_force[j] - old[b]);
        }
    }
    if change > 1e-10 {
        for (a, &i) in rows.iter().enumerate() {
            data.efc_force[i] = old[a];
        }
        return 0.0;
    }
    change
}

/// Runs the no-slip sweeps on `data`'s rows after the main soft solve; `scale` is the solver's
/// improvement scale 1 / (meaninertia · nv). Updates `efc_force`, `qacc`, `qfrc_constraint` and
/// adds its sweeps to `solver_niter`.
pub fn solve_noslip(model: &Model, data: &mut Data, scale: f64) {
    let nv = model.nv;
    let n = data.nefc;
    super::pgs::dual_matrix(model, data);
    for i in 0..n {
        // b = J a₀ − aref
        let ja: f64 = (0..nv).map(|k| data.efc_j[(i, k)] * data.qacc_smooth[k]).sum();
        data.soft.jar[i] = ja - data.efc_aref[i];
    }
    let residual = |data: &Data, r: usize| -> f64 {
        let af: f64 = (0..n).map(|j| data.soft.ar[(r, j)] * data.efc_force[j]).sum();
        af + data.soft.jar[r]
    };
    let (ne, nf) = (data.ne, data.nf);
    let mut iter = 0;
    while iter < model.options.noslip_iterations {
        let mut improvement = 0.0;
        if iter == 0 {
            for i in 0..n {
                improvement += 0.5 * data.efc_force[i] * data.efc_force[i] * data.efc_r[i];
            }
        }
        for i in ne..ne + nf {
            let res = residual(data, i);
            let old = data.efc_force[i];
            let a = data.soft.ar[(i, i)];
            let b = data.efc_frictionloss[i];
            data.efc_force[i] = (old - res / a).clamp(-b, b);
            let d = data.efc_force[i] - old;
            improvement -= 0.5 * d * d * a + d * res;
        }
        let mut i = ne + nf;
        while i < n {
            if data.efc_type[i] != EfcType::ContactPyramidal {
                i += 1;
                continue;
            }
            let dim = data.contacts[data.efc_id[i]].condim.clamp(1, 6) as usize;
            let mut j = i;
            while j < i + 2 * (dim - 1) {
                let res = [residual(data, j), residual(data, j + 1)];
                let old = [data.efc_force[j], data.efc_force[j + 1]];
                let ac = [
                    data.soft.ar[(j, j)],
                    data.soft.ar[(j, j + 1)],
                    data.soft.ar[(j + 1, j)],
                    data.soft.ar[(j + 1, j + 1)],
                ];
                let bc = [res[0] - ac[0] * old[0] - ac[1] * old[1], res[1] - ac[2] * old[0] - ac[3] * old[1]];
                let mid = 0.5 * (old[0] + old[1]);
                let k1 = ac[0] + ac[3] - ac[1] - ac[2];
                let k0 = mid * (ac[0] - ac[3]) + bc[0] - bc[1];
                let (f0, f1) = if k1 < MIN_VAL {
                    (mid, mid)
                } else {
                    let y = -k0 / k1;
                    if y < -mid {
                        (0.0, 2.0 * mid)
                    } else if y > mid {
                        (2.0 * mid, 0.0)
                    } else {
                        (mid + y, mid - y)
                    }
                };
                data.efc_force[j] = f0;
                data.efc_force[j + 1] = f1;
                improvement -= cost_change(data, &[j, j + 1], &old, &res);
                j += 2;
            }
            i += 2 * (dim - 1);
        }
        improvement *= scale;
        iter += 1;
        if improvement < model.options.noslip_tolerance {
            break;
        }
    }
    data.solver_niter += iter;
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
}
