//! The Python exceptions the bindings raise and the conversions from the library's typed errors:
//! a load error (file:line, element, what is wrong), an input error (a wrong length, an unknown
//! name, a non-finite value) and a simulation error (divergence, a refused step) each keep the
//! library's message.

use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyValueError};
use pyo3::prelude::*;

create_exception!(
    lagrange,
    LagrangeError,
    PyException,
    "Base class of the errors lagrange raises for loading and simulating."
);
create_exception!(
    lagrange,
    LoadError,
    LagrangeError,
    "A model file or text could not be loaded; the message names the file, line and element."
);
create_exception!(
    lagrange,
    SimulationError,
    LagrangeError,
    "A step failed (diverged, did not converge) or was refused after a failure until reset."
);
create_exception!(
    lagrange,
    InputError,
    PyValueError,
    "An argument does not fit the model: a wrong length, an unknown name or index, a non-finite value."
);

/// Adds the exception classes to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("LagrangeError", py.get_type::<LagrangeError>())?;
    m.add("LoadError", py.get_type::<LoadError>())?;
    m.add("SimulationError", py.get_type::<SimulationError>())?;
    m.add("InputError", py.get_type::<InputError>())?;
    Ok(())
}

/// A load error as `lagrange.LoadError`.
pub fn load(e: lagrange::io::LoadError) -> PyErr {
    LoadError::new_err(e.to_string())
}

/// A library input error as `lagrange.InputError` (a `ValueError`).
pub fn input(e: lagrange::error::InputError) -> PyErr {
    InputError::new_err(e.to_string())
}

/// A simulation error as `lagrange.SimulationError`.
pub fn sim(e: lagrange::sim::SimError) -> PyErr {
    SimulationError::new_err(e.to_string())
}

/// An argument of the bindings that does not fit (shape, value) as `lagrange.InputError`.
pub fn bad(message: String) -> PyErr {
    InputError::new_err(message)
}
