//! The library's [`Error`] as Python exceptions: one class per variant, defined in
//! `mcgv_video/errors.py` (so that each can also derive from the built-in exception a Python
//! caller expects: `ValueError` for bad input, `OSError` for files).

use mcgv_video::Error;
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use pyo3::types::PyTuple;

/// The Python exception of a library error.
pub fn to_py(error: Error) -> PyErr {
    Python::attach(|py| match raise(py, &error) {
        Ok(err) => err,
        // The errors module cannot be imported (a broken install): still an exception.
        Err(import) => PyRuntimeError::new_err(format!("{error} (and {import})")),
    })
}

fn raise(py: Python<'_>, error: &Error) -> PyResult<PyErr> {
    let module = py.import("mcgv_video.errors")?;
    let message = error.to_string();
    let class = |name: &str| module.getattr(name);
    let value = match error {
        Error::Io { path, source } => {
            let args = match source.raw_os_error() {
                Some(errno) => PyTuple::new(
                    py,
                    [
                        errno.into_pyobject(py)?.into_any(),
                        message.into_pyobject(py)?.into_any(),
                        path.display().to_string().into_pyobject(py)?.into_any(),
                    ],
                )?,
                None => PyTuple::new(py, [message.into_pyobject(py)?.into_any()])?,
            };
            let value = class("FileError")?.call1(args)?;
            value.setattr("filename", path.display().to_string())?;
            value
        }
        Error::Mesh(_) => class("MeshError")?.call1((message,))?,
        Error::Stream(_) => class("StreamError")?.call1((message,))?,
        Error::Codec(_) => class("CodecError")?.call1((message,))?,
        Error::InvalidOption { option, .. } => {
            let value = class("InvalidOptionError")?.call1((message,))?;
            value.setattr("option", *option)?;
            value
        }
        Error::Usage(_) => class("UsageError")?.call1((message,))?,
        Error::Atlas(_) => class("AtlasError")?.call1((message,))?,
        Error::Padding(_) => class("PaddingError")?.call1((message,))?,
    };
    Ok(PyErr::from_value(value))
}

/// `Result<T, Error>` → `PyResult<T>`.
pub trait IntoPy<T> {
    /// The error as its Python exception.
    fn py_err(self) -> PyResult<T>;
}

impl<T> IntoPy<T> for mcgv_video::Result<T> {
    fn py_err(self) -> PyResult<T> {
        self.map_err(to_py)
    }
}

/// An invalid option as Python's `InvalidOptionError`, by the keyword argument's name.
pub fn option(name: &'static str, message: impl Into<String>) -> PyErr {
    to_py(Error::option(name, message))
}
