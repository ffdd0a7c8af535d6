//! Composite-rigid-body algorithm for M(q) (RBDA §6.2, Table 6.2) and the tree-sparse LᵀDL
//! factorization and solve (RBDA §6.3, Tables 6.3–6.4).

use crate::kinematics::update_joint;
use crate::model::{Data, Model, NO_DOF};
use crate::spatial::Force;
use nalgebra::{DMatrix, DVector};

/// Joint-space inertia matrix M(q), armature included, into `data.mass_matrix` (and returned).
pub fn crba<'d>(model: &Model, data: &'d mut Data, q: &[f64]) -> &'d DMatrix<f64> {
    // Pass 1: joint transforms and motion subspaces; composite inertias start as body inertias.
    for b in 1..model.nbody() {
        update_joint(model, data, b, q);
        data.i_composite[b] = model.bodies[b].inertia;
    }
    data.mass_matrix.fill(0.0);
    // Pass 2, leaves to root: F = Iᶜ S, then walk F up the ancestors, filling M's row block.
    let mut f_cols = [Force::zero(); 6];
    for b in (1..model.nbody()).rev() {
        let j = model.joint_of(b);
        let (da, nv_j) = (j.dof_adr, j.kind.nv());
        for k in 0..nv_j {
            f_cols[k] = data.i_composite[b].mul_motion(&data.s_body[da + k]);
            for l in 0..=k {
                let m_kl = data.s_body[da + l].dot(&f_cols[k]);
                data.mass_matrix[(da + k, da + l)] = m_kl;
                data.mass_matrix[(da + l, da + k)] = m_kl;
            }
            data.mass_matrix[(da + k, da + k)] += model.dof_armature[da + k];
        }
        let mut cur = b;
        while model.bodies[cur].parent != 0 {
            let x = data.x_parent_body[cur];
            for f in f_cols.iter_mut().take(nv_j) {
                *f = x.act_force(f);
            }
            cur = model.bodies[cur].parent;
            let jc = model.joint_of(cur);
            for k in 0..nv_j {
                for l in jc.dof_adr..jc.dof_adr + jc.kind.nv() {
                    let m_kl = data.s_body[l].dot(&f_cols[k]);
                    data.mass_matrix[(da + k, l)] = m_kl;
                    data.mass_matrix[(l, da + k)] = m_kl;
                }
            }
        }
        // The subtree of b is complete: add it to its parent's composite inertia.
        let p = model.bodies[b].parent;
        if p != 0 {
            let i_in_parent = data.i_composite[b].transformed(&data.x_parent_body[b]);
            data.i_composite[p] += &i_in_parent;
        }
    }
    &data.mass_matrix
}

/// Factorizes `data.mass_matrix` as M = Lᵀ D L into `data.mass_factor`, exploiting the tree's
/// sparsity: fill-in stays on the ancestor paths λ (RBDA Table 6.3). Run [`crba`] first.
pub fn factorize_mass_matrix(model: &Model, data: &mut Data) {
    let lambda = &model.dof_parent;
    let h = &mut data.mass_factor;
    h.copy_from(&data.mass_matrix);
    for k in (0..model.nv).rev() {
        let mut i = lambda[k];
        while i != NO_DOF {
            let a = h[(k, i)] / h[(k, k)];
            let mut j = i;
            while j != NO_DOF {
                h[(i, j)] -= a * h[(k, j)];
                j = lambda[j];
            }
            h[(k, i)] = a;
            i = lambda[i];
        }
    }
}

/// Solves M x = b in place (`x` holds b on entry) with the factor of [`factorize_mass_matrix`]
/// (RBDA Table 6.4): x ← L⁻¹ D⁻¹ L⁻ᵀ b.
pub fn solve_mass_matrix(model: &Model, data: &Data, x: &mut DVector<f64>) {
    let lambda = &model.dof_parent;
    let h = &data.mass_factor;
    // Lᵀ z = b, from the leaves up.
    for i in (0..model.nv).rev() {
        let mut j = lambda[i];
        while j != NO_DOF {
            x[j] -= h[(i, j)] * x[i];
            j = lambda[j];
        }
    }
    // D w = z.
    for i in 0..model.nv {
        x[i] /= h[(i, i)];
    }
    // L x = w, from the root down.
    for i in 0..model.nv {
        let mut j = lambda[i];
        while j != NO_DOF {
            x[i] -= h[(i, j)] * x[j];
            j = lambda[j];
        }
    }
}
