//! Bindings of `crate::synth` and `crate::dem` (filled by the synthesis issue).
use pyo3::prelude::*;

pub fn register(_m: &Bound<'_, PyModule>) -> PyResult<()> {
    Ok(())
}
