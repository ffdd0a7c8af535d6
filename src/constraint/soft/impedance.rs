//! Per-row parameters of the soft constraint model (MuJoCo documentation, "Computation → Soft
//! constraints" and "XML Reference → solref / solimp"; MuJoCo's `mj_diagApprox` and
//! `mj_makeImpedance`):
//!
//! - the impedance d(r) ∈ (0, 1) from `solimp` = (dmin, dmax, width, midpoint, power): d = dmin
//!   at r = 0 rising to dmax at |r| ≥ width along two power-law halves joined at the midpoint,
//!   with r the row's violation (pos − margin; the norm of the 3 or 6 rows of a connect or weld);
//! - stiffness k and damping b from `solref`: (timeconst, dampratio) > 0 gives
//!   b = 2 / (dmax · timeconst), k = 1 / (dmax² · timeconst² · dampratio²) (timeconst raised to
//!   2 · timestep unless `refsafe` is off); negative values are (−stiffness, −damping) directly,
//!   k = stiffness / dmax², b = damping / dmax. Friction rows have k = 0;
//! - the regularizer R = (1 − d)/d · Â with Â the diagonal approximation of J M⁻¹ Jᵀ from the
//!   inverse weights ([`InverseWeights`]); for frictional contacts R of the first tangent row is
//!   R_normal / impratio, the other friction rows keep R_i μ_i² equal, the regularized cone's
//!   μ = μ₁ √(R₁/R₀), and a pyramidal contact's rows all get 2 μ² R_normal; D = 1/R;
//! - the reference acceleration aref = −b · J v − k · d · (pos − margin), minus J̇ v for connect
//!   and weld rows.

use super::weights::InverseWeights;
use crate::model::{Data, EfcType, EqualityKind, Model};

/// MuJoCo's `mjMINVAL`, `mjMINIMP` and `mjMAXIMP`.
const MINVAL: f64 = 1e-15;
const MINIMP: f64 = 0.0001;
const MAXIMP: f64 = 0.9999;

/// Impedance d and its derivative at violation `x` = pos − margin (MuJoCo's `getimpedance`).
pub fn impedance(solimp: &[f64; 5], x: f64) -> (f64, f64) {
    let [dmin, dmax, width, mid, power] = *solimp;
    if dmin == dmax || width <= MINVAL {
        return (0.5 * (dmin + dmax), 0.0);
    }
    let (mut y, sgn) = (x / width, if x < 0.0 { -1.0 } else { 1.0 });
    y = y.abs();
    if y >= 1.0 || y <= 0.0 {
        return (if y >= 1.0 { dmax } else { dmin }, 0.0);
    }
    let (f, df) = if power == 1.0 {
        (y, 1.0)
    } else if power == 2.0 {
        // MJCF's default: the same halves without calls to pow (x¹ = x, x² = x · x).
        if y <= mid {
            let a = 1.0 / mid;
            (a * (y * y), power * a * y)
        } else {
            let (b, z) = (1.0 / (1.0 - mid), 1.0 - y);
            (1.0 - b * (z * z), power * b * z)
        }
    } else if y <= mid {
        let a = 1.0 / mid.powf(power - 1.0);
        (a * y.powf(power), power * a * y.powf(power - 1.0))
    } else {
        let b = 1.0 / (1.0 - mid).powf(power - 1.0);
        (1.0 - b * (1.0 - y).powf(power), power * b * (1.0 - y).powf(power - 1.0))
    };
    (dmin + f * (dmax - dmin), df * sgn * (dmax - dmin) / width)
}

/// `solref` and `solimp` as MuJoCo uses them: mixed-sign `solref` replaced by the default, the
/// time constant raised to 2 · timestep (`refsafe`), `solimp` clamped to its valid range.
fn sanitize(model: &Model, solref: [f64; 2], solimp: [f64; 5], friction: bool) -> ([f64; 2], [f64; 5]) {
    let mut solref = solref;
    if (solref[0] > 0.0) != (solref[1] > 0.0) {
        solref = if friction { [0.0, 0.0] } else { crate::model::equality::DEFAULT_SOLREF };
    }
    if model.options.flags.refsafe && solref[0] > 0.0 {
        solref[0] = solref[0].max(2.0 * model.options.timestep);
    }
    let mut s = solimp;
    s[0] = s[0].clamp(MINIMP, MAXIMP);
    s[1] = s[1].clamp(MINIMP, MAXIMP);
    s[2] = s[2].max(0.0);
    s[3] = s[3].clamp(MINIMP, MAXIMP);
    s[4] = s[4].max(1.0);
    (solref, s)
}

/// (k, b) of `solref` for impedance width dmax (module doc).
fn stiffness_damping(solref: &[f64; 2], dmax: f64) -> (f64, f64) {
    let k = if solref[0] > 0.0 {
        1.0 / (dmax * dmax * solref[0] * solref[0] * solref[1] * solref[1]).max(MINVAL)
    } else {
        -solref[0] / (dmax * dmax).max(MINVAL)
    };
    let b =
        if solref[1] > 0.0 { 2.0 / (dmax * solref[0]).max(MINVAL) } else { -solref[1] / dmax.max(MINVAL) };
    (k, b)
}

/// `efc_diag_a` of the block at row `i`: MuJoCo's diagonal approximation of J M⁻¹ Jᵀ per row
/// (`mj_diagApprox`); an equality's block is its `nrow` rows, a pyramidal contact's its
/// 2 (dim − 1) edges in pairs.
fn diag_approx(model: &Model, w: &InverseWeights, data: &mut Data, i: usize) {
    let id = data.efc_id[i];
    let kind = data.efc_type[i];
    let diag_a = data.efc_diag_a.as_mut_slice();
    match kind {
        EfcType::Equality => {
            let eq = &model.equalities[id];
            let n = eq.kind.nrow();
            let frames = |f1: usize, f2: usize| (w.of_frame(model, f1), w.of_frame(model, f2));
            for k in 0..n {
                diag_a[i + k] = match &eq.kind {
                    EqualityKind::Connect { frame1, frame2, .. } => {
                        let (a, b) = frames(*frame1, *frame2);
                        a[0] + b[0]
                    }
                    EqualityKind::Weld { frame1, frame2, .. } => {
                        let (a, b) = frames(*frame1, *frame2);
                        let rot = usize::from(k > 2);
                        a[rot] + b[rot]
                    }
                    EqualityKind::Joint { joint1, joint2, .. } => {
                        let dof = |j: usize| w.dof_invweight0[model.joints[j].dof_adr];
                        dof(*joint1) + joint2.map_or(0.0, dof)
                    }
                    EqualityKind::Mimic { joint, leader, .. } => {
                        let dof = |j: usize| w.dof_invweight0[model.joints[j].dof_adr];
                        dof(*joint) + dof(*leader)
                    }
                    EqualityKind::Tendon { tendon1, tendon2, .. } => {
                        w.tendon_invweight0[*tendon1] + tendon2.map_or(0.0, |t| w.tendon_invweight0[t])
                    }
                };
            }
        }
        EfcType::FrictionDof => diag_a[i] = w.dof_invweight0[id],
        EfcType::LimitJoint => diag_a[i] = w.dof_invweight0[model.joints[id].dof_adr],
        EfcType::LimitTendon | EfcType::FrictionTendon => diag_a[i] = w.tendon_invweight0[id],
        kind => {
            let c = &data.contacts[id];
            let (mut tran, mut rot) = (0.0, 0.0);
            for g in c.geom {
                let iw = w.frame_invweight0[w.geom_frame[g]];
                tran += iw[0];
                rot += iw[1];
            }
            let dim = c.condim.clamp(1, 6) as usize;
            match kind {
                EfcType::ContactFrictionless => diag_a[i] = tran,
                EfcType::ContactElliptic => {
                    for j in 0..dim {
                        diag_a[i + j] = if j < 3 { tran } else { rot };
                    }
                }
                _ => {
                    for j in 0..dim - 1 {
                        let f = c.friction[j];
                        let v = tran + f * f * if j < 2 { tran } else { rot };
                        diag_a[i + 2 * j] = v;
                        diag_a[i + 2 * j + 1] = v;
                    }
                }
            }
        }
    }
}

/// `solref`, `solreffriction` (contacts only, else zero) and `solimp` of row `i`.
fn parameters(model: &Model, data: &Data, i: usize) -> ([f64; 2], [f64; 2], [f64; 5]) {
    let id = data.efc_id[i];
    match data.efc_type[i] {
        EfcType::Equality => {
            let e = &model.equalities[id];
            (e.solref, [0.0; 2], e.solimp)
        }
        EfcType::LimitJoint => {
            let s = &model.joints[id].soft;
            (s.solref_limit, [0.0; 2], s.solimp_limit)
        }
        EfcType::LimitTendon => {
            let s = &model.tendons[id].soft;
            (s.solref_limit, [0.0; 2], s.solimp_limit)
        }
        EfcType::FrictionTendon => {
            let s = &model.tendons[id].soft;
            (s.solref_friction, [0.0; 2], s.solimp_friction)
        }
        EfcType::FrictionDof => {
            let s = &model.joint_of(model.dof_body[id]).soft;
            (s.solref_friction, [0.0; 2], s.solimp_friction)
        }
        _ => {
            let c = &data.contacts[id];
            (c.solref, c.solreffriction, c.solimp)
        }
    }
}

/// The row's violation for the impedance and the number of rows sharing it (module doc).
fn violation(model: &Model, data: &Data, i: usize, len: usize) -> (f64, usize) {
    match data.efc_type[i] {
        EfcType::Equality => match model.equalities[data.efc_id[i]].kind {
            EqualityKind::Connect { .. } => (data.efc_pos.rows(i, 3).norm(), 3),
            EqualityKind::Weld { .. } => {
                let n = model.equalities[data.efc_id[i]].kind.nrow();
                (data.efc_pos.rows(i, n).norm(), n)
            }
            _ => (data.efc_pos[i], 1),
        },
        _ => (data.efc_pos[i], len),
    }
}

/// `efc_diag_a`, `efc_kbip`, `efc_r`, `efc_d`, `contact_mu` and `efc_aref` of the rows of
/// `soft_positions` with `efc_vel` and `efc_jdotv`.
#[inline(never)]
pub(crate) fn make_impedance(model: &Model, w: &InverseWeights, data: &mut Data) {
    // One pass over the blocks (a row, an equality's rows, a contact's rows).
    let mut i = 0;
    while i < data.nefc {
        let len = data.efc_block_len(i);
        diag_approx(model, w, data, i);
        let kind = data.efc_type[i];
        let frictional_dof = matches!(kind, EfcType::FrictionDof | EfcType::FrictionTendon);
        let (solref, solreffriction, solimp) = parameters(model, data, i);
        let (solref, solimp) = sanitize(model, solref, solimp, false);
        let (x, dim) = violation(model, data, i, len);
        let (imp, imp_d) = impedance(&solimp, x - data.efc_margin[i]);
        // (k, b) of the block's first row, and of an elliptic contact's friction rows (k = 0,
        // b from `solreffriction` when it is given, else from `solref`).
        let (mut k, b) = stiffness_damping(&solref, solimp[1]);
        if frictional_dof {
            k = 0.0;
        }
        let friction_b = if kind == EfcType::ContactElliptic && dim > 1 {
            let (solreffriction, _) = sanitize(model, solreffriction, solimp, true);
            let sref =
                if solreffriction[0] != 0.0 || solreffriction[1] != 0.0 { &solreffriction } else { &solref };
            stiffness_damping(sref, solimp[1]).1
        } else {
            b
        };
        let (efc_r, efc_diag_a) = (data.efc_r.as_mut_slice(), data.efc_diag_a.as_slice());
        for j in 0..dim {
            let r = i + j;
            efc_r[r] = ((1.0 - imp) * efc_diag_a[r] / imp).max(MINVAL);
            data.efc_kbip[r] = if kind == EfcType::ContactElliptic && j > 0 {
                [0.0, friction_b, imp, imp_d]
            } else {
                [k, b, imp, imp_d]
            };
        }
        // Frictional contacts: R of the friction rows and the regularized cone's μ.
        if matches!(kind, EfcType::ContactElliptic | EfcType::ContactPyramidal) {
            let c = &data.contacts[data.efc_id[i]];
            let efc_r = data.efc_r.as_mut_slice();
            let r1 = efc_r[i] / model.options.impratio.max(MINVAL);
            let mu = c.friction[0] * (r1 / efc_r[i]).sqrt();
            if kind == EfcType::ContactElliptic {
                efc_r[i + 1] = r1;
                for j in 1..len - 1 {
                    efc_r[i + j + 1] = r1 * c.friction[0] * c.friction[0] / (c.friction[j] * c.friction[j]);
                }
            } else {
                let rpy = 2.0 * mu * mu * efc_r[i];
                efc_r[i..i + len].fill(rpy);
            }
            data.contact_mu[data.efc_id[i]] = mu;
        }
        i += dim;
    }
    // Over slices: a `DVector`'s own indexing checks its shape at every access.
    let n = data.nefc;
    let Data {
        efc_d, efc_r, efc_kbip, efc_diag_a, efc_aref, efc_vel, efc_pos, efc_margin, efc_jdotv, ..
    } = &mut *data;
    let (efc_vel, efc_pos, efc_margin, efc_jdotv) = (
        &efc_vel.as_slice()[..n],
        &efc_pos.as_slice()[..n],
        &efc_margin.as_slice()[..n],
        &efc_jdotv.as_slice()[..n],
    );
    let (efc_d, efc_diag_a, efc_aref) = (
        &mut efc_d.as_mut_slice()[..n],
        &mut efc_diag_a.as_mut_slice()[..n],
        &mut efc_aref.as_mut_slice()[..n],
    );
    let (efc_r, efc_kbip) = (&efc_r.as_slice()[..n], &efc_kbip[..n]);
    for i in 0..n {
        efc_d[i] = 1.0 / efc_r[i];
        let [k, b, imp, _] = efc_kbip[i];
        efc_diag_a[i] = efc_r[i] * imp / (1.0 - imp);
        efc_aref[i] = -b * efc_vel[i] - k * imp * (efc_pos[i] - efc_margin[i]) - efc_jdotv[i];
    }
}

#[cfg(test)]
mod tests {
    use super::impedance;

    /// MuJoCo's `getimpedance` halves with `pow`, as the general branch computes them.
    fn by_pow(solimp: &[f64; 5], x: f64) -> (f64, f64) {
        let [dmin, dmax, width, mid, power] = *solimp;
        let y = (x / width).abs();
        let (f, df) = if y <= mid {
            let a = 1.0 / mid.powf(power - 1.0);
            (a * y.powf(power), power * a * y.powf(power - 1.0))
        } else {
            let b = 1.0 / (1.0 - mid).powf(power - 1.0);
            (1.0 - b * (1.0 - y).powf(power), power * b * (1.0 - y).powf(power - 1.0))
        };
        (dmin + f * (dmax - dmin), df * x.signum() * (dmax - dmin) / width)
    }

    #[test]
    fn power_two_without_pow_agrees_with_pow_to_round_off() {
        for mid in [0.5, 0.3, 0.9] {
            let solimp = [0.9, 0.95, 0.001, mid, 2.0];
            for t in 1..200 {
                let x = -0.001 + 0.002 * f64::from(t) / 200.0;
                if x == 0.0 {
                    continue;
                }
                let (d, dd) = impedance(&solimp, x);
                let (d_pow, dd_pow) = by_pow(&solimp, x);
                assert!((d - d_pow).abs() <= 4.0 * f64::EPSILON * d_pow.abs(), "d at {x}: {d} vs {d_pow}");
                assert!(
                    (dd - dd_pow).abs() <= 8.0 * f64::EPSILON * dd_pow.abs(),
                    "d' at {x}: {dd} vs {dd_pow}"
                );
            }
        }
    }
}
