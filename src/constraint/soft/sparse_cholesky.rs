//! Cholesky factorization of the Newton Hessian H = M + Jᵀ D J that does only the work its
//! nonzeros need (docs/constraints.md, "Soft constraints"): the tree sparsity of M (a dof couples
//! only to its ancestors) plus the couplings of the rows (a row touches only its bodies'
//! ancestor dofs). Independent groups of dofs — bodies that touch nothing, separate piles,
//! MuJoCo's constraint islands — stay uncoupled in the factor, so their cost adds instead of
//! multiplying.
//!
//! Elimination order: the dofs from the last to the first — MuJoCo's reverse Cholesky
//! (H = LᵀL, `mju_cholFactorSymbolic`/`mju_cholFactorNumeric`, engine_util_solve.c), children
//! before their parents, so that a tree's M fills nothing. Internally H is factored as
//! P H P = L' L'ᵀ with P the reversal (dof k at position n − 1 − k); the callers see dof
//! indices only.
//!
//! Method (Davis, *Direct Methods for Sparse Linear Systems*, SIAM 2006, §4.1–4.3, 4.8): the
//! elimination tree of P H P by Liu's algorithm with path compression; the pattern of each row
//! of L' as the set reached from the row's nonzeros of P H P by walking up the tree (`ereach`);
//! then the left-looking numeric factorization, column by column: column p is H's column minus
//! the columns c of row p's pattern, each from row p down. Its work is Σ_c |col c|² / 2 — that
//! of MuJoCo's — where the up-looking row form costs Σ_p |row p| · |col p| (on the settled bin
//! of 400 primitives, one island of 306 bodies: 1.5M against 8.0M multiply–adds per factor, and
//! the natural order's L holds 94k entries against the reverse order's 62k).
//!
//! The symbolic part (H's pattern, the tree, L's pattern by rows and by columns) is done by
//! [`SparseCholesky::analyze`] from the rows' cliques and kept while they are unchanged — for all
//! the iterations of a Newton solve, whose pattern covers every row that can press, and across
//! steps while the contacts touch the same dofs; [`SparseCholesky::factor_kept`] is then
//! only the numeric factorization (MuJoCo likewise keeps its sparse Hessian's structure,
//! engine_solver.c). When the cliques do change, the structure of every component of H's pattern
//! (trees joined by cliques: the constraint islands) whose cliques are those of the last analysis
//! is copied from it, and only the components whose contacts changed are analyzed — as MuJoCo's
//! island solves analyze each island on its own.
//!
//! The arithmetic is the dense factorization's ([`crate::constraint::dense::cholesky`]) of
//! P H P minus its products with structural zeros, in the same order: factor and solves agree
//! with the dense ones of P H P to the last bit. Buffers grow only when a Hessian has more
//! nonzeros than any before it.

#[cfg(test)]
use nalgebra::DMatrix;

const NONE: usize = usize::MAX;

/// The most vectors of one rank update ([`SparseCholesky::rank_update`]: a pyramidal contact of
/// condim 3 has four rows).
pub(crate) const RANK: usize = 4;

/// The factor L (H = L Lᵀ), its symbolic structure (kept while the pattern is unchanged) and the
/// scratch of its computation.
#[derive(Clone, Debug, Default)]
pub(crate) struct SparseCholesky {
    /// Strictly lower part of H by rows: row k's columns j < k with H[k, j] ≠ 0 (dof indices).
    h_start: Vec<usize>,
    h_cols: Vec<usize>,
    h_count: Vec<usize>,
    /// H's values on its analyzed pattern: the strictly lower entries beside `h_cols` (row k's
    /// columns ascending) and the diagonal — the only copy of H the sparse path keeps (no nv²
    /// storage: assembled in place by `hessian.rs`, read by the factorization row by row).
    h_vals: Vec<f64>,
    h_diag: Vec<f64>,
    /// The same of P H P (positions: dof k at n − 1 − k), the transpose of H's.
    p_start: Vec<usize>,
    p_cols: Vec<usize>,
    /// From here on, positions in P H P (dof k at n − 1 − k).
    /// Elimination tree (parent of each position; `NONE` at a root) and Liu's ancestor scratch.
    parent: Vec<usize>,
    ancestor: Vec<usize>,
    /// Stamp per dof or position: the row whose pattern is being reached.
    mark: Vec<usize>,
    /// L's strictly lower pattern by rows (columns ascending), and its diagonal.
    l_start: Vec<usize>,
    l_cols: Vec<usize>,
    diag: Vec<f64>,
    /// L's strictly lower part by columns (rows ascending), the only copy of its values;
    /// `c_slot[u]` is where the row pattern's entry u sits in it.
    c_start: Vec<usize>,
    c_rows: Vec<usize>,
    c_vals: Vec<f64>,
    c_slot: Vec<usize>,
    /// Dense scratch row of L (zero between calls).
    x: Vec<f64>,
    /// The vectors of a rank update, interleaved (`RANK` per position; zero between calls).
    xb: Vec<f64>,
    /// The cliques of the pattern being analyzed (clique c's dofs are
    /// `clique_cols[clique_start[c]..clique_start[c + 1]]`, ascending) and each dof's cliques.
    clique_start: Vec<usize>,
    clique_cols: Vec<usize>,
    d_start: Vec<usize>,
    d_cliques: Vec<usize>,
    /// The cliques and size of the analyzed pattern (the symbolic structure's key).
    key_start: Vec<usize>,
    key_cols: Vec<usize>,
    key_n: usize,
    /// Stamps of the coverage test (`covers_cliques`): per dof, and the last one given.
    cover: Vec<usize>,
    stamp: usize,
    /// The components of the analyzed pattern (the trees M couples, joined by the cliques): each
    /// dof's component by its smallest dof, and each component's cliques (component r's are
    /// `comp_cliques[comp_start[r]..comp_start[r + 1]]`, indices into the key, in order); the
    /// same of the analysis before, and per dof whether its component is one of that analysis
    /// unchanged (its structure is then copied: [`Self::analyze`]).
    comp: Vec<usize>,
    comp_start: Vec<usize>,
    comp_cliques: Vec<usize>,
    old_comp: Vec<usize>,
    old_comp_start: Vec<usize>,
    old_comp_cliques: Vec<usize>,
    same: Vec<bool>,
    /// The analysis before's H rows, elimination tree and L rows (read for unchanged components).
    old_h_start: Vec<usize>,
    old_h_cols: Vec<usize>,
    old_parent: Vec<usize>,
    old_l_start: Vec<usize>,
    old_l_cols: Vec<usize>,
    /// The analysis before's L by columns and each row entry's slot there.
    old_c_start: Vec<usize>,
    old_c_rows: Vec<usize>,
    old_c_slot: Vec<usize>,
    /// Whether the symbolic structure (H's and L's patterns, the elimination tree) is set.
    analyzed: bool,
    /// Whether the analyzed pattern is one kept for cliques it covers (`covers_cliques`): it may
    /// then couple dofs that no row couples now (other groups, `numeric`'s `group`).
    kept_wider: bool,
    /// Symbolic analyses done (a pattern changed), for tests and profiles.
    analyses: usize,
}

impl SparseCholesky {
    /// Buffers sized for an n-dof Hessian as sparse as a tree's M (more grow when needed).
    pub fn with_capacity(n: usize) -> Self {
        let nnz = (n * n.saturating_sub(1) / 2).min((64 * n).max(4096));
        Self {
            h_start: Vec::with_capacity(n + 1),
            h_cols: Vec::with_capacity(nnz),
            h_count: Vec::with_capacity(n + 1),
            h_vals: Vec::with_capacity(nnz),
            h_diag: Vec::with_capacity(n),
            p_start: Vec::with_capacity(n + 1),
            p_cols: Vec::with_capacity(nnz),
            parent: Vec::with_capacity(n),
            ancestor: Vec::with_capacity(n),
            mark: Vec::with_capacity(n),
            l_start: Vec::with_capacity(n + 1),
            l_cols: Vec::with_capacity(nnz),
            diag: Vec::with_capacity(n),
            c_start: Vec::with_capacity(n + 1),
            c_rows: Vec::with_capacity(nnz),
            c_vals: Vec::with_capacity(nnz),
            c_slot: Vec::with_capacity(nnz),
            x: Vec::with_capacity(n),
            xb: Vec::with_capacity(RANK * n),
            clique_start: Vec::with_capacity(n + 1),
            clique_cols: Vec::with_capacity(nnz),
            d_start: Vec::with_capacity(n + 1),
            d_cliques: Vec::with_capacity(nnz),
            key_start: Vec::with_capacity(n + 1),
            key_cols: Vec::with_capacity(nnz),
            key_n: 0,
            cover: Vec::with_capacity(n),
            stamp: 0,
            comp: Vec::with_capacity(n),
            comp_start: Vec::with_capacity(n + 1),
            comp_cliques: Vec::with_capacity(n),
            old_comp: Vec::with_capacity(n),
            old_comp_start: Vec::with_capacity(n + 1),
            old_comp_cliques: Vec::with_capacity(n),
            same: Vec::with_capacity(n),
            old_h_start: Vec::with_capacity(n + 1),
            old_h_cols: Vec::with_capacity(nnz),
            old_parent: Vec::with_capacity(n),
            old_l_start: Vec::with_capacity(n + 1),
            old_l_cols: Vec::with_capacity(nnz),
            old_c_start: Vec::with_capacity(n + 1),
            old_c_rows: Vec::with_capacity(nnz),
            old_c_slot: Vec::with_capacity(nnz),
            analyzed: false,
            kept_wider: false,
            analyses: 0,
        }
    }

    /// H's values on the analyzed pattern, to assemble in place ([`SparseH`]).
    pub fn h_mut(&mut self) -> SparseH<'_> {
        SparseH { start: &self.h_start, cols: &self.h_cols, vals: &mut self.h_vals, diag: &mut self.h_diag }
    }

    /// Sets H's rows `dofs` (strictly lower entries and diagonal) to M's: the diagonal, each
    /// dof's ancestors (`dof_parent`) from `m` (M's nonzeros, `tree_mass.rs`), zero elsewhere on
    /// the pattern — the start of a Hessian's assembly on those dofs.
    pub fn set_rows_to_m(&mut self, dofs: &[usize], m: &super::tree_mass::TreeMass, dof_parent: &[usize]) {
        for &k in dofs {
            let (a, b) = (self.h_start[k], self.h_start[k + 1]);
            let (cols, vals) = (&self.h_cols[a..b], &mut self.h_vals[a..b]);
            vals.fill(0.0);
            let column = m.column(k);
            self.h_diag[k] = column[0];
            // The ancestors descend, the row's columns ascend: one backward walk.
            let mut u = cols.len();
            let mut l = dof_parent[k];
            for &m_lk in &column[1..] {
                while u > 0 && cols[u - 1] > l {
                    u -= 1;
                }
                debug_assert!(u > 0 && cols[u - 1] == l, "an ancestor outside H's pattern");
                if u > 0 {
                    vals[u - 1] = m_lk;
                }
                l = dof_parent[l];
            }
        }
    }

    /// Copies the lower triangle of the dense `h` on the analyzed pattern into H's values.
    #[cfg(test)]
    pub fn load(&mut self, h: &DMatrix<f64>) {
        let n = self.h_start.len() - 1;
        for k in 0..n {
            for u in self.h_start[k]..self.h_start[k + 1] {
                self.h_vals[u] = h[(k, self.h_cols[u])];
            }
            self.h_diag[k] = h[(k, k)];
        }
    }

    /// The strictly lower nonzeros of H's row k on the analyzed pattern (ascending).
    #[cfg(test)]
    pub fn pattern_row(&self, k: usize) -> &[usize] {
        &self.h_cols[self.h_start[k]..self.h_start[k + 1]]
    }

    /// How many symbolic analyses were done (each pattern change costs one).
    #[allow(dead_code)]
    pub fn analyses(&self) -> usize {
        self.analyses
    }

    /// The symbolic structure of n × n Hessians whose strictly lower nonzeros lie in M's tree
    /// pattern (each dof's ancestors, `dof_parent`) and in the cliques of the constraint row
    /// groups `groups` (rows `first..=last`: the union of their columns
    /// `nz_index[nz_start[r]..nz_start[r + 1]]` couple pairwise). Kept as is when the cliques are
    /// those of the last analysis (the usual case from one Newton iteration or one step to the
    /// next); else H's pattern, the elimination tree and L's pattern are recomputed. A pattern
    /// that covers more entries than a Hessian's nonzeros factors it to the same bits: the extra
    /// entries only add products with exact zeros.
    pub fn analyze(
        &mut self,
        n: usize,
        dof_parent: &[usize],
        groups: &[(usize, usize)],
        nz_start: &[usize],
        nz_index: &[usize],
    ) {
        // The cliques' dofs (each group's rows' columns, once, ascending); a clique equal to the
        // one before it (one contact after another on the same bodies) is taken once.
        self.mark.clear();
        self.mark.resize(n, NONE);
        // (Owned locals and slices: their lengths and addresses stay in registers.)
        let (mut clique_start, mut clique_cols) =
            (std::mem::take(&mut self.clique_start), std::mem::take(&mut self.clique_cols));
        clique_start.clear();
        clique_start.push(0);
        clique_cols.clear();
        let mark = self.mark.as_mut_slice();
        for (c, &(first, last)) in groups.iter().enumerate() {
            let begin = clique_cols.len();
            let row = |r: usize| &nz_index[nz_start[r]..nz_start[r + 1]];
            if (first + 1..=last).all(|r| row(r) == row(first)) {
                // The usual group: a contact's rows over one shared column list (ascending).
                clique_cols.extend_from_slice(row(first));
            } else {
                for &p in &nz_index[nz_start[first]..nz_start[last + 1]] {
                    if mark[p] != c {
                        mark[p] = c;
                        clique_cols.push(p);
                    }
                }
                clique_cols[begin..].sort_unstable();
            }
            let nc = clique_start.len() - 1;
            let repeat = nc > 0 && clique_cols[clique_start[nc - 1]..begin] == clique_cols[begin..];
            // A clique of one dof couples nothing, nor one whose dofs lie on one chain of a tree
            // (each an ancestor of the next: a body's contact with the world) — M's pattern holds
            // it already. Left out, such rows appearing and leaving do not change the key.
            let chain = clique_cols[begin..].windows(2).all(|w| {
                let mut l = dof_parent[w[1]];
                while l != NONE && l > w[0] {
                    l = dof_parent[l];
                }
                l == w[0]
            });
            if repeat || chain {
                clique_cols.truncate(begin);
            } else {
                clique_start.push(clique_cols.len());
            }
        }
        self.clique_start = clique_start;
        self.clique_cols = clique_cols;
        if self.analyzed && self.key_n == n {
            if self.key_start == self.clique_start && self.key_cols == self.clique_cols {
                // The pattern of exactly these cliques: no coupling beyond theirs.
                self.kept_wider = false;
                return;
            }
            if self.covers_cliques() {
                self.kept_wider = true;
                return;
            }
        }
        self.analyses += 1;
        self.kept_wider = false;
        let incremental = self.analyzed && self.key_n == n;
        // (The last analysis's cliques stay in `clique_start`/`clique_cols`.)
        std::mem::swap(&mut self.key_start, &mut self.clique_start);
        std::mem::swap(&mut self.key_cols, &mut self.clique_cols);
        self.key_n = n;
        self.components(n, dof_parent, incremental);
        let ncliques = self.key_start.len() - 1;
        // Each dof's cliques (counting sort).
        self.d_start.clear();
        self.d_start.resize(n + 1, 0);
        for &p in &self.key_cols {
            self.d_start[p + 1] += 1;
        }
        for k in 0..n {
            self.d_start[k + 1] += self.d_start[k];
        }
        self.h_count.clear();
        self.h_count.extend_from_slice(&self.d_start[..n]);
        overwrite_len(&mut self.d_cliques, self.d_start[n]);
        {
            let (next, d_cliques) = (self.h_count.as_mut_slice(), self.d_cliques.as_mut_slice());
            let (key_start, key_cols) = (self.key_start.as_slice(), self.key_cols.as_slice());
            for c in 0..ncliques {
                for &p in &key_cols[key_start[c]..key_start[c + 1]] {
                    d_cliques[next[p]] = c;
                    next[p] += 1;
                }
            }
        }
        // Row k of H's strict lower pattern: k's ancestors and the dofs below k of its cliques.
        self.mark.clear();
        self.mark.resize(n, NONE);
        // (The lists built here are owned locals and the others slices, so that their lengths
        // and addresses stay in registers across the stores.)
        std::mem::swap(&mut self.h_start, &mut self.old_h_start);
        std::mem::swap(&mut self.h_cols, &mut self.old_h_cols);
        let (mut h_start, mut h_cols) = (std::mem::take(&mut self.h_start), std::mem::take(&mut self.h_cols));
        h_start.clear();
        h_start.push(0);
        h_cols.clear();
        {
            let mark = self.mark.as_mut_slice();
            let (d_start, d_cliques) = (self.d_start.as_slice(), self.d_cliques.as_slice());
            let (key_start, key_cols) = (self.key_start.as_slice(), self.key_cols.as_slice());
            let (same, old_start, old_cols) =
                (self.same.as_slice(), self.old_h_start.as_slice(), self.old_h_cols.as_slice());
            for k in 0..n {
                if same[k] {
                    // An unchanged component's row: the last analysis's.
                    h_cols.extend_from_slice(&old_cols[old_start[k]..old_start[k + 1]]);
                    h_start.push(h_cols.len());
                    continue;
                }
                mark[k] = k;
                let mut l = dof_parent[k];
                while l != NONE {
                    if mark[l] != k {
                        mark[l] = k;
                        h_cols.push(l);
                    }
                    l = dof_parent[l];
                }
                for &c in &d_cliques[d_start[k]..d_start[k + 1]] {
                    for &q in &key_cols[key_start[c]..key_start[c + 1]] {
                        // A clique's dofs ascend: those below k come first.
                        if q >= k {
                            break;
                        }
                        if mark[q] != k {
                            mark[q] = k;
                            h_cols.push(q);
                        }
                    }
                }
                // Ascending (the elimination tree, the row patterns and the numeric scatter do
                // not depend on the order; the in-place assembly walks the rows in it).
                let begin = *h_start.last().unwrap_or(&0);
                h_cols[begin..].sort_unstable();
                h_start.push(h_cols.len());
            }
        }
        self.h_start = h_start;
        self.h_cols = h_cols;
        self.symbolic(n);
    }

    /// Factors `h` (lower triangle read) with the symbolic structure of the last
    /// [`Self::analyze`], without reading the rest of `h`: the work is that of the nonzeros.
    /// Returns false if a pivot is not positive.
    #[cfg(test)]
    pub fn factor_analyzed(&mut self, h: &DMatrix<f64>) -> bool {
        self.load(h);
        self.numeric(0.0, None)
    }

    /// Factors H (its values as assembled on the analyzed pattern, [`Self::h_mut`]) with the
    /// symbolic structure of the last [`Self::analyze`], at the dofs `rows` only: the dofs of independent groups (constraint
    /// islands, `island.rs`), each group's ascending, that no other dof of L' couples to
    /// (factored from the list's end: children before parents); the other columns of L' keep
    /// stale values, which [`Self::solve_rows`] does not read. The work is that of the listed
    /// columns' nonzeros. `group` gives each dof's group: a listed dof's entries in another
    /// group's rows and columns (a kept pattern's coupling that no row makes now,
    /// [`Self::analyze`]) are set to zero, as the factor of H has them.
    pub fn factor_rows(&mut self, rows: &[usize], group: &[usize]) -> bool {
        self.numeric(0.0, Some((rows, group)))
    }

    /// Factors the symmetric `h` (its lower triangle is read; n × n at the top left) into L.
    /// Returns false if a pivot is not above `tol` (as the dense factorization).
    #[cfg(test)]
    pub fn factor(&mut self, h: &DMatrix<f64>, n: usize, tol: f64) -> bool {
        self.pattern_of_h(h, n);
        self.analyzed = false;
        self.kept_wider = false;
        self.same.clear();
        self.same.resize(n, false);
        self.symbolic(n);
        self.load(h);
        self.numeric(tol, None)
    }

    /// Row lists of H's strictly lower nonzeros, from its lower triangle read by columns
    /// (contiguous in memory), transposed by counting.
    #[cfg(test)]
    fn pattern_of_h(&mut self, h: &DMatrix<f64>, n: usize) {
        self.h_count.clear();
        self.h_count.resize(n + 1, 0);
        for j in 0..n {
            let col = &h.as_slice()[j * h.nrows()..j * h.nrows() + n];
            for (i, &v) in col.iter().enumerate().skip(j + 1) {
                if v != 0.0 {
                    self.h_count[i + 1] += 1;
                }
            }
        }
        for k in 0..n {
            self.h_count[k + 1] += self.h_count[k];
        }
        self.h_start.clear();
        self.h_start.extend_from_slice(&self.h_count);
        self.h_cols.clear();
        self.h_cols.resize(self.h_start[n], 0);
        // h_count becomes the next free slot of each row; columns arrive ascending.
        for j in 0..n {
            let col = &h.as_slice()[j * h.nrows()..j * h.nrows() + n];
            for (i, &v) in col.iter().enumerate().skip(j + 1) {
                if v != 0.0 {
                    self.h_cols[self.h_count[i]] = j;
                    self.h_count[i] += 1;
                }
            }
        }
    }

    /// The components of the pattern of the key's cliques (`comp`, `comp_start`,
    /// `comp_cliques`: union–find over dofs, each tree's dofs joined from the start, each
    /// clique's dofs joined; a component is named by its smallest dof) and, when `incremental`
    /// (the analysis before was of n dofs too; its cliques in `clique_start`/`clique_cols`), which
    /// dofs lie in a component of that analysis unchanged (`same`): one with the same smallest
    /// dof and the same cliques in the same order — the same trees, so the same rows of H, the
    /// same elimination subtree and the same rows of L, which are copied instead of computed.
    fn components(&mut self, n: usize, dof_parent: &[usize], incremental: bool) {
        std::mem::swap(&mut self.comp, &mut self.old_comp);
        std::mem::swap(&mut self.comp_start, &mut self.old_comp_start);
        std::mem::swap(&mut self.comp_cliques, &mut self.old_comp_cliques);
        let comp = &mut self.comp;
        comp.clear();
        for k in 0..n {
            // Parents come first: each dof points at its tree's root (itself at a root).
            let t = if dof_parent[k] == NONE { k } else { comp[dof_parent[k]] };
            comp.push(t);
        }
        fn find(comp: &mut [usize], mut x: usize) -> usize {
            while comp[x] != x {
                comp[x] = comp[comp[x]];
                x = comp[x];
            }
            x
        }
        let (key_start, key_cols) = (self.key_start.as_slice(), self.key_cols.as_slice());
        let ncliques = key_start.len() - 1;
        for c in 0..ncliques {
            let clique = &key_cols[key_start[c]..key_start[c + 1]];
            let mut a = find(comp, clique[0]);
            for &q in &clique[1..] {
                let b = find(comp, q);
                if a != b {
                    // The smaller root stays: a component is named by its smallest dof.
                    let (lo, hi) = if a < b { (a, b) } else { (b, a) };
                    comp[hi] = lo;
                    a = lo;
                }
            }
        }
        for k in 0..n {
            let r = find(comp, k);
            comp[k] = r;
        }
        // Each component's cliques, in order (counting sort by component).
        let starts = &mut self.comp_start;
        starts.clear();
        starts.resize(n + 1, 0);
        for c in 0..ncliques {
            starts[comp[key_cols[key_start[c]]] + 1] += 1;
        }
        for k in 0..n {
            starts[k + 1] += starts[k];
        }
        self.h_count.clear();
        self.h_count.extend_from_slice(&starts[..n]);
        overwrite_len(&mut self.comp_cliques, ncliques);
        for c in 0..ncliques {
            let r = comp[key_cols[key_start[c]]];
            self.comp_cliques[self.h_count[r]] = c;
            self.h_count[r] += 1;
        }
        self.same.clear();
        self.same.resize(n, false);
        if !incremental || self.old_comp.len() != n {
            return;
        }
        let (old_start, old_cols) = (self.clique_start.as_slice(), self.clique_cols.as_slice());
        for k in 0..n {
            let r = comp[k];
            if r != k {
                // (r < k: its flag is set.)
                self.same[k] = self.same[r];
                continue;
            }
            let new = &self.comp_cliques[starts[r]..starts[r + 1]];
            let old = &self.old_comp_cliques[self.old_comp_start[r]..self.old_comp_start[r + 1]];
            self.same[r] = self.old_comp[r] == r
                && new.len() == old.len()
                && new.iter().zip(old).all(|(&a, &b)| {
                    key_cols[key_start[a]..key_start[a + 1]] == old_cols[old_start[b]..old_start[b + 1]]
                });
        }
    }

    /// Whether the analyzed H pattern holds every pair of every clique just built (the
    /// contacts of a step are those of an earlier one, or fewer of them), while the analyzed
    /// pattern has at most twice as many cliques as the new one (a pattern left over from many
    /// contacts since gone is analyzed afresh rather than kept, its fill costing every factor).
    /// A kept pattern may couple dofs no row couples now — other islands: the factor of one
    /// island's rows then zeroes its entries in another's columns (`numeric`'s `group`).
    fn covers_cliques(&mut self) -> bool {
        let (new, kept) = (self.clique_start.len() - 1, self.key_start.len() - 1);
        if kept > 2 * new + 8 {
            return false;
        }
        (0..new).all(|c| self.clique_covered(c))
    }

    /// Whether the analyzed H pattern holds every pair of new clique c.
    fn clique_covered(&mut self, c: usize) -> bool {
        let clique = &self.clique_cols[self.clique_start[c]..self.clique_start[c + 1]];
        for (t, &p) in clique.iter().enumerate().skip(1) {
            self.stamp += 1;
            for &q in &self.h_cols[self.h_start[p]..self.h_start[p + 1]] {
                self.cover[q] = self.stamp;
            }
            if clique[..t].iter().any(|&q| self.cover[q] != self.stamp) {
                return false;
            }
        }
        true
    }

    /// Whether a clique of the analyzed pattern holds dofs of two groups (`group` by dof; false
    /// when it is empty).
    fn cliques_span(&self, group: &[usize]) -> bool {
        if group.is_empty() {
            return false;
        }
        self.key_start.windows(2).any(|w| {
            let clique = &self.key_cols[w[0]..w[1]];
            clique.split_first().is_some_and(|(&first, rest)| rest.iter().any(|&q| group[q] != group[first]))
        })
    }

    /// From H's pattern: P H P's (its transpose, reindexed), the elimination tree, L's pattern
    /// by rows (each row's `ereach`, ascending) and by columns, and where each entry of the one
    /// sits in the other.
    fn symbolic(&mut self, n: usize) {
        // Row p of P H P's strict lower part: dof k = n − 1 − p's entries j > k of H, at
        // positions n − 1 − j (counting sort; a row's order does not matter below).
        self.p_start.clear();
        self.p_start.resize(n + 1, 0);
        // (An unchanged component's rows are left out: only the rows analyzed anew read P H P.)
        for j in 0..n {
            if !self.same[j] {
                for &k in &self.h_cols[self.h_start[j]..self.h_start[j + 1]] {
                    self.p_start[n - k] += 1;
                }
            }
        }
        for p in 0..n {
            self.p_start[p + 1] += self.p_start[p];
        }
        self.h_count.clear();
        self.h_count.extend_from_slice(&self.p_start[..n]);
        overwrite_len(&mut self.p_cols, self.p_start[n]);
        {
            let (next, p_cols) = (self.h_count.as_mut_slice(), self.p_cols.as_mut_slice());
            let (h_start, h_cols) = (self.h_start.as_slice(), self.h_cols.as_slice());
            for j in (0..n).filter(|&j| !self.same[j]) {
                for &k in &h_cols[h_start[j]..h_start[j + 1]] {
                    let p = n - 1 - k;
                    p_cols[next[p]] = n - 1 - j;
                    next[p] += 1;
                }
            }
        }
        self.elimination_tree(n);
        self.mark.clear();
        self.mark.resize(n, NONE);
        std::mem::swap(&mut self.l_start, &mut self.old_l_start);
        std::mem::swap(&mut self.l_cols, &mut self.old_l_cols);
        let (mut l_start, mut l_cols) = (std::mem::take(&mut self.l_start), std::mem::take(&mut self.l_cols));
        l_start.clear();
        l_start.push(0);
        l_cols.clear();
        {
            let (mark, parent) = (self.mark.as_mut_slice(), self.parent.as_slice());
            let (p_start, p_cols) = (self.p_start.as_slice(), self.p_cols.as_slice());
            let (same, old_start, old_cols) =
                (self.same.as_slice(), self.old_l_start.as_slice(), self.old_l_cols.as_slice());
            for k in 0..n {
                if same[n - 1 - k] {
                    // An unchanged component's row of L: the last analysis's (ascending; the
                    // order does not matter here).
                    l_cols.extend_from_slice(&old_cols[old_start[k]..old_start[k + 1]]);
                    l_start.push(l_cols.len());
                    continue;
                }
                // Row k's pattern: every dof reached from H's row k up the tree (all below k),
                // in the order reached (sorted below).
                mark[k] = k;
                for &j in &p_cols[p_start[k]..p_start[k + 1]] {
                    let mut i = j;
                    while mark[i] != k {
                        mark[i] = k;
                        l_cols.push(i);
                        i = parent[i];
                    }
                }
                l_start.push(l_cols.len());
            }
        }
        self.l_start = l_start;
        self.l_cols = l_cols;
        let nnz = self.l_cols.len();
        // (The last analysis's columns: an unchanged component's are copied. Its positions'
        // entries lie in its own rows and columns only.)
        std::mem::swap(&mut self.c_start, &mut self.old_c_start);
        std::mem::swap(&mut self.c_rows, &mut self.old_c_rows);
        std::mem::swap(&mut self.c_slot, &mut self.old_c_slot);
        let same_at = |same: &[bool], p: usize| same[n - 1 - p];
        self.c_start.clear();
        self.c_start.resize(n + 1, 0);
        for k in 0..n {
            if same_at(&self.same, k) {
                // Column k's count as before.
                self.c_start[k + 1] += self.old_c_start[k + 1] - self.old_c_start[k];
            } else {
                for &j in &self.l_cols[self.l_start[k]..self.l_start[k + 1]] {
                    self.c_start[j + 1] += 1;
                }
            }
        }
        for j in 0..n {
            self.c_start[j + 1] += self.c_start[j];
        }
        self.h_count.clear();
        self.h_count.extend_from_slice(&self.c_start[..n]);
        // (Every entry of c_rows and c_slot is written below; c_vals is written by `numeric`
        // before any read: a solve factors every island of a new pattern first.)
        overwrite_len(&mut self.c_rows, nnz);
        overwrite_len(&mut self.c_vals, nnz);
        overwrite_len(&mut self.c_slot, nnz);
        // L by columns: rows taken in ascending order, so each column's rows ascend (an
        // unchanged column's rows as before).
        {
            let (next, c_rows) = (self.h_count.as_mut_slice(), self.c_rows.as_mut_slice());
            let (l_start, l_cols) = (self.l_start.as_slice(), self.l_cols.as_slice());
            let (same, old_start, old_rows) =
                (self.same.as_slice(), self.old_c_start.as_slice(), self.old_c_rows.as_slice());
            for k in 0..n {
                if same_at(same, k) {
                    let old = &old_rows[old_start[k]..old_start[k + 1]];
                    c_rows[next[k]..next[k] + old.len()].copy_from_slice(old);
                    continue;
                }
                for &j in &l_cols[l_start[k]..l_start[k + 1]] {
                    c_rows[next[j]] = k;
                    next[j] += 1;
                }
            }
        }
        // L by rows again from its columns, taken in ascending order: each row's columns ascend
        // (two counting passes instead of a sort per row); and where each entry sits in the
        // column storage. (`ancestor` is free scratch after the elimination tree.) An unchanged
        // row's columns ascend already (copied): its entries' slots are the old ones moved with
        // their columns.
        self.ancestor.clear();
        self.ancestor.extend_from_slice(&self.l_start[..n]);
        {
            let next = self.ancestor.as_mut_slice();
            let (l_start, old_l_start) = (self.l_start.as_slice(), self.old_l_start.as_slice());
            let (l_cols, c_slot) = (self.l_cols.as_mut_slice(), self.c_slot.as_mut_slice());
            let (c_start, c_rows) = (self.c_start.as_slice(), self.c_rows.as_slice());
            let (same, old_c_start, old_slot) =
                (self.same.as_slice(), self.old_c_start.as_slice(), self.old_c_slot.as_slice());
            for j in 0..n {
                if same_at(same, j) {
                    // Row j (unchanged): each entry's slot in its column, moved.
                    let (a, b) = (l_start[j], l_start[j + 1]);
                    let old = old_l_start[j];
                    for u in a..b {
                        let c = l_cols[u];
                        c_slot[u] = old_slot[old + (u - a)] - old_c_start[c] + c_start[c];
                    }
                    continue;
                }
                for slot in c_start[j]..c_start[j + 1] {
                    let k = c_rows[slot];
                    let u = next[k];
                    next[k] += 1;
                    l_cols[u] = j;
                    c_slot[u] = slot;
                }
            }
        }
        // The scratch rows are zero between calls: set only when the size changes.
        if self.x.len() != n {
            self.x.clear();
            self.x.resize(n, 0.0);
        }
        if self.xb.len() != RANK * n {
            self.xb.clear();
            self.xb.resize(RANK * n, 0.0);
        }
        // (The diagonal and H's values are written before a factorization or solve reads them;
        // the coverage stamps are all below the next one.)
        overwrite_len(&mut self.diag, n);
        overwrite_len(&mut self.h_vals, self.h_cols.len());
        overwrite_len(&mut self.h_diag, n);
        overwrite_len(&mut self.cover, n);
        self.analyzed = true;
    }

    /// Liu's algorithm: parent[i] = the first row k > i with L[k, i] ≠ 0.
    fn elimination_tree(&mut self, n: usize) {
        std::mem::swap(&mut self.parent, &mut self.old_parent);
        self.parent.clear();
        self.parent.resize(n, NONE);
        self.ancestor.clear();
        self.ancestor.resize(n, NONE);
        let (parent, ancestor) = (self.parent.as_mut_slice(), self.ancestor.as_mut_slice());
        let (p_start, p_cols) = (self.p_start.as_slice(), self.p_cols.as_slice());
        let (same, old_parent) = (self.same.as_slice(), self.old_parent.as_slice());
        for k in 0..n {
            if same[n - 1 - k] {
                // An unchanged component's positions: their parents (in the component) as before.
                parent[k] = old_parent[k];
                continue;
            }
            for &j in &p_cols[p_start[k]..p_start[k + 1]] {
                let mut i = j;
                while i != NONE && i < k {
                    let next = ancestor[i];
                    ancestor[i] = k;
                    if next == NONE {
                        parent[i] = k;
                    }
                    i = next;
                }
            }
        }
    }

    /// Left-looking factorization of P H P on the analyzed pattern, column by column: column p
    /// (dof k = n − 1 − p) is H's column k less Σ L'[p, c] L'[p.., c] over row p's columns c,
    /// ascending (MuJoCo's `mju_cholFactorNumeric` does the same products, its L being L'
    /// reindexed). Every position in order, or (`rows`) the listed dofs' positions only, in the
    /// reverse of the list's order: islands whose dofs are listed ascending each; entries in
    /// another group's rows or columns (`group`, by dof) are set to zero.
    fn numeric(&mut self, tol: f64, rows: Option<(&[usize], &[usize])>) -> bool {
        let n = self.diag.len();
        let all = (0..if rows.is_some() { 0 } else { n }).map(|p| n - 1 - p);
        let (listed, group) = rows.unwrap_or((&[], &[]));
        // Entries across groups exist only in a kept wider pattern or where a clique spans
        // groups (a contact whose rows' columns differ): else no entry needs the test.
        let group = if self.kept_wider || self.cliques_span(group) { group } else { &[] };
        let x = &mut self.x;
        let other = |a: usize, b: usize| !group.is_empty() && group[n - 1 - a] != group[n - 1 - b];
        for k in all.chain(listed.iter().rev().copied()) {
            let p = n - 1 - k;
            // H's column k below the diagonal (its row k left of it), at positions.
            let (a, b) = (self.h_start[k], self.h_start[k + 1]);
            for (&j, &h_kj) in self.h_cols[a..b].iter().zip(&self.h_vals[a..b]) {
                x[n - 1 - j] = h_kj;
            }
            let mut d = self.h_diag[k];
            for u in self.l_start[p]..self.l_start[p + 1] {
                let (c, slot) = (self.l_cols[u], self.c_slot[u]);
                if other(c, p) {
                    // A kept pattern's coupling to another group: zero in this factor.
                    self.c_vals[slot] = 0.0;
                    continue;
                }
                let l_pc = self.c_vals[slot];
                d -= l_pc * l_pc;
                let end = self.c_start[c + 1];
                for (&i, &l_ic) in self.c_rows[slot + 1..end].iter().zip(&self.c_vals[slot + 1..end]) {
                    x[i] -= l_ic * l_pc;
                }
            }
            if d <= tol {
                // (The scratch is cleared for the next factorization.)
                for &i in &self.c_rows[self.c_start[p]..self.c_start[p + 1]] {
                    x[i] = 0.0;
                }
                return false;
            }
            let d = d.sqrt();
            self.diag[p] = d;
            for slot in self.c_start[p]..self.c_start[p + 1] {
                let i = self.c_rows[slot];
                let v = if other(i, p) { 0.0 } else { x[i] / d };
                x[i] = 0.0;
                self.c_vals[slot] = v;
            }
        }
        true
    }

    /// The factor of H ± w wᵀ from that of H (a rank-one update, `add`, or downdate), with
    /// w = `scale` · v, v nonzero on the dofs `cols` (ascending) with values `vals`: the
    /// columns of L' on the elimination-tree path from w's first position (its last dof) to its
    /// root change
    /// (Davis, *Direct Methods for Sparse Linear Systems*, §4.8; MuJoCo's Newton solver keeps its
    /// factor the same way as rows enter and leave their quadratic state, `HessianIncremental`,
    /// engine_solver.c). w's pattern must lie in the analyzed one (a row of the analyzed
    /// cliques). Returns false if a downdate leaves a pivot at or below 1e-10 of its square
    /// before: the factor is then spoiled and the caller factors H afresh.
    #[cfg(test)]
    pub fn rank_one(&mut self, cols: &[usize], vals: &[f64], scale: f64, add: bool) -> bool {
        self.rank_update(cols, &[vals], &[scale], &[add])
    }

    /// [`Self::rank_one`] for up to [`RANK`] vectors on the same dofs `cols` (a contact's rows
    /// entering or leaving together: `vals[v]`, `scale[v]`, `add[v]` each), applied one after
    /// the other — to the same bits as that many calls of `rank_one` in order — in one walk of
    /// their common elimination-tree path: at each column the vectors' rotations in turn, then
    /// each entry of the column rotated by them in turn (each of L's entries read and written
    /// once for all of them).
    pub fn rank_update(&mut self, cols: &[usize], vals: &[&[f64]], scale: &[f64], add: &[bool]) -> bool {
        match vals.len() {
            0 => true,
            1 => self.rank_update_of::<1>(cols, vals, scale, add),
            2 => self.rank_update_of::<2>(cols, vals, scale, add),
            3 => self.rank_update_of::<3>(cols, vals, scale, add),
            _ => self.rank_update_of::<RANK>(cols, vals, scale, add),
        }
    }

    fn rank_update_of<const K: usize>(
        &mut self,
        cols: &[usize],
        vals: &[&[f64]],
        scale: &[f64],
        add: &[bool],
    ) -> bool {
        let Some(&last) = cols.last() else {
            return true;
        };
        let n = self.diag.len();
        let first = n - 1 - last;
        let mut sign = [0.0; K];
        for v in 0..K {
            sign[v] = if add[v] { 1.0 } else { -1.0 };
        }
        // The vectors interleaved: vector v's entry at position p in xb[RANK p + v].
        let xb = &mut self.xb;
        for (t, &k) in cols.iter().enumerate() {
            let p = n - 1 - k;
            for v in 0..K {
                xb[RANK * p + v] = scale[v] * vals[v][t];
            }
        }
        // xb is nonzero only on the path (a column's rows are its ancestors): each entry is
        // cleared as its column is passed, so xb is zero again at the end.
        let mut k = first;
        let mut ok = true;
        while k != NONE {
            // Each vector's rotation (c, s, sign · s, 1 / c) at column k, in order (each from
            // the pivot the one before left); `live` where one applies.
            let mut rot = [[0.0; 4]; K];
            let mut live = [false; K];
            for v in 0..K {
                let w_k = xb[RANK * k + v];
                xb[RANK * k + v] = 0.0;
                if ok && w_k != 0.0 {
                    let l_kk = self.diag[k];
                    let r2 = l_kk * l_kk + sign[v] * w_k * w_k;
                    if r2 <= 1e-10 * l_kk * l_kk {
                        ok = false;
                    } else {
                        let r = r2.sqrt();
                        let (c, s, inv_c) = (r / l_kk, w_k / l_kk, l_kk / r);
                        rot[v] = [c, s, sign[v] * s, inv_c];
                        live[v] = true;
                        self.diag[k] = r;
                    }
                }
            }
            if ok && live.iter().all(|&l| l) {
                // Every vector rotates this column (the usual case): the same products in the
                // same order without the per-vector test.
                let (a, b) = (self.c_start[k], self.c_start[k + 1]);
                for (&i, l_ik) in self.c_rows[a..b].iter().zip(&mut self.c_vals[a..b]) {
                    let x = &mut xb[RANK * i..RANK * i + K];
                    let mut l = *l_ik;
                    for v in 0..K {
                        let [c, s, signed_s, inv_c] = rot[v];
                        let x_i = x[v];
                        l = (l + signed_s * x_i) * inv_c;
                        x[v] = c * x_i - s * l;
                    }
                    *l_ik = l;
                }
            } else if ok && live.iter().any(|&l| l) {
                let (a, b) = (self.c_start[k], self.c_start[k + 1]);
                for (&i, l_ik) in self.c_rows[a..b].iter().zip(&mut self.c_vals[a..b]) {
                    let x = &mut xb[RANK * i..RANK * i + K];
                    let mut l = *l_ik;
                    for v in 0..K {
                        if live[v] {
                            let [c, s, signed_s, inv_c] = rot[v];
                            let x_i = x[v];
                            l = (l + signed_s * x_i) * inv_c;
                            x[v] = c * x_i - s * l;
                        }
                    }
                    *l_ik = l;
                }
            }
            k = self.parent[k];
        }
        ok
    }

    /// Solves H x = b in place with the last factor (b holds x on return).
    #[cfg(test)]
    pub fn solve(&self, b: &mut [f64]) {
        self.solve_where(b, None);
    }

    /// Solves H x = b in place (b holds x on return) on the dofs `rows` of the last
    /// [`Self::factor_rows`] (the other entries of b are left as they are).
    pub fn solve_rows(&self, b: &mut [f64], rows: &[usize]) {
        self.solve_where(b, Some(rows));
    }

    /// Forward then backward substitution with L' on P b: over every position (`rows` None) or
    /// the listed dofs' (each independent group's ascending: forward in the reverse of the
    /// list's order, backward in its order).
    fn solve_where(&self, b: &mut [f64], rows: Option<&[usize]>) {
        let n = self.diag.len();
        let b = &mut b[..n];
        let all = (0..if rows.is_some() { 0 } else { n }).map(|p| n - 1 - p);
        let listed = rows.unwrap_or(&[]);
        // Position p is dof n − 1 − p: b[n − 1 − p] holds (P b)[p]. Forward by columns (each
        // entry's products subtracted in ascending column order, as the row form would);
        // backward by rows of L'ᵀ, each row's sum from its last entry to its first; each unknown
        // scaled by its pivot's reciprocal: the dense `cholesky_solve`'s arithmetic.
        for k in all.clone().chain(listed.iter().rev().copied()) {
            let p = n - 1 - k;
            let y = b[k] * (1.0 / self.diag[p]);
            b[k] = y;
            if y == 0.0 {
                continue;
            }
            let (lo, hi) = (self.c_start[p], self.c_start[p + 1]);
            for (&l, &i) in self.c_vals[lo..hi].iter().zip(&self.c_rows[lo..hi]) {
                b[n - 1 - i] -= l * y;
            }
        }
        for k in all.rev().chain(listed.iter().copied()) {
            let p = n - 1 - k;
            let (lo, hi) = (self.c_start[p], self.c_start[p + 1]);
            let mut s = b[k];
            for (&l, &j) in self.c_vals[lo..hi].iter().zip(&self.c_rows[lo..hi]).rev() {
                s -= l * b[n - 1 - j];
            }
            b[k] = s * (1.0 / self.diag[p]);
        }
    }
}

/// H's values on the analyzed pattern, borrowed for assembly in place: row k's strictly lower
/// entries at columns `cols[start[k]..start[k + 1]]` (ascending) hold `vals` there, the
/// diagonal `diag[k]`.
pub(crate) struct SparseH<'a> {
    pub start: &'a [usize],
    pub cols: &'a [usize],
    pub vals: &'a mut [f64],
    pub diag: &'a mut [f64],
}

/// Sets `v`'s length to `len` for a pass that writes every entry before any is read: only
/// entries beyond its old length are filled (a symbolic analysis reuses its buffers without
/// clearing them first).
fn overwrite_len<T: Copy + Default>(v: &mut Vec<T>, len: usize) {
    if v.len() < len {
        v.resize(len, T::default());
    } else {
        v.truncate(len);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::constraint::dense::{cholesky, cholesky_solve};

    /// A block-sparse SPD matrix: a chain of 3×3 blocks, two far blocks coupled, one block alone.
    fn sample(n: usize) -> DMatrix<f64> {
        let mut b = DMatrix::zeros(n, n);
        for i in 0..n {
            b[(i, i)] = 1.0 + (i % 5) as f64;
            if i % 3 != 0 {
                b[(i, i - 1)] = 0.3 + 0.01 * i as f64;
            }
        }
        b[(n - 2, 1)] = 0.7;
        b[(n - 1, 4)] = -0.2;
        &b * b.transpose() + DMatrix::identity(n, n) * 0.5
    }

    #[test]
    fn factor_and_solve_equal_the_dense_ones_of_the_reversed_matrix_bit_for_bit() {
        // The sparse factor is P H P's (P the reversal): the dense one of P H P, P b and P x.
        let n = 17;
        let h = sample(n);
        let reversed = DMatrix::from_fn(n, n, |i, j| h[(n - 1 - i, n - 1 - j)]);
        let mut dense = DMatrix::zeros(n, n);
        assert!(cholesky(&reversed, n, &mut dense, 0.0));
        let mut sparse = SparseCholesky::default();
        assert!(sparse.factor(&h, n, 0.0));
        let rhs: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
        let (mut xd, mut xs): (Vec<f64>, _) = (rhs.iter().rev().copied().collect(), rhs.clone());
        cholesky_solve(&dense, n, &mut xd);
        sparse.solve(&mut xs);
        xd.reverse();
        assert_eq!(xd, xs);
        for p in 0..n {
            assert_eq!(sparse.diag[p], dense[(p, p)]);
        }
        // Fewer stored entries than the dense lower triangle: the structure was used.
        assert!(sparse.l_cols.len() < n * (n - 1) / 2);
    }

    #[test]
    fn the_structured_factor_equals_the_scanning_one() {
        // A tree 0 → 1 → 2 and a free chain 3 → 4 → 5, and dof 6 alone; two constraint rows
        // coupling {2, 4} and {5, 6}.
        let n = 7;
        let dof_parent = [NONE, 0, 1, NONE, 3, 4, NONE];
        let mut h = DMatrix::zeros(n, n);
        for k in 0..n {
            h[(k, k)] = 4.0 + k as f64;
            let mut l = dof_parent[k];
            while l != NONE {
                h[(k, l)] = 0.3 + 0.1 * (k + l) as f64;
                h[(l, k)] = h[(k, l)];
                l = dof_parent[l];
            }
        }
        for (a, b, v) in [(4, 2, 0.5), (6, 5, -0.4)] {
            h[(a, b)] += v;
            h[(b, a)] += v;
        }
        let (nz_start, nz_index) = ([0, 2, 4, 6], [2, 4, 5, 6, 0, 3]);
        let mut structured = SparseCholesky::default();
        structured.analyze(n, &dof_parent, &[(0, 0), (1, 1)], &nz_start, &nz_index);
        assert!(structured.factor_analyzed(&h));
        let mut scanning = SparseCholesky::default();
        assert!(scanning.factor(&h, n, 0.0));
        let rhs: Vec<f64> = (0..n).map(|i| 1.0 + i as f64).collect();
        let (mut x1, mut x2) = (rhs.clone(), rhs.clone());
        structured.solve(&mut x1);
        scanning.solve(&mut x2);
        assert_eq!(x1, x2);
        // Dof 6 couples only to 5: no fill reaches the first tree.
        assert_eq!(structured.pattern_row(6), &[5]);
        // The same cliques again: the structure is kept, the factor the same.
        structured.analyze(n, &dof_parent, &[(0, 0), (1, 1)], &nz_start, &nz_index);
        assert_eq!(structured.analyses(), 1);
        assert!(structured.factor_analyzed(&h));
        let mut x3 = rhs.clone();
        structured.solve(&mut x3);
        assert_eq!(x3, x2);
        // A wider pattern (a third group coupling dofs 0 and 3, whose entry of h is zero, and
        // rows 0 and 1 as one group) factors the same h to the same bits.
        structured.analyze(n, &dof_parent, &[(0, 1), (2, 2)], &nz_start, &nz_index);
        assert_eq!(structured.analyses(), 2);
        assert!(structured.pattern_row(3).contains(&0) && structured.pattern_row(5).contains(&2));
        assert!(structured.factor_analyzed(&h));
        let mut x4 = rhs;
        structured.solve(&mut x4);
        assert_eq!(x4, x2);
    }

    /// A positive definite matrix with M's pattern for the tree `dof_parent`: 3 + k on the
    /// diagonal, 0.4 between each dof and its ancestors.
    fn tree_matrix(dof_parent: &[usize]) -> DMatrix<f64> {
        let n = dof_parent.len();
        let mut h = DMatrix::zeros(n, n);
        for k in 0..n {
            h[(k, k)] = 3.0 + k as f64;
            let mut l = dof_parent[k];
            while l != NONE {
                h[(k, l)] = 0.4;
                h[(l, k)] = 0.4;
                l = dof_parent[l];
            }
        }
        h
    }

    #[test]
    fn a_kept_factor_solves_its_rows_as_the_whole_factor() {
        // Two uncoupled trees 0 → 1 → 2 and 3 → 4, a row coupling 1 and 2 only: keeping the
        // first tree's rows gives the whole factor's solution there and leaves the rest of b.
        let n = 5;
        let dof_parent = [NONE, 0, 1, NONE, 3];
        let h = tree_matrix(&dof_parent);
        let (nz_start, nz_index) = ([0, 2], [1, 2]);
        let mut f = SparseCholesky::default();
        f.analyze(n, &dof_parent, &[(0, 0)], &nz_start, &nz_index);
        assert!(f.factor_analyzed(&h));
        let rhs = [1.0, -2.0, 0.5, 3.0, -1.0];
        let mut whole = rhs;
        f.solve(&mut whole);
        let first_tree = [0, 1, 2];
        let mut g = SparseCholesky::default();
        g.analyze(n, &dof_parent, &[(0, 0)], &nz_start, &nz_index);
        g.load(&h);
        assert!(g.factor_rows(&first_tree, &[0, 0, 0, 1, 1]));
        let mut kept = rhs;
        g.solve_rows(&mut kept, &first_tree);
        assert_eq!(&kept[..3], &whole[..3]);
        assert_eq!(&kept[3..], &rhs[3..]);
    }

    #[test]
    fn rank_one_updates_and_downdates_give_the_factor_of_the_modified_matrix() {
        // The kept-factor sample's two trees and a row coupling dofs 1, 2 and 4 (one clique):
        // H + w wᵀ factored afresh against the update, then the downdate back to H's factor.
        let n = 5;
        let dof_parent = [NONE, 0, 1, NONE, 3];
        let h = tree_matrix(&dof_parent);
        let (nz_start, nz_index) = ([0, 3], [1, 2, 4]);
        let (cols, vals, scale) = ([1, 2, 4], [0.5, -1.5, 2.0], 1.7);
        let mut f = SparseCholesky::default();
        f.analyze(n, &dof_parent, &[(0, 0)], &nz_start, &nz_index);
        assert!(f.factor_analyzed(&h));
        assert!(f.rank_one(&cols, &vals, scale, true));
        let mut h_plus = h.clone();
        for a in 0..3 {
            for b in 0..3 {
                h_plus[(cols[a], cols[b])] += scale * scale * vals[a] * vals[b];
            }
        }
        let mut g = SparseCholesky::default();
        g.analyze(n, &dof_parent, &[(0, 0)], &nz_start, &nz_index);
        assert!(g.factor_analyzed(&h_plus));
        let rhs = [1.0, -2.0, 0.5, 3.0, -1.0];
        let (mut x1, mut x2) = (rhs, rhs);
        f.solve(&mut x1);
        g.solve(&mut x2);
        for k in 0..n {
            assert!((x1[k] - x2[k]).abs() <= 1e-13 * (1.0 + x2[k].abs()), "{x1:?} against {x2:?}");
            assert!((f.diag[k] - g.diag[k]).abs() <= 1e-13 * g.diag[k]);
        }
        // The scratch is clean, and the downdate returns H's factor.
        assert!(f.xb.iter().all(|&v| v == 0.0));
        assert!(f.rank_one(&cols, &vals, scale, false));
        let mut h_factor = SparseCholesky::default();
        h_factor.analyze(n, &dof_parent, &[(0, 0)], &nz_start, &nz_index);
        assert!(h_factor.factor_analyzed(&h));
        let (mut y1, mut y2) = (rhs, rhs);
        f.solve(&mut y1);
        h_factor.solve(&mut y2);
        for k in 0..n {
            assert!((y1[k] - y2[k]).abs() <= 1e-13 * (1.0 + y2[k].abs()), "{y1:?} against {y2:?}");
        }
        // A downdate that would leave H indefinite is refused.
        assert!(!f.rank_one(&cols, &vals, 10.0, false));
        assert!(f.xb.iter().all(|&v| v == 0.0));
    }

    #[test]
    fn a_rank_update_of_several_vectors_is_their_rank_one_updates_in_order_to_the_bit() {
        // Two trees and a row group on dofs 1, 2 and 4: three vectors (two updates and a
        // downdate) at once against one after the other.
        let n = 5;
        let dof_parent = [NONE, 0, 1, NONE, 3];
        let h = tree_matrix(&dof_parent);
        let (nz_start, nz_index) = ([0, 3], [1, 2, 4]);
        let cols = [1, 2, 4];
        let vals: [&[f64]; 3] = [&[0.5, -1.5, 2.0], &[1.0, 0.25, -0.5], &[0.3, 0.2, 0.1]];
        let (scale, add) = ([1.7, 0.9, 0.8], [true, true, false]);
        let mut one = SparseCholesky::default();
        one.analyze(n, &dof_parent, &[(0, 0)], &nz_start, &nz_index);
        assert!(one.factor_analyzed(&h));
        let mut all = one.clone();
        for v in 0..3 {
            assert!(one.rank_one(&cols, vals[v], scale[v], add[v]));
        }
        assert!(all.rank_update(&cols, &vals, &scale, &add));
        assert_eq!(one.diag, all.diag);
        assert_eq!(one.c_vals, all.c_vals);
        assert!(all.xb.iter().all(|&v| v == 0.0));
    }

    #[test]
    fn a_kept_wider_pattern_factors_one_group_as_its_own_pattern_does() {
        // Trees 0 → 1 → 2 and 3 → 4; first a row couples 2 and 4 (one group), factored whole;
        // then no row couples them: the wider pattern is kept, and factoring the first tree's
        // rows alone (its entries in the second tree's rows and columns, left coupled by the
        // first factor, zeroed) solves its part as a factor of its own pattern does.
        let n = 5;
        let dof_parent = [NONE, 0, 1, NONE, 3];
        let h = tree_matrix(&dof_parent);
        let mut coupled = h.clone();
        coupled[(4, 2)] = 0.9;
        coupled[(2, 4)] = 0.9;
        let (nz_start, nz_index) = ([0, 2], [2, 4]);
        let mut f = SparseCholesky::default();
        f.analyze(n, &dof_parent, &[(0, 0)], &nz_start, &nz_index);
        assert!(f.factor_analyzed(&coupled));
        f.analyze(n, &dof_parent, &[], &nz_start, &nz_index);
        assert_eq!(f.analyses(), 1);
        let (first_tree, group) = ([0, 1, 2], [0, 0, 0, 1, 1]);
        f.load(&h);
        assert!(f.factor_rows(&first_tree, &group));
        let rhs = [1.0, -2.0, 0.5, 3.0, -1.0];
        let mut kept = rhs;
        f.solve_rows(&mut kept, &first_tree);
        let mut own = SparseCholesky::default();
        own.analyze(n, &dof_parent, &[], &nz_start, &nz_index);
        assert!(own.factor_analyzed(&h));
        let mut want = rhs;
        own.solve(&mut want);
        assert_eq!(&kept[..3], &want[..3]);
        assert_eq!(&kept[3..], &rhs[3..]);
    }

    #[test]
    fn an_analysis_that_copies_unchanged_components_equals_a_fresh_one() {
        // Three trees 0 → 1 → 2, 3 → 4, 5 → 6 → 7 and dof 8 alone. First rows couple {2, 4} and
        // {6, 8}; then {2, 4} stays and {6, 8} becomes {7, 8}: the component of trees 0 and 3
        // is copied, the other analyzed, and the structure is the fresh analysis's.
        let n = 9;
        let dof_parent = [NONE, 0, 1, NONE, 3, NONE, 5, 6, NONE];
        let (start_a, index_a) = ([0, 2, 4], [2, 4, 6, 8]);
        let (start_b, index_b) = ([0, 2, 4], [2, 4, 7, 8]);
        let groups = [(0, 0), (1, 1)];
        let mut kept = SparseCholesky::default();
        kept.analyze(n, &dof_parent, &groups, &start_a, &index_a);
        kept.analyze(n, &dof_parent, &groups, &start_b, &index_b);
        assert_eq!(kept.analyses(), 2);
        assert_eq!(kept.same, [true, true, true, true, true, false, false, false, false]);
        let mut fresh = SparseCholesky::default();
        fresh.analyze(n, &dof_parent, &groups, &start_b, &index_b);
        assert_eq!(fresh.same, [false; 9]);
        assert_eq!((&kept.h_start, &kept.h_cols), (&fresh.h_start, &fresh.h_cols));
        assert_eq!(kept.parent, fresh.parent);
        assert_eq!((&kept.l_start, &kept.l_cols), (&fresh.l_start, &fresh.l_cols));
        assert_eq!(
            (&kept.c_start, &kept.c_rows, &kept.c_slot),
            (&fresh.c_start, &fresh.c_rows, &fresh.c_slot)
        );
        // And it factors and solves as the fresh one.
        let mut h = tree_matrix(&dof_parent);
        for (a, b, v) in [(4, 2, 0.5), (8, 7, -0.3)] {
            h[(a, b)] = v;
            h[(b, a)] = v;
        }
        assert!(kept.factor_analyzed(&h) && fresh.factor_analyzed(&h));
        let rhs: Vec<f64> = (0..n).map(|i| (i as f64 * 0.7).cos()).collect();
        let (mut x1, mut x2) = (rhs.clone(), rhs);
        kept.solve(&mut x1);
        fresh.solve(&mut x2);
        assert_eq!(x1, x2);
    }

    #[test]
    fn a_matrix_that_is_not_positive_definite_is_refused() {
        let n = 8;
        let mut h = sample(n);
        h[(5, 5)] = -1.0;
        assert!(!SparseCholesky::default().factor(&h, n, 0.0));
    }
}
