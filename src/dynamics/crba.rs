//! Composite-rigid-body algorithm for M(q) (RBDA §6.2, Table 6.2) and the tree-sparse LᵀDL
//! factorization and solve (RBDA §6.3, Tables 6.3–6.4).

use crate::kinematics::body_poses;
use crate::model::{Data, Model, NO_DOF};
use nalgebra::{DMatrix, DVector};

/// Joint-space inertia matrix M(q), armature included, into `data.mass_matrix` (and returned).
///
/// The composite-rigid-body algorithm (RBDA Table 6.2) evaluated in world coordinates: composite
/// inertias then add without change of frame, and the entry M[i][j] for j an ancestor degree of
/// freedom is the plain product S_jᵀ (Iᶜ_i S_i) of world-frame vectors, so the walk up the tree
/// transforms nothing.
pub fn crba<'d>(model: &Model, data: &'d mut Data, q: &[f64]) -> &'d DMatrix<f64> {
    // Pass 1: body poses; then world-frame motion subspaces and body inertias.
    body_poses(model, data, q);
    for b in 1..model.nbody() {
        let x_world_body = data.x_world_body[b];
        let j = model.joint_of(b);
        for k in j.dof_adr..j.dof_adr + j.kind.nv() {
            data.s_world[k] = x_world_body.act_motion(&data.s_body[k]);
        }
        data.i_composite[b] = model.bodies[b].inertia.transformed(&x_world_body);
    }
    data.mass_matrix.fill(0.0);
    let nv = model.nv;
    let m = data.mass_matrix.as_mut_slice();
    // Pass 2, leaves to root: F = Iᶜ S for each dof of b, dotted with the S of b and its ancestors;
    // then the finished composite inertia of b joins its parent's.
    for b in (1..model.nbody()).rev() {
        let j = model.joint_of(b);
        let i_c = data.i_composite[b];
        for k in j.dof_adr..j.dof_adr + j.kind.nv() {
            let f_world = i_c.mul_motion(&data.s_world[k]);
            let mut l = k;
            loop {
                // Column-major storage: (row k, col l) at k + l·nv; M is symmetric.
                let m_kl = data.s_world[l].dot(&f_world);
                m[k + l * nv] = m_kl;
                m[l + k * nv] = m_kl;
                l = model.dof_parent[l];
                if l == NO_DOF {
                    break;
                }
            }
            m[k + k * nv] += model.dof_armature[k];
        }
        let p = model.bodies[b].parent;
        if p != 0 {
            data.i_composite[p] += &i_c;
        }
    }
    &data.mass_matrix
}

/// Factorizes `data.mass_matrix` as M = Lᵀ D L into `data.mass_factor`, exploiting the tree's
/// sparsity: fill-in stays on the ancestor paths λ (RBDA Table 6.3). Run [`crba`] first.
pub fn factorize_mass_matrix(model: &Model, data: &mut Data) {
    let lambda = &model.dof_parent;
    let nv = model.nv;
    data.mass_factor.copy_from(&data.mass_matrix);
    // Column-major storage: entry (r, c) at r + c·nv.
    let h = data.mass_factor.as_mut_slice();
    for k in (0..nv).rev() {
        let h_kk = h[k + k * nv];
        let mut i = lambda[k];
        while i != NO_DOF {
            let a = h[k + i * nv] / h_kk;
            let mut j = i;
            while j != NO_DOF {
                h[i + j * nv] -= a * h[k + j * nv];
                j = lambda[j];
            }
            h[k + i * nv] = a;
            i = lambda[i];
        }
    }
}

/// Solves M x = b in place (`x` holds b on entry) with the factor of [`factorize_mass_matrix`]
/// (RBDA Table 6.4): x ← L⁻¹ D⁻¹ L⁻ᵀ b.
pub fn solve_mass_matrix(model: &Model, data: &Data, x: &mut DVector<f64>) {
    solve_with_factor(model, &data.mass_factor, x.as_mut_slice());
}

/// [`solve_mass_matrix`] on a slice, with the factor passed explicitly (so that the right-hand
/// side may be another buffer of the same `Data`).
pub fn solve_with_factor(model: &Model, factor: &DMatrix<f64>, x: &mut [f64]) {
    let lambda = &model.dof_parent;
    let nv = model.nv;
    let h = factor.as_slice();
    // Lᵀ z = b, from the leaves up.
    for i in (0..nv).rev() {
        let mut j = lambda[i];
        while j != NO_DOF {
            x[j] -= h[i + j * nv] * x[i];
            j = lambda[j];
        }
    }
    // D w = z.
    for i in 0..nv {
        x[i] /= h[i + i * nv];
    }
    // L x = w, from the root down.
    for i in 0..nv {
        let mut j = lambda[i];
        while j != NO_DOF {
            x[i] -= h[i + j * nv] * x[j];
            j = lambda[j];
        }
    }
}
