//! Zero-copy NumPy views of buffers owned by a Python object: the array's base is the owner, so
//! the owner (a `lagrange.Data`) lives as long as any view of it, and writes through the view
//! change the buffer the library reads.

use numpy::ndarray::{ArrayViewD, IxDyn};
use numpy::{PyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;

/// A writable C-ordered view of `shape` over the `f64`s at `ptr`, kept alive by `owner`.
///
/// # Safety
/// `ptr` must point to `shape.iter().product()` initialized `f64`s (or be a dangling, aligned
/// pointer when that is 0) that live as long as `owner` and are never reallocated while it
/// lives; every buffer of `lagrange::Data` the bindings view is allocated once by `Data::new`
/// and only moved out and back (same allocation) by the library's calls.
pub unsafe fn view<'py>(
    owner: Bound<'py, PyAny>,
    ptr: *const f64,
    shape: &[usize],
) -> Bound<'py, PyArrayDyn<f64>> {
    // SAFETY: the caller guarantees the extent and lifetime of the buffer.
    let array = unsafe { ArrayViewD::from_shape_ptr(IxDyn(shape), ptr) };
    // SAFETY: `owner` becomes the array's base, which keeps the buffer alive (caller's contract).
    let out = unsafe { PyArrayDyn::borrow_from_array(&array, owner) };
    debug_assert!(out.is_contiguous());
    out
}
