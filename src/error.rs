//! The typed error of the library's entry points that take user input after a model is loaded:
//! a slice of the wrong length, an index or name that is not in the model, a value that is not
//! finite. Each names the function, the argument, what was expected and what was given, so the
//! caller can fix the call (loading has [`LoadError`](crate::io::LoadError), a simulation that
//! fails has [`SimError`](crate::sim::SimError)).

use thiserror::Error;

/// Why a call was refused; nothing was computed or changed.
#[derive(Clone, Debug, Error, PartialEq)]
#[non_exhaustive]
pub enum InputError {
    /// A slice argument has the wrong length.
    #[error("{function}: {argument} has {got} values, the model needs {expected} ({size})")]
    Length {
        /// The function called (`aba`, `Model::spring_energy`, …).
        function: &'static str,
        /// The argument or buffer whose length is wrong (`q`, `tau`, `data.qpos`, …).
        argument: &'static str,
        /// The length the model needs.
        expected: usize,
        /// The length given.
        got: usize,
        /// The model's size the length must equal (`nq`, `nv`, `nu`, `na`, …).
        size: &'static str,
    },
    /// An index is not in the model or data.
    #[error("{function}: {what} {index} does not exist ({count} {what}s; indices 0..{count})")]
    Index {
        /// The function called.
        function: &'static str,
        /// What the index counts (`contact`, `frame`, …).
        what: &'static str,
        /// The index given.
        index: usize,
        /// How many there are.
        count: usize,
    },
    /// A name is not in the model.
    #[error("{function}: the model has no {what} named '{name}'{hint}")]
    Name {
        /// The function called.
        function: &'static str,
        /// What was looked up (`keyframe`, `body, link or site`, …).
        what: &'static str,
        /// The name given.
        name: String,
        /// Some of the names the model has, to pick from.
        hint: String,
    },
    /// A value is not finite.
    #[error("{function}: {argument}[{index}] is {value}, not a finite number")]
    NonFinite {
        /// The function called.
        function: &'static str,
        /// The argument holding the value.
        argument: &'static str,
        /// The value's index in the argument.
        index: usize,
        /// The value (NaN or ±∞).
        value: f64,
    },
    /// A value is outside what the function accepts (a step size of 0, negative or NaN; a zero ray
    /// direction; a frame that is not a site, …).
    #[error("{function}: {argument} {detail}")]
    Value {
        /// The function called.
        function: &'static str,
        /// The argument holding the value.
        argument: &'static str,
        /// What is wrong with it and what is accepted.
        detail: String,
    },
    /// The call asks for something lagrange does not compute yet (e.g. a distance to a height
    /// field).
    #[error("{function}: {what} is not supported{reason}")]
    Unsupported {
        /// The function called.
        function: &'static str,
        /// What is not supported.
        what: String,
        /// Why, with a leading separator (may be empty).
        reason: String,
    },
}

impl InputError {
    /// `Ok` when `got` equals `expected`, else [`InputError::Length`].
    #[inline]
    pub fn check_len(
        function: &'static str,
        argument: &'static str,
        got: usize,
        expected: usize,
        size: &'static str,
    ) -> Result<(), InputError> {
        if got == expected {
            Ok(())
        } else {
            Err(length_error(function, argument, expected, got, size))
        }
    }

    /// `Ok` when every value is finite, else [`InputError::NonFinite`] naming the first one.
    pub fn check_finite(
        function: &'static str,
        argument: &'static str,
        values: &[f64],
    ) -> Result<(), InputError> {
        match values.iter().position(|x| !x.is_finite()) {
            None => Ok(()),
            Some(index) => Err(InputError::NonFinite { function, argument, index, value: values[index] }),
        }
    }

    /// [`InputError::Name`] listing up to 8 of the names the model has.
    pub fn unknown_name<'a>(
        function: &'static str,
        what: &'static str,
        name: &str,
        known: impl Iterator<Item = &'a str>,
    ) -> InputError {
        let known: Vec<&str> = known.filter(|n| !n.is_empty()).collect();
        let hint = if known.is_empty() {
            format!(" (it has no named {what}s)")
        } else {
            let more = if known.len() > 8 { ", …" } else { "" };
            format!(
                " (it has: {}{more})",
                known.iter().take(8).map(|n| format!("'{n}'")).collect::<Vec<_>>().join(", ")
            )
        };
        InputError::Name { function, what, name: name.to_string(), hint }
    }
}

/// [`InputError::Length`], built out of the kernels' hot path.
#[cold]
#[inline(never)]
fn length_error(
    function: &'static str,
    argument: &'static str,
    expected: usize,
    got: usize,
    size: &'static str,
) -> InputError {
    InputError::Length { function, argument, expected, got, size }
}

/// The checks of a kernel's arguments (crate-internal): `data` made for `model`, and the lengths
/// of q (nq), v-like vectors (nv).
pub(crate) mod check {
    use super::InputError;
    use crate::model::{Data, Model};

    /// `data`'s kinematic buffers have `model`'s body and dof counts.
    #[inline]
    pub fn data(function: &'static str, model: &Model, data: &Data) -> Result<(), InputError> {
        InputError::check_len(function, "data (bodies)", data.x_world_body.len(), model.nbody(), "nbody")?;
        InputError::check_len(function, "data (dofs)", data.tau.len(), model.nv, "nv")
    }

    /// A configuration: nq values.
    #[inline]
    pub fn q(function: &'static str, model: &Model, q: &[f64]) -> Result<(), InputError> {
        InputError::check_len(function, "q", q.len(), model.nq, "nq")
    }

    /// A frame index of the model.
    pub fn frame(function: &'static str, model: &Model, frame: usize) -> Result<(), InputError> {
        let count = model.frames.len();
        if frame < count {
            Ok(())
        } else {
            Err(InputError::Index { function, what: "frame", index: frame, count })
        }
    }

    /// A velocity, acceleration or generalized force named `argument`: nv values.
    #[inline]
    pub fn v(
        function: &'static str,
        argument: &'static str,
        model: &Model,
        v: &[f64],
    ) -> Result<(), InputError> {
        InputError::check_len(function, argument, v.len(), model.nv, "nv")
    }
}
