//! The PyO3 layer: `fractalgeo_rs._core`. Each domain registers its functions
//! from its own file; a binding converts arrays, releases the GIL around the
//! kernel (`py.detach`), runs it in a pool of `n_threads` and maps the error.
//! Nothing else lives here.
use crate::error::CoreError;
use pyo3::exceptions::{
    PyFileNotFoundError, PyMemoryError, PyOSError, PyRuntimeError, PyValueError,
};
use pyo3::prelude::*;

pub mod convert;
mod dem;
mod dimension;
pub mod geometry;
mod io;
mod lsystem;
mod progress;
mod radar;
mod radiometry;
mod synth;
mod tin;
mod transform;

impl From<CoreError> for PyErr {
    fn from(e: CoreError) -> PyErr {
        match e {
            CoreError::InvalidArgument { .. } => PyValueError::new_err(e.to_string()),
            CoreError::Io(_) | CoreError::System(_) => PyOSError::new_err(e.to_string()),
            CoreError::NotFound(_) => PyFileNotFoundError::new_err(e.to_string()),
            CoreError::OutOfMemory { .. } => PyMemoryError::new_err(e.to_string()),
            CoreError::Internal(_) => PyRuntimeError::new_err(e.to_string()),
        }
    }
}

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    dem::register(m)?;
    dimension::register(m)?;
    geometry::register(m)?;
    io::register(m)?;
    synth::register(m)?;
    lsystem::register(m)?;
    progress::register(m)?;
    transform::register(m)?;
    tin::register(m)?;
    radar::register(m)?;
    radiometry::register(m)?;
    Ok(())
}
