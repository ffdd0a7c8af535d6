//! A fixed-capacity list of a vector's nonzero entries — each one's offset in a column-major
//! matrix's storage and its value — on the stack and never zero-filled. The dense AVX2 kernels
//! (`dense::cholesky_avx2`'s earlier columns reaching a row, `soft::primal`'s J x over the
//! nonzero x_k) list them once per call and then sweep only those columns; filling two lists of
//! 256 entries with zeros first, as plain arrays would, cost each call as much as a short product
//! (a 4 KB store).

use std::mem::MaybeUninit;

/// Up to `N` listed (offset, value) pairs, in the order listed.
pub(crate) struct NonzeroList<const N: usize> {
    offsets: [MaybeUninit<usize>; N],
    values: [MaybeUninit<f64>; N],
    len: usize,
}

impl<const N: usize> NonzeroList<N> {
    /// An empty list (nothing written).
    #[inline(always)]
    pub(crate) fn new() -> Self {
        NonzeroList { offsets: [MaybeUninit::uninit(); N], values: [MaybeUninit::uninit(); N], len: 0 }
    }

    /// Replaces the list by the entries `entry(k)` = (offset, value), k = 0 .. count − 1 in
    /// order, whose value is not zero (a NaN is listed). Branch-free: every entry is written at
    /// the list's end, which advances past the nonzero ones only.
    ///
    /// # Panics
    /// When `count` exceeds `N`.
    #[inline(always)]
    pub(crate) fn list(&mut self, count: usize, mut entry: impl FnMut(usize) -> (usize, f64)) {
        assert!(count <= N, "{count} entries listed in a list of {N}");
        let mut m = 0;
        for k in 0..count {
            let (o, v) = entry(k);
            // SAFETY: m ≤ k < count ≤ N (asserted above): inside both arrays.
            unsafe {
                *self.offsets.get_unchecked_mut(m) = MaybeUninit::new(o);
                *self.values.get_unchecked_mut(m) = MaybeUninit::new(v);
            }
            m += usize::from(v != 0.0);
        }
        self.len = m;
    }

    /// The listed offsets.
    #[inline(always)]
    pub(crate) fn offsets(&self) -> &[usize] {
        // SAFETY: `list` wrote the first `len` entries (len ≤ N).
        unsafe { std::slice::from_raw_parts(self.offsets.as_ptr().cast::<usize>(), self.len) }
    }

    /// The listed values.
    #[inline(always)]
    pub(crate) fn values(&self) -> &[f64] {
        // SAFETY: `list` wrote the first `len` entries (len ≤ N).
        unsafe { std::slice::from_raw_parts(self.values.as_ptr().cast::<f64>(), self.len) }
    }
}

#[cfg(test)]
mod tests {
    use super::NonzeroList;

    #[test]
    fn lists_the_nonzero_entries_in_order_and_relists_from_empty() {
        let x = [0.0, 2.0, -0.0, f64::NAN, 5.0, 0.0];
        let mut list = NonzeroList::<8>::new();
        list.list(x.len(), |k| (10 * k, x[k]));
        assert_eq!(list.offsets(), &[10, 30, 40]);
        assert_eq!(list.values()[0], 2.0);
        assert!(list.values()[1].is_nan());
        assert_eq!(list.values()[2], 5.0);
        list.list(2, |k| (k, 0.0));
        assert!(list.offsets().is_empty() && list.values().is_empty());
    }

    #[test]
    #[should_panic(expected = "9 entries listed in a list of 8")]
    fn refuses_more_entries_than_it_holds() {
        NonzeroList::<8>::new().list(9, |k| (k, 1.0));
    }
}
