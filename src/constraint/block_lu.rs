//! A general linear system `A x = b` solved block by block where its matrix decouples: the
//! exact mode's polish systems (docs/constraints.md, "Exact mode") couple two rows only when
//! their contacts or joints share a moving body's degrees of freedom, so a pile of separate
//! objects gives a matrix that is block diagonal up to a permutation, one block per group of
//! touching objects (the constraint islands).
//!
//! The unknowns are grouped into the connected components of the matrix's pattern (i and j
//! joined where `A[i][j]` or `A[j][i]` is not zero; a breadth-first search), and each block is
//! solved by the LU with complete pivoting of `dense.rs` ([`lu_kernel_dispatch`]), with the whole
//! system's thresholds (rank tolerance from the largest entry of A, consistency from the largest
//! entry of b). Complete pivoting on the whole matrix picks, at each step, the largest remaining
//! entry, which lies in one block and eliminates within it (the other blocks' entries of its
//! row and column are zero): each block sees the pivot sequence it sees alone. So the result is
//! the whole-matrix LU's, up to the order in which ties between entries of equal magnitude are
//! broken, in O(Σ size³) instead of O(n³) — a hundredfold less for ten separate objects.
//!
//! The buffers grow with the largest system solved ([`BlockLu::grow`]); a solve allocates
//! nothing.

use super::dense::{largest_entry, lu_kernel_dispatch, LuBounds};
use super::RANK_TOLERANCE;
use nalgebra::DMatrix;

/// Scratch of [`BlockLu::solve`] for systems of up to `capacity` unknowns.
#[derive(Clone, Debug, Default)]
pub(crate) struct BlockLu {
    /// Each unknown's component while searching.
    label: Vec<usize>,
    /// The unknowns grouped by component (components in the order of their first unknown).
    order: Vec<usize>,
    /// Where each component starts in `order` (one past the last entry: `order.len()`).
    start: Vec<usize>,
    /// One block's matrix (column-major, `capacity` rows) and right-hand side.
    block: Vec<f64>,
    rhs: Vec<f64>,
    /// The LU's row and column pivots.
    piv: Vec<usize>,
    capacity: usize,
}

impl BlockLu {
    /// Room for systems of `n` unknowns (allocates only when `n` exceeds every earlier size).
    pub fn grow(&mut self, n: usize) {
        if n <= self.capacity {
            return;
        }
        let n = n.max(2 * self.capacity);
        self.label.resize(n, 0);
        self.order.resize(n, 0);
        self.start.resize(n + 1, 0);
        self.block.resize(n * n, 0.0);
        self.rhs.resize(n, 0.0);
        self.piv.resize(2 * n, 0);
        self.capacity = n;
    }

    /// The largest system the buffers hold without growing (for tests).
    #[cfg(test)]
    pub fn capacity(&self) -> usize {
        self.capacity
    }

    /// Solves `A x = b` for the top-left n × n block of `a`, n = `b.len()`, into `b`: the result
    /// and the failures of the whole-matrix LU (`dense::lu_solve`, its tests' reference) with the
    /// same `floor`, block by block. `a` is read (and overwritten with its factors when it is one block). Grows the
    /// buffers first when n is larger than every earlier system.
    pub fn solve(&mut self, a: &mut DMatrix<f64>, b: &mut [f64], floor: f64) -> bool {
        let n = b.len();
        self.grow(n);
        let stride = a.nrows();
        let m = a.as_mut_slice();
        // The components, and the largest entry on the way (every column is scanned once).
        let (blocks, scale) = match self.components(m, stride, n) {
            Some(found) => found,
            None => (1, largest_entry(m, stride, n)),
        };
        if !(scale > 0.0 && scale.is_finite()) {
            return false;
        }
        let b_scale = b.iter().fold(0.0f64, |acc, x| acc.max(x.abs()));
        let bounds = LuBounds { tol: scale * RANK_TOLERANCE, b_scale, floor };
        if blocks == 1 {
            return lu_kernel_dispatch(m, stride, b, &mut self.piv, bounds)
                && b.iter().all(|x| x.is_finite());
        }
        let cap = self.capacity;
        for c in 0..blocks {
            let members = &self.order[self.start[c]..self.start[c + 1]];
            let s = members.len();
            for (jl, &j) in members.iter().enumerate() {
                let col = &m[j * stride..j * stride + n];
                for (il, &i) in members.iter().enumerate() {
                    self.block[il + jl * cap] = col[i];
                }
                self.rhs[jl] = b[j];
            }
            if !lu_kernel_dispatch(&mut self.block, cap, &mut self.rhs[..s], &mut self.piv, bounds) {
                return false;
            }
            for (il, &i) in members.iter().enumerate() {
                b[i] = self.rhs[il];
            }
        }
        b.iter().all(|x| x.is_finite())
    }

    /// Groups the n unknowns into the connected components of the pattern of `m` (column-major,
    /// `stride`) by breadth-first search over the columns, each scanned once (O(n²), contiguous
    /// reads): fills `order` (components in the order of their first unknown, each in the order
    /// reached) and `start`; returns the number of components and the largest |entry|. Every
    /// entry `A[i][j] ≠ 0` is met when column j is scanned: i joins j's component, or already
    /// belongs to it; an i already in an earlier component (a pattern that is not symmetric)
    /// stops the search: None, the whole system is one block.
    fn components(&mut self, m: &[f64], stride: usize, n: usize) -> Option<(usize, f64)> {
        const NONE: usize = usize::MAX;
        let label = &mut self.label[..n];
        label.fill(NONE);
        let (mut blocks, mut len, mut scale) = (0, 0, 0.0f64);
        for seed in 0..n {
            if label[seed] != NONE {
                continue;
            }
            let c = blocks;
            self.start[c] = len;
            blocks += 1;
            label[seed] = c;
            self.order[len] = seed;
            len += 1;
            let mut head = len - 1;
            while head < len {
                let u = self.order[head];
                head += 1;
                for (i, &x) in m[u * stride..u * stride + n].iter().enumerate() {
                    if x == 0.0 {
                        continue;
                    }
                    scale = scale.max(x.abs());
                    if label[i] == NONE {
                        label[i] = c;
                        self.order[len] = i;
                        len += 1;
                    } else if label[i] != c {
                        return None;
                    }
                }
            }
            if len == n {
                break;
            }
        }
        self.start[blocks] = n;
        Some((blocks, scale))
    }
}

#[cfg(test)]
mod tests {
    use super::BlockLu;
    use crate::constraint::dense::lu_solve;
    use nalgebra::DMatrix;

    /// A pseudo-random generator (no dependency): xorshift.
    fn rng(seed: &mut u64) -> f64 {
        *seed ^= *seed << 13;
        *seed ^= *seed >> 7;
        *seed ^= *seed << 17;
        (*seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    }

    /// A system of `n` unknowns whose matrix couples unknowns i and j only when
    /// `group(i) == group(j)`, interleaved (not contiguous), with a redundant pair of rows in one
    /// group when `redundant`.
    fn system(n: usize, groups: usize, redundant: bool, seed: &mut u64) -> (DMatrix<f64>, Vec<f64>) {
        let group = |i: usize| (i * 7 + 3) % groups;
        let mut a = DMatrix::zeros(n + 3, n + 3);
        for j in 0..n {
            for i in 0..n {
                if group(i) == group(j) {
                    a[(i, j)] = rng(seed) + if i == j { 2.0 } else { 0.0 };
                }
            }
        }
        let mut b: Vec<f64> = (0..n).map(|_| rng(seed)).collect();
        if redundant {
            // Two unknowns of group 0 with identical rows and right-hand sides.
            let members: Vec<usize> = (0..n).filter(|&i| group(i) == 0).collect();
            let (r0, r1) = (members[0], members[1]);
            for j in 0..n {
                a[(r1, j)] = a[(r0, j)];
            }
            b[r1] = b[r0];
        }
        (a, b)
    }

    /// Block by block gives the whole-matrix LU's solution (to round-off: ties between equal
    /// entries aside, the same pivots), on interleaved blocks, with and without redundant rows,
    /// and on one block (the whole-matrix path itself).
    #[test]
    fn block_solve_equals_the_whole_matrix_lu() {
        let mut seed = 0x2545_f491_4f6c_dd1d;
        let mut lu = BlockLu::default();
        for &(n, groups, redundant) in
            &[(1, 1, false), (12, 1, false), (12, 3, false), (40, 7, false), (40, 5, true), (9, 9, false)]
        {
            let (a, b) = system(n, groups, redundant, &mut seed);
            let (mut a_whole, mut x_whole) = (a.clone(), b.clone());
            let mut piv = vec![0; 2 * n];
            assert!(lu_solve(&mut a_whole, &mut x_whole, &mut piv, 0.0), "whole n={n} groups={groups}");
            let (mut a_blocks, mut x_blocks) = (a.clone(), b.clone());
            assert!(lu.solve(&mut a_blocks, &mut x_blocks, 0.0), "blocks n={n} groups={groups}");
            let worst = x_whole.iter().zip(&x_blocks).map(|(p, q)| (p - q).abs()).fold(0.0, f64::max);
            assert!(worst <= 1e-12, "n={n} groups={groups} redundant={redundant}: {worst:e}");
            // And the solution solves the system (the redundant one: consistently).
            for i in 0..n {
                let r: f64 = (0..n).map(|j| a[(i, j)] * x_blocks[j]).sum::<f64>() - b[i];
                assert!(r.abs() <= 1e-10, "row {i}: residual {r:e}");
            }
        }
    }

    /// An inconsistent block fails the whole solve, as the whole-matrix LU does; a zero matrix
    /// too.
    #[test]
    fn an_inconsistent_block_fails_the_solve() {
        let mut seed = 7;
        let (mut a, mut b) = system(20, 4, true, &mut seed);
        let r1 = (0..20).filter(|&i| (i * 7 + 3) % 4 == 0).nth(1).unwrap();
        b[r1] += 1.0;
        let mut lu = BlockLu::default();
        let (mut a2, mut b2) = (a.clone(), b.clone());
        assert!(!lu_solve(&mut a2, &mut b2, &mut [0; 40], 0.0));
        assert!(!lu.solve(&mut a, &mut b, 0.0));
        let mut zero = DMatrix::zeros(3, 3);
        assert!(!lu.solve(&mut zero, &mut [1.0, 0.0, 0.0], 0.0));
    }
}
