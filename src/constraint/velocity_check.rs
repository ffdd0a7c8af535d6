//! Whether the exact mode's post-step velocity projection would change anything
//! (docs/constraints.md, "Drift correction"): the projection looks for impulses p with
//! v' = v + M⁻¹Jᵀp obeying each row's velocity-level law ([`super::project_velocities`]). When
//! the step's own velocity already obeys them — dry-friction dofs, contacts held closed and every
//! friction row at rest within `tol_v`, the other unilateral rows not approaching faster than
//! `tol_v` — p = 0 is that solution (the step's friction forces are inside their cones already),
//! so the Delassus matrix and the Coulomb solve are skipped. A body resting on its contacts, the
//! common case, pays for J v alone. Equality rows (loops, couplings) are always projected.

use crate::model::{Data, EfcType};

/// Fills `efc_vel` with J v for the current rows and returns whether v already satisfies the
/// velocity projection's conditions to `tol_v` (m/s or rad/s per row).
pub(crate) fn already_projected(data: &mut Data, nv: usize, v: &[f64], tol_v: f64) -> bool {
    let n = data.nefc;
    // J v down J's columns (contiguous in its storage): per row the terms of the row-wise sum in
    // its order, started from the same empty sum, so the same bits.
    let zero: f64 = std::iter::empty::<f64>().sum();
    let stride = data.efc_j.nrows();
    let (j, vel) = (data.efc_j.as_slice(), &mut data.efc_vel.as_mut_slice()[..n]);
    vel.fill(zero);
    for (k, &vk) in v[..nv].iter().enumerate() {
        for (x, &jik) in vel.iter_mut().zip(&j[k * stride..k * stride + n]) {
            *x += jik * vk;
        }
    }
    let mut i = 0;
    while i < n {
        let jv = data.efc_vel[i];
        let len = data.efc_block_len(i);
        let ok = match data.efc_type[i] {
            // Loop closures and couplings are always projected (their solve is a cheap linear
            // one, and it keeps them at round-off rather than at the tolerance).
            EfcType::Equality => false,
            EfcType::FrictionDof => jv.abs() <= tol_v,
            EfcType::LimitJoint | EfcType::ContactFrictionless | EfcType::ContactElliptic => {
                // A row pressing at the last solve is held closed by the projection; any other
                // may separate but not approach.
                let closed = data.efc_previous_force(i, 0) > 0.0;
                let normal = if closed { jv.abs() <= tol_v } else { jv >= -tol_v };
                // Friction rows at rest (sticking): the step's friction is inside its cone.
                normal && (i + 1..i + len).all(|k| data.efc_vel[k].abs() <= tol_v)
            }
            // Rows of the soft mode: never skipped.
            _ => false,
        };
        if !ok || !jv.is_finite() {
            return false;
        }
        i += len;
    }
    true
}
