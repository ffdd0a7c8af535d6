//! The exact mode's energy guard for an iterative contact solve that did not converge: the
//! forces it leaves must not add kinetic energy.
//!
//! With Y = M⁻¹Jᵀ and A = J Y (the Delassus matrix), forces λ acting over a step h change the
//! velocity the step would reach without them, v′, by h Y λ, and the kinetic energy by exactly
//! ΔT(λ) = h λᵀ J v′ + ½ h² λᵀ A λ (at the velocity level, impulses μ added to v:
//! ΔT(μ) = μᵀ J v + ½ μᵀ A μ). A converged solve satisfies Signorini's and Coulomb's laws, whose
//! forces do no positive work (docs/physics.md §2.5); an iterate stopped early (the iteration limit,
//! the work budget, or a Gauss–Seidel sweep that wanders on the non-symmetric sliding law) may
//! push bodies apart with forces no contact can give. When ΔT(λ) > 0, λ is replaced by s λ with
//! s = argmin ΔT(s λ) = −λᵀ J v′ / (h λᵀ A λ) clamped to [0, 1]: the same force directions (still in
//! every cone and box that contains 0), scaled to take out as much energy as they can, and never
//! to add any. Only unconverged solves are guarded: a converged solve is the law itself.

use super::coulomb::column_dot;
use crate::model::Data;

/// Scales the forces of an unconverged solve (λ in `exact.rhs`, first nefc entries) so that
/// they do not add kinetic energy. `jv_free[i]` is J_i v′, the row velocity the step reaches
/// without the forces, and `h` the step (1 at the velocity level, where λ are impulses). Needs
/// the full (symmetric) Delassus matrix in `exact.delassus`. Returns the scale applied (1 when
/// nothing changed).
pub(crate) fn limit_energy(data: &mut Data, h: f64, jv_free: impl Fn(&Data, usize) -> f64) -> f64 {
    let n = data.nefc;
    let lambda = &data.exact.rhs.as_slice()[..n];
    let mut quadratic = 0.0;
    for j in 0..n {
        if lambda[j] == 0.0 {
            continue;
        }
        // (A λ)_j down column j, over the Delassus pattern (the same sum without exact zeros).
        let a_lambda = column_dot(data, j, lambda);
        quadratic += lambda[j] * a_lambda;
    }
    let linear: f64 = (0..n).map(|i| lambda[i] * jv_free(data, i)).sum();
    let gain = h * linear + 0.5 * h * h * quadratic;
    if gain.is_finite() && gain <= 0.0 {
        return 1.0;
    }
    let s = if quadratic > 0.0 && quadratic.is_finite() && linear.is_finite() {
        (-linear / (h * quadratic)).clamp(0.0, 1.0)
    } else {
        0.0
    };
    for l in &mut data.exact.rhs.as_mut_slice()[..n] {
        *l *= s;
    }
    data.efc_energy_limited += 1;
    s
}
