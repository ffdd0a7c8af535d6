//! Python bindings of lagrange: the extension module `lagrange._lagrange` that the Python package
//! `lagrange` (python/lagrange/) re-exports, built by maturin (python/pyproject.toml).
//!
//! The idioms follow MuJoCo's Python bindings for the model, the data and the pipeline
//! (`lagrange.forward(m, d)`, `lagrange.step(m, d)`, `d.qpos` a NumPy view of the state) and
//! Pinocchio's for the kernels (`lagrange.rnea(m, d, q, v, a)`, `crba`, `aba`, frame Jacobians
//! with linear rows first). `docs/python.md` is the user documentation.

use pyo3::prelude::*;

mod arrays;
mod contact;
mod data;
mod error;
mod functions;
mod model;
mod rollout;
mod view;

/// The extension module: classes, functions and exceptions.
#[pymodule]
fn _lagrange(m: &Bound<'_, PyModule>) -> PyResult<()> {
    error::register(m)?;
    m.add_class::<model::PyModel>()?;
    m.add_class::<model::PyOptions>()?;
    m.add_class::<data::PyData>()?;
    m.add_class::<contact::PyContact>()?;
    functions::register(m)?;
    m.add_function(wrap_pyfunction!(rollout::rollout, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
