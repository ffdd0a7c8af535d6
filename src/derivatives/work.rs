//! [`DerivativesWork`]: the preallocated buffers and results of the derivative kernels
//! ([`rnea_derivatives`](super::rnea_derivatives), [`aba_derivatives`](super::aba_derivatives),
//! [`smooth_derivatives`](super::smooth_derivatives)), made once per model so that the kernels
//! allocate nothing.

use super::rnea_sweep::RneaSweep;
use crate::error::InputError;
use crate::Model;
use nalgebra::{DMatrix, DVector};

/// Buffers and results of the derivative kernels for one model. Matrices are nv × nv, rows the
/// outputs (τ or q̈ components), columns the inputs; q columns are in each joint's tangent
/// space (MuJoCo's `mj_integratePos` layout), velocities, accelerations and forces in lagrange's
/// (MuJoCo's) coordinates. See docs/derivatives.md.
pub struct DerivativesWork {
    pub(crate) sweep: RneaSweep,
    /// ∂τ/∂q of inverse dynamics (tangent columns).
    pub dtau_dq: DMatrix<f64>,
    /// ∂τ/∂v of inverse dynamics (= ∂c/∂v, independent of the acceleration).
    pub dtau_dv: DMatrix<f64>,
    /// ∂q̈/∂q of forward dynamics (tangent columns).
    pub dqacc_dq: DMatrix<f64>,
    /// ∂q̈/∂v of forward dynamics.
    pub dqacc_dv: DMatrix<f64>,
    /// ∂q̈/∂τ = M⁻¹ of forward dynamics.
    pub dqacc_dtau: DMatrix<f64>,
    /// The acceleration the forward-dynamics derivatives were taken at.
    pub qacc: DVector<f64>,
    /// The generalized force the forward-dynamics derivatives were taken at (for
    /// [`smooth_derivatives`](super::smooth_derivatives): passive + actuator + applied).
    pub tau: DVector<f64>,
    /// 3 nv × nv scratch of the solves (the three right-hand sides stacked).
    pub(crate) scratch: DMatrix<f64>,
}

impl DerivativesWork {
    /// Buffers sized for `model`, every result zero.
    pub fn new(model: &Model) -> Self {
        let nv = model.nv;
        Self {
            sweep: RneaSweep::new(model),
            dtau_dq: DMatrix::zeros(nv, nv),
            dtau_dv: DMatrix::zeros(nv, nv),
            dqacc_dq: DMatrix::zeros(nv, nv),
            dqacc_dv: DMatrix::zeros(nv, nv),
            dqacc_dtau: DMatrix::zeros(nv, nv),
            qacc: DVector::zeros(nv),
            tau: DVector::zeros(nv),
            scratch: DMatrix::zeros(3 * nv, nv),
        }
    }

    /// [`InputError::Length`] when the buffers were made for a model of another size.
    pub(crate) fn check(&self, function: &'static str, model: &Model) -> Result<(), InputError> {
        InputError::check_len(function, "work (dofs)", self.qacc.len(), model.nv, "nv")?;
        InputError::check_len(function, "work (bodies)", self.sweep.nbody(), model.nbody(), "nbody")
    }
}
