//! Articulated-body algorithm for forward dynamics (RBDA §7.3, Table 7.1).

use crate::dynamics::crba::{crba_unchecked, factorize_mass_matrix, solve_with_factor_unchecked};
use crate::dynamics::rnea::rnea_unchecked;
use crate::error::{check, InputError};
use crate::kinematics::{joint_velocity, update_joint};
use crate::model::warning::MIN_PIVOT;
use crate::model::{Data, Model};
use crate::spatial::{ArticulatedInertia, Force, Motion, Vec3};
use nalgebra::{DVector, Matrix6};

/// Forward dynamics q̈ = M(q)⁻¹ (τ − c(q, v)) into `data.aba_qacc` (and returned), in O(n), armature
/// included.
///
/// A mass matrix singular at q (duplicated joints, a moving body without mass or inertia: a
/// joint's articulated inertia D = Sᵀ Iᴬ S below MuJoCo's `mjMINVAL` = 1e-15, [`MIN_PIVOT`]) gives
/// MuJoCo 4.0's regularized result instead of ABA's division by a vanishing D: q̈ from M's LᵀDL
/// factor with its small pivots raised to 1e-15 ([`factorize_mass_matrix`]), warned in
/// `data.warnings.inertia` (the dofs named). ABA's D of a dof is that factor's pivot, so the
/// same states are caught; the extra cost is a comparison per body on regular states.
///
/// On x86-64 CPUs with AVX2 the kernel runs compiled for AVX2 (chosen at run time): the same
/// operations in the same order, so the same bits (`avx2_kernel_is_bit_for_bit`), in fewer,
/// 3-operand instructions.
///
/// # Errors
/// [`InputError::Length`] when q is not nq long, v or tau not nv long, or `data` was made for
/// another model; nothing is computed then.
///
/// ```
/// use lagrange::prelude::*;
/// let model = Model::from_file("models/ur5/ur5.urdf")?;
/// let mut data = Data::new(&model);
/// let (q, v) = (vec![0.1; 6], vec![0.0; 6]);
/// // The torques RNEA says hold the arm still give zero acceleration back.
/// let tau = lagrange::dynamics::rnea(&model, &mut data, &q, &v, &[0.0; 6])?.clone();
/// let qacc = lagrange::dynamics::aba(&model, &mut data, &q, &v, tau.as_slice())?;
/// assert!(qacc.amax() < 1e-9);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn aba<'d>(
    model: &Model,
    data: &'d mut Data,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
) -> Result<&'d DVector<f64>, InputError> {
    check::data("aba", model, data)?;
    check::q("aba", model, q)?;
    check::v("aba", "v", model, v)?;
    check::v("aba", "tau", model, tau)?;
    Ok(aba_unchecked(model, data, q, v, tau))
}

/// [`aba`] without the argument checks (the crate's own callers, whose sizes are right).
pub(crate) fn aba_unchecked<'d>(
    model: &Model,
    data: &'d mut Data,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
) -> &'d DVector<f64> {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2 (checked just above), all `aba_avx2` requires.
        unsafe { aba_avx2(model, data, q, v, tau) };
        regularize_singular(model, data, q, v, tau);
        return &data.aba_qacc;
    }
    aba_kernel(model, data, q, v, tau);
    regularize_singular(model, data, q, v, tau);
    &data.aba_qacc
}

/// After ABA: when a joint's D was below [`MIN_PIVOT`] (D⁻¹'s first entry beyond 1e15, or not
/// finite: a singular multi-dof D leaves NaN there), `data.aba_qacc` = M⁻¹ (τ − c) with M's
/// regularized factor (MuJoCo's `mj_factorM` and `mj_solveM` at a singular M).
#[inline]
fn regularize_singular(model: &Model, data: &mut Data, q: &[f64], v: &[f64], tau: &[f64]) {
    if (1..model.nbody()).all(|b| data.d_inv[b][(0, 0)].abs() <= 1.0 / MIN_PIVOT) {
        return;
    }
    crba_unchecked(model, data, q);
    factorize_mass_matrix(model, data);
    data.aba_qacc.fill(0.0);
    let mut x = std::mem::take(&mut data.aba_qacc);
    // c(q, v) into data.tau: RNEA at zero acceleration.
    rnea_unchecked(model, data, q, v, x.as_slice());
    for k in 0..model.nv {
        x[k] = tau[k] - data.tau[k];
    }
    solve_with_factor_unchecked(model, &data.mass_factor, x.as_mut_slice());
    data.aba_qacc = x;
}

/// [`aba_kernel`] compiled for AVX2 (no fused multiply–add: the bits of the baseline build).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn aba_avx2(model: &Model, data: &mut Data, q: &[f64], v: &[f64], tau: &[f64]) {
    aba_kernel(model, data, q, v, tau);
}

#[inline(always)]
fn aba_kernel(model: &Model, data: &mut Data, q: &[f64], v: &[f64], tau: &[f64]) {
    let nb = model.nbody();
    // The joint transforms and subspaces of an earlier pass at this q (the collision pass's,
    // the same bits) are not formed again (`Data::poses_stamp`).
    let posed = data.poses_stamp.matches(q);
    if !posed {
        data.poses_stamp.clear();
    }
    data.v_body[0] = Motion::zero();
    // Pass 1, root to leaves: velocities, velocity-product accelerations c, and the rigid-body
    // inertias and bias forces pᴬ = v ×* I v that start the articulated quantities.
    for b in 1..nb {
        if !posed {
            update_joint(model, data, b, q);
        }
        let p = model.bodies[b].parent;
        let v_joint = joint_velocity(model, data, b, v);
        let v_body = data.x_parent_body[b].inv_act_motion(&data.v_body[p]) + v_joint;
        let j = model.joint_of(b);
        data.c_body[b] = j.kind.bias_motion(&v_joint) + v_body.cross_motion(&v_joint);
        let inertia = &model.bodies[b].inertia;
        data.i_articulated[b] = ArticulatedInertia::from(inertia);
        data.f_body[b] = v_body.cross_force(&inertia.mul_motion(&v_body));
        data.v_body[b] = v_body;
    }
    // The body velocities at (q, v), as RNEA's and `forward_velocities`' (the same expression).
    data.velocity_stamp.set(q, v);
    // Pass 2, leaves to root: U = Iᴬ S, D = Sᵀ U, u = τ − Sᵀ pᴬ; hand the articulated inertia
    // Iᵃ = Iᴬ − U D⁻¹ Uᵀ and bias pᵃ = pᴬ + Iᵃ c + U D⁻¹ u to the parent (RBDA eq. 7.42–7.43).
    for b in (1..nb).rev() {
        let j = model.joint_of(b);
        let (da, nv_j) = (j.dof_adr, j.kind.nv());
        let i_a = data.i_articulated[b];
        let p_a = data.f_body[b];
        let mut i_handed = i_a;
        let mut p_handed = p_a;
        // A body on the world hands nothing on: only D⁻¹, U and u are needed (pass 3).
        let p = model.bodies[b].parent;
        let hands_on = p != 0;
        if nv_j == 1 {
            let u_col = i_a.mul_motion(&data.s_body[da]);
            let d = data.s_body[da].dot(&u_col) + model.dof_armature[da];
            let d_inv = 1.0 / d;
            let u = tau[da] - data.s_body[da].dot(&p_a);
            data.u_dof[da] = u_col;
            data.u_tau[da] = u;
            data.d_inv[b][(0, 0)] = d_inv;
            if hands_on {
                i_handed.sub_rank_one(&u_col, d_inv);
                p_handed += u_col * (d_inv * u);
            }
        } else {
            let mut d = Matrix6::<f64>::identity();
            for k in 0..nv_j {
                data.u_dof[da + k] = i_a.mul_motion(&data.s_body[da + k]);
                data.u_tau[da + k] = tau[da + k] - data.s_body[da + k].dot(&p_a);
            }
            for k in 0..nv_j {
                for l in 0..nv_j {
                    d[(k, l)] = data.s_body[da + k].dot(&data.u_dof[da + l]);
                }
                d[(k, k)] += model.dof_armature[da + k];
            }
            // D is embedded in an identity so that the fixed-size inverse holds D⁻¹ top-left.
            let d_inv = d.try_inverse().unwrap_or_else(|| Matrix6::from_element(f64::NAN));
            data.d_inv[b] = d_inv;
            for k in 0..if hands_on { nv_j } else { 0 } {
                let mut coeff_u = 0.0;
                for l in 0..nv_j {
                    i_handed.sub_outer(&data.u_dof[da + k], &data.u_dof[da + l], d_inv[(k, l)]);
                    coeff_u += d_inv[(k, l)] * data.u_tau[da + l];
                }
                p_handed += data.u_dof[da + k] * coeff_u;
            }
        }
        if hands_on {
            p_handed += i_handed.mul_motion(&data.c_body[b]);
            let x = data.x_parent_body[b];
            let mut target = data.i_articulated[p];
            i_handed.add_transformed_to(&x, &mut target);
            data.i_articulated[p] = target;
            data.f_body[p] += x.act_force(&p_handed);
        }
    }
    // Pass 3, root to leaves: accelerations q̈ = D⁻¹(u − Uᵀ a′), a = a′ + S q̈ with
    // a′ = X a_parent + c; gravity enters as the world's upward acceleration.
    data.a_body[0] = Motion::new(Vec3::zeros(), -model.gravity);
    for b in 1..nb {
        let j = model.joint_of(b);
        let (da, nv_j) = (j.dof_adr, j.kind.nv());
        let p = model.bodies[b].parent;
        let a_prime = data.x_parent_body[b].inv_act_motion(&data.a_body[p]) + data.c_body[b];
        let mut a_body = a_prime;
        let mut rhs = [0.0; 6];
        for k in 0..nv_j {
            rhs[k] = data.u_tau[da + k] - a_prime.dot(&data.u_dof[da + k]);
        }
        for k in 0..nv_j {
            let mut acc = 0.0;
            for (l, r) in rhs.iter().enumerate().take(nv_j) {
                acc += data.d_inv[b][(k, l)] * r;
            }
            data.aba_qacc[da + k] = acc;
            a_body += data.s_body[da + k] * acc;
        }
        data.a_body[b] = a_body;
    }
}

impl ArticulatedInertia {
    /// Subtracts `coeff · u₁ u₂ᵀ` (one term of U D⁻¹ Uᵀ for multi-dof joints).
    #[inline]
    pub(crate) fn sub_outer(&mut self, u1: &Force, u2: &Force, coeff: f64) {
        let n1 = u1.ang * coeff;
        let f1 = u1.lin * coeff;
        self.a -= n1 * u2.ang.transpose();
        self.b -= n1 * u2.lin.transpose();
        self.c -= f1 * u2.lin.transpose();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The AVX2 build of the kernel gives q̈ bit for bit (no fused multiply–add, no reordering).
    #[test]
    #[cfg(target_arch = "x86_64")]
    #[ignore = "compares the CPU-specific (AVX2/FMA) build of the kernel with the portable one; needs such a CPU: cargo test --release -p lagrange --lib -- --ignored (as .ci/run does)"]
    fn avx2_kernel_is_bit_for_bit() {
        if !std::arch::is_x86_feature_detected!("avx2") {
            eprintln!("skipped: this CPU has no AVX2, the AVX2 kernel is never used here");
            return;
        }
        for (file, model, q) in crate::kernel_test_states::robots() {
            let mut data = Data::new(&model);
            let v: Vec<f64> = (0..model.nv).map(|k| 0.5 * (k as f64).cos()).collect();
            let tau: Vec<f64> = (0..model.nv).map(|k| 0.3 - 0.1 * k as f64).collect();
            aba_kernel(&model, &mut data, &q, &v, &tau);
            let baseline = data.aba_qacc.clone();
            data.aba_qacc.fill(0.0);
            // SAFETY: AVX2 is present (checked above).
            unsafe { aba_avx2(&model, &mut data, &q, &v, &tau) };
            assert_eq!(baseline.as_slice(), data.aba_qacc.as_slice(), "{file}");
        }
    }
}
