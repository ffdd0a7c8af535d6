//! Reading NumPy arguments: strict for the kernels' and rollouts' inputs (a C-contiguous float64
//! array of the model's shape with finite values, else a Python exception naming the argument),
//! lenient for attribute assignment (`d.qpos = [...]` converts as NumPy does, as MuJoCo's
//! bindings accept).

use crate::error::bad;
use numpy::{PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;

/// The values of `arg`, a C-contiguous float64 NumPy array of `shape`, all finite; `name` names
/// the argument in the exception.
pub fn strict<'py>(arg: &Bound<'py, PyAny>, name: &str, shape: &[usize]) -> PyResult<Vec<f64>> {
    let mut out = vec![0.0; shape.iter().product()];
    read_strict(arg, name, shape, &mut out)?;
    Ok(out)
}

/// [`strict`] into `out` (its length is the product of `shape`), without allocating.
pub fn read_strict(arg: &Bound<'_, PyAny>, name: &str, shape: &[usize], out: &mut [f64]) -> PyResult<()> {
    let array = arg.cast::<PyArrayDyn<f64>>().map_err(|_| {
        let kind = match arg.getattr("dtype") {
            Ok(dtype) => format!("a NumPy array of dtype {dtype}"),
            Err(_) => format!("a {}", arg.get_type().name().map(|n| n.to_string()).unwrap_or_default()),
        };
        PyTypeError::new_err(format!(
            "{name}: expected a float64 NumPy array of shape {shape:?}, got {kind} (use numpy.asarray({name}, dtype=float))"
        ))
    })?;
    if array.shape() != shape {
        return Err(bad(format!("{name}: expected shape {shape:?}, got {:?}", array.shape())));
    }
    let readonly = array.try_readonly().map_err(|e| bad(format!("{name}: {e}")))?;
    let values = readonly.as_slice().map_err(|_| {
        bad(format!("{name}: the array is not C-contiguous (use numpy.ascontiguousarray({name}))"))
    })?;
    if let Some(i) = values.iter().position(|x| !x.is_finite()) {
        return Err(bad(format!("{name}: element {i} (flat index) is {}, not a finite number", values[i])));
    }
    out.copy_from_slice(values);
    Ok(())
}

/// The values of `value` converted by `numpy.asarray(value, dtype=float64)` and checked against
/// `shape` (that shape, or as many values in one dimension). A copy, so that `value` may be a
/// view of the very buffer it is assigned to.
pub fn assign(value: &Bound<'_, PyAny>, name: &str, shape: &[usize]) -> PyResult<Vec<f64>> {
    let py = value.py();
    let numpy = py.import("numpy")?;
    let converted = numpy.call_method1("ascontiguousarray", (value, "float64"))?;
    let array = converted.cast::<PyArrayDyn<f64>>()?;
    let given: Vec<usize> = array.shape().to_vec();
    let len: usize = shape.iter().product();
    let fits = given == shape || (given.iter().product::<usize>() == len && given.len() <= 1);
    if !fits {
        return Err(bad(format!("{name}: expected shape {shape:?}, got {given:?}")));
    }
    let readonly = array.try_readonly().map_err(|e| bad(format!("{name}: {e}")))?;
    let values = readonly.as_slice().map_err(|_| bad(format!("{name}: not contiguous")))?;
    Ok(values.to_vec())
}
