//! [`rnea_derivatives`]: ∂τ/∂q and ∂τ/∂v of inverse dynamics τ = RNEA(q, v, a) (the quantities
//! of Pinocchio's `computeRNEADerivatives`, in lagrange's coordinates; ∂τ/∂a is the mass
//! matrix M). One sweep root to leaves and one back, in world axes (`rnea_sweep`).

use super::DerivativesWork;
use crate::error::{check, InputError};
use crate::{Data, Model};

/// ∂τ/∂q and ∂τ/∂v of τ = RNEA(q, v, a) into `work.dtau_dq` and `work.dtau_dv` (τ itself is left
/// in `data.tau`). Cost: about three RNEAs plus a few 6-vector products per (dof, ancestor dof)
/// pair, O(nv · depth); no allocation.
///
/// # Errors
/// [`InputError::Length`] when q is not nq long, v or a not nv long, or `data` or `work` was made
/// for another model.
pub fn rnea_derivatives(
    model: &Model,
    data: &mut Data,
    work: &mut DerivativesWork,
    q: &[f64],
    v: &[f64],
    a: &[f64],
) -> Result<(), InputError> {
    check::data("rnea_derivatives", model, data)?;
    work.check("rnea_derivatives", model)?;
    check::q("rnea_derivatives", model, q)?;
    check::v("rnea_derivatives", "v", model, v)?;
    check::v("rnea_derivatives", "a", model, a)?;
    rnea_derivatives_unchecked(model, data, work, q, v, a);
    Ok(())
}

/// [`rnea_derivatives`] without the argument checks.
pub(crate) fn rnea_derivatives_unchecked(
    model: &Model,
    data: &mut Data,
    work: &mut DerivativesWork,
    q: &[f64],
    v: &[f64],
    a: &[f64],
) {
    work.sweep.compute(model, data, q, v, a, (&mut work.dtau_dq, &mut work.dtau_dv));
}
