//! The nonzeros of the soft rows' Jacobian `efc_j` by rows (MuJoCo keeps J sparse in
//! `efc_J_rownnz`/`efc_J_rowadr`/`efc_J_colind`; here J stays dense for the other readers and its
//! nonzeros are recorded beside it): recorded once per position stage ([`record`]), read by
//! the velocity stage (J v), the solvers' products and the Hessian's pattern, and used to
//! clear the rows before the next position stage writes them ([`clear_recorded`]) instead of
//! clearing every row of J.
//!
//! The record is valid while only the soft position stage writes `efc_j`: the exact rows'
//! writer (`ConstraintModel::positions_unchecked`, which the variational integrator also
//! calls) marks it stale, and a stale record is rebuilt or replaced by a full clear. A contact's
//! rows are recorded as they are written (`rows.rs`, `contact_rows`) over one shared column list,
//! exact zeros included.

use nalgebra::DMatrix;

/// The nonzero columns of J's rows 0..nefc, ascending, into `start`/`index` (row i's are
/// `index[start[i]..start[i + 1]]`) and J's values there into `value`, from one pass over J's
/// columns (contiguous in its storage): each column's nonzero rows are appended column after
/// column (`start` counting them per row), then regrouped by row through `scratch`.
pub(crate) fn record(
    j: &DMatrix<f64>,
    nefc: usize,
    start: &mut Vec<usize>,
    index: &mut Vec<usize>,
    value: &mut Vec<f64>,
    scratch: &mut Vec<(usize, usize)>,
) {
    start.clear();
    start.resize(nefc + 1, 0);
    scratch.clear();
    let rows = j.nrows();
    let data = j.as_slice();
    for k in 0..j.ncols() {
        // J is mostly zeros (a row touches only its bodies' ancestor dofs): blocks of 8 entries
        // are tested at once (a branch-free test the compiler vectorizes), entry by entry only
        // where one is nonzero.
        for (b, block) in data[k * rows..k * rows + nefc].chunks(8).enumerate() {
            if block.iter().fold(0u8, |any, &v| any | u8::from(v != 0.0)) == 0 {
                continue;
            }
            for (t, &v) in block.iter().enumerate() {
                if v != 0.0 {
                    let i = 8 * b + t;
                    start[i + 1] += 1;
                    scratch.push((i, k));
                }
            }
        }
    }
    for i in 0..nefc {
        start[i + 1] += start[i];
    }
    index.clear();
    index.resize(start[nefc], 0);
    value.clear();
    value.resize(start[nefc], 0.0);
    // start[i] is row i's next free slot while filling (columns arrive in ascending order), then
    // shifted back.
    for &(i, k) in scratch.iter() {
        index[start[i]] = k;
        value[start[i]] = data[k * rows + i];
        start[i] += 1;
    }
    for i in (1..=nefc).rev() {
        start[i] = start[i - 1];
    }
    start[0] = 0;
}

/// Zeroes rows `first..` of `j` that the record (`start`, `index`, rows 0..start.len() − 1)
/// lists as nonzero: with the record current, every row of `j` from `first` on is zero after.
/// `blocks` (first row, rows), ascending, are runs of rows recorded over the same columns (a
/// contact's rows): those are cleared column by column, each column's run contiguous in J's
/// storage.
pub(crate) fn clear_recorded(
    j: &mut DMatrix<f64>,
    first: usize,
    start: &[usize],
    index: &[usize],
    blocks: &[(usize, usize)],
) {
    let rows = j.nrows();
    let data = j.as_mut_slice();
    let recorded = start.len().saturating_sub(1);
    let clear_row = |data: &mut [f64], i: usize| {
        for &k in &index[start[i]..start[i + 1]] {
            data[k * rows + i] = 0.0;
        }
    };
    let mut i = first;
    for &(b0, n) in blocks {
        while i < b0.min(recorded) {
            clear_row(data, i);
            i += 1;
        }
        let (lo, end) = (i.max(b0), (b0 + n).min(recorded));
        if lo < end {
            for &k in &index[start[b0]..start[b0 + 1]] {
                let run = &mut data[k * rows + lo..k * rows + end];
                // A condim-3 pyramidal contact's four rows in one store, not a call to memset.
                if let Ok(four) = <&mut [f64; 4]>::try_from(&mut *run) {
                    *four = [0.0; 4];
                } else {
                    run.fill(0.0);
                }
            }
        }
        i = i.max(end);
    }
    while i < recorded {
        clear_row(data, i);
        i += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_record_lists_each_rows_nonzeros_and_clears_them() {
        let mut j = DMatrix::zeros(5, 4);
        for (i, k, v) in [(0, 1, 2.0), (0, 3, -1.0), (1, 0, 0.5), (2, 2, 3.0), (2, 3, 4.0)] {
            j[(i, k)] = v;
        }
        let (mut start, mut index, mut value, mut scratch) = (vec![], vec![], vec![], vec![]);
        record(&j, 3, &mut start, &mut index, &mut value, &mut scratch);
        assert_eq!(start, [0, 2, 3, 5]);
        assert_eq!(index, [1, 3, 0, 2, 3]);
        assert_eq!(value, [2.0, -1.0, 0.5, 3.0, 4.0]);
        clear_recorded(&mut j, 1, &start, &index, &[]);
        assert_eq!(j[(0, 1)], 2.0);
        assert_eq!(j[(0, 3)], -1.0);
        assert_eq!(j.rows(1, 4).iter().filter(|&&x| x != 0.0).count(), 0);
    }

    #[test]
    fn blocks_of_rows_on_the_same_columns_are_cleared_as_runs() {
        // Row 0 alone, rows 1–3 a block on columns 0 and 2, row 4 alone; cleared from row 2 on.
        let mut j = DMatrix::zeros(6, 3);
        for (i, k, v) in [(0, 1, 1.0), (1, 0, 2.0), (1, 2, 3.0), (2, 0, 4.0), (2, 2, 5.0), (3, 0, 6.0)] {
            j[(i, k)] = v;
        }
        j[(3, 2)] = 7.0;
        j[(4, 1)] = 8.0;
        let (mut start, mut index, mut value, mut scratch) = (vec![], vec![], vec![], vec![]);
        record(&j, 5, &mut start, &mut index, &mut value, &mut scratch);
        clear_recorded(&mut j, 2, &start, &index, &[(1, 3)]);
        assert_eq!(j[(0, 1)], 1.0);
        assert_eq!((j[(1, 0)], j[(1, 2)]), (2.0, 3.0));
        assert_eq!(j.rows(2, 4).iter().filter(|&&x| x != 0.0).count(), 0);
    }
}
