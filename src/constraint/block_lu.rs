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
//! The symmetric positive semi-definite systems of the polish (its active set's Delassus block,
//! minimum-norm where redundant) decouple the same way: [`BlockLu::solve_psd`] solves each
//! component with `dense::solve_psd_tol` under the whole system's rank tolerance. The minimum-norm
//! solution of a block-diagonal system is the blocks' own (its pseudo-inverse is block diagonal),
//! and a block's Cholesky, its rows kept in ascending order, is the whole factor's restriction to
//! them: O(Σ size³) again.
//!
//! The buffers grow with the largest system solved ([`BlockLu::grow`]); a solve allocates
//! nothing.

use super::dense::{largest_entry, lu_kernel_dispatch, psd_rank_tolerance, solve_psd_tol, LuBounds};
use super::RANK_TOLERANCE;
use nalgebra::{DMatrix, DVector};

/// Symmetric systems smaller than this are solved whole ([`BlockLu::solve_psd`]): their
/// factorization is a few ten thousand multiply-adds, and the whole solve keeps the
/// minimum-norm solution's round-off that of `dense::solve_psd` (a redundant block's pivoted
/// factor and QR differ from the whole matrix's in the last bits).
pub(crate) const PSD_SPLIT_SIZE: usize = 48;

/// Scratch of [`BlockLu::solve`] for systems of up to `capacity` unknowns.
#[derive(Clone, Debug, Default)]
pub(crate) struct BlockLu {
    /// Each unknown's component while searching.
    label: Vec<usize>,
    /// The unknowns grouped by component (components in the order of their first unknown).
    order: Vec<usize>,
    /// Where each component starts in `order` (one past the last entry: `order.len()`).
    start: Vec<usize>,
    /// One block's matrix (`capacity` × `capacity`; the symmetric solve's too) and right-hand
    /// side.
    block: DMatrix<f64>,
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
        self.block = DMatrix::zeros(n, n);
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
            let s = self.gather(c, m, stride, n, b);
            if !lu_kernel_dispatch(self.block.as_mut_slice(), cap, &mut self.rhs[..s], &mut self.piv, bounds)
            {
                return false;
            }
            self.scatter(c, b);
        }
        b.iter().all(|x| x.is_finite())
    }

    /// Copies component `c`'s rows and columns of the n × n matrix `m` (column stride `stride`)
    /// into `block` and its entries of `b` into `rhs`, in the component's order; returns its size.
    fn gather(&mut self, c: usize, m: &[f64], stride: usize, n: usize, b: &[f64]) -> usize {
        let (lo, hi) = (self.start[c], self.start[c + 1]);
        for jl in 0..hi - lo {
            let j = self.order[lo + jl];
            let col = &m[j * stride..j * stride + n];
            for il in 0..hi - lo {
                self.block[(il, jl)] = col[self.order[lo + il]];
            }
            self.rhs[jl] = b[j];
        }
        hi - lo
    }

    /// Writes component `c`'s solution (in `rhs`) back to its entries of `b`.
    fn scatter(&self, c: usize, b: &mut [f64]) {
        for (il, &i) in self.order[self.start[c]..self.start[c + 1]].iter().enumerate() {
            b[i] = self.rhs[il];
        }
    }

    /// Solves `A x = b` for the symmetric positive semi-definite top-left n × n block of `a`,
    /// n = `b.len()`, into `b`, component by component of A's pattern, each as `dense::solve_psd`
    /// solves a whole system (Cholesky, or the minimum-norm solution when redundant) with the whole
    /// system's rank tolerance (`RANK_TOLERANCE` times A's largest diagonal entry). Returns the
    /// numerical rank (the sum of the blocks'). One component (or a pattern that is not
    /// symmetric), or fewer than [`PSD_SPLIT_SIZE`] unknowns, is `dense::solve_psd` itself. `work` (n × n) and `vec` (n) are its scratch; `a`
    /// is overwritten when it is one block. Grows the buffers first when n is larger than
    /// every earlier system.
    pub fn solve_psd(
        &mut self,
        a: &mut DMatrix<f64>,
        b: &mut [f64],
        work: &mut DMatrix<f64>,
        vec: &mut DVector<f64>,
    ) -> usize {
        let n = b.len();
        let Some(tol) = psd_rank_tolerance(a, b) else { return 0 };
        if n < PSD_SPLIT_SIZE {
            return solve_psd_tol(a, b, work, vec, tol);
        }
        let stride = a.nrows();
        self.grow(n);
        let blocks = match self.components(a.as_slice(), stride, n) {
            Some((blocks, _)) if blocks > 1 => blocks,
            _ => return solve_psd_tol(a, b, work, vec, tol),
        };
        let mut rank = 0;
        for c in 0..blocks {
            // Ascending, as in the whole system: the block's factor is the whole one's rows.
            self.order[self.start[c]..self.start[c + 1]].sort_unstable();
            let s = self.gather(c, a.as_slice(), stride, n, b);
            rank += solve_psd_tol(&mut self.block, &mut self.rhs[..s], work, vec, tol);
            self.scatter(c, b);
        }
        rank
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
                // Eight entries at a time, a run of zeros (most of a sparse column) passed over by
                // one test of their bits (±0 only: a NaN counts as an entry, as one by one).
                for (g, chunk) in m[u * stride..u * stride + n].chunks(8).enumerate() {
                    if chunk.iter().fold(0u64, |acc, x| acc | (x.to_bits() << 1)) == 0 {
                        continue;
                    }
                    for (k, &x) in chunk.iter().enumerate() {
                        if x == 0.0 {
                            continue;
                        }
                        let i = 8 * g + k;
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

    /// The symmetric solve block by block gives the whole matrix's solution (minimum-norm when
    /// redundant) and rank, on interleaved blocks of a system large enough to be split.
    #[test]
    fn block_psd_solve_equals_the_whole_matrix_solve() {
        use crate::constraint::dense::solve_psd;
        use nalgebra::DVector;
        let mut seed = 0x9e37_79b9_7f4a_7c15;
        for &(n, groups, redundant) in &[(60, 5, false), (64, 4, true), (50, 1, true)] {
            // A = B Bᵀ over each group (B's columns fewer than the group's rows when redundant).
            let group = |i: usize| (i * 7 + 3) % groups;
            let mut a = DMatrix::zeros(n, n);
            for g in 0..groups {
                let members: Vec<usize> = (0..n).filter(|&i| group(i) == g).collect();
                let cols = if redundant { members.len() - 2 } else { members.len() };
                let bm: Vec<Vec<f64>> =
                    members.iter().map(|_| (0..cols).map(|_| rng(&mut seed)).collect()).collect();
                for (p, &i) in members.iter().enumerate() {
                    for (q, &j) in members.iter().enumerate() {
                        a[(i, j)] = (0..cols).map(|c| bm[p][c] * bm[q][c]).sum::<f64>()
                            + if i == j && !redundant { 1.0 } else { 0.0 };
                    }
                }
            }
            let b: Vec<f64> = (0..n).map(|_| rng(&mut seed)).collect();
            let (mut work, mut vec) = (DMatrix::zeros(n, n), DVector::zeros(n));
            let (mut a_whole, mut x_whole) = (a.clone(), b.clone());
            let rank_whole = solve_psd(&mut a_whole, &mut x_whole, &mut work, &mut vec);
            let mut lu = BlockLu::default();
            let (mut a_blocks, mut x_blocks) = (a.clone(), b.clone());
            let rank_blocks = lu.solve_psd(&mut a_blocks, &mut x_blocks, &mut work, &mut vec);
            assert_eq!(rank_whole, rank_blocks, "n={n} groups={groups}");
            assert!(!redundant || rank_blocks < n);
            let scale = x_whole.iter().fold(1.0f64, |m, x| m.max(x.abs()));
            let worst = x_whole.iter().zip(&x_blocks).map(|(p, q)| (p - q).abs()).fold(0.0, f64::max);
            assert!(worst <= 1e-9 * scale, "n={n} groups={groups} redundant={redundant}: {worst:e}");
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
