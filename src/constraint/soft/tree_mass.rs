//! The mass matrix's nonzeros in a compact copy for the soft Newton and CG solves on the islands'
//! path (docs/architecture.md, "Constraint solvers"): M[l][k] ≠ 0 only when l is k or one of k's
//! ancestor dofs (RBDA §6.3, the tree's sparsity; MuJoCo keeps only these, `qM` with
//! `dof_Madr`). `Data::mass_matrix` is dense nv × nv: with many free bodies (the bins of
//! `validation/bench_contact_rich.py`, nv = 2400: 46 MB) each of its columns lies on its own
//! memory page, and every pass over its nonzeros — M x at each Newton iteration, the islands'
//! scales, the Hessian's start — pays a page walk and a cache miss per dof. The solve gathers
//! the nonzeros here once ([`TreeMass::gather`]) and reads them contiguously after.
//!
//! Dof k's entries are `val[start[k]..start[k + 1]]`: M[k][k], then M[l][k] for the ancestors l
//! of k in the order of the chain walk (parent first). The values are M's, so every product
//! formed from them has M's bits.

use crate::model::NO_DOF;
use nalgebra::DMatrix;

/// M's diagonal and each dof's ancestor-chain entries, compact (see the module doc).
#[derive(Clone, Debug, Default)]
pub(crate) struct TreeMass {
    start: Vec<usize>,
    val: Vec<f64>,
}

impl TreeMass {
    /// The layout for the dof tree `dof_parent` (values zero until [`Self::gather`]).
    pub fn new(dof_parent: &[usize]) -> Self {
        let mut start = Vec::with_capacity(dof_parent.len() + 1);
        start.push(0);
        for k in 0..dof_parent.len() {
            let mut n = 1;
            let mut l = dof_parent[k];
            while l != NO_DOF {
                n += 1;
                l = dof_parent[l];
            }
            start.push(start[k] + n);
        }
        let val = vec![0.0; start[dof_parent.len()]];
        Self { start, val }
    }

    /// Copies M's nonzeros from the dense, symmetric `m` (column-major: entry (l, k) at
    /// k · nv + l; column k read from its upper part).
    pub fn gather(&mut self, m: &DMatrix<f64>, dof_parent: &[usize]) {
        let (nv, m) = (m.nrows(), m.as_slice());
        for (k, w) in self.start.windows(2).enumerate() {
            let vals = &mut self.val[w[0]..w[1]];
            let column = &m[k * nv..k * nv + k + 1];
            vals[0] = column[k];
            let mut l = dof_parent[k];
            for v in &mut vals[1..] {
                *v = column[l];
                l = dof_parent[l];
            }
        }
    }

    /// M[k][k].
    #[inline]
    pub fn diag(&self, k: usize) -> f64 {
        self.val[self.start[k]]
    }

    /// Dof k's entries: M[k][k], then M[l][k] along k's ancestor chain (parent first).
    #[inline]
    pub fn column(&self, k: usize) -> &[f64] {
        &self.val[self.start[k]..self.start[k + 1]]
    }

    /// r ← M x on the dofs `dofs` (whole trees, each tree's dofs ascending; M couples a dof
    /// only to its tree): the diagonal products, then each dof's chain entries, in the order of
    /// `primal::mul_m_on` (the same products and sums, so the same bits). The other entries of
    /// r are left as they are.
    pub fn mul_on(
        &self,
        dof_parent: &[usize],
        dofs: impl IntoIterator<Item = usize> + Clone,
        x: &[f64],
        r: &mut [f64],
    ) {
        for k in dofs.clone() {
            r[k] = self.diag(k) * x[k];
        }
        for k in dofs {
            let mut l = dof_parent[k];
            for &m_lk in &self.column(k)[1..] {
                r[l] += m_lk * x[k];
                r[k] += m_lk * x[l];
                l = dof_parent[l];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_compact_product_equals_the_dense_ones_bits_on_a_tree() {
        // Two trees: 0 ← 1 ← 2 and 0 ← 3 (a branch), and 4 alone.
        let dof_parent = [NO_DOF, 0, 1, 0, NO_DOF];
        let mut m = DMatrix::zeros(5, 5);
        let mut v = 1.0;
        for k in 0..5 {
            m[(k, k)] = 10.0 + k as f64;
            let mut l = dof_parent[k];
            while l != NO_DOF {
                v += 0.5;
                m[(l, k)] = v;
                m[(k, l)] = v;
                l = dof_parent[l];
            }
        }
        let mut tm = TreeMass::new(&dof_parent);
        tm.gather(&m, &dof_parent);
        assert_eq!(tm.column(2), &[12.0, m[(1, 2)], m[(0, 2)]]);
        assert_eq!(tm.diag(4), 14.0);
        // The same bits as the product that reads the dense M's nonzeros.
        let x = [1.0, -2.0, 0.5, 3.0, -1.5];
        let (mut r, mut r_dense) = ([0.0; 5], [0.0; 5]);
        tm.mul_on(&dof_parent, 0..5, &x, &mut r);
        super::super::primal::mul_m_on(&dof_parent, &m, 0..5, &x, &mut r_dense);
        assert_eq!(r, r_dense);
        assert_ne!(r, [0.0; 5]);
    }
}
